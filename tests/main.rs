//! The validation suite: `cargo test` is how Hooke's users check it.
//!
//! One test binary (fast to link) with a module per concern. Physics tests compare with
//! closed forms; snapshot tests lock real trajectories (see `tests/snapshots/`).

mod common;
mod oscillator;
mod conservation;
mod collisions;
mod scenes;
mod worlds;
