//! The library half of the `hooke` command: turning scenes into draw lists and images,
//! reading SCENE arguments, atomic output files and the demo's stills. The binary's
//! commands are built on it, and the validation suite renders its golden images with it.

#![forbid(unsafe_code)]

pub mod draw;
pub mod driver;
pub mod export;
pub mod image_out;
pub mod interrupt;
pub mod memory;
pub mod output;
pub mod source;
pub mod stills;
pub mod threads;
