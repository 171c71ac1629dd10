//! `hooke drape MATERIAL`: Cusick's drape test on a fabric (hooke::drape), its repeats
//! summarised as labs report them, pictures of it, and `--fit-dc`: the bending rigidity that
//! gives a measured drape coefficient.

use anyhow::{Result, anyhow};
use clap::Args;
use hooke::drape::{Meter, Repeat, Summary, fit_bending};
use hooke_core::Integrator;
use hooke_scene::material::{Material, PRESETS};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `hooke drape`'s arguments.
#[derive(Args, Clone, Debug)]
pub struct DrapeArgs {
    /// A preset (cotton, silk, wool, denim) or a TOML file holding a `[material]` table
    /// (without `bending` for --fit-dc). Keys given below override it.
    pub material: Option<String>,
    /// The specimen's diameter, cm: 24, 30 or 36 (BS 5058).
    #[arg(long, default_value_t = 30)]
    pub size: u32,
    /// Repeats, each from its own seed's tilt and turn.
    #[arg(long, default_value_t = 5)]
    pub repeats: u32,
    /// The first repeat's seed (repeat k uses seed + k); the same seeds give the same bits.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = parse_seed)]
    pub seed: u64,
    /// Print one JSON line instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write the first repeat's view from above (the meter's shadow) to this PNG.
    #[arg(long, value_name = "FILE.png")]
    pub top: Option<PathBuf>,
    /// Write a three-quarter still of the first repeat to this PNG.
    #[arg(long, value_name = "FILE.png")]
    pub still: Option<PathBuf>,
    /// Find the bending rigidity that gives this drape coefficient (bisection on log B to
    /// 2 %, each try the mean of --repeats repeats from the same seeds).
    #[arg(long, value_name = "DC", allow_negative_numbers = true)]
    pub fit_dc: Option<f64>,
    /// The specimen's own mesh: an OBJ disc of --size across, centred on the origin in the
    /// x–z plane (default: the built-in disc of irregular triangles on rings 1 cm apart).
    #[arg(long, value_name = "FILE.obj")]
    pub mesh: Option<PathBuf>,
    /// Coulomb friction of the cloth on the pedestal and between its folds.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub friction: f64,
    /// Integrator (default symplectic Euler at its own step; vbd and newton at 1/60 s).
    #[arg(long)]
    pub integrator: Option<hooke_core::Integrator>,
    /// The step, seconds.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// The longest a repeat runs, simulated seconds, before it is measured unsettled.
    #[arg(long, default_value_t = 15.0, allow_negative_numbers = true)]
    pub longest: f64,
    /// Areal density, kg/m².
    #[arg(long, allow_negative_numbers = true)]
    pub density: Option<f64>,
    /// Membrane stiffness per unit width, N/m.
    #[arg(long, allow_negative_numbers = true)]
    pub stretch: Option<f64>,
    /// Shear stiffness per unit width, N/m.
    #[arg(long, allow_negative_numbers = true)]
    pub shear: Option<f64>,
    /// Bending rigidity per unit width, N·m.
    #[arg(long, allow_negative_numbers = true)]
    pub bending: Option<f64>,
    /// Stiffness-proportional damping, s.
    #[arg(long, allow_negative_numbers = true)]
    pub damping: Option<f64>,
}

/// The material the arguments give: the preset's or file's values under the keys given.
fn material(args: &DrapeArgs) -> Result<(String, Material)> {
    let mut name = "the given values".to_string();
    let mut base: Option<hooke_scene::spec::MaterialSpec> = None;
    if let Some(m) = &args.material {
        if let Some(p) = PRESETS.iter().find(|p| p.name == m) {
            name = p.name.to_string();
            base = Some(hooke_scene::spec::MaterialSpec {
                preset: Some(p.name.to_string()),
                ..Default::default()
            });
        } else {
            let path = PathBuf::from(m);
            let text = hooke_core::text::read_text(&path).map_err(|e| {
                anyhow!(format!(
                    "{m}: not a preset ({}) and not a file I can read: {e}",
                    PRESETS.map(|p| p.name).join(", ")
                ))
            })?;
            let spec =
                hooke_scene::material::parse_material_file(&text, &path).map_err(|e| anyhow!(e))?;
            name = path.display().to_string();
            base = Some(spec);
        }
    }
    let mut spec = base.unwrap_or_default();
    let set = |v: Option<f64>, key: &str| -> Result<Option<f64>> {
        match v {
            Some(x) if !(x.is_finite() && x >= 0.0) => Err(anyhow!(format!(
                "--{key}: expected a finite number ≥ 0, found {x}"
            ))),
            _ => Ok(v),
        }
    };
    use hooke_scene::spec::{NonNegative, Positive};
    let positive = |v: Option<f64>, key: &str| -> Result<Option<f64>> {
        match v {
            Some(x) if !(x.is_finite() && x > 0.0) => Err(anyhow!(format!(
                "--{key}: expected a finite number above 0, found {x}"
            ))),
            _ => Ok(v),
        }
    };
    if let Some(x) = positive(args.density, "density")? {
        spec.density = Some(Positive::of(x));
    }
    if let Some(x) = positive(args.stretch, "stretch")? {
        spec.stretch = Some(Positive::of(x));
    }
    if let Some(x) = set(args.shear, "shear")? {
        spec.shear = Some(NonNegative::of(x));
    }
    if let Some(x) = set(args.bending, "bending")? {
        spec.bending = Some(NonNegative::of(x));
    }
    if let Some(x) = set(args.damping, "damping")? {
        spec.damping = Some(NonNegative::of(x));
    }
    if args.fit_dc.is_some() && spec.bending.is_none() {
        // The fit finds it: any value stands in until then.
        spec.bending = Some(NonNegative::of(1e-5));
    }
    let m = spec
        .resolve("material")
        .map_err(|e| anyhow!(e.to_string()))?;
    Ok((name, m))
}

/// The most `--repeats`: a lab's five, or many more for statistics, but not a run that
/// never ends.
const MOST_REPEATS: u32 = 1000;

/// The relative bracket `--fit-dc` bisects `log B` to.
const FIT_TOLERANCE: f64 = 0.02;

/// Says, when a large step runs the meter, what it was measured to do to light fabrics.
fn large_step_note(meter: &Meter) {
    if matches!(
        meter.integrator,
        Integrator::Vbd | Integrator::Newton | Integrator::Implicit
    ) {
        eprintln!(
            "note: with {} at {:.4} s a light fabric falls slower (its self-contact bounds \
             hold it back) and settles in fewer, wider folds than small steps give (silk: 8 \
             nodes and DC 0.46 against 10 and 0.37; docs/materials.md, \"Drape test\"); the \
             default, symplectic Euler at its own step, is the meter's reference",
            meter.integrator.name(),
            meter.dt
        );
    }
}

/// Runs `repeats` of the test on `m`.
fn repeats(
    meter: &Meter,
    m: &Material,
    args: &DrapeArgs,
    what: &str,
) -> hooke::Result<Vec<Repeat>> {
    let mut out = Vec::new();
    for k in 0..args.repeats {
        let label = format!("drape {what}, repeat {} of {}", k + 1, args.repeats);
        let (repeat, scene) = meter.repeat(m, args.seed + u64::from(k), Some(&label))?;
        if k == 0 {
            pictures(meter, &repeat, &scene, args)?;
        }
        out.push(repeat);
    }
    Ok(out)
}

/// The first repeat's pictures, when asked for.
fn pictures(
    meter: &Meter,
    repeat: &Repeat,
    scene: &hooke_scene::Scene,
    args: &DrapeArgs,
) -> hooke::Result<()> {
    if let Some(path) = &args.top {
        let image = meter.top_view(&meter.shadow(scene), &repeat.outline);
        hooke::image_out::write_png_named(path, "--top", &image)?;
    }
    if let Some(path) = &args.still {
        let view = hooke::image_out::View::checked((800, 600), "solid", (30.0, 35.0), 1.0, 2)?;
        // The specimen, not the whole pedestal: framed on the drape's top.
        let mut camera = view.camera(scene);
        camera.target = nalgebra::Vector3::new(0.0, 0.44, 0.0);
        camera.distance = 2.2 * meter.specimen;
        let image = view.pixels(scene, &camera);
        hooke::image_out::write_png_named(path, "--still", &image)?;
    }
    Ok(())
}

/// `hooke drape`.
pub fn drape(args: &DrapeArgs) -> Result<ExitCode> {
    for (path, flag) in [(&args.top, "--top"), (&args.still, "--still")] {
        if let Some(p) = path {
            hooke::output::check_output_file(p, flag, &["png"])?;
            // The pictures are written as names hooke chooses are (never through a link):
            // refused now, not after the whole run.
            hooke::output::check_named(p, flag)?;
        }
    }
    // No picture over another, nor over the material or mesh the run reads.
    let mut claims = hooke::output::claims::Claims::default();
    if let Some(m) = &args.material
        && Path::new(m).is_file()
    {
        claims.input("the material file", Path::new(m));
    }
    if let Some(mesh) = &args.mesh {
        claims.input("the specimen's mesh (--mesh)", mesh);
    }
    for (path, flag) in [(&args.top, "--top"), (&args.still, "--still")] {
        if let Some(p) = path {
            claims.file(flag, p);
        }
    }
    claims.check()?;
    if !(1..=MOST_REPEATS).contains(&args.repeats) {
        return Err(anyhow!(
            "--repeats: expected from 1 to {MOST_REPEATS}, found {}",
            args.repeats
        ));
    }
    if !(args.longest.is_finite() && args.longest > 0.0 && args.longest <= 600.0) {
        return Err(anyhow!(
            "--longest: expected simulated seconds above 0 and at most 600, found {}",
            args.longest
        ));
    }
    if let Some(dt) = args.dt
        && !(dt.is_finite() && dt > 0.0 && dt <= 0.1)
    {
        return Err(anyhow!(
            "--dt: expected a step above 0 and at most 0.1 s, found {dt}"
        ));
    }
    if !(args.friction.is_finite() && (0.0..=10.0).contains(&args.friction)) {
        return Err(anyhow!(
            "--friction: expected a coefficient from 0 to 10, found {}",
            args.friction
        ));
    }
    let meter = Meter {
        specimen: f64::from(args.size) / 100.0,
        friction: args.friction,
        mesh: args.mesh.clone(),
        longest: args.longest,
        integrator: args.integrator.unwrap_or(Integrator::Symplectic),
        dt: args.dt.unwrap_or(match args.integrator {
            Some(Integrator::Vbd | Integrator::Newton | Integrator::Implicit) => 1.0 / 60.0,
            _ => 0.0,
        }),
        ..Meter::default()
    };
    let (name, m) = material(args)?;
    if let Some(target) = args.fit_dc {
        // A disc hanging straight down covers the pedestal; a rigid one its own area.
        let least = (meter.pedestal / meter.specimen).powi(2);
        if !(target > least && target < 1.0) {
            return Err(anyhow!(format!(
                "--fit-dc: a drape coefficient lies between the pedestal's share of the \
                 specimen, {least:.3} (a disc hanging straight down), and 1 (a rigid disc), \
                 both excluded; found {target}"
            )));
        }
        let mut unsettled = 0;
        let mut evaluate = |trial: &Material| -> hooke::Result<f64> {
            let what = format!("B = {:.3e} N·m", trial.bending);
            let runs = repeats(&meter, trial, args, &what)?;
            unsettled += runs.iter().filter(|r| !r.settled).count();
            Ok(Summary::of(&runs).dc_mean)
        };
        let fit = fit_bending(target, &m, FIT_TOLERANCE, &mut evaluate)?;
        let (bending, dc) = (fit.bending, fit.dc);
        if fit.outside(target) {
            let (lo, hi) = hooke::drape::FIT_RANGE;
            return Err(anyhow!(format!(
                "--fit-dc {target}: no bending rigidity from {lo:.0e} to {hi:.0e} N·m gives it \
                 with these density, stretch and shear: the nearest is DC {dc:.3}, at B = \
                 {bending:.3e} N·m; change --density, --stretch or --shear, or the target"
            )));
        }
        if args.json {
            let line = serde_json::json!({
                "target_dc": target, "bending": bending, "dc": dc,
                "bracket": [fit.bracket.0, fit.bracket.1], "evaluations": fit.evaluations,
                "density": m.density, "stretch": m.stretch, "shear": m.shear,
                "damping": m.damping,
            });
            println!("{line}");
        } else {
            println!(
                "DC {target} is reached at B = {bending:.3e} N·m (DC {dc:.3} there; bisection on \
                 log B to {} %, {} runs of {} repeat(s)):\n\n\
                 [body.material]\ndensity = {}\nstretch = {}\nshear = {}\nbending = {bending:e}\ndamping = {:e}",
                100.0 * FIT_TOLERANCE,
                fit.evaluations,
                args.repeats,
                m.density,
                m.stretch,
                m.shear,
                m.damping
            );
        }
        if unsettled > 0 {
            eprintln!(
                "warning: {unsettled} repeat(s) of the fit had not settled by {} s: their DC is of a moving specimen",
                meter.longest
            );
        }
        if (dc - target).abs() > 0.02 {
            eprintln!(
                "warning: the DC reached, {dc:.3}, is {:.3} from the target: between \
                 B = {:.3e} and {:.3e} N·m the node count changes and DC jumps; more \
                 --repeats average the jump",
                (dc - target).abs(),
                fit.bracket.0,
                fit.bracket.1
            );
        }
        large_step_note(&meter);
        return Ok(ExitCode::SUCCESS);
    }
    let runs = repeats(&meter, &m, args, &name)?;
    let s = Summary::of(&runs);
    let unsettled: Vec<u64> = runs.iter().filter(|r| !r.settled).map(|r| r.seed).collect();
    if args.json {
        let line = serde_json::json!({
            "material": name, "specimen_cm": args.size, "pedestal_cm": 18,
            "dc": runs.iter().map(|r| r.dc).collect::<Vec<_>>(),
            "dc_mean": s.dc_mean, "dc_sd": s.dc_sd, "nodes": s.nodes, "mode": s.mode,
            "dc_at_mode": s.dc_at_mode,
            "settled": runs.iter().map(|r| r.settled).collect::<Vec<_>>(),
            "seconds": runs.iter().map(|r| r.time).collect::<Vec<_>>(),
            "integrator": meter.integrator.name(), "dt": runs[0].step,
        });
        println!("{line}");
    } else {
        println!(
            "drape test of {name}: a {} cm specimen on an 18 cm pedestal, {} repeat(s), {} at dt = {:.3e} s",
            args.size,
            runs.len(),
            meter.integrator.name(),
            runs[0].step
        );
        for r in &runs {
            println!(
                "  seed {}: DC {:.3}, {} nodes, {} {:.2} s",
                r.seed,
                r.dc,
                r.nodes,
                if r.settled {
                    "settled at"
                } else {
                    "NOT SETTLED, measured at"
                },
                r.time
            );
        }
        let mut counts: Vec<usize> = s.nodes.clone();
        counts.sort_unstable();
        counts.dedup();
        let how_often = |c: usize| s.nodes.iter().filter(|&&n| n == c).count();
        let spread: Vec<String> = counts
            .iter()
            .map(|&c| format!("{c} ×{}", how_often(c)))
            .collect();
        let tied = counts
            .iter()
            .filter(|&&c| how_often(c) == how_often(s.mode))
            .count();
        // A tie has no most frequent count: say so rather than pick one.
        let mode = if tied > 1 {
            format!("{tied} counts tie, none most often")
        } else {
            format!("most often {} nodes, DC there {:.3}", s.mode, s.dc_at_mode)
        };
        println!(
            "DC {:.3} ± {:.3} (mean ± sd); nodes {}; {mode}",
            s.dc_mean,
            s.dc_sd,
            spread.join(", "),
        );
    }
    large_step_note(&meter);
    if !unsettled.is_empty() {
        eprintln!(
            "warning: repeat(s) with seed {:?} had not settled by {} s (kinetic energy under {} J/kg and DC within {} for {} s): their readings are of a moving specimen",
            unsettled, meter.longest, meter.settle_energy, meter.settle_band, meter.settle_for
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// A seed: a whole number from 0 (clap's own message for `-1` was "invalid digit").
fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| {
        format!(
            "expected a whole number from 0 to {}, found '{s}'",
            u64::MAX
        )
    })
}
