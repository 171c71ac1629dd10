//! A parameter sweep, as `hooke.sweep` runs one in Python (there with a process pool or
//! Ray): every point of a grid of scene-file keys, run on rayon's threads, with a metric per
//! point. Each point's result is the same bits wherever and in whatever order it runs.
//!
//!     cargo run --release --example sweep -- [SECONDS]

use hooke::scene::{Overrides, TableOverride};
use rayon::prelude::*;

/// Where the cloth's lowest point ends after `seconds` on `table` with structural springs
/// of stiffness `ks`.
fn lowest_point(ks: f64, table: &str, seconds: f64) -> Result<f64, hooke::Error> {
    let mut read = hooke::source::read("cloth-table")?;
    read.spec
        .set("body.springs.structural.ks", toml::Value::Float(ks))
        .map_err(|e| hooke::Error::from(e).context("cloth-table"))?;
    let overrides = Overrides {
        duration: Some(seconds),
        table: Some(TableOverride::Mesh(table.to_string())),
        ..Overrides::default()
    };
    let prepared = hooke::source::prepare(read, "cloth-table", &overrides)?;
    let mut scene = hooke::source::build_prepared(prepared, "cloth-table")?;
    let steps = scene.steps;
    hooke::driver::advance(&mut scene, steps)?;
    let x = &scene.simulation.particles().x;
    Ok(x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min))
}

fn main() -> Result<(), hooke::Error> {
    let seconds: f64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let tables = ["builtin:table.obj", "builtin:square-table.obj"];
    let grid: Vec<(f64, &str)> = [150.0, 600.0]
        .into_iter()
        .flat_map(|ks| tables.map(|t| (ks, t)))
        .collect();
    let rows: Vec<_> = grid
        .par_iter()
        .map(|&(ks, table)| lowest_point(ks, table, seconds).map(|y| (ks, table, y)))
        .collect::<Result<_, _>>()?;
    println!("{:>8} {:<26} {:>12}", "ks", "table", "lowest (m)");
    for (ks, table, y) in rows {
        println!("{ks:>8} {table:<26} {y:>12.4}");
    }
    Ok(())
}
