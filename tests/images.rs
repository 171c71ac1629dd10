//! Image goldens: a still of each built-in scene and of one jello world, rendered and
//! compared with `golden/<name>.png` as decoded pixels; and what a picture must show:
//! shadows where the geometry puts them, strain reddest at the pins, a solid's flat faces.
//!
//! **Tolerance** (`hooke::report::pixels`, which `hooke report` uses too). A pixel matches
//! when each channel is within [`CHANNEL_TOLERANCE`] levels; an image matches when at most
//! `MISMATCH_FRACTION` of its pixels do not. Other platforms'
//! libm (sin/cos place the rotated jelly) and the sticking decisions of `cloth-table` (a
//! discontinuous response that amplifies round-off) may move a few edge pixels; a change to
//! the physics or the renderer moves whole surfaces, thousands of pixels.
//!
//! **Updating**, following insta's habits: by default a mismatch (or a missing golden)
//! writes `golden/<name>.new.png` and `target/golden-diff/<name>.diff.png` (mismatched
//! pixels red over the golden, dimmed) and fails; look at them, then accept by renaming the
//! `.new.png` over the golden or by running with `INSTA_UPDATE=always`, which overwrites
//! goldens. With `CI` set (or `INSTA_UPDATE=no`) nothing is written, only compared.

use crate::common::root;
use hooke::image_out::View;
use hooke::report::pixels::{CHANNEL_TOLERANCE, allowed, compare};
use hooke::stills::{still_scene, still_view};
use hooke_scene::Overrides;
use image::{Rgba, RgbaImage};
use std::path::{Path, PathBuf};

/// Golden stills are small: enough to recognise each scene, cheap to store and compare.
fn view() -> View {
    View {
        size: (320, 240),
        ..View::default()
    }
}

enum Update {
    /// Compare only (CI, or `INSTA_UPDATE=no`).
    Never,
    /// Write `.new.png` and a diff on mismatch (the default off CI).
    New,
    /// Overwrite the golden (`INSTA_UPDATE=always`).
    Always,
}

fn update_mode() -> Update {
    match std::env::var("INSTA_UPDATE").as_deref() {
        Ok("always") => Update::Always,
        Ok("no") => Update::Never,
        _ if std::env::var_os("CI").is_some() => Update::Never,
        _ => Update::New,
    }
}

fn save(path: &Path, image: &RgbaImage) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    image.save(path).unwrap();
}

/// Compares `actual` with `golden/<name>.png`, returning a failure message.
fn check(name: &str, actual: &RgbaImage) -> Option<String> {
    let golden_path = root().join("golden").join(format!("{name}.png"));
    let new_path = root().join("golden").join(format!("{name}.new.png"));
    let diff_path: PathBuf = root()
        .join("target/golden-diff")
        .join(format!("{name}.diff.png"));
    let mode = update_mode();
    if let Update::Always = mode {
        save(&golden_path, actual);
        return None;
    }
    // A golden that cannot be compared: keep the new image for review (off CI) and fail.
    let unusable = |message: String| {
        if let Update::New = mode {
            save(&new_path, actual);
        }
        Some(format!(
            "{message}; the new still is {}",
            new_path.display()
        ))
    };
    let golden = match image::open(&golden_path) {
        Ok(g) => g.to_rgba8(),
        Err(e) => {
            return unusable(format!(
                "{name}: no golden at {} ({e})",
                golden_path.display()
            ));
        }
    };
    if golden.dimensions() != actual.dimensions() {
        return unusable(format!(
            "{name}: golden is {:?} pixels, the still is {:?}",
            golden.dimensions(),
            actual.dimensions()
        ));
    }
    let (bad, diff) = compare(&golden, actual);
    let allowed = allowed((golden.width() * golden.height()) as usize);
    if bad <= allowed {
        let _ = std::fs::remove_file(&new_path);
        return None;
    }
    let written = if let Update::New = mode {
        save(&new_path, actual);
        save(&diff_path, &diff);
        format!(
            "actual: {}\n  diff:   {}",
            new_path.display(),
            diff_path.display()
        )
    } else {
        "(CI: nothing written)".to_string()
    };
    Some(format!(
        "{name}: {bad} pixels differ by more than {CHANNEL_TOLERANCE} levels (at most {allowed} may)\n  {written}"
    ))
}

#[test]
fn stills_match_the_golden_images() {
    let mut failures = Vec::new();
    for (name, _) in hooke_scene::builtin::BUILTINS {
        let scene = still_scene(name).unwrap();
        let view = still_view(name, &view());
        let image = view.pixels(&scene, &view.camera(&scene));
        failures.extend(check(name, &image));
    }
    // A jello world drawn as springs: box edges, the inclined plane and the three families.
    let world = root().join("assets/worlds/rotate.w");
    let mut scene = hooke::source::build(world.to_str().unwrap(), &Overrides::default()).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let springs = View {
        style: hooke::draw::Style::Springs,
        ..view()
    };
    let image = springs.pixels(&scene, &springs.camera(&scene));
    failures.extend(check("world-rotate", &image));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison itself: identical images match, a moved square does not.
#[test]
fn the_comparison_catches_a_moved_surface_and_forgives_a_shade() {
    let square = |x0: u32, shade: u8| {
        RgbaImage::from_fn(100, 100, |x, y| {
            if (x0..x0 + 30).contains(&x) && (30..60).contains(&y) {
                Rgba([200, 40, 40, 255])
            } else {
                Rgba([shade, shade, shade, 255])
            }
        })
    };
    let golden = square(30, 230);
    assert_eq!(compare(&golden, &square(30, 230)).0, 0);
    // A background three levels off is within tolerance.
    assert_eq!(compare(&golden, &square(30, 227)).0, 0);
    // Moving the square 4 pixels changes 2 × 4 × 30 = 240 pixels: 2.4 %, far over 0.5 %.
    assert_eq!(compare(&golden, &square(34, 230)).0, 240);
}

/// Issue 57: a shadow falls where the geometry puts it. A 0.4 m square held 1.5 m over a
/// uniform ground, seen from above under the key light: the pixels a shadowed render
/// darkens against an unshadowed one have their centroid within 2 pixels of the centroid of
/// the pixels whose ground point the square hides from the light (a ray cast per pixel,
/// less those where the square itself is in view), and the ground inside the shadow is at
/// most 0.6 of its lit brightness (the key light is 0.65 of a lit surface's light).
#[test]
fn a_square_casts_its_shadow_where_the_geometry_puts_it() {
    use hooke_render::{Camera, DrawList, RenderOptions, render};
    use nalgebra::{Vector3, Vector4};
    let (side, height) = (0.4, 1.5);
    let mut list = DrawList::default();
    let quad = |list: &mut DrawList, half: f64, y: f64, color: [f32; 3]| {
        let p = |x: f64, z: f64| Vector3::new(x, y, z);
        list.flat([p(-half, -half), p(half, -half), p(half, half)], color);
        list.flat([p(-half, -half), p(half, half), p(-half, half)], color);
    };
    quad(&mut list, 3.0, 0.0, [0.7, 0.7, 0.7]);
    quad(&mut list, side / 2.0, height, [0.8, 0.3, 0.2]);
    let camera = Camera {
        target: Vector3::zeros(),
        distance: 6.0,
        yaw: 20.0,
        pitch: 70.0,
        fov_y: 40.0,
    };
    let (w, h) = (320usize, 240usize);
    let options = |shadows| RenderOptions {
        width: w as u32,
        height: h as u32,
        shadows,
        ..RenderOptions::default()
    };
    let lit = render(&list, &camera, &options(false));
    let shaded = render(&list, &camera, &options(true));
    // The pixel's view ray, from the inverse of the camera's projection.
    let inverse = camera
        .view_projection(w as f64 / h as f64)
        .try_inverse()
        .unwrap();
    let eye = camera.eye();
    let light = camera.key_light();
    let inside = |p: Vector3<f64>| p.x.abs() < side / 2.0 && p.z.abs() < side / 2.0;
    let (mut expected, mut found) = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
    let (mut dark, mut bright) = ((0.0, 0.0), (0.0, 0.0));
    for y in 0..h {
        for x in 0..w {
            let ndc = Vector4::new(
                2.0 * (x as f64 + 0.5) / w as f64 - 1.0,
                1.0 - 2.0 * (y as f64 + 0.5) / h as f64,
                0.5,
                1.0,
            );
            let q = inverse * ndc;
            let ray = (q.xyz() / q.w - eye).normalize();
            let at = |plane: f64| eye + ray * ((plane - eye.y) / ray.y);
            let sees_square = inside(at(height));
            let ground = at(0.0);
            let shadowed = inside(ground + light * (height / light.y));
            let k = (y * w + x) * 4;
            let ratio = shaded[k + 1] as f64 / lit[k + 1].max(1) as f64;
            if sees_square {
                continue;
            }
            if shadowed {
                expected = (
                    expected.0 + x as f64,
                    expected.1 + y as f64,
                    expected.2 + 1.0,
                );
            }
            if ratio < 0.8 {
                found = (found.0 + x as f64, found.1 + y as f64, found.2 + 1.0);
            }
            // Well inside or well outside the shadow (its soft edge is left out).
            let core = inside(ground + light * (height / light.y))
                && inside((ground + light * (height / light.y)) * 1.4);
            if core {
                dark = (dark.0 + shaded[k + 1] as f64, dark.1 + 1.0);
            } else if !shadowed && ground.norm() < 1.5 {
                bright = (bright.0 + shaded[k + 1] as f64, bright.1 + 1.0);
            }
        }
    }
    assert!(
        expected.2 > 200.0,
        "the shadow covers {} pixels",
        expected.2
    );
    let (ex, ey) = (expected.0 / expected.2, expected.1 / expected.2);
    let (fx, fy) = (found.0 / found.2, found.1 / found.2);
    assert!(
        (ex - fx).hypot(ey - fy) < 2.0,
        "shadow centroid ({fx:.1}, {fy:.1}) over {} pixels, geometry's ({ex:.1}, {ey:.1}) \
         over {}",
        found.2,
        expected.2
    );
    let ratio = (dark.0 / dark.1) / (bright.0 / bright.1);
    assert!(ratio < 0.6, "shadowed ground at {ratio:.2} of lit ground");
}

/// Issue 57: the hanging cloth coloured by strain. Its springs stretch most at the pinned
/// corners (each corner carries the cloth's weight on few springs): the particle of largest
/// strain is within two spacings of a pin, the reddest pixel of the picture lies within 12
/// pixels of a pinned particle's image, and the legend's bar runs from the map's low end to
/// its high end over exactly the range the surface was coloured with, whose ends it prints.
#[test]
fn the_hanging_cloth_is_reddest_by_strain_at_its_pinned_corners() {
    use hooke::quantity::ColorBy;
    let scene = still_scene("hanging-cloth").unwrap();
    let view = View {
        color: ColorBy::Strain,
        ..still_view("hanging-cloth", &view())
    };
    let p = scene.simulation.particles();
    let pins: Vec<usize> = (0..p.len()).filter(|&i| p.is_pinned(i)).collect();
    let (values, range) = view.quantity(&scene).unwrap();
    let largest = (0..values.len())
        .max_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap();
    let spacing = scene
        .simulation
        .model()
        .springs
        .iter()
        .map(|s| s.rest)
        .fold(f64::INFINITY, f64::min);
    let nearest_pin = pins
        .iter()
        .map(|&i| (p.x[i] - p.x[largest]).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(
        nearest_pin <= 2.0 * spacing + 1e-9,
        "largest strain {:.2} % at particle {largest}, {nearest_pin:.3} m from a pin",
        values[largest]
    );
    assert!(range.0 < 0.0 && range.1 >= values[largest] && range.0 == -range.1);
    let camera = view.camera(&scene);
    let image = view.pixels(&scene, &camera);
    let (w, h) = image.dimensions();
    let legend = ColorBy::Strain.legend(&scene, range);
    let (x0, y0, x1, y1) = legend.bar(w, h);
    // The reddest pixel of the scene (left of the legend's panel).
    let mut reddest = (i32::MIN, 0, 0);
    for y in 0..h {
        for x in 0..x0.saturating_sub(60) {
            let c = image.get_pixel(x, y).0;
            let red = c[0] as i32 - c[2] as i32;
            if red > reddest.0 {
                reddest = (red, x, y);
            }
        }
    }
    let project = camera.view_projection(w as f64 / h as f64);
    let on_image = |q: hooke_core::Vec3| {
        let c = project * nalgebra::Vector4::new(q.x, q.y, q.z, 1.0);
        (
            (c.x / c.w + 1.0) * 0.5 * w as f64,
            (1.0 - c.y / c.w) * 0.5 * h as f64,
        )
    };
    let nearest = pins
        .iter()
        .map(|&i| {
            let (px, py) = on_image(p.x[i]);
            (px - reddest.1 as f64).hypot(py - reddest.2 as f64)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(
        nearest < 12.0,
        "the reddest pixel ({}, {}) is {nearest:.1} px from the nearest pin",
        reddest.1,
        reddest.2
    );
    // The bar: the map's high end at the top, its low end at the bottom, the range printed.
    let expect = |t: f64| ColorBy::Strain.map().at(t).map(|v| (v * 255.0 + 0.5) as u8);
    let bar = |y: u32| {
        let c = image.get_pixel((x0 + x1) / 2, y).0;
        [c[0], c[1], c[2]]
    };
    assert_eq!(bar(y0), expect(1.0));
    assert_eq!(bar(y1 - 1), expect(0.0));
    assert_eq!(legend.range, range);
    assert_eq!(
        legend.end_labels(),
        (hooke_render::short(range.1), hooke_render::short(range.0))
    );
}

/// A jelly filling a cube mesh is drawn with flat faces: across the face nearest the
/// camera (away from its edges) every pixel is within 3 levels of the others. Smooth
/// normals averaged across the 90° corners shaded that face as a rounded one, with shadow
/// acne on it: a spread of tens of levels.
#[test]
fn a_solid_cube_is_drawn_with_flat_faces() {
    use hooke_core::Vec3;
    let dir = std::env::temp_dir().join(format!("hooke-flat-faces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let corner = |i: u32| Vec3::new((i >> 2 & 1) as f64, (i >> 1 & 1) as f64, (i & 1) as f64);
    let quads = hooke_collide::BOX_FACES.map(|q| q.map(|k| k as u32));
    let mut obj = String::new();
    for i in 0..8 {
        let p = corner(i) * 0.6;
        obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for q in &quads {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    let text = r#"
name = "cube"
[simulation]
integrator = "symplectic"
dt = 0.0005
duration = 0.001
every = 1
[[body]]
name = "jelly"
mass = 0.05
origin = [-0.3, 0.01, -0.3]
rotate = [0.0, 30.0, 0.0]
shape = { kind = "solid", path = "cube.obj", spacing = 0.1 }
[body.springs.structural]
ks = 600.0
kd = 1.0
[[collider]]
shape = { kind = "ground", height = 0.0 }
response = { kind = "restitution", cr = 0.0, friction = 0.5 }
"#;
    let scene = hooke_scene::parse_scene(text, "cube.toml")
        .unwrap()
        .build(&dir)
        .unwrap();
    let view = View {
        size: (400, 300),
        ..View::default()
    };
    let camera = view.camera(&scene);
    let image = view.pixels(&scene, &camera);
    let (w, h) = image.dimensions();
    let mut v = Vec::new();
    scene.bodies[0].vertices(&scene.simulation.particles().x, &mut v);
    let eye = camera.eye();
    // The face most squarely toward the camera.
    let (face, centre) = quads
        .iter()
        .map(|q| {
            let c = q.iter().map(|&i| v[i as usize]).sum::<Vec3>() / 4.0;
            let [a, b, d] = [q[0], q[1], q[3]].map(|i| v[i as usize]);
            let n = (b - a).cross(&(d - a)).normalize();
            (n.dot(&(eye - c).normalize()), q, c)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, q, c)| (q, c))
        .unwrap();
    let project = camera.view_projection(w as f64 / h as f64);
    let pixel = |q: Vec3| {
        let c = project * nalgebra::Vector4::new(q.x, q.y, q.z, 1.0);
        let (x, y) = (
            (c.x / c.w + 1.0) * 0.5 * w as f64,
            (1.0 - c.y / c.w) * 0.5 * h as f64,
        );
        let p = image.get_pixel(x as u32, y as u32).0;
        p[0] as i32 + p[1] as i32 + p[2] as i32
    };
    // A grid over the middle 70 % of the face.
    let [a, b, _, d] = face.map(|i| v[i as usize]);
    let (u, s) = (b - a, d - a);
    let mut levels = Vec::new();
    for i in 0..=10 {
        for j in 0..=10 {
            let (fu, fs) = (0.15 + 0.07 * i as f64, 0.15 + 0.07 * j as f64);
            levels.push(pixel(a + u * fu + s * fs));
        }
    }
    let spread = levels.iter().max().unwrap() - levels.iter().min().unwrap();
    assert!(
        spread <= 9,
        "the face about {centre:?} spans {spread} levels (summed over RGB)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
