//! The command line's parts that its fuzz target and tests drive too: the options that
//! describe a picture, parsed as `hooke render` parses them, and the progress bars. The
//! library everything else is built on is the `hooke` crate.

#![forbid(unsafe_code)]

pub mod args;
pub mod bars;
