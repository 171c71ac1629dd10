//! # hooke-core: the mass-spring solver
//!
//! Particles as flat arrays, springs as index pairs, the forces of the physics contract
//! (`docs/physics.md` §1: damped springs, gravity, a force field on a grid, penalty springs),
//! seven integrators (§4), the three collision responses and the contact phase (§3). Units are SI throughout:
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

// What is public is what another crate uses: the rest is `pub(crate)`, and this lint says
// so of any `pub` item no other crate can reach.
#![warn(unreachable_pub)]

// The areas, each using only those above it: the state, what a collider is, the forces,
// the model that holds them, the contact phase, the spring assembly and its kernels, the
// integrators, the simulation that steps them. `tests/layout.rs` keeps it so.
mod assembly;
mod collider;
pub mod contact;
pub mod forces;
pub mod integrator;
mod model;
mod particles;
mod simulation;

// Small tools every area may use.
mod excerpt;
mod keyframes;
mod number;
mod parallel;
pub mod text;

pub use assembly::kernel::Kernel;
pub use collider::moving::Moving;
pub use collider::response::Response;
pub use collider::{Circle, Collider, Contact, Feature};
pub use contact::ContactStats;
pub use excerpt::excerpt;
pub use forces::air::{AeroSurface, Air, Gust};
pub use forces::field::ForceField;
pub use forces::spring::{Spring, SpringKind};
pub use integrator::{Integrator, SolveTimes, StopRule, UnknownIntegrator};
pub use keyframes::{Key, KeyError, Keyframes};
pub use model::motion::{PinMotion, PinPath};
pub use model::surface::{DEFAULT_CLOTH_THICKNESS, DEFAULT_SURFACE_FRICTION, Surface};
pub use model::{Attachment, ColliderSlot, Model};
pub use number::{Approx, Num};
pub use particles::{Particles, SANE_BOUND, Vec3};
pub use simulation::divergence::Divergence;
pub use simulation::notice::{Cause, Notice, Through};
pub use simulation::renumber::Renumbering;
pub use simulation::stability::StabilityEstimate;
pub use simulation::start::{PushedOut, StartInside};
pub use simulation::summary::Summary;
pub use simulation::swept::MOST_PARTS;
pub use simulation::{RenumberError, Simulation};
