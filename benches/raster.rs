//! Rasterizer benches: a smooth-shaded grid of 2·(N-1)² triangles (the cloth-N workload's
//! surface) at 1024×1024 with 4× anti-aliasing, one renderer reused as in an animation.
//!
//! `cargo bench -p hooke-tests --bench raster`; figures in `benches/README.md`.

#![allow(
    missing_docs,
    reason = "criterion_group! generates undocumented functions"
)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use hooke_render::{Camera, DrawList, RenderOptions, Renderer, Triangle};
use nalgebra::Vector3;
use std::hint::black_box;

fn grid(n: usize) -> DrawList {
    let h = 1.0 / (n - 1) as f64;
    let p = |i: usize, j: usize| Vector3::new(i as f64 * h, 1.0, j as f64 * h);
    let up = Vector3::y();
    let mut list = DrawList::default();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            for tri in [
                [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
            ] {
                list.triangles.push(Triangle {
                    p: tri,
                    n: [up; 3],
                    color: [0.22, 0.42, 0.78],
                });
            }
        }
    }
    list
}

fn triangles(c: &mut Criterion) {
    let mut group = c.benchmark_group("raster");
    let options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    for n in [256, 1024] {
        let list = grid(n);
        let (lo, hi) = list.bounds().unwrap();
        let camera = Camera::framing(lo, hi, 30.0, 22.0);
        let mut renderer = Renderer::default();
        group.throughput(Throughput::Elements(list.triangles.len() as u64));
        group.bench_with_input(BenchmarkId::new("cloth-grid", n), &n, |b, _| {
            b.iter(|| black_box(renderer.render(&list, &camera, &options)))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = triangles
}
criterion_main!(benches);
