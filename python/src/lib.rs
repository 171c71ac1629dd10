//! `hooke._hooke`: the extension module behind the `hooke` Python package. It holds a built
//! scene and steps it with the same code as the `hooke` command (so a trajectory stepped
//! from Python is the command's, bit for bit), releases the GIL while stepping, answers
//! Ctrl-C between steps, and hands positions, renders and exports to numpy and files.
//!
//! The Python half (`hooke/__init__.py`) re-exports this and adds `sweep`.

use hooke_cli::export::{Exporter, FolderFormat, Target};
use hooke_cli::image_out::View;
use hooke_cli::{driver, source};
use hooke_core::{Divergence, Integrator, Vec3};
use hooke_scene::{Overrides, Scene};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::Path;
use std::time::{Duration, Instant};

create_exception!(
    hooke,
    HookeError,
    PyException,
    "A scene, file or value Hooke cannot use; the message names the file and line or the key."
);
create_exception!(
    hooke,
    DivergenceError,
    HookeError,
    "A run stopped because its state stopped making sense; the message names the step, the \
     particle and a stable step size."
);

/// A Rust error as the Python exception that says the same as the command would.
fn error(e: anyhow::Error) -> PyErr {
    let message = format!("{e:#}");
    if e.chain().any(|c| c.downcast_ref::<Divergence>().is_some()) {
        DivergenceError::new_err(message)
    } else {
        HookeError::new_err(message)
    }
}

/// Longest a stretch of stepping runs without the GIL before Python's signal handlers get a
/// turn (so Ctrl-C interrupts a long `advance` within this time).
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// A scene being simulated: positions and velocities as numpy arrays, stepping, rendering,
/// exporting.
#[pyclass(module = "hooke")]
struct Simulation {
    scene: Scene,
    /// The source it was loaded from, for its repr.
    source: String,
    /// A pool of the requested size, when `threads` was given; otherwise rayon's global one.
    pool: Option<rayon::ThreadPool>,
}

impl Simulation {
    /// Runs `f` on a worker of this simulation's pool, or of rayon's global one: the
    /// solver's parallel loops are then cheap joins, and a stretch of steps moves to the
    /// pool once, not once per step.
    fn on_pool<T: Send>(pool: Option<&rayon::ThreadPool>, f: impl FnOnce() -> T + Send) -> T {
        match pool {
            Some(pool) => pool.install(f),
            // From outside the pool, `join` runs its first closure on a global worker.
            None => rayon::join(f, || ()).0,
        }
    }

    /// Steps `n` times with the GIL released, in stretches of at most [`SIGNAL_CHECK`];
    /// between stretches Python's signal handlers run, and a `KeyboardInterrupt` stops the
    /// run after a whole step.
    fn run_steps(&mut self, py: Python<'_>, n: u64) -> PyResult<()> {
        let mut left = n;
        while left > 0 {
            // One step hops onto the pool by itself when its system needs the pool (see
            // `hooke_core::Simulation::step`); a stretch of steps hops once here.
            let pool = if left == 1 && self.pool.is_none() {
                Pool::Here
            } else {
                Pool::Worker(self.pool.as_ref())
            };
            let scene = &mut self.scene;
            let done = py.detach(|| {
                pool.run(|| {
                    let started = Instant::now();
                    let mut done = 0;
                    while done < left {
                        scene.simulation.step()?;
                        done += 1;
                        if done % 16 == 0 && started.elapsed() > SIGNAL_CHECK {
                            break;
                        }
                    }
                    Ok::<u64, Divergence>(done)
                })
            });
            left -= done.map_err(|e| error(e.into()))?;
            py.check_signals()?;
        }
        Ok(())
    }

    /// A read-only numpy array of shape `(N, 3)` holding the vectors `v`.
    fn matrix<'py>(py: Python<'py>, v: &[Vec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let values: Vec<f64> = v.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        let array = PyArray1::from_vec(py, values).reshape([v.len(), 3])?;
        read_only(array.as_any())?;
        Ok(array)
    }
}

/// Where a stretch of steps runs.
#[derive(Clone, Copy)]
enum Pool<'a> {
    /// On the calling thread.
    Here,
    /// On a worker of this pool, or of rayon's global one.
    Worker(Option<&'a rayon::ThreadPool>),
}

impl Pool<'_> {
    fn run<T: Send>(self, f: impl FnOnce() -> T + Send) -> T {
        match self {
            Self::Here => f(),
            Self::Worker(pool) => Simulation::on_pool(pool, f),
        }
    }
}

/// Marks a numpy array read-only: it is a snapshot, and writing to it would change nothing.
fn read_only(array: &Bound<'_, PyAny>) -> PyResult<()> {
    array.getattr("flags")?.setattr("writeable", false)
}

#[pymethods]
impl Simulation {
    /// Advances `n` steps (default 1). Raises `DivergenceError` when the state stops making
    /// sense, and `KeyboardInterrupt` on Ctrl-C (after a whole step).
    #[pyo3(signature = (n = 1))]
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<()> {
        self.run_steps(py, n)
    }

    /// Advances by `seconds` of simulated time: the whole number of steps nearest to
    /// `seconds / dt`.
    fn advance(&mut self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "advance: expected a time in seconds >= 0, found {seconds}"
            )));
        }
        let steps = driver::steps_for(&self.scene, seconds);
        if steps as f64 > driver::MAX_STILL_STEPS {
            return Err(PyValueError::new_err(format!(
                "advance: {seconds} s is {steps:.1e} steps of dt = {} s, more than the {:.0e} a \
                 call may take",
                self.scene.simulation.dt(),
                driver::MAX_STILL_STEPS
            )));
        }
        self.run_steps(py, steps)
    }

    /// Runs to the end of the scene's run (its `duration` or `steps`), if not there yet.
    fn run(&mut self, py: Python<'_>) -> PyResult<()> {
        let left = self
            .scene
            .steps
            .saturating_sub(self.scene.simulation.steps());
        self.run_steps(py, left)
    }

    /// Simulated time in seconds.
    #[getter]
    fn time(&self) -> f64 {
        self.scene.simulation.time()
    }

    /// Steps taken so far.
    #[getter]
    fn steps_taken(&self) -> u64 {
        self.scene.simulation.steps()
    }

    /// The step size in seconds.
    #[getter]
    fn dt(&self) -> f64 {
        self.scene.simulation.dt()
    }

    /// The integrator's name.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.scene.simulation.integrator().name()
    }

    /// Steps in the scene's whole run.
    #[getter]
    fn total_steps(&self) -> u64 {
        self.scene.steps
    }

    /// A frame every this many steps, as the command writes them.
    #[getter]
    fn every(&self) -> u64 {
        self.scene.every
    }

    /// Positions in metres, an `(N, 3)` float64 array: a read-only copy of the state now.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Self::matrix(py, &self.scene.simulation.particles().x)
    }

    /// Velocities in m/s, an `(N, 3)` float64 array: a read-only copy of the state now.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Self::matrix(py, &self.scene.simulation.particles().v)
    }

    /// Masses in kg, an `(N,)` float64 array (read-only).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let array = PyArray1::from_slice(py, &self.scene.simulation.particles().mass);
        read_only(array.as_any())?;
        Ok(array)
    }

    /// Which particles are pinned, an `(N,)` bool array (read-only).
    #[getter]
    fn pinned<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let p = self.scene.simulation.particles();
        let pinned: Vec<bool> = (0..p.len()).map(|i| p.is_pinned(i)).collect();
        let array = PyArray1::from_vec(py, pinned);
        read_only(array.as_any())?;
        Ok(array)
    }

    /// The springs' end particles, an `(M, 2)` int64 array (read-only), in the model's order.
    #[getter]
    fn springs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let springs = &self.scene.simulation.model().springs;
        let ends: Vec<i64> = springs
            .iter()
            .flat_map(|s| [i64::from(s.i), i64::from(s.j)])
            .collect();
        let array = PyArray1::from_vec(py, ends).reshape([springs.len(), 2])?;
        read_only(array.as_any())?;
        Ok(array)
    }

    /// The bodies: a list of `(name, first particle, particle count)`.
    #[getter]
    fn bodies(&self) -> Vec<(String, usize, usize)> {
        self.scene
            .bodies
            .iter()
            .map(|b| (b.name.clone(), b.range.start, b.range.len()))
            .collect()
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.scene.spec.name.clone()
    }

    /// The scene as it stands now drawn by Hooke's rasterizer: an `(height, width, 3)`
    /// uint8 array. `style` is `solid`, `springs` or `both`; `yaw` and `pitch` in degrees
    /// turn the camera about the scene; `zoom` multiplies the framing distance (below 1
    /// moves closer); `supersample` is 1 to 4 samples per pixel along each axis.
    #[pyo3(signature = (width = 800, height = 600, style = "solid", yaw = 30.0, pitch = 22.0, zoom = 1.0, supersample = 2))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
        style: &str,
        yaw: f64,
        pitch: f64,
        zoom: f64,
        supersample: u32,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        let view = View::checked((width, height), style, (yaw, pitch), zoom, supersample)
            .map_err(error)?;
        let (scene, pool) = (&self.scene, self.pool.as_ref());
        let rgb = py.detach(|| {
            Self::on_pool(pool, || {
                let image = view.pixels(scene, &view.camera(scene));
                image
                    .pixels()
                    .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
                    .collect::<Vec<u8>>()
            })
        });
        let array = PyArray1::from_vec(py, rgb).reshape([height as usize, width as usize, 3])?;
        Ok(array)
    }

    /// Runs the rest of the scene's run (from now to its end) writing its frames as
    /// `hooke run --export` does: `PATH.usda`, `PATH.pc2` (with `body`), or a folder ending
    /// in `/` with `format` `"ply"` or `"obj"`. Returns what was written. Frame 0 is the
    /// state now.
    #[pyo3(signature = (path, format = None, body = None))]
    fn export(
        &mut self,
        py: Python<'_>,
        path: &str,
        format: Option<&str>,
        body: Option<&str>,
    ) -> PyResult<String> {
        let format = match format {
            None => None,
            Some("ply") => Some(FolderFormat::Ply),
            Some("obj") => Some(FolderFormat::Obj),
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "format: expected \"ply\" or \"obj\", found {other:?}"
                )));
            }
        };
        let target = Target::new(Path::new(path), format, body).map_err(error)?;
        let mut exporter = Exporter::create(&target, &self.scene).map_err(error)?;
        let left = self
            .scene
            .steps
            .saturating_sub(self.scene.simulation.steps());
        let every = self.scene.every;
        exporter.frame(0, &self.scene).map_err(error)?;
        let mut frame = 0;
        let mut stepped = 0;
        while stepped < left {
            let n = every.min(left - stepped);
            self.run_steps(py, n)?;
            stepped += n;
            if n == every {
                frame += 1;
                exporter.frame(frame, &self.scene).map_err(error)?;
            }
        }
        exporter.finish().map_err(error)
    }

    fn __repr__(&self) -> String {
        let sim = &self.scene.simulation;
        format!(
            "<hooke.Simulation '{}' from {:?}: {} particles, {} springs, {} dt = {} s, t = {} s>",
            self.scene.spec.name,
            self.source,
            sim.particles().len(),
            sim.model().springs.len(),
            sim.integrator(),
            sim.dt(),
            sim.time()
        )
    }
}

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
#[pyo3(signature = (source, *, dt = None, integrator = None, steps = None, duration = None, every = None, table = None, threads = None, set = None))]
#[allow(clippy::too_many_arguments)]
fn load(
    source: &str,
    dt: Option<f64>,
    integrator: Option<&str>,
    steps: Option<u64>,
    duration: Option<f64>,
    every: Option<u64>,
    table: Option<&str>,
    threads: Option<usize>,
    set: Option<&Bound<'_, PyDict>>,
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
    if steps == Some(0) || every == Some(0) {
        return Err(HookeError::new_err("steps and every: expected at least 1"));
    }
    let table = table.map(source::table).transpose().map_err(error)?;
    let overrides = Overrides {
        integrator,
        dt: positive("dt", dt)?,
        steps,
        duration: positive("duration", duration)?,
        every,
        table,
    };
    let mut read = source::read(source).map_err(error)?;
    if let Some(set) = set {
        for (key, value) in set.iter() {
            let key: String = key.extract()?;
            read.spec
                .set(&key, toml_value(&value)?)
                .map_err(|e| error(anyhow::Error::new(e).context(format!("scene '{source}'"))))?;
        }
    }
    let pool = match threads {
        None => None,
        Some(0) => return Err(HookeError::new_err("threads: expected at least 1")),
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| HookeError::new_err(format!("threads: {e}")))?,
        ),
    };
    let scene = Simulation::on_pool(pool.as_ref(), || {
        source::build_from(read, source, &overrides)
    })
    .map_err(error)?;
    Ok(Simulation {
        scene,
        source: source.to_string(),
        pool,
    })
}

/// The built-in scenes: a dict of name to one-line description.
#[pyfunction]
fn scenes() -> Vec<(String, String)> {
    hooke_scene::builtin::BUILTINS
        .iter()
        .map(|(name, make)| (name.to_string(), make().description))
        .collect()
}

/// Hooke: mass-spring simulation you can trust.
#[pymodule]
fn _hooke(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add("HookeError", m.py().get_type::<HookeError>())?;
    m.add("DivergenceError", m.py().get_type::<DivergenceError>())?;
    Ok(())
}
