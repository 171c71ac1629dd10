//! The drape test (docs/materials.md, "Drape test"): each fabric preset on Cusick's meter,
//! its view from above with its coefficient and nodes; and the coefficient against the
//! overhang in bending lengths for a sweep of the bending rigidity.

use super::folder::{Pending, drape_file};
use crate::Result;
use crate::drape::Meter;
use hooke_scene::material::{Material, PRESETS};
use serde::Serialize;
use std::path::Path;

/// The sweep's bending rigidities, N·m: 0.5 to 200 µN·m.
pub(crate) const SWEEP: [f64; 9] = [
    0.5e-6, 1e-6, 2e-6, 5e-6, 10e-6, 20e-6, 50e-6, 100e-6, 200e-6,
];

/// The preset whose other values the sweep keeps.
const SWEPT: &str = "cotton";

/// The least difference in DC between neighbouring presets (silk, cotton, wool, denim).
pub(crate) const APART: f64 = 0.05;

/// How far DC may fall from one rigidity of the sweep to the next stiffer one: the spread
/// of a single repeat with the node count it happens to settle at.
pub(crate) const DIP: f64 = 0.03;

/// One run of the meter.
#[derive(Clone, Serialize)]
pub(crate) struct Reading {
    /// The preset's name, or the sweep's rigidity.
    pub(crate) what: String,
    /// Bending rigidity, N·m.
    pub(crate) bending: f64,
    /// The overhang `(R_specimen − R_pedestal)` in bending lengths `(B / ρg)^⅓`.
    pub(crate) overhang: f64,
    pub(crate) dc: f64,
    pub(crate) nodes: usize,
    pub(crate) settled: bool,
    /// Its view from above (presets only).
    pub(crate) file: Option<String>,
}

/// The section's readings.
#[derive(Serialize)]
pub(crate) struct Drape {
    pub(crate) presets: Vec<Reading>,
    pub(crate) sweep: Vec<Reading>,
}

/// The presets in the order their drape coefficients must rise.
const ORDER: [&str; 4] = ["silk", "cotton", "wool", "denim"];

/// Gravity on the meter, m/s² (the scenes' default).
const GRAVITY: f64 = 9.81;

/// Runs one repeat (seed 1) of `m` on the standard meter.
fn reading(
    meter: &Meter,
    what: &str,
    m: &Material,
) -> Result<(Reading, crate::drape::Repeat, hooke_scene::Scene)> {
    let (repeat, scene) = meter.repeat(m, 1, None)?;
    let half = 0.5 * (meter.specimen - meter.pedestal);
    let c = (m.bending / (m.density * GRAVITY)).cbrt();
    Ok((
        Reading {
            what: what.to_string(),
            bending: m.bending,
            overhang: half / c,
            dc: repeat.dc,
            nodes: repeat.nodes,
            settled: repeat.settled,
            file: None,
        },
        repeat,
        scene,
    ))
}

/// The presets and the sweep, each a repeat of the standard 30 cm test; `None` with
/// `quick` (a minute's work and more).
pub(crate) fn runs(
    quick: bool,
    files: &mut Pending,
    tick: &mut dyn FnMut(),
) -> Result<Option<Drape>> {
    if quick {
        return Ok(None);
    }
    let meter = Meter::default();
    let mut presets = Vec::new();
    for name in ORDER {
        let Some(preset) = PRESETS.iter().find(|p| p.name == name) else {
            continue;
        };
        let (mut r, repeat, scene) = reading(&meter, preset.name, &preset.material)?;
        let image = meter.top_view(&meter.shadow(&scene), &repeat.outline);
        let file = drape_file(preset.name);
        files.add(
            file.clone(),
            crate::image_out::png_bytes(Path::new(&file), &image)?,
        );
        r.file = Some(file);
        presets.push(r);
        tick();
    }
    let base = PRESETS
        .iter()
        .find(|p| p.name == SWEPT)
        .map(|p| p.material)
        .expect("the swept preset is one of the presets");
    let mut sweep = Vec::new();
    for b in SWEEP {
        let m = Material { bending: b, ..base };
        sweep.push(reading(&meter, &format!("B = {} µN·m", b * 1e6), &m)?.0);
        tick();
    }
    Ok(Some(Drape { presets, sweep }))
}

/// Ticks [`runs`] gives.
pub(crate) fn ticks(quick: bool) -> usize {
    if quick {
        0
    } else {
        PRESETS.len() + SWEEP.len()
    }
}

/// Whether `x ≥ least` (a NaN is not).
fn at_least(x: f64, least: f64) -> bool {
    x >= least
}

/// The section's failed checks, each in a line.
pub(crate) fn failures(d: &Drape) -> Vec<String> {
    let mut out = Vec::new();
    for r in d.presets.iter().chain(&d.sweep) {
        if !r.settled {
            out.push(format!(
                "drape: {} had not settled by the meter's longest time",
                r.what
            ));
        }
    }
    for r in &d.presets {
        if !(0.2..=0.98).contains(&r.dc) || !(3..=14).contains(&r.nodes) {
            out.push(format!(
                "drape: {} gives DC {:.3} with {} nodes, expected DC 0.2–0.98 and 3–14 nodes",
                r.what, r.dc, r.nodes
            ));
        }
    }
    for w in d.presets.windows(2) {
        if !at_least(w[1].dc - w[0].dc, APART) {
            out.push(format!(
                "drape: {} (DC {:.3}) is not {APART} above {} (DC {:.3})",
                w[1].what, w[1].dc, w[0].what, w[0].dc
            ));
        }
    }
    for w in d.sweep.windows(2) {
        if !at_least(w[1].dc, w[0].dc - DIP) {
            out.push(format!(
                "drape: DC falls from {:.3} at {} to {:.3} at {}",
                w[0].dc, w[0].what, w[1].dc, w[1].what
            ));
        }
    }
    if let (Some(first), Some(last)) = (d.sweep.first(), d.sweep.last())
        && !at_least(last.dc - first.dc, 0.3)
    {
        out.push(format!(
            "drape: DC rises only from {:.3} to {:.3} across the sweep",
            first.dc, last.dc
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading(what: &str, dc: f64, nodes: usize) -> Reading {
        Reading {
            what: what.into(),
            bending: 1e-6,
            overhang: 3.0,
            dc,
            nodes,
            settled: true,
            file: None,
        }
    }

    /// Presets too close, a sweep that falls and an unsettled run are each a failed check;
    /// presets apart and a rising sweep are none.
    #[test]
    fn presets_too_close_and_a_falling_sweep_fail_the_report() {
        let good = Drape {
            presets: vec![
                reading("silk", 0.36, 10),
                reading("cotton", 0.43, 9),
                reading("wool", 0.62, 7),
                reading("denim", 0.86, 6),
            ],
            sweep: vec![
                reading("a", 0.3, 10),
                reading("b", 0.29, 9),
                reading("c", 0.9, 5),
            ],
        };
        assert!(failures(&good).is_empty(), "{:?}", failures(&good));
        let mut bad = good;
        bad.presets[1].dc = 0.39;
        bad.sweep[1].dc = 0.2;
        bad.sweep[2].settled = false;
        let said = failures(&bad).join("\n");
        assert!(
            said.contains("cotton (DC 0.390) is not 0.05 above silk"),
            "{said}"
        );
        assert!(
            said.contains("DC falls from 0.300 at a to 0.200 at b"),
            "{said}"
        );
        assert!(said.contains("c had not settled"), "{said}");
    }
}
