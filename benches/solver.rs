//! Solver benches: a step in each compilation of the spring loop the CPU runs, and one
//! step of each integrator, on the cloth-N workload
//! (`docs/benchmarks.md`) and on a public jello world.
//!
//! `cargo bench -p hooke-tests --bench solver`; figures in `benches/README.md`.

#![allow(
    missing_docs,
    reason = "criterion_group! generates undocumented functions"
)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use hooke_core::{Integrator, Kernel};
use hooke_scene::{Overrides, Scene};
use std::hint::black_box;
use std::path::Path;

fn cloth(n: usize, integrator: Integrator) -> Scene {
    let mut spec = hooke_scene::workload::cloth(n);
    Overrides {
        integrator: Some(integrator),
        ..Overrides::default()
    }
    .apply(&mut spec)
    .unwrap();
    spec.build(Path::new(".")).unwrap()
}

fn root() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The public `jello.w` world with another integrator.
fn jello(integrator: Integrator) -> Scene {
    let world = hooke_scene::world::load_world(&root().join("assets/worlds/jello.w")).unwrap();
    let mut spec = world.to_scene("jello").unwrap();
    Overrides {
        integrator: Some(integrator),
        ..Overrides::default()
    }
    .apply(&mut spec)
    .unwrap();
    spec.build(&root()).unwrap()
}

/// A symplectic step of cloth-256 in each compilation of the spring loop this CPU runs: the
/// loop is most of the step, so this compares the kernels through the public API.
fn kernels(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernels");
    for kernel in Kernel::available() {
        let mut scene = cloth(256, Integrator::Symplectic);
        scene.simulation.set_kernel(kernel).unwrap();
        group.throughput(Throughput::Elements(
            scene.simulation.model().springs.len() as u64
        ));
        group.bench_function(BenchmarkId::new("cloth-256-step", kernel), |b| {
            b.iter(|| {
                scene.simulation.step().unwrap();
                black_box(&scene);
            })
        });
    }
    group.finish();
}

fn steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    for integrator in Integrator::ALL {
        let mut scene = cloth(128, integrator);
        group.throughput(Throughput::Elements(
            scene.simulation.model().springs.len() as u64
        ));
        group.bench_function(BenchmarkId::new("cloth-128", integrator), |b| {
            b.iter(|| scene.simulation.step().unwrap())
        });
    }
    for integrator in Integrator::ALL {
        let mut scene = jello(integrator);
        group.throughput(Throughput::Elements(
            scene.simulation.model().springs.len() as u64
        ));
        group.bench_function(BenchmarkId::new("jello-world", integrator), |b| {
            b.iter(|| {
                // Explicit Euler drifts out of bounds over millions of iterations: start
                // again rather than time a diverged state.
                if scene.simulation.step().is_err() {
                    scene = jello(integrator);
                }
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = kernels, steps
}
criterion_main!(benches);
