//! Solver benches: one force evaluation, the spring loop in each compilation the CPU runs,
//! and one step of each integrator, on the cloth-N workload
//! (`docs/benchmarks.md`) and on a public jello world.
//!
//! `cargo bench -p hooke-tests --bench solver`; figures in `benches/README.md`.

#![allow(
    missing_docs,
    reason = "criterion_group! generates undocumented functions"
)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use hooke_core::{Assembly, Integrator, Kernel, Vec3};
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

fn forces(c: &mut Criterion) {
    let mut group = c.benchmark_group("forces");
    for n in [64, 256] {
        let scene = cloth(n, Integrator::Symplectic);
        let (model, p) = (scene.simulation.model(), scene.simulation.particles());
        let mut assembly = Assembly::new(p.len(), &model.springs);
        let mut a = vec![Vec3::zeros(); p.len()];
        group.throughput(Throughput::Elements(model.springs.len() as u64));
        group.bench_with_input(BenchmarkId::new("cloth", n), &n, |b, _| {
            b.iter(|| {
                assembly.accelerations(model, (&p.mass, &p.inv_mass), (&p.x, &p.v), &[], &mut a);
                black_box(&a);
            })
        });
    }
    // The spring loop alone, in each compilation this CPU runs.
    let scene = cloth(256, Integrator::Symplectic);
    let (model, p) = (scene.simulation.model(), scene.simulation.particles());
    group.throughput(Throughput::Elements(model.springs.len() as u64));
    for kernel in Kernel::available() {
        let mut assembly = Assembly::new(p.len(), &model.springs);
        assembly.set_kernel(kernel);
        group.bench_function(BenchmarkId::new("springs-256", kernel), |b| {
            b.iter(|| {
                assembly.scatter(&p.x, &p.v);
                black_box(&assembly);
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
    targets = forces, steps
}
criterion_main!(benches);
