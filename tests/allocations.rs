//! ARCHITECTURE.md's claim, checked: after its first steps, stepping allocates nothing, for
//! every integrator (the contact phase's candidate lists aside, which only grow to a
//! high-water mark; the scenes here have no contact thickness).
//!
//! A test binary of its own: the counting allocator sees every thread, so no other test may
//! run beside it. The steps run in a pool of one worker: with more, rayon's own work-stealing
//! queues grow now and then when work is stolen unevenly (2 allocations in 10 steps, in
//! about one run of six), which is rayon's bookkeeping, not the solver's. Every parallel
//! helper still runs through rayon here, so an allocation in one is seen.

#![allow(unsafe_code, reason = "a global allocator is an unsafe trait")]

use hooke_core::Integrator;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The system allocator, counting allocations while `COUNTING` is set.
struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: every call is passed to the system allocator unchanged; counting touches only
// atomics.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: the caller's contract is the system allocator's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: as above.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `steps` steps after `warm` untimed ones, on `pool`'s one worker.
fn allocations(
    pool: &rayon::ThreadPool,
    mut scene: hooke_scene::Scene,
    warm: u64,
    steps: u64,
) -> u64 {
    pool.install(|| {
        scene.simulation.advance(warm).unwrap();
        ALLOCATIONS.store(0, Ordering::SeqCst);
        COUNTING.store(true, Ordering::SeqCst);
        let result = scene.simulation.advance(steps);
        COUNTING.store(false, Ordering::SeqCst);
        result.unwrap();
        ALLOCATIONS.load(Ordering::SeqCst)
    })
}

#[test]
fn stepping_allocates_nothing_for_any_integrator() {
    // Large enough that every parallel helper splits into blocks (cloth-100 has 10,000
    // particles; the jello world exercises the force field and penalty colliders).
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut failures = Vec::new();
    // One pool for every scene: a pool dropped after one scene's count would let its
    // worker's exit (crossbeam-epoch's thread-local handle, freed when the thread ends)
    // allocate during the next count on a loaded machine (seen in about two runs of three
    // with both cores busy).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for integrator in Integrator::ALL {
        let cloth = {
            let mut spec = hooke_scene::workload::cloth(100);
            spec.simulation.integrator = hooke_scene::spec::IntegratorName(integrator);
            spec.build(&root).unwrap()
        };
        let world = hooke_scene::world::load_world(&root.join("assets/worlds/jello.w"))
            .unwrap()
            .to_scene("jello")
            .unwrap();
        let mut world_spec = world;
        world_spec.simulation.integrator = hooke_scene::spec::IntegratorName(integrator);
        let jello = world_spec.build(&root).unwrap();
        for (name, scene) in [("cloth-100", cloth), ("jello.w", jello)] {
            let n = allocations(&pool, scene, 3, 10);
            if n > 0 {
                failures.push(format!(
                    "{integrator} on {name}: {n} allocations in 10 steps"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
