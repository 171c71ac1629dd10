//! # hooke-core: the mass-spring solver
//!
//! Particles as flat arrays, springs as index pairs, the forces of the physics contract
//! (`docs/physics.md` §1: damped springs, gravity, a force field on a grid, penalty springs),
//! five integrators (§4), the three collision responses and the contact phase (§3). Units are SI throughout:
//! metres, seconds, kilograms, newtons; scenes are +Y up.
//!
//! This crate knows nothing of parry3d, meshes, images, files or the command line: colliders
//! come in through the [`Collider`] trait it owns, and it does no I/O.
//!
//! ## Quick start
//!
//! ```
//! use hooke_core::*;
//! // A 1 kg mass hanging from a pinned anchor by a 1 m spring of 100 N/m.
//! let mut p = Particles::default();
//! let anchor = p.push(Vec3::new(0.0, 2.0, 0.0), Vec3::zeros(), 1.0);
//! p.pin(anchor);
//! p.push(Vec3::new(0.0, 1.0, 0.0), Vec3::zeros(), 1.0);
//! let spring = Spring { i: 0, j: 1, rest: 1.0, ks: 100.0, kd: 2.0, kind: SpringKind::Structural };
//! let model = Model { springs: vec![spring], gravity: Vec3::new(0.0, -9.81, 0.0), ..Model::default() };
//! let mut sim = Simulation::new(p, model, Integrator::Rk4, 1e-3);
//! sim.advance(20_000).unwrap();
//! // Settles at rest length + m g / k below the anchor.
//! let y = sim.particles().x[1].y;
//! assert!((y - (1.0 - 9.81 / 100.0)).abs() < 1e-6);
//! ```
//!
//! ## Why is it slow?
//!
//! Build with `--release`: unoptimised nalgebra arithmetic is tens of times slower.

pub mod air;
mod assembly;
mod collider;
pub mod contact;
mod divergence;
mod excerpt;
mod force_field;
pub mod integrator;
mod kernel;
mod model;
mod number;
mod parallel;
mod particles;
mod renumber;
mod response;
mod simulation;
mod spring;
mod stability;
mod summary;
mod surface;

pub use air::{AeroSurface, Air, Gust};
pub use assembly::Assembly;
pub use collider::{Collider, Contact, Feature};
pub use contact::ContactStats;
pub use contact::proximity::Circle;
pub use divergence::Divergence;
pub use excerpt::excerpt;
pub use force_field::{FIELD_HALF_EXTENT, ForceField};
pub use integrator::{Integrator, StepReport, Sym3, UnknownIntegrator, Workspace};
pub use kernel::{Kernel, UnknownKernel};
pub use model::{Attachment, ColliderSlot, Model, Near};
pub use number::Num;
pub use particles::{Particles, SANE_BOUND, Vec3};
pub use renumber::Renumbering;
pub use response::Response;
pub use simulation::{RenumberError, Simulation};
pub use spring::{DEGENERATE_LENGTH, Spring, SpringKind};
pub use stability::StabilityEstimate;
pub use summary::Summary;
pub use surface::{DEFAULT_CLOTH_THICKNESS, DEFAULT_SURFACE_FRICTION, Surface};
