//! The validation suite: `cargo test` is how Hooke's users check it.
//!
//! One test binary (fast to link) with a module per concern. Physics tests compare with
//! closed forms; snapshot tests lock real trajectories (see `tests/snapshots/`).

mod air;
mod bodies;
mod caches;
mod cancel;
mod collisions;
mod common;
mod conservation;
mod contact;
mod creases;
mod deforming;
mod determinism;
mod documents;
mod drape;
mod face_order;
mod friction;
mod images;
mod large_steps;
mod layers;
mod layout;
mod material;
mod mesh_files;
mod meshes;
mod motion;
mod newton;
mod oscillator;
mod roundtrip;
mod scenes;
mod slivers;
mod starts;
mod statics;
mod worlds;
