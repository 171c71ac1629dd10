//! # hooke: mass-spring scenes to load, step, render and write
//!
//! The library a Rust program adds to use Hooke, and what the `hooke` command and the
//! Python package are built on. It loads a scene (a built-in name, a `.toml` scene or a
//! `.w` jello world; [`source`]), steps it frame by frame with interrupts and a memory
//! budget ([`driver`], [`interrupt`], [`memory`]), renders stills ([`image_out`]), and
//! writes every output through one [`Sink`] (trajectory CSV, GIF, PC2, USD, PLY and OBJ),
//! atomically and never over its own inputs or a device ([`output`]). Every fallible call
//! returns [`Error`], whose variants tell a bad input from a divergence, a refused output
//! or an interrupt.
//!
//! The physics is `hooke-core`'s (re-exported as [`core`]), the scenes `hooke-scene`'s
//! ([`scene`]), the rasterizer `hooke-render`'s ([`render`]).
//!
//! ```
//! use hooke::image_out::View;
//! // Load the course's hanging cloth, step it half a second, draw it.
//! let mut scene = hooke::source::build("hanging-cloth", &Default::default())?;
//! let lowest = |s: &hooke::scene::Scene| s.simulation.particles().x.iter().map(|x| x.y).fold(f64::MAX, f64::min);
//! let start = lowest(&scene);
//! let steps = hooke::driver::steps_for(&scene, 0.5);
//! hooke::driver::advance(&mut scene, steps)?;
//! assert!(lowest(&scene) < start - 0.1, "the cloth falls and swings down from its pins");
//! let view = View { size: (160, 120), ..View::default() };
//! let image = view.pixels(&scene, &view.camera(&scene));
//! assert_eq!(image.dimensions(), (160, 120));
//! # Ok::<(), hooke::Error>(())
//! ```
//!
//! ## Features
//!
//! * `export-usd` (default): the USD (`.usda`) export.
//! * `report` (default): [`report`], the checks of `hooke report` written as a page with
//!   plots (plotters, serde_json).
//! * `clap`: command-line parsing for the option types ([`draw::Style`],
//!   [`export::FolderFormat`]), for applications with their own command line.

#![forbid(unsafe_code)]

mod creases;
pub mod drape;
pub mod draw;
pub mod driver;
mod error;
pub mod export;
pub mod frames;
pub mod image_out;
pub mod interrupt;
pub mod memory;
pub mod output;
pub mod progress;
pub mod quantity;
#[cfg(feature = "report")]
pub mod report;
mod sink;
pub mod source;
pub mod stills;
pub mod threads;
pub mod trajectory;

pub use error::{Context, Error, Location, Result};
pub use sink::{Recording, Sink, record};

pub use hooke_core as core;
pub use hooke_render as render;
pub use hooke_scene as scene;
