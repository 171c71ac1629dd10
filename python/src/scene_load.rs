//! `hooke.load`: a scene from a name or a file, with the command line's overrides and
//! scene-file keys set from a dict.

use crate::errors::{HookeError, error};
use crate::{Inner, Simulation, whole};
use hooke::source;
use hooke_core::Integrator;
use hooke_scene::Overrides;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::Mutex;

/// A Python value as a TOML value for a scene key.
fn toml_value(value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = value.extract::<bool>() {
        return Ok(toml::Value::Boolean(b));
    }
    if let Ok(i) = value.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = value.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    if let Ok(s) = value.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    if let Ok(list) = value.cast::<PyList>() {
        return list
            .iter()
            .map(|item| toml_value(&item))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    Err(PyValueError::new_err(format!(
        "expected a number, string, bool or list for a scene key, found {}",
        value.get_type().name()?
    )))
}

/// Loads a scene: a built-in name (see `scenes()`), a `.toml` scene or a `.w` jello world,
/// with the command line's overrides, and `set`, a dict of scene-file keys to values
/// (`{"body.springs.structural.ks": 500.0}`) applied before the overrides.
#[pyfunction]
#[pyo3(signature = (source, *, dt = None, integrator = None, steps = None, duration = None, every = None, table = None, threads = None, set = None, tolerance = None, iterations = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn load(
    source: &str,
    dt: Option<f64>,
    integrator: Option<&str>,
    steps: Option<i64>,
    duration: Option<f64>,
    every: Option<i64>,
    table: Option<&str>,
    threads: Option<i64>,
    set: Option<&Bound<'_, PyDict>>,
    tolerance: Option<f64>,
    iterations: Option<i64>,
) -> PyResult<Simulation> {
    let integrator = integrator
        .map(|name| name.parse::<Integrator>())
        .transpose()
        .map_err(|e| HookeError::new_err(format!("integrator: {e}")))?;
    let positive = |name: &str, x: Option<f64>| match x {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(HookeError::new_err(format!(
            "{name}: expected a finite number of seconds > 0, found {x}"
        ))),
        _ => Ok(x),
    };
    let steps = steps
        .map(|n| whole(n, "steps", 1, hooke_scene::MAX_STEPS))
        .transpose()?;
    let every = every
        .map(|n| whole(n, "every", 1, hooke_scene::MAX_STEPS))
        .transpose()?;
    let iterations = iterations
        .map(|n| whole(n, "iterations", 1, u64::MAX))
        .transpose()?;
    let tolerance = match tolerance {
        Some(t) if !(t.is_finite() && t > 0.0) => {
            return Err(HookeError::new_err(format!(
                "tolerance: expected a finite speed in m/s > 0, found {t}"
            )));
        }
        t => t,
    };
    let table = table.map(source::table).transpose().map_err(error)?;
    let overrides = Overrides {
        integrator,
        dt: positive("dt", dt)?,
        steps,
        duration: positive("duration", duration)?,
        every,
        table,
        tolerance,
        iterations,
    };
    let mut read = source::read(source).map_err(error)?;
    if let Some(set) = set {
        for (key, value) in set.iter() {
            let key: String = key.extract()?;
            read.spec
                .set(&key, toml_value(&value)?)
                .map_err(|e| error(hooke::Error::from(e).context(format!("scene '{source}'"))))?;
        }
    }
    let threads = threads
        .map(|t| whole(t, "threads", 0, u64::MAX).map(|n| n as usize))
        .transpose()?;
    let pool = match threads {
        None => {
            // rayon's global pool reads RAYON_NUM_THREADS: bounded like `threads`.
            hooke::threads::from_environment().map_err(error)?;
            None
        }
        Some(n) => Some(hooke::threads::pool(Some(n), "threads").map_err(error)?),
    };
    let prepared = source::prepare(read, source, &overrides).map_err(error)?;
    let inputs = prepared.inputs();
    let scene = Simulation::on_pool(pool.as_ref(), || source::build_prepared(prepared, source))
        .map_err(error)?;
    Ok(Simulation {
        inner: Mutex::new(Inner { scene, pool }),
        source: source.to_string(),
        inputs,
    })
}
