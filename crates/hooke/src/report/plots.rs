//! The report's plots, drawn by plotters as SVG files the page shows beside its tables.

use super::convergence::Sweep;
use super::drape::Reading;
use super::energy::EnergyRun;
use crate::Result;
use plotters::prelude::*;

/// One colour per integrator, in `Integrator::ALL`'s order, readable on white.
const PALETTE: [RGBColor; 6] = [
    RGBColor(213, 94, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 60, 30),
    RGBColor(230, 159, 0),
];

const SIZE: (u32, u32) = (720, 460);

/// A kind of mark on the stability plot: its label, colour, value and sideways shift.
type Mark = (&'static str, RGBColor, fn(&Sweep) -> f64, f64);

/// plotters' drawing errors as the report's output errors.
fn drawing<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> crate::Error {
    crate::Error::Output {
        message: format!("cannot draw a plot: {e}"),
    }
}

/// A chart on `root` with its caption and room for the axes' labels.
fn builder<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: impl AsRef<str>,
    y_labels: u32,
) -> ChartBuilder<'a, 'b, SVGBackend<'b>> {
    let mut b = ChartBuilder::on(root);
    b.caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(y_labels);
    b
}

/// The series' legend at `at`, on a light box.
fn legend<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    at: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(at)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(drawing)
}

/// The range `[lo, hi]` of positive values, widened to whole decades.
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (1e-3, 1.0);
    }
    (
        10f64.powf(lo.log10().floor()),
        10f64.powf(hi.log10().ceil()),
    )
}

/// Error against step size on log–log axes, a line per integrator, the fitted slope in
/// the legend.
pub(crate) fn convergence(sweeps: &[Sweep]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let x = decades(sweeps.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
        let y = decades(sweeps.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
        let mut chart = builder(&root, "single-spring: largest height error over 2 s", 70)
            .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_desc("step dt (s)")
            .y_desc("error (m)")
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(drawing)?;
        for (k, s) in sweeps.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| p.1.is_finite() && p.1 > 0.0)
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(drawing)?
                .label(format!(
                    "{}: slope {:.2} (order {})",
                    s.integrator, s.slope, s.expected
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(drawing)?;
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

/// Per integrator the step at which it goes unstable: theory, measured, `hooke check`.
pub(crate) fn stability(sweeps: &[Sweep]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let values = sweeps
            .iter()
            .flat_map(|s| [s.theory_limit, s.measured_limit, s.check_limit]);
        let y = decades(values);
        let names: Vec<String> = sweeps.iter().map(|s| s.integrator.clone()).collect();
        let mut chart = builder(&root, "single-spring: largest stable step", 70)
            .build_cartesian_2d(
                -0.5f64..sweeps.len() as f64 - 0.5,
                (y.0..y.1 * 10.0).log_scale(),
            )
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_labels(sweeps.len())
            .x_label_formatter(&|v| {
                let k = v.round();
                if (v - k).abs() < 0.01 && k >= 0.0 {
                    names.get(k as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .y_desc("dt (s); top row: never unstable")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(drawing)?;
        // An infinite limit is drawn at the top of the axis.
        let top = y.1 * 5.0;
        let at = |v: f64| if v.is_finite() { v } else { top };
        let marks: [Mark; 3] = [
            (
                "linear stability theory",
                RGBColor(0, 114, 178),
                |s| s.theory_limit,
                -0.15,
            ),
            (
                "measured here",
                RGBColor(213, 94, 0),
                |s| s.measured_limit,
                0.0,
            ),
            (
                "hooke check's estimate",
                RGBColor(120, 120, 120),
                |s| s.check_limit,
                0.15,
            ),
        ];
        for (label, colour, value, shift) in marks {
            let points: Vec<(f64, f64)> = sweeps
                .iter()
                .enumerate()
                .map(|(k, s)| (k as f64 + shift, at(value(s))))
                .collect();
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 6, colour.filled())))
                .map_err(drawing)?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

/// Total energy over time of one scene, a line per integrator, and the energy the
/// damping alone would leave for the scene's own integrator (dashed black).
pub(crate) fn energy(scene: &str, runs: &[&EnergyRun], own: &str) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let t_end = runs
            .iter()
            .flat_map(|r| r.energy.last().map(|e| e.0))
            .fold(0.0f64, f64::max)
            .max(1e-9);
        // The range of the scene's own integrator, the damping's prediction and the runs
        // that stay near them: a run that blows up (explicit Euler in the flag's wind)
        // leaves the plot instead of flattening the others.
        let reference: Vec<f64> = runs
            .iter()
            .filter(|r| r.integrator == own)
            .flat_map(|r| r.energy.iter().chain(&r.predicted).map(|e| e.1))
            .collect();
        let (rlo, rhi) = reference
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let near = |v: f64| {
            rlo > rhi
                || (v - 0.5 * (rlo + rhi)).abs() <= 2.0 * (rhi - rlo).max(1e-9 * rhi.abs().max(1.0))
        };
        let finite = runs
            .iter()
            .filter(|r| !r.diverged && r.energy.iter().all(|e| near(e.1)))
            .flat_map(|r| r.energy.iter().chain(&r.predicted).map(|e| e.1));
        let (lo, hi) = finite.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        let pad = ((hi - lo) * 0.1).max(1e-9 * hi.abs().max(1.0));
        let mut chart = builder(&root, format!("{scene}: total energy"), 80)
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_labels(6)
            .y_labels(6)
            .x_desc("t (s)")
            .y_desc("E (J)")
            .y_label_formatter(&|v| format!("{v:.4}"))
            .draw()
            .map_err(drawing)?;
        for (k, r) in runs.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let label = if r.diverged {
                format!("{} (diverged)", r.integrator)
            } else {
                r.integrator.clone()
            };
            let points = r
                .energy
                .iter()
                .copied()
                .filter(|e| e.1 >= lo - pad && e.1 <= hi + pad);
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                .map_err(drawing)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            if r.integrator == own {
                let dashes = r
                    .predicted
                    .windows(2)
                    .step_by(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], BLACK.stroke_width(2)));
                chart.draw_series(dashes).map_err(drawing)?;
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

/// The drape coefficient against the overhang in bending lengths: the sweep of `B` as a
/// line with its points, each preset as a labelled point.
pub(crate) fn drape(sweep: &[Reading], presets: &[Reading]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let most = sweep
            .iter()
            .chain(presets)
            .map(|r| r.overhang)
            .fold(1.0f64, f64::max);
        let mut chart = builder(
            &root,
            "Cusick's drape test, 30 cm on 18 cm: DC against the overhang",
            60,
        )
        .build_cartesian_2d(0.0..(most * 1.1).ceil(), 0.0..1.0)
        .map_err(drawing)?;
        chart
            .configure_mesh()
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_desc("overhang (R_specimen − R_pedestal) / c, c = (B/ρg)^⅓")
            .y_desc("drape coefficient")
            .draw()
            .map_err(drawing)?;
        let line: Vec<(f64, f64)> = sweep.iter().map(|r| (r.overhang, r.dc)).collect();
        let colour = PALETTE[1];
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(drawing)?
            .label("cotton's density and membrane, B from 0.5 to 200 µN·m")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
            });
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(drawing)?;
        let mark = PALETTE[0];
        chart
            .draw_series(presets.iter().map(|r| {
                EmptyElement::at((r.overhang, r.dc))
                    + Cross::new((0, 0), 6, mark.stroke_width(2))
                    + Text::new(r.what.clone(), (8, -14), ("sans-serif", 15))
            }))
            .map_err(drawing)?
            .label("the presets")
            .legend(move |(x, y)| Cross::new((x + 9, y), 6, mark.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}
