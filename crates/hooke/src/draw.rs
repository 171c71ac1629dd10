//! Turning a scene's particles, springs and colliders into a draw list for the rasterizer.

use hooke_core::{SpringKind, Vec3};
use hooke_render::{Camera, DrawList, Line, Mesh, Point, Rgb};
use hooke_scene::{Body, ColliderGeometry, Scene, SkinVertex, Topology, collider_mesh};

/// What to draw of the bodies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Style {
    /// Shaded surfaces (cloth, jelly); chains as beads on a string.
    Solid,
    /// Every spring as a line, coloured by kind.
    Springs,
    /// Surfaces and springs together.
    Both,
}

impl Style {
    /// The style named `solid`, `springs` or `both` (any case).
    pub fn from_name(name: &str) -> Option<Self> {
        match name.to_ascii_lowercase().as_str() {
            "solid" => Some(Self::Solid),
            "springs" => Some(Self::Springs),
            "both" => Some(Self::Both),
            _ => None,
        }
    }
}

const CLOTH: Rgb = [0.22, 0.42, 0.78];
const JELLY: Rgb = [0.36, 0.74, 0.30];
const BEAD: Rgb = [0.80, 0.30, 0.20];
const STRING: Rgb = [0.25, 0.25, 0.28];
/// Pinned particles: dark, like the fixed hook they hang from.
const PIN: Rgb = [0.30, 0.30, 0.34];
const TABLE: Rgb = [0.58, 0.40, 0.24];
const PLANE: Rgb = [0.85, 0.55, 0.65];
const EDGE: Rgb = [0.25, 0.28, 0.35];
const GROUND: [Rgb; 2] = [[0.78, 0.78, 0.76], [0.68, 0.68, 0.66]];

/// The spring palette: the course's white / red / yellow, darkened to read on a light ground.
fn spring_color(kind: SpringKind) -> Rgb {
    match kind {
        SpringKind::Structural => [0.15, 0.20, 0.45],
        SpringKind::Shear => [0.80, 0.20, 0.20],
        SpringKind::Bend => [0.90, 0.62, 0.05],
        SpringKind::Other => STRING,
    }
}

/// Adds a `rows × cols` sheet of particles (`index(r, c)`) as a smooth-shaded mesh, two
/// triangles per grid square; coloured per particle by `tint` when given.
fn sheet(
    list: &mut DrawList,
    (x, tint): (&[Vec3], Option<&[Rgb]>),
    rows: usize,
    cols: usize,
    index: impl Fn(usize, usize) -> usize,
    color: Rgb,
) {
    if rows < 2 || cols < 2 {
        return;
    }
    let positions: Vec<Vec3> = (0..rows * cols)
        .map(|k| x[index(k / cols, k % cols)])
        .collect();
    let at = |r: usize, c: usize| positions[r * cols + c];
    let mut normals = vec![Vec3::zeros(); rows * cols];
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            let n = (at(r + 1, c) - at(r, c)).cross(&(at(r, c + 1) - at(r, c)));
            for (rr, cc) in [(r, c), (r + 1, c), (r, c + 1), (r + 1, c + 1)] {
                normals[rr * cols + cc] += n;
            }
        }
    }
    for n in &mut normals {
        *n = n.try_normalize(1e-18).unwrap_or(Vec3::y());
    }
    let corner = |r: usize, c: usize| (r * cols + c) as u32;
    let mut triangles = Vec::with_capacity(2 * (rows - 1) * (cols - 1));
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            triangles.push([corner(r, c), corner(r + 1, c), corner(r + 1, c + 1)]);
            triangles.push([corner(r, c), corner(r + 1, c + 1), corner(r, c + 1)]);
        }
    }
    let colors = tint.map_or_else(Vec::new, |tint| {
        (0..rows * cols)
            .map(|k| tint[index(k / cols, k % cols)])
            .collect()
    });
    list.meshes.push(Mesh {
        positions,
        normals,
        triangles,
        color,
        colors,
    });
}

/// A body made from a mesh, drawn as the user's faces at its vertices (which follow the
/// particles), each vertex tinted as the particle it is or rides nearest.
fn skin(list: &mut DrawList, (x, tint): (&[Vec3], Option<&[Rgb]>), body: &Body, color: Rgb) {
    let Some(skin) = &body.skin else {
        return;
    };
    let mut positions = Vec::new();
    body.vertices(x, &mut positions);
    let triangles = skin.triangles();
    let mut normals = Vec::new();
    crate::export::vertex_normals(&positions, &triangles, &mut normals);
    for n in &mut normals {
        if *n == Vec3::zeros() {
            *n = Vec3::y();
        }
    }
    let colors = tint.map_or_else(Vec::new, |tint| {
        skin.vertices
            .iter()
            .map(|v| match v {
                SkinVertex::Particle(i) => tint[*i as usize],
                SkinVertex::Embedded { corners, weights } => {
                    let k = (0..8).fold(0, |k, m| if weights[m] > weights[k] { m } else { k });
                    tint[corners[k] as usize]
                }
                SkinVertex::Fixed(_) => color,
            })
            .collect()
    });
    let mut mesh = Mesh {
        positions,
        normals,
        triangles,
        color,
        colors,
    };
    // A solid's box corners are edges, not curves; a cloth's folds stay smooth.
    if matches!(body.topology, Topology::Solid) {
        crate::creases::split(&mut mesh);
    }
    list.meshes.push(mesh);
}

fn ground(list: &mut DrawList, height: f64, centre: Vec3, half: f64) {
    let tile = 0.25;
    let n = (half / tile).ceil() as i64;
    let (cx, cz) = (
        (centre.x / tile).round() * tile,
        (centre.z / tile).round() * tile,
    );
    for i in -n..n {
        for j in -n..n {
            let (x0, z0) = (cx + i as f64 * tile, cz + j as f64 * tile);
            let p = |dx: f64, dz: f64| Vec3::new(x0 + dx, height, z0 + dz);
            let color = GROUND[((i + j).rem_euclid(2)) as usize];
            list.flat([p(0.0, 0.0), p(0.0, tile), p(tile, tile)], color);
            list.flat([p(0.0, 0.0), p(tile, tile), p(tile, 0.0)], color);
        }
    }
}

fn cylinder(list: &mut DrawList, c: &hooke_collide::Cylinder) {
    for t in collider_mesh::cylinder_triangles(c) {
        list.flat(t, TABLE);
    }
}

/// A helical spring from `a` to `b`: a fixed number of turns, so it visibly stretches.
fn coil(list: &mut DrawList, a: Vec3, b: Vec3, rest: f64) {
    const TURNS: usize = 14;
    const SEGMENTS: usize = 12;
    let axis = b - a;
    let Some(dir) = axis.try_normalize(1e-12) else {
        return;
    };
    let helper = if dir.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let (u, v) = (
        dir.cross(&helper).normalize(),
        dir.cross(&helper).normalize().cross(&dir),
    );
    let radius = 0.06 * rest.max(0.05);
    // Straight leads at both ends, the helix between.
    let lead = 0.08;
    let point = |k: usize| {
        let t = k as f64 / (TURNS * SEGMENTS) as f64;
        let angle = std::f64::consts::TAU * TURNS as f64 * t;
        a + axis * (lead + (1.0 - 2.0 * lead) * t) + (u * angle.cos() + v * angle.sin()) * radius
    };
    let mut line = |p: Vec3, q: Vec3| {
        list.lines.push(Line {
            a: p,
            b: q,
            color: STRING,
            width: 2.0,
        })
    };
    line(a, point(0));
    for k in 0..TURNS * SEGMENTS {
        line(point(k), point(k + 1));
    }
    line(point(TURNS * SEGMENTS), b);
}

/// Corner `k` of the box: x from bit 2, y from bit 1, z from bit 0.
fn box_edges(list: &mut DrawList, min: Vec3, max: Vec3) {
    let corner = |k: usize| collider_mesh::box_corner(min, max, k);
    for a in 0..8 {
        for bit in [1, 2, 4] {
            if a & bit == 0 {
                list.lines.push(Line {
                    a: corner(a),
                    b: corner(a | bit),
                    color: EDGE,
                    width: 1.5,
                });
            }
        }
    }
}

/// The polygon where the plane `a x + b y + c z + d = 0` cuts the box, as a triangle fan.
fn plane_in_box(list: &mut DrawList, coefficients: [f64; 4], min: Vec3, max: Vec3) {
    let points = collider_mesh::plane_in_box(coefficients, min, max);
    if points.is_empty() {
        return;
    }
    let centre = points.iter().sum::<Vec3>() / points.len() as f64;
    for k in 0..points.len() {
        list.flat([centre, points[k], points[(k + 1) % points.len()]], PLANE);
        list.lines.push(Line {
            a: points[k],
            b: points[(k + 1) % points.len()],
            color: EDGE,
            width: 1.0,
        });
    }
}

/// The draw list of a scene's current state.
pub fn draw(scene: &Scene, style: Style) -> DrawList {
    draw_with(scene, style, |_| true)
}

/// [`draw`], showing only the springs of the kinds `show` accepts (the viewer's s / h / b
/// toggles); chains' strings and lone coils are always drawn.
pub fn draw_with(scene: &Scene, style: Style, show: impl Fn(SpringKind) -> bool) -> DrawList {
    draw_tinted(scene, style, show, None)
}

/// [`draw_with`], the bodies' surfaces and beads coloured per particle by `tint` (a
/// quantity's colour map, [`crate::quantity::ColorBy`]) when given.
pub fn draw_tinted(
    scene: &Scene,
    style: Style,
    show: impl Fn(SpringKind) -> bool,
    tint: Option<&[Rgb]>,
) -> DrawList {
    let mut list = DrawList::default();
    let sim = &scene.simulation;
    let x = &sim.particles().x;
    let tint = tint.filter(|t| t.len() == x.len());
    let xs = (x.as_slice(), tint);
    let surfaces = style != Style::Springs;
    for body in &scene.bodies {
        let s = body.range.start;
        match body.topology {
            Topology::Grid([a, b]) if surfaces => {
                sheet(&mut list, xs, a, b, |r, c| s + r * b + c, CLOTH)
            }
            Topology::Lattice([a, b, c]) if surfaces => {
                let idx = move |i: usize, j: usize, k: usize| s + (i * b + j) * c + k;
                sheet(&mut list, xs, a, b, |i, j| idx(i, j, 0), JELLY);
                sheet(&mut list, xs, a, b, |i, j| idx(i, j, c - 1), JELLY);
                sheet(&mut list, xs, a, c, |i, k| idx(i, 0, k), JELLY);
                sheet(&mut list, xs, a, c, |i, k| idx(i, b - 1, k), JELLY);
                sheet(&mut list, xs, b, c, |j, k| idx(0, j, k), JELLY);
                sheet(&mut list, xs, b, c, |j, k| idx(a - 1, j, k), JELLY);
            }
            Topology::Mesh if surfaces => skin(&mut list, xs, body, CLOTH),
            Topology::Solid if surfaces => skin(&mut list, xs, body, JELLY),
            Topology::Chain | Topology::Points => {
                for i in body.range.clone() {
                    let pinned = sim.particles().is_pinned(i);
                    list.points.push(Point {
                        p: x[i],
                        color: match tint {
                            Some(t) => t[i],
                            None if pinned => PIN,
                            None => BEAD,
                        },
                        radius: if pinned { 5.0 } else { 6.0 },
                    });
                }
            }
            _ => {}
        }
    }
    let lines_for_all = style != Style::Solid;
    let strings = scene
        .bodies
        .iter()
        .filter(|b| matches!(b.topology, Topology::Chain | Topology::Points))
        .map(|b| b.range.clone())
        .collect::<Vec<_>>();
    // A lone spring reads as a spring when drawn as a coil; in a chain of many, coils would
    // crowd, and a string reads better.
    let coils = scene
        .bodies
        .iter()
        .filter(|b| matches!(b.topology, Topology::Chain | Topology::Points) && b.range.len() <= 3)
        .map(|b| b.range.clone())
        .collect::<Vec<_>>();
    for spring in &sim.model().springs {
        let (i, j) = (spring.i as usize, spring.j as usize);
        let on_string = strings.iter().any(|r| r.contains(&i));
        if !lines_for_all && coils.iter().any(|r| r.contains(&i)) {
            coil(&mut list, x[i], x[j], spring.rest);
            continue;
        }
        if (lines_for_all && show(spring.kind)) || on_string {
            let color = if on_string && !lines_for_all {
                STRING
            } else {
                spring_color(spring.kind)
            };
            list.lines.push(Line {
                a: x[i],
                b: x[j],
                color,
                width: if on_string { 2.0 } else { 1.0 },
            });
        }
    }
    let body_bounds = list.bounds();
    let mut box_bounds = None;
    let t = scene.simulation.time();
    for (k, c) in scene.colliders.iter().enumerate() {
        // A moving collider is drawn as its triangles where it is now.
        if let Some(tris) = scene.collider_triangles_at(k, t) {
            tris.into_iter().for_each(|tri| list.flat(tri, TABLE));
            continue;
        }
        if let Some(pose) = scene.collider_pose(k, t) {
            let half = (Vec3::zeros(), Vec3::zeros());
            for tri in c.triangles(Vec3::zeros(), 0.0, half) {
                list.flat(tri.map(|p| pose.place(&p)), TABLE);
            }
            continue;
        }
        match c {
            // Drawn where they are: contacts keep cloth a thickness away from them.
            ColliderGeometry::Mesh(tris) => tris.iter().for_each(|t| list.flat(*t, TABLE)),
            ColliderGeometry::Cylinder(cyl) => cylinder(&mut list, cyl),
            ColliderGeometry::Sphere(ball) => collider_mesh::sphere_triangles(ball)
                .into_iter()
                .for_each(|t| list.flat(t, TABLE)),
            ColliderGeometry::Box(b) => {
                box_edges(&mut list, b.min, b.max);
                box_bounds = Some((b.min, b.max));
            }
            _ => {}
        }
    }
    for c in &scene.colliders {
        match c {
            ColliderGeometry::Plane(coefficients) => {
                let (min, max) = box_bounds.unwrap_or((Vec3::repeat(-2.0), Vec3::repeat(2.0)));
                plane_in_box(&mut list, *coefficients, min, max);
            }
            ColliderGeometry::Ground(h) => {
                let centre = body_bounds.map_or(Vec3::zeros(), |(lo, hi)| (lo + hi) * 0.5);
                ground(&mut list, *h, centre, 2.5);
            }
            _ => {}
        }
    }
    list
}

/// The default view direction of every picture: yaw and pitch in degrees (the command
/// line's `--yaw` and `--pitch` defaults, the viewer's start, the benchmarks' stills).
pub const DEFAULT_YAW_PITCH: (f64, f64) = (30.0, 22.0);

/// A camera that frames the bodies and colliders (not the ground) from `yaw`, `pitch`
/// degrees ([`DEFAULT_YAW_PITCH`] is the three-quarter view every picture starts from); a
/// moving collider is framed at each of its keys' poses, so that it stays in view.
pub fn frame_camera(scene: &Scene, yaw: f64, pitch: f64) -> Camera {
    let x = &scene.simulation.particles().x;
    let mut lo = x.iter().fold(Vec3::repeat(f64::INFINITY), |a, p| a.inf(p));
    let mut hi = x
        .iter()
        .fold(Vec3::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
    for (k, c) in scene.colliders.iter().enumerate() {
        let pts: Vec<Vec3> = match c {
            ColliderGeometry::Mesh(t) => t.iter().flatten().copied().collect(),
            ColliderGeometry::Cylinder(c) => vec![
                c.center + Vec3::new(c.radius, 0.0, c.radius),
                c.center - Vec3::new(c.radius, c.thickness, c.radius),
            ],
            ColliderGeometry::Box(b) => vec![b.min, b.max],
            ColliderGeometry::Sphere(ball) => vec![
                ball.center.add_scalar(-ball.radius),
                ball.center.add_scalar(ball.radius),
            ],
            _ => vec![],
        };
        let poses = scene.collider_key_poses(k);
        let placed = pts
            .iter()
            .flat_map(|p| poses.iter().map(move |pose| pose.place(p)));
        for p in pts.iter().copied().chain(placed) {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    Camera::framing(lo, hi, yaw, pitch)
}
