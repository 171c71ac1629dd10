//! A cloth given as a material (`[body.material]`, docs/physics.md §1.1) bends as its
//! bending rigidity says, whatever the resolution: Peirce's cantilever, checked against the
//! heavy elastica solved here.

use crate::common::root;
use hooke_scene::Scene;

const G: f64 = 9.81;

/// The heavy elastica: a strip clamped level at `s = 0`, free at `s = L`, under its own
/// weight `q` per unit area with bending rigidity `B` per unit width. Its angle below the
/// horizontal `φ(s)` solves `B φ'' = -q (L - s) cos φ` with `φ(0) = 0` and `φ'(L) = 0`
/// (the moment vanishes at the tip). Shooting on `φ'(0)` by bisection, RK4 in `s`. Returns
/// the chord's angle below the horizontal from the clamp to the tip, in degrees.
pub(crate) fn elastica_chord(b: f64, q: f64, l: f64) -> f64 {
    let steps = 4000;
    let ds = l / steps as f64;
    // (φ, φ', x, y) along s.
    let run = |k0: f64| {
        let rhs =
            |s: f64, y: [f64; 4]| [y[1], -q / b * (l - s) * y[0].cos(), y[0].cos(), y[0].sin()];
        let mut y = [0.0, k0, 0.0, 0.0];
        for n in 0..steps {
            let s = n as f64 * ds;
            let add = |y: [f64; 4], k: [f64; 4], h: f64| std::array::from_fn(|i| y[i] + h * k[i]);
            let k1 = rhs(s, y);
            let k2 = rhs(s + ds / 2.0, add(y, k1, ds / 2.0));
            let k3 = rhs(s + ds / 2.0, add(y, k2, ds / 2.0));
            let k4 = rhs(s + ds, add(y, k3, ds));
            y = std::array::from_fn(|i| {
                y[i] + ds / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        y
    };
    // φ'(L) falls as φ'(0) rises: bisect for its zero.
    let (mut lo, mut hi) = (0.0, 100.0 / l);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if run(mid)[1] > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let y = run(0.5 * (lo + hi));
    y[3].atan2(y[2]).to_degrees()
}

/// A strip `width` wide given as a material, its first two rows of particles pinned level
/// (the clamp), overhanging by `overhang` in `segments` spacings, settled by the implicit
/// integrator at large steps (whose damping of the slow modes settles it in seconds), with
/// gravity along -y. Returns the chord's angle below the horizontal from the clamp's edge
/// to the tip, averaged over the width, in degrees.
fn cantilever(material: &str, overhang: f64, segments: usize) -> f64 {
    cantilever_with(material, overhang, segments, ("implicit", 0.01, 2500))
}

/// [`cantilever`] stepped by `integrator` at `dt` for `steps` steps.
fn cantilever_with(
    material: &str,
    overhang: f64,
    segments: usize,
    (integrator, dt, steps): (&str, f64, u64),
) -> f64 {
    let h = overhang / segments as f64;
    let nx = segments + 2;
    let nz = 3;
    let pins: Vec<String> = (0..2 * nz).map(|k| k.to_string()).collect();
    let text = format!(
        r#"
name = "cantilever"
[simulation]
integrator = "{integrator}"
dt = {dt}
tolerance = 1e-5
duration = 30.0
every = 1
gravity = [0.0, -{G}, 0.0]
[[body]]
name = "strip"
pins = [{}]
thickness = 0.0
self_collision = false
[body.shape]
kind = "grid"
size = [{nx}, {nz}]
spacing = {h}
[body.material]
{material}
"#,
        pins.join(", ")
    );
    let mut scene: Scene = hooke_scene::parse_scene(&text, "cantilever.toml")
        .unwrap()
        .build(&root().join("assets/scenes"))
        .unwrap();
    scene.simulation.advance(steps).unwrap();
    let p = scene.simulation.particles();
    let fastest = p.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(fastest < 1e-4, "not settled: {fastest} m/s");
    let at = |i: usize| (0..nz).map(|j| p.x[i * nz + j]).sum::<hooke_core::Vec3>() / nz as f64;
    let chord = at(nx - 1) - at(1);
    (-chord.y).atan2(chord.x).to_degrees()
}

/// Peirce's bending length `c = (B / w)^(1/3)`; at an overhang of `2c` the heavy elastica's
/// chord drops 41.5° (Peirce 1930, ASTM D1388), which the solver here reproduces.
#[test]
fn the_heavy_elastica_drops_its_chord_41_5_degrees_at_twice_the_bending_length() {
    let (b, q) = (2e-3, 0.2 * G);
    let c = (b / q).cbrt();
    let angle = elastica_chord(b, q, 2.0 * c);
    assert!((angle - 41.5).abs() < 0.5, "{angle}°");
}

/// A strip of a stiff material (B = 2 mN·m, 0.2 kg/m², so c = 10 cm) at overhangs of
/// 1.5c and 2c, each at 20 and 40 spacings, settles to the heavy elastica's chord angle
/// within 0.5° (41.5° at 2c; the issue asks for 2.5°), and the two resolutions agree within
/// 0.3°. (Measured: 41.61° and 41.52° against 41.49° at 2c; 22.24° and 22.19° at 1.5c.)
#[test]
fn a_material_cantilever_drops_to_the_heavy_elastica_at_any_resolution() {
    let material = "density = 0.2\nstretch = 2000.0\nshear = 100.0\nbending = 2e-3\ndamping = 1e-3";
    let (b, q) = (2e-3, 0.2 * G);
    let c = (b / q).cbrt();
    for ratio in [1.5, 2.0] {
        let exact = elastica_chord(b, q, ratio * c);
        let coarse = cantilever(material, ratio * c, 20);
        let fine = cantilever(material, ratio * c, 40);
        for (n, got) in [(20, coarse), (40, fine)] {
            assert!(
                (got - exact).abs() < 0.5,
                "overhang {ratio} c, {n} spacings: chord {got}°, elastica {exact}°"
            );
        }
        assert!((coarse - fine).abs() < 0.3, "{coarse}° vs {fine}°");
    }
}

/// The built-in `tablecloth` (cotton, 1.6 m square, on the square table whose top is at
/// y = 0.9 m and 1 m wide) at `n × n` particles, run for its 3 s. Returns its lowest point,
/// its centroid and the median gap between the top and the particles over it (more than
/// 5 cm inside its edges), over the cloth's thickness.
fn tablecloth(n: usize) -> (f64, hooke_core::Vec3, f64) {
    let mut spec = hooke_scene::builtin::tablecloth();
    let (side, _) = hooke_scene::builtin::TABLECLOTH;
    spec.bodies[0].shape = hooke_scene::spec::ShapeSpec::Grid {
        size: [n, n],
        spacing: hooke_scene::spec::Positive::of(side / (n - 1) as f64),
    };
    let mut scene = spec.build(&root().join("assets/scenes")).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let x = &scene.simulation.particles().x;
    let lowest = x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let centroid = x.iter().sum::<hooke_core::Vec3>() / x.len() as f64;
    let mut gaps: Vec<f64> = x
        .iter()
        .filter(|p| p.x.abs() < 0.45 && p.z.abs() < 0.45)
        .map(|p| p.y - 0.9)
        .collect();
    gaps.sort_by(f64::total_cmp);
    let thickness = scene.bodies[0].thickness;
    (lowest, centroid, gaps[gaps.len() / 2] / thickness)
}

/// Cotton (150 g/m², B = 5 µN·m) hangs like cloth on the square table: at 36² and at 72²
/// its lowest point is at most 0.58 m (Blender 5.0's and NVIDIA Newton's default cloths
/// reach 0.49–0.54 there; the spring cloth of earlier stopped at 0.63), it rests on the top
/// with a median gap under 1.6 thicknesses, and the two resolutions drape alike: lowest
/// points within 3 cm, centroids within 2 cm.
#[test]
fn a_cotton_tablecloth_drapes_alike_at_36_and_72_particles_a_side() {
    let (low36, c36, gap36) = tablecloth(36);
    let (low72, c72, gap72) = tablecloth(72);
    for (n, low, gap) in [(36, low36, gap36), (72, low72, gap72)] {
        assert!(low <= 0.58, "{n}²: lowest point {low} m");
        assert!(gap < 1.6, "{n}²: median gap on the top {gap} thicknesses");
    }
    assert!((low36 - low72).abs() < 0.03, "lowest {low36} vs {low72} m");
    assert!((c36 - c72).norm() < 0.02, "centroid {c36:?} vs {c72:?}");
}

/// Issue 54: a drag per particle changes a material cloth with its resolution, so a scene
/// with both is refused, naming `mass_drag`; a drag per kilogram is the same at any
/// resolution: a cotton sheet falling freely under `mass_drag = c` approaches `g / c`, as
/// `v(t) = (g / c)(1 - e^(-c t))` says, at 10 and at 40 particles a side alike.
#[test]
fn a_drag_per_kilogram_is_the_same_at_any_resolution_and_one_per_particle_is_refused() {
    let sheet = |n: usize, drag: &str| {
        let text = format!(
            r#"
name = "falling-cotton"
[simulation]
integrator = "symplectic"
dt = 2.5e-4
duration = 0.5
every = 100
{drag}
[[body]]
name = "cloth"
origin = [0.0, 100.0, 0.0]
shape = {{ kind = "grid", size = [{n}, {n}], spacing = {} }}
material = {{ preset = "cotton" }}
"#,
            1.0 / (n - 1) as f64
        );
        let spec: hooke_scene::spec::SceneSpec = toml::from_str(&text).unwrap();
        spec.build(&root())
    };
    let e = sheet(10, "drag = 0.002").unwrap_err().to_string();
    assert!(
        e.contains("simulation.drag") && e.contains("mass_drag ="),
        "{e}"
    );
    let c = 4.0;
    let want = 9.81 / c * (1.0 - (-c * 0.5f64).exp());
    for n in [10, 40] {
        let mut scene: Scene = sheet(n, &format!("mass_drag = {c}")).unwrap();
        let steps = scene.steps;
        scene.simulation.advance(steps).unwrap();
        let p = scene.simulation.particles();
        let speed = p.v.iter().map(|v| -v.y).sum::<f64>() / p.len() as f64;
        assert!(
            (speed - want).abs() < 2e-3 * want,
            "{n}²: falls at {speed} m/s, the closed form says {want}"
        );
    }
}

/// Issue 56: a strip of the `denim` preset (B = 100 µN·m, 0.4 kg/m²: c = 2.9 cm) clamped
/// level and overhanging 2c at 40 and 80 spacings (1.5 and 0.7 mm: `ks dt² / m` of 1.5e6 and
/// 6e6 at 1/60 s), settled by Newton's step at 1/60 s (its steps solved to 1e-5 m/s: the
/// default 0.01 m/s is 10 % of a spacing a step on a strip this small), drops to the heavy
/// elastica's chord within 2.5°.
#[test]
fn a_denim_cantilever_settles_to_the_elastica_under_newton_at_60_hz() {
    let material = "preset = \"denim\"";
    let (b, q) = (100e-6, 0.4 * G);
    let c = (b / q).cbrt();
    let exact = elastica_chord(b, q, 2.0 * c);
    for segments in [40, 80] {
        let got = cantilever_with(material, 2.0 * c, segments, ("newton", 1.0 / 60.0, 600));
        assert!(
            (got - exact).abs() < 2.5,
            "{segments} spacings: chord {got}°, elastica {exact}°"
        );
    }
}
