//! The report as a static page: plain HTML and CSS (light and dark, phone and laptop), its
//! SVG plots and PNG pictures beside it, the numbers in `report.json`. A line of script
//! only counts the images that loaded, for the browser test; the page reads the same
//! without it.

use super::folder::{CONVERGENCE, JSON, PAGE, Pending, STABILITY, energy_file};
use super::{Report, plots};
use crate::Result;
use std::fmt::Write;

/// `s` safe inside HTML text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A number in a table: 4 significant digits, `∞` for infinity.
fn num(v: f64) -> String {
    if v.is_infinite() {
        "∞".into()
    } else if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{}", (v * 1e4).round() / 1e4)
    } else {
        format!("{v:.3e}")
    }
}

fn verdict(ok: bool) -> &'static str {
    if ok {
        "<span class=ok>✔</span>"
    } else {
        "<span class=bad>✘ fails</span>"
    }
}

const STYLE: &str = r#"
:root { color-scheme: light dark; --bg: #ffffff; --fg: #1f2328; --muted: #59636e;
  --card: #f6f8fa; --line: #d1d9e0; --ok: #1a7f37; --bad: #cf222e; }
@media (prefers-color-scheme: dark) {
  :root { --bg: #0d1117; --fg: #e6edf3; --muted: #9198a1; --card: #151b23; --line: #3d444d;
    --ok: #3fb950; --bad: #f85149; }
}
* { box-sizing: border-box; }
body { margin: 0 auto; max-width: 1120px; padding: 1rem; background: var(--bg);
  color: var(--fg); font: 16px/1.5 system-ui, -apple-system, "Segoe UI", sans-serif; }
h1 { font-size: 1.7rem; margin: .2rem 0; } h2 { margin-top: 2.2rem; border-bottom: 1px solid var(--line); }
.muted { color: var(--muted); }
.banner { padding: .8rem 1rem; border-radius: 8px; color: #fff; margin: 1rem 0; }
.banner.pass { background: var(--ok); } .banner.fail { background: var(--bad); }
.banner ul { margin: .4rem 0 0; padding-left: 1.2rem; }
.ok { color: var(--ok); font-weight: 600; } .bad { color: var(--bad); font-weight: 600; }
figure { margin: 0; background: var(--card); border: 1px solid var(--line); border-radius: 8px; padding: .5rem; }
figure img { width: 100%; height: auto; display: block; border-radius: 4px; background: #fff; }
figcaption { font-size: .85rem; color: var(--muted); margin-top: .3rem; }
.grid { display: grid; gap: 1rem; grid-template-columns: repeat(auto-fit, minmax(300px, 1fr)); }
.triple { display: grid; gap: .5rem; grid-template-columns: repeat(3, 1fr); }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; width: 100%; font-size: .9rem; font-variant-numeric: tabular-nums; }
th, td { padding: .3rem .55rem; border-bottom: 1px solid var(--line); text-align: right; white-space: nowrap; }
th:first-child, td:first-child { text-align: left; }
nav a { margin-right: .8rem; color: inherit; }
@media (max-width: 600px) { body { padding: .6rem; font-size: 15px; } .triple { grid-template-columns: 1fr; } }
"#;

/// Counts the images that loaded (`data-images="N/M"` on the body) for the browser test,
/// and says in the console which did not.
const SCRIPT: &str = r#"addEventListener('load', () => {
  const all = [...document.images];
  const ok = all.filter(i => i.complete && i.naturalWidth > 0);
  all.filter(i => !ok.includes(i)).forEach(i => console.error('image did not load: ' + i.src));
  document.body.dataset.images = ok.length + '/' + all.length;
});"#;

/// Adds the plots, `report.json` and `index.html` to `files`.
pub(super) fn write(files: &mut Pending, r: &Report) -> Result<()> {
    files.add(CONVERGENCE, plots::convergence(&r.convergence)?);
    files.add(STABILITY, plots::stability(&r.convergence)?);
    let json = serde_json::to_string_pretty(r).map_err(|e| crate::Error::Output {
        message: format!("{JSON}: {e}"),
    })?;
    files.add(JSON, json);
    let mut h = String::new();
    writeln!(
        h,
        "<!doctype html><html lang=en><head><meta charset=utf-8>\
         <meta name=viewport content=\"width=device-width, initial-scale=1\">\
         <title>Hooke report</title><style>{STYLE}</style></head><body>"
    )?;
    writeln!(
        h,
        "<h1>Hooke: the evidence, run on this machine</h1><p class=muted>hooke {}{} · {} · {} logical CPUs · spring kernel {}</p>",
        r.hooke_version,
        if r.quick { " · <b>--quick</b>" } else { "" },
        esc(&r.machine.cpu),
        r.machine.logical_cpus,
        r.machine.spring_kernel
    )?;
    if r.failures.is_empty() {
        writeln!(
            h,
            "<div class=\"banner pass\"><b>Every check passed.</b></div>"
        )?;
    } else {
        writeln!(
            h,
            "<div class=\"banner fail\" id=failures><b>{} check{} failed:</b><ul>",
            r.failures.len(),
            if r.failures.len() == 1 { "" } else { "s" }
        )?;
        for f in &r.failures {
            writeln!(h, "<li>{}</li>", esc(f))?;
        }
        writeln!(h, "</ul></div>")?;
    }
    writeln!(
        h,
        "<nav><a href=#convergence>Convergence</a><a href=#physics>Closed forms</a>\
         <a href=#energy>Energy</a><a href=#scenes>Scenes</a><a href=#worlds>Worlds</a>\
         <a href=#drape>Drape test</a>\
         <a href=#determinism>Determinism and speed</a><a href=report.json>report.json</a></nav>"
    )?;
    convergence(&mut h, r)?;
    physics(&mut h, r)?;
    energy(&mut h, files, r)?;
    scenes(&mut h, r)?;
    worlds(&mut h, r)?;
    drape(&mut h, files, r)?;
    machine(&mut h, r)?;
    writeln!(h, "<script>{SCRIPT}</script></body></html>")?;
    files.add(PAGE, h);
    Ok(())
}

fn convergence(h: &mut String, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=convergence>Convergence and stability</h2><p>The built-in <code>single-spring</code> \
         (1 kg, k = 100 N/m, damping ratio 0.05, released 0.5 m stretched) against the damped \
         oscillator's closed form with g = 9.81 m/s²: the largest height error over 2 s at each \
         step size, and the order fitted to it (must be within 0.1 of the scheme's order). Then the \
         step beyond which the swing grows: measured here by bisection, against linear stability \
         theory for this spring (must agree within 5 %) and <code>hooke check</code>'s estimate \
         (the scheme's stability radius over ω<sub>max</sub>: right for symplectic Euler and RK4 on \
         a lightly damped spring, far too generous for explicit Euler and midpoint, which grow on \
         an undamped spring at any step and here stay stable only below 2ζ/ω and its like).</p>\
         <div class=grid><figure><img src=convergence.svg alt=\"error against step size, log-log\">\
         <figcaption>Error against step; slopes in the legend.</figcaption></figure>\
         <figure><img src=stability.svg alt=\"largest stable step per integrator\">\
         <figcaption>Largest stable step per integrator.</figcaption></figure></div>\
         <div class=scroll><table><tr><th>integrator</th><th>fitted order</th><th>expected</th>\
         <th></th><th>unstable from (measured, s)</th><th>theory (s)</th><th>hooke check (s)</th><th></th></tr>"
    )?;
    for s in &r.convergence {
        writeln!(
            h,
            "<tr><td>{}</td><td>{:.3}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            s.integrator,
            s.slope,
            s.expected,
            verdict(s.order_agrees()),
            num(s.measured_limit),
            num(s.theory_limit),
            num(s.check_limit),
            verdict(s.stability_agrees())
        )?;
    }
    writeln!(h, "</table></div>")?;
    Ok(())
}

fn physics(h: &mut String, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=physics>Closed forms</h2><div class=scroll><table><tr><th>quantity</th><th>formula</th>\
         <th>expected</th><th>measured</th><th>tolerance</th><th></th></tr>"
    )?;
    for c in &r.closed_forms {
        writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:.6} {}</td><td>{:.6} {}</td><td>{:.1e}</td><td>{}</td></tr>",
            esc(&c.what),
            esc(&c.formula),
            c.expected,
            c.unit,
            c.measured,
            c.unit,
            c.tolerance,
            verdict(c.passed())
        )?;
    }
    writeln!(h, "</table></div>")?;
    Ok(())
}

fn energy(h: &mut String, files: &mut Pending, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=energy>Energy</h2><p>Total energy (kinetic, springs, gravity, penalty) over the \
         first {} s of each built-in scene with each integrator, the explicit ones at the \
         scene's step and the large-step ones (implicit, vbd) at 1/60 s. The dashed \
         black line is what the damping alone would leave for the scene's own integrator: E(0) \
         − ∫ Σ k<sub>d</sub> (Δv·u)² + drag |v|² dt. Where nothing else takes energy (no collider, \
         air or field) midpoint's and RK4's loss must equal it within 1 %; the first-order schemes \
         show their own energy error of order dt (symplectic Euler's oscillates, backward \
         Euler's and block descent's damp), and elsewhere the difference is the contacts' and \
         the air's work.</p><div class=grid>",
        r.energy_window_seconds
    )?;
    for (name, make) in hooke_scene::builtin::BUILTINS {
        let own = make().simulation.integrator.0.to_string();
        let runs: Vec<_> = r.energy.iter().filter(|e| e.scene == name).collect();
        let file = energy_file(name);
        files.add(file.clone(), plots::energy(name, &runs, &own)?);
        let own_run = runs.iter().find(|e| e.integrator == own);
        let caption = match own_run {
            Some(e) if e.closed => format!(
                "{own}: ΔE = {} J, damping took {} J",
                num(e.change),
                num(-e.predicted_change)
            ),
            Some(e) => format!(
                "{own}: ΔE = {} J, damping took {} J; contacts or air do the rest",
                num(e.change),
                num(-e.predicted_change)
            ),
            None => String::new(),
        };
        writeln!(
            h,
            "<figure><img src=\"{file}\" alt=\"energy of {name}\" loading=lazy><figcaption>{}</figcaption></figure>",
            esc(&caption)
        )?;
    }
    writeln!(h, "</div>")?;
    Ok(())
}

fn scenes(h: &mut String, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=scenes>Scenes</h2><p>Each built-in scene's still, rendered here, beside its golden \
         image and the pixels that differ by more than {} levels (red; at most {:.1} % may). On every \
         frame up to the still: crossings between the cloth and the colliders and within the cloth \
         (none allowed), and the cloth's smallest gap to a collider.</p>",
        super::pixels::CHANNEL_TOLERANCE,
        100.0 * super::pixels::MISMATCH_FRACTION
    )?;
    writeln!(
        h,
        "<div class=scroll><table><tr><th>scene</th><th>t (s)</th><th>pixels off</th><th></th>\
         <th>frames</th><th>crossings</th><th>min gap (mm)</th><th></th></tr>"
    )?;
    for s in &r.scenes {
        writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{} of {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            s.name,
            num(s.time),
            s.differing_pixels,
            s.pixels,
            verdict(s.matches_golden()),
            s.frames,
            s.crossings(),
            s.min_gap.map_or("—".into(), |g| format!("{:.2}", 1e3 * g)),
            verdict(s.crossings() == 0)
        )?;
    }
    writeln!(h, "</table></div>")?;
    for s in &r.scenes {
        writeln!(
            h,
            "<h3>{}</h3><div class=triple>\
             <figure><img src=\"{}\" alt=\"{} now\"><figcaption>rendered now</figcaption></figure>\
             <figure><img src=\"{}\" alt=\"{} golden\"><figcaption>golden</figcaption></figure>\
             <figure><img src=\"{}\" alt=\"{} difference\"><figcaption>{} pixels differ</figcaption></figure></div>",
            s.name, s.still, s.name, s.golden, s.name, s.diff, s.name, s.differing_pixels
        )?;
        if let Some(strain) = &s.strain {
            writeln!(
                h,
                "<div class=triple><figure><img src=\"{}\" alt=\"{} strain\"><figcaption>\
                 strain: largest {:.2} %; a column of the cloth hanging from one structural \
                 spring stretches it {:.2} % (pinned corners hold more than a column)\
                 </figcaption></figure></div>",
                strain.file, s.name, strain.largest, strain.weight
            )?;
        }
    }
    Ok(())
}

fn drape(h: &mut String, files: &mut Pending, r: &Report) -> Result<()> {
    let Some(d) = &r.drape else {
        return Ok(writeln!(
            h,
            "<h2 id=drape>Drape test</h2><p class=muted>Not run with --quick: \
             `hooke drape PRESET` runs it.</p>"
        )?);
    };
    writeln!(
        h,
        "<h2 id=drape>Drape test</h2><p>Cusick's drape meter (BS 5058, docs/materials.md \
         \"Drape test\"): a 30 cm disc of irregular triangles on an 18 cm pedestal, one \
         repeat (seed 1) each, run by `hooke drape` with its defaults until settled. \
         DC = (A<sub>shadow</sub> − A<sub>pedestal</sub>) / (A<sub>specimen</sub> − \
         A<sub>pedestal</sub>); nodes are the outline's peaks that rise {} mm above their \
         valleys. The presets must order silk &lt; cotton &lt; wool &lt; denim at least {} \
         apart, each DC within 0.2–0.98 and 3–14 nodes; across the sweep of B DC must rise \
         (by 0.3 at least, never falling more than {} from one B to the next).</p>\
         <div class=grid>",
        1e3 * crate::drape::Meter::default().prominence,
        super::drape::APART,
        super::drape::DIP
    )?;
    for p in &d.presets {
        writeln!(
            h,
            "<figure><img src=\"{}\" alt=\"{} from above\" loading=lazy><figcaption>{}: \
             DC {:.3}, {} nodes, overhang {:.1} bending lengths{}</figcaption></figure>",
            p.file.as_deref().unwrap_or_default(),
            p.what,
            p.what,
            p.dc,
            p.nodes,
            p.overhang,
            if p.settled { "" } else { " (NOT SETTLED)" }
        )?;
    }
    files.add(
        super::folder::DRAPE_SWEEP,
        plots::drape(&d.sweep, &d.presets)?,
    );
    writeln!(
        h,
        "</div><figure><img src=\"{}\" alt=\"DC against overhang\"></figure>\
         <div class=scroll><table><tr><th>B (µN·m)</th><th>overhang / c</th><th>DC</th>\
         <th>nodes</th><th>settled</th></tr>",
        super::folder::DRAPE_SWEEP
    )?;
    for s in &d.sweep {
        writeln!(
            h,
            "<tr><td>{}</td><td>{:.2}</td><td>{:.3}</td><td>{}</td><td>{}</td></tr>",
            num(s.bending * 1e6),
            s.overhang,
            s.dc,
            s.nodes,
            verdict(s.settled)
        )?;
    }
    writeln!(h, "</table></div>")?;
    Ok(())
}

fn worlds(h: &mut String, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=worlds>Jello worlds</h2><p>The five course worlds against the reference \
         trajectories the validation suite locks (eight corners at steps 100, 500 and 1000): the \
         largest difference. With the world's own integrator it must be within the references' \
         rounding ({:.0e} m); the other integrators at the world's step show how far each drifts \
         from it.</p><div class=scroll><table><tr><th>world</th>",
        super::worlds::ROUNDING
    )?;
    let integrators: Vec<String> = hooke_core::Integrator::ALL
        .iter()
        .map(|i| i.to_string())
        .collect();
    for i in &integrators {
        write!(h, "<th>{i} (m)</th>")?;
    }
    writeln!(h, "</tr>")?;
    let mut names: Vec<&str> = r.worlds.iter().map(|w| w.world.as_str()).collect();
    names.dedup();
    for name in names {
        write!(h, "<tr><td>{name}</td>")?;
        for i in &integrators {
            match r
                .worlds
                .iter()
                .find(|w| w.world == name && &w.integrator == i)
            {
                None => write!(h, "<td class=muted>—</td>")?,
                Some(w) => {
                    let text = w.max_difference.map_or("diverged".into(), num);
                    if w.own {
                        write!(
                            h,
                            "<td><b>{text}</b> {}</td>",
                            verdict(w.matches_reference())
                        )?;
                    } else {
                        write!(h, "<td>{text}</td>")?;
                    }
                }
            }
        }
        writeln!(h, "</tr>")?;
    }
    writeln!(
        h,
        "</table></div><p class=muted>Bold: the world's own integrator.</p>"
    )?;
    Ok(())
}

fn machine(h: &mut String, r: &Report) -> Result<()> {
    writeln!(
        h,
        "<h2 id=determinism>Determinism and speed</h2><p>A hash of every frame's positions and \
         velocities on one thread and on {} (they must be equal: the same bits whatever the \
         thread count).</p><div class=scroll><table><tr><th>run</th><th>1 thread</th><th>{} threads</th><th></th></tr>",
        r.determinism.first().map_or(2, |d| d.threads),
        r.determinism.first().map_or(2, |d| d.threads)
    )?;
    for d in &r.determinism {
        writeln!(
            h,
            "<tr><td>{}</td><td><code>{}</code></td><td><code>{}</code></td><td>{}</td></tr>",
            esc(&d.run),
            d.one_thread,
            d.many_threads,
            verdict(d.agree())
        )?;
    }
    let s = &r.speed;
    writeln!(
        h,
        "</table></div><p>Speed on this machine ({}): {} at {:.1} steps/s, {:.3e} spring \
         updates/s; the built-in <code>cloth-table</code> takes {:.2} s of wall time per simulated \
         second. <span class=muted>For the full benchmark, <code>hooke bench</code>; figures from \
         other machines are in <code>benches/README.md</code>.</span></p>",
        if s.threads == 1 {
            "1 thread".to_string()
        } else {
            format!("{} threads", s.threads)
        },
        esc(&s.workload),
        s.steps_per_second,
        s.spring_updates_per_second,
        s.cloth_table_wall_per_simulated
    )?;
    writeln!(
        h,
        "<p class=muted>Machine: {} · {} · {} logical CPUs.</p>",
        esc(&r.machine.cpu),
        r.machine.os,
        r.machine.logical_cpus
    )?;
    Ok(())
}
