//! The forces of docs/physics.md §1 that act on particles: damped springs (and their
//! batched layouts for the kernels), the force field on a grid, and air on triangles.
//! Gravity, attachments and penalty springs are the model's (`crate::model`), as they
//! read its colliders and pins.

pub mod air;
pub(crate) mod field;
pub(crate) mod spring;
