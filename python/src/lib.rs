//! `hooke._hooke`: the extension module behind the `hooke` Python package. It holds a built
//! scene and steps it with the same code as the `hooke` command (so a trajectory stepped
//! from Python is the command's, bit for bit), releases the GIL while stepping, answers
//! Ctrl-C between steps, and hands positions, renders and exports to numpy and files.
//!
//! The Python half (`hooke/__init__.py`) re-exports this and adds `sweep`.

mod errors;
mod scene_load;

use errors::{DivergenceError, HookeError, error};
use scene_load::load;

use hooke::driver;
use hooke::export::{FolderFormat, Target};
use hooke::image_out::View;
use hooke_core::Vec3;
use hooke_scene::Scene;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::Path;
use std::sync::{Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

/// Longest a stretch of stepping runs without the GIL before Python's signal handlers get a
/// turn (so Ctrl-C interrupts a long `advance` within this time).
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// What a second thread is told while a simulation is busy.
const IN_USE: &str = "this Simulation is in use by another thread (stepping, rendering or \
                      exporting); a Simulation serves one thread at a time: wait for that call \
                      to return, or load one Simulation per thread";

/// A scene being simulated: positions and velocities as numpy arrays, stepping, rendering,
/// exporting. One thread uses it at a time: a call from a second thread while another's
/// runs raises `HookeError`.
#[pyclass(module = "hooke", frozen)]
struct Simulation {
    /// The scene and its pool, held by one call at a time (its steps run without the GIL).
    inner: Mutex<Inner>,
    /// The source it was loaded from, for its repr.
    source: String,
    /// The files it was built from (scene file, meshes), which no export may replace.
    inputs: Vec<(String, std::path::PathBuf)>,
}

/// A simulation's state.
struct Inner {
    scene: Scene,
    /// A pool of the requested size, when `threads` was given; otherwise rayon's global one.
    pool: Option<rayon::ThreadPool>,
}

impl Simulation {
    /// The state, or `HookeError` while another thread's call holds it.
    fn lock(&self) -> PyResult<MutexGuard<'_, Inner>> {
        match self.inner.try_lock() {
            Ok(inner) => Ok(inner),
            // A panic in a call leaves the scene as its last whole step left it.
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(HookeError::new_err(IN_USE)),
        }
    }

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
}

impl Inner {
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
                    Ok::<u64, hooke_core::Divergence>(done)
                })
            });
            // What the steps could not keep of the run's promises (a surface through a
            // collider) is a Python warning, as the command line's is a printed one.
            for n in self.scene.simulation.take_notices() {
                let message =
                    std::ffi::CString::new(driver::describe(&self.scene, &n)).unwrap_or_default();
                PyErr::warn(
                    py,
                    &py.get_type::<pyo3::exceptions::PyRuntimeWarning>(),
                    &message,
                    1,
                )?;
            }
            left -= done.map_err(|e| error(e.into()))?;
            py.check_signals()?;
        }
        Ok(())
    }
}

/// A body as shown: its vertices and its triangles.
type Shown<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// A read-only numpy array of shape `(N, 3)` holding the vectors `v`.
fn matrix<'py>(py: Python<'py>, v: &[Vec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let values: Vec<f64> = v.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let array = PyArray1::from_vec(py, values).reshape([v.len(), 3])?;
    read_only(array.as_any())?;
    Ok(array)
}

/// A whole number `value` given as argument `name`, from `min` to `max`: one outside is a
/// `HookeError` that says what was expected, as any bad value is (a negative count would
/// otherwise be Python's bare `OverflowError`).
fn whole(value: i64, name: &str, min: u64, max: u64) -> PyResult<u64> {
    match u64::try_from(value) {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(HookeError::new_err(format!(
            "{name}: expected a whole number from {min} to {max}, found {value}"
        ))),
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
    fn step(&self, py: Python<'_>, n: i64) -> PyResult<()> {
        let n = whole(n, "step", 0, driver::MAX_STILL_STEPS as u64)?;
        self.lock()?.run_steps(py, n)
    }

    /// Advances by `seconds` of simulated time: the whole number of steps nearest to
    /// `seconds / dt`.
    fn advance(&self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        let mut inner = self.lock()?;
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "advance: expected a time in seconds >= 0, found {seconds}"
            )));
        }
        let steps = driver::steps_for(&inner.scene, seconds);
        if steps as f64 > driver::MAX_STILL_STEPS {
            return Err(PyValueError::new_err(format!(
                "advance: {seconds} s is {steps:.1e} steps of dt = {} s, more than the {:.0e} a \
                 call may take",
                inner.scene.simulation.dt(),
                driver::MAX_STILL_STEPS
            )));
        }
        inner.run_steps(py, steps)
    }

    /// Runs to the end of the scene's run (its `duration` or `steps`), if not there yet.
    fn run(&self, py: Python<'_>) -> PyResult<()> {
        let mut inner = self.lock()?;
        let left = inner
            .scene
            .steps
            .saturating_sub(inner.scene.simulation.steps());
        inner.run_steps(py, left)
    }

    /// Simulated time in seconds.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock()?.scene.simulation.time())
    }

    /// Steps taken so far.
    #[getter]
    fn steps_taken(&self) -> PyResult<u64> {
        Ok(self.lock()?.scene.simulation.steps())
    }

    /// Steps so far that the large-step integrator ended at its iteration budget before its
    /// stopping rule was met (docs/physics.md §4.1, "Stopping rule and accuracy"): zero for
    /// the explicit integrators.
    #[getter]
    fn unsolved_steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.scene.simulation.unsolved().steps)
    }

    /// The step size in seconds.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.lock()?.scene.simulation.dt())
    }

    /// The integrator's name.
    #[getter]
    fn integrator(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.scene.simulation.integrator().name())
    }

    /// Steps in the scene's whole run.
    #[getter]
    fn total_steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.scene.steps)
    }

    /// A frame every this many steps, as the command writes them.
    #[getter]
    fn every(&self) -> PyResult<u64> {
        Ok(self.lock()?.scene.every)
    }

    /// Positions in metres, an `(N, 3)` float64 array: a read-only copy of the state now.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, &self.lock()?.scene.simulation.particles().x)
    }

    /// Velocities in m/s, an `(N, 3)` float64 array: a read-only copy of the state now.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, &self.lock()?.scene.simulation.particles().v)
    }

    /// Masses in kg, an `(N,)` float64 array (read-only).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let array = PyArray1::from_slice(py, &self.lock()?.scene.simulation.particles().mass);
        read_only(array.as_any())?;
        Ok(array)
    }

    /// Which particles are pinned, an `(N,)` bool array (read-only).
    #[getter]
    fn pinned<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let inner = self.lock()?;
        let p = inner.scene.simulation.particles();
        let pinned: Vec<bool> = (0..p.len()).map(|i| p.is_pinned(i)).collect();
        let array = PyArray1::from_vec(py, pinned);
        read_only(array.as_any())?;
        Ok(array)
    }

    /// The springs' end particles, an `(M, 2)` int64 array (read-only), in the model's order.
    #[getter]
    fn springs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let inner = self.lock()?;
        let springs = &inner.scene.simulation.model().springs;
        let ends: Vec<i64> = springs
            .iter()
            .flat_map(|s| [i64::from(s.i), i64::from(s.j)])
            .collect();
        let array = PyArray1::from_vec(py, ends).reshape([springs.len(), 2])?;
        read_only(array.as_any())?;
        Ok(array)
    }

    /// The bodies' surface triangles, an `(F, 3)` int64 array of particle indices (rows of
    /// `positions`), read-only: every body's, in the scene's order; a body made from a mesh
    /// has its faces cut into triangles (quads along their shorter diagonal).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let inner = self.lock()?;
        let triangles: Vec<[u32; 3]> = inner
            .scene
            .bodies
            .iter()
            .flat_map(|b| b.triangles.iter().copied())
            .collect();
        let flat: Vec<i64> = triangles.iter().flatten().map(|&i| i64::from(i)).collect();
        let array = PyArray1::from_vec(py, flat).reshape([triangles.len(), 3])?;
        read_only(array.as_any())?;
        Ok(array)
    }

    /// Body `name` as it is shown and exported: `(vertices, triangles)`, a `(V, 3)` float64
    /// array of its vertices now and a `(T, 3)` int64 array of rows of it. A body made from a
    /// mesh has its file's vertices in their count and order (its faces as fans of
    /// triangles); any other, its particles and surface triangles.
    fn mesh<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Shown<'py>> {
        let inner = self.lock()?;
        let scene = &inner.scene;
        let Some(body) = scene.bodies.iter().find(|b| b.name == name) else {
            let names: Vec<&str> = scene.bodies.iter().map(|b| b.name.as_str()).collect();
            return Err(HookeError::new_err(format!(
                "the scene has no body '{name}'; its bodies: {}",
                names.join(", ")
            )));
        };
        let mut x = Vec::new();
        body.vertices(&scene.simulation.particles().x, &mut x);
        let triangles = body.face_triangles();
        let flat: Vec<i64> = triangles.iter().flatten().map(|&i| i64::from(i)).collect();
        let faces = PyArray1::from_vec(py, flat).reshape([triangles.len(), 3])?;
        read_only(faces.as_any())?;
        Ok((matrix(py, &x)?, faces))
    }

    /// The bodies: a list of `(name, first particle, particle count)`.
    #[getter]
    fn bodies(&self) -> PyResult<Vec<(String, usize, usize)>> {
        Ok(self
            .lock()?
            .scene
            .bodies
            .iter()
            .map(|b| (b.name.clone(), b.range.start, b.range.len()))
            .collect())
    }

    /// Where collider `k` (in the scene file's order) is now: `(translate, rotate)`, metres
    /// and degrees about x, then y, then z, relative to where the scene placed it; `None` for
    /// a collider that does not move (docs/physics.md §2.1).
    #[allow(clippy::type_complexity)]
    fn collider_pose(&self, k: usize) -> PyResult<Option<([f64; 3], [f64; 3])>> {
        let inner = self.lock()?;
        let scene = &inner.scene;
        if k >= scene.colliders.len() {
            return Err(HookeError::new_err(format!(
                "collider {k}: the scene has {} (0 to {})",
                scene.colliders.len(),
                scene.colliders.len().saturating_sub(1)
            )));
        }
        Ok(scene
            .collider_pose(k, scene.simulation.time())
            .map(|pose| (pose.translate.into(), pose.rotate.into())))
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> PyResult<String> {
        Ok(self.lock()?.scene.spec.name.clone())
    }

    /// The scene as it stands now drawn by Hooke's rasterizer: an `(height, width, 3)`
    /// uint8 array. `style` is `solid`, `springs` or `both`; `yaw` and `pitch` in degrees
    /// turn the camera about the scene; `zoom` multiplies the framing distance (below 1
    /// moves closer); `supersample` is 1 to 4 samples per pixel along each axis;
    /// `distance` places the camera that many metres from the framed centre; `color` is
    /// `"none"`, `"strain"` (%), `"speed"` (m/s) or `"gap"` (m), drawn with a legend over
    /// `range` (`(lo, hi)`, default the frame's own rounded up); `shadows` casts the key
    /// light's shadows.
    #[pyo3(signature = (width = 800, height = 600, style = "solid", yaw = 30.0, pitch = 22.0, zoom = 1.0, supersample = 2, distance = None, color = "none", range = None, shadows = true))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: i64,
        height: i64,
        style: &str,
        yaw: f64,
        pitch: f64,
        zoom: f64,
        supersample: i64,
        distance: Option<f64>,
        color: &str,
        range: Option<(f64, f64)>,
        shadows: bool,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        let supersample = whole(supersample, "supersample", 1, 4)? as u32;
        let width = whole(width, "width", 1, u64::from(u32::MAX))? as u32;
        let height = whole(height, "height", 1, u64::from(u32::MAX))? as u32;
        let mut view = View::checked((width, height), style, (yaw, pitch), zoom, supersample)
            .map_err(error)?;
        view.color = hooke::quantity::ColorBy::from_name(color).ok_or_else(|| {
            HookeError::new_err(format!(
                "color: expected none, strain, speed or gap, found '{color}'"
            ))
        })?;
        if let Some(d) = distance
            && !(d.is_finite() && (1e-3..=1e6).contains(&d))
        {
            return Err(HookeError::new_err(format!(
                "distance: expected metres from 0.001 to 1e6, found {d}"
            )));
        }
        if let Some((lo, hi)) = range
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            return Err(HookeError::new_err(format!(
                "range: expected (lo, hi) with finite lo below hi, found ({lo}, {hi})"
            )));
        }
        view.distance = distance;
        view.range = range;
        view.shadows = shadows;
        let inner = self.lock()?;
        let (scene, pool) = (&inner.scene, inner.pool.as_ref());
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
    /// in `/` with `format` `"ply"` or `"obj"` (a file per frame) or `"pc2"` (a point cache
    /// per body). Returns what was written. Frame 0 is the state now.
    #[pyo3(signature = (path, format = None, body = None))]
    fn export(
        &self,
        py: Python<'_>,
        path: &str,
        format: Option<&str>,
        body: Option<&str>,
    ) -> PyResult<String> {
        let format = match format {
            None => None,
            Some("ply") => Some(FolderFormat::Ply),
            Some("obj") => Some(FolderFormat::Obj),
            Some("pc2") => Some(FolderFormat::Pc2),
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "format: expected \"ply\", \"obj\" or \"pc2\", found {other:?}"
                )));
            }
        };
        let target = Target::new(Path::new(path), format, body).map_err(error)?;
        // No export replaces a file the simulation was built from.
        let mut claims = hooke::output::claims::Claims::with_inputs(self.inputs.clone());
        target.claim(&mut claims);
        let mut inner = self.lock()?;
        target
            .claim_bodies(&inner.scene, &mut claims)
            .map_err(error)?;
        claims.check().map_err(error)?;
        let mut exporter = hooke::export::create(&target, &inner.scene).map_err(error)?;
        let left = inner
            .scene
            .steps
            .saturating_sub(inner.scene.simulation.steps());
        let every = inner.scene.every;
        exporter.frame(0, &inner.scene).map_err(error)?;
        let mut frame = 0;
        let mut stepped = 0;
        while stepped < left {
            let n = every.min(left - stepped);
            inner.run_steps(py, n)?;
            stepped += n;
            if n == every {
                frame += 1;
                exporter.frame(frame, &inner.scene).map_err(error)?;
            }
        }
        exporter.finish().map_err(error)
    }

    fn __repr__(&self) -> String {
        let Ok(inner) = self.lock() else {
            return format!(
                "<hooke.Simulation from {:?}: in use by another thread>",
                self.source
            );
        };
        let sim = &inner.scene.simulation;
        format!(
            "<hooke.Simulation '{}' from {:?}: {} particles, {} springs, {} dt = {} s, t = {} s>",
            inner.scene.spec.name,
            self.source,
            sim.particles().len(),
            sim.model().springs.len(),
            sim.integrator(),
            sim.dt(),
            sim.time()
        )
    }
}

/// The built-in scenes: a dict of name to one-line description.
#[pyfunction]
fn scenes() -> Vec<(String, String)> {
    hooke_scene::builtin::BUILTINS
        .iter()
        .map(|(name, make)| (name.to_string(), make().description))
        .collect()
}

/// Runs the checks of `hooke report` and writes the page into `dir`: `dir/index.html`,
/// its plots, and every number in `dir/report.json`. Returns the page's path and the
/// failed checks (empty when all passed). Runs without the GIL.
#[pyfunction]
#[pyo3(signature = (dir, *, quick = false))]
fn report(py: Python<'_>, dir: std::path::PathBuf, quick: bool) -> PyResult<(String, Vec<String>)> {
    let outcome = py
        .detach(|| hooke::report::write(&dir, &hooke::report::Options { quick }))
        .map_err(error)?;
    Ok((
        outcome.page.to_string_lossy().into_owned(),
        outcome.failures,
    ))
}

/// Hooke: mass-spring simulation you can trust.
#[pymodule]
fn _hooke(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    m.add("HookeError", m.py().get_type::<HookeError>())?;
    m.add("DivergenceError", m.py().get_type::<DivergenceError>())?;
    Ok(())
}
