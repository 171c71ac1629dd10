//! The `hooke` binary as a user runs it.

mod common;

use common::*;
use std::path::Path;

/// `hooke run SCENE --steps N --every K --trajectory CSV` in `dir`, which must succeed;
/// returns the trajectory's text.
fn run_trajectory(scene: &str, steps: u64, every: u64, csv: &str, dir: &Path) -> String {
    let (steps, every) = (steps.to_string(), every.to_string());
    let out = hooke(
        &[
            "run",
            scene,
            "--steps",
            &steps,
            "--every",
            &every,
            "--trajectory",
            csv,
        ],
        dir,
    );
    assert!(out.status.success(), "{scene}: {}", stderr(&out));
    std::fs::read_to_string(dir.join(csv)).unwrap()
}

#[test]
fn every_builtin_runs_and_writes_a_spec_trajectory() {
    let dir = scratch("builtins");
    for (name, particles) in [
        ("single-spring", 2),
        ("chain", 12),
        ("jello-cube", 512),
        ("hanging-cloth", 625),
        ("cloth-table", 1024),
    ] {
        let text = run_trajectory(name, 205, 50, "t.csv", &dir);
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("frame,time,particle,x,y,z,vx,vy,vz"));
        // Frames 0..=4 (steps 0, 50, ..., 200): the last multiple of 50 that 205 steps reach.
        assert_eq!(lines.clone().count(), 5 * particles, "{name}");
        let last: Vec<&str> = lines.last().unwrap().split(',').collect();
        assert_eq!(last[0], "4");
        let dt: f64 = match name {
            "single-spring" => 1e-3,
            "chain" => 2e-4,
            _ => 2.5e-4,
        };
        assert_eq!(
            last[1].parse::<f64>().unwrap(),
            200.0 * dt,
            "{name}: time is f·K·dt as one product"
        );
        assert_eq!(last[2], (particles - 1).to_string());
    }
}

#[test]
fn a_printed_scene_reproduces_the_builtin_run_bit_for_bit() {
    let dir = scratch("roundtrip");
    let printed = hooke(&["scene", "cloth-table"], &dir);
    assert!(printed.status.success());
    std::fs::write(dir.join("mine.toml"), &printed.stdout).unwrap();
    assert_eq!(
        run_trajectory("cloth-table", 400, 100, "a.csv", &dir),
        run_trajectory("mine.toml", 400, 100, "b.csv", &dir)
    );
}

#[test]
fn public_worlds_run_from_the_command_line() {
    let dir = scratch("worlds");
    for name in ["jello", "gravity", "moveLeft", "rotate", "skewedCorner"] {
        let world = root().join(format!("assets/worlds/{name}.w"));
        let text = run_trajectory(world.to_str().unwrap(), 100, 50, "t.csv", &dir);
        assert_eq!(text.lines().count(), 1 + 3 * 512, "{name}");
    }
}

#[test]
fn worlds_convert_to_scenes_and_back() {
    let dir = scratch("convert");
    let world = root().join("assets/worlds/rotate.w");
    let out = hooke(&["convert", world.to_str().unwrap(), "rotate.toml"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = hooke(&["convert", "rotate.toml", "rotate.w"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    for (input, csv) in [
        (world.to_str().unwrap(), "a.csv"),
        ("rotate.toml", "b.csv"),
        ("rotate.w", "c.csv"),
    ] {
        let out = hooke(&["run", input, "--steps", "50", "--trajectory", csv], &dir);
        assert!(out.status.success(), "{input}: {}", stderr(&out));
    }
    let a = std::fs::read(dir.join("a.csv")).unwrap();
    assert_eq!(a, std::fs::read(dir.join("b.csv")).unwrap());
    assert_eq!(a, std::fs::read(dir.join("c.csv")).unwrap());
}

#[test]
fn bad_input_is_refused_with_the_file_and_line_and_writes_nothing() {
    let dir = scratch("bad");
    std::fs::write(dir.join("bad.w"), "RK4\n0.001 1\n1 2 3\n").unwrap();
    std::fs::write(
        dir.join("bad.toml"),
        "name = \"x\"\n[simulation]\nintegrator = \"rk5\"\ndt = 0.001\nsteps = 10\nevery = 1\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["run", "bad.w", "--trajectory", "t.csv"],
            "bad.w:3: unexpected end of file: expected dCollision",
        ),
        (&["run", "bad.toml", "--trajectory", "t.csv"], "line 3"),
        (
            &["run", "no-such-scene", "--trajectory", "t.csv"],
            "no built-in scene 'no-such-scene'",
        ),
        (
            &["run", "chain", "--dt", "-1", "--trajectory", "t.csv"],
            "'--dt <DT>': expected a time in seconds > 0, found '-1'",
        ),
        (
            &[
                "run",
                "cloth-table",
                "--table",
                "missing.obj",
                "--trajectory",
                "t.csv",
            ],
            "missing.obj",
        ),
    ];
    for (args, expected) in cases {
        let out = hooke(args, &dir);
        assert!(!out.status.success(), "{args:?} should fail");
        let e = stderr(&out);
        assert!(
            e.contains(expected),
            "{args:?}: expected '{expected}' in:\n{e}"
        );
        assert!(!e.contains("panicked"), "{args:?} panicked:\n{e}");
        assert!(!dir.join("t.csv").exists(), "{args:?} left an output file");
    }
    let leftovers = file_names(&dir);
    assert_eq!(
        leftovers.len(),
        2,
        "temporary files left behind: {leftovers:?}"
    );
}

#[test]
fn divergence_names_the_step_and_particle_and_keeps_complete_frames() {
    let dir = scratch("diverge");
    let out = hooke(
        &[
            "run",
            "jello-cube",
            "--dt",
            "0.01",
            "--steps",
            "2000",
            "--every",
            "1",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.contains("diverged at step") && e.contains("particle") && e.contains("use dt = "),
        "{e}"
    );
    let text = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    let rows = text.lines().count() - 1;
    assert!(
        rows > 0 && rows.is_multiple_of(512),
        "{rows} rows is not a whole number of frames"
    );
}

#[test]
fn the_table_can_be_swapped_from_the_command_line() {
    use hooke_collide::table::{round, square};
    let dir = scratch("table");
    let square_mesh = root().join("assets/meshes/square-table.obj");
    // The cloth's centre particle (16, 16) of 32 × 32 ends resting on whichever top is in
    // place, a contact thickness (5 mm) above it: the swap really changed the collider.
    for (table, top) in [
        (square_mesh.to_str().unwrap(), square::TOP_Y),
        ("cylinder", round::TOP_Y),
    ] {
        let out = hooke(
            &[
                "run",
                "cloth-table",
                "--table",
                table,
                "--every",
                "12000",
                "--trajectory",
                "t.csv",
            ],
            &dir,
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let csv = std::fs::read_to_string(dir.join("t.csv")).unwrap();
        let centre: Vec<f64> = csv
            .lines()
            .filter(|l| l.starts_with("1,") && l.split(',').nth(2) == Some("528"))
            .flat_map(|l| l.split(',').skip(3).take(3).map(|v| v.parse().unwrap()))
            .collect();
        assert_eq!(
            centre.len(),
            3,
            "frame 1 (t = 3 s) of particle 528 in {csv:.200}"
        );
        let expected = top + 0.005;
        assert!(
            (centre[1] - expected).abs() < 1e-3,
            "{table}: the centre rests at y = {}, expected {expected} (top + thickness)",
            centre[1]
        );
        assert!(
            centre[0].abs() < 0.05 && centre[2].abs() < 0.05,
            "{centre:?}"
        );
    }
    let out = hooke(
        &["run", "chain", "--table", "cylinder", "--steps", "100"],
        &dir,
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("has no table"), "{}", stderr(&out));
}

/// Ctrl-C stops a long run cleanly: exit status 130, the trajectory ends at a complete frame,
/// every frame PNG decodes, and no temporary file is left.
#[test]
fn ctrl_c_stops_a_run_at_a_complete_frame() {
    let dir = scratch("sigint");
    let child = spawn(
        &[
            "run",
            "chain",
            "--duration",
            "100000",
            "--every",
            "200",
            "--trajectory",
            "t.csv",
            "--frames",
            "frames",
            "--size",
            "64x48",
        ],
        &dir,
    );
    // Let it write some frames, then interrupt.
    wait_for("frames", || {
        std::fs::read_dir(dir.join("frames")).is_ok_and(|d| {
            d.flatten()
                .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
                .count()
                >= 2
        })
    });
    interrupt(&child);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("interrupted at step"),
        "{}",
        stderr(&out)
    );

    let csv = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    // The chain has 12 particles: whole frames only, each row complete.
    assert!(rows.len() >= 12, "some frames were written");
    assert_eq!(
        rows.len() % 12,
        0,
        "{} rows is not whole frames",
        rows.len()
    );
    assert!(rows.iter().all(|r| r.split(',').count() == 9));
    // Beside the frames, only hooke's hidden marker.
    let frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap() != ".hooke-frames")
        .collect();
    assert_eq!(frames.len(), rows.len() / 12);
    for f in &frames {
        image::open(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
    let leftovers: Vec<_> = file_names(&dir)
        .into_iter()
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// `--frames` writes one PNG per frame and `--gif` an animation with as many frames, each
/// showing the chain (not a blank image), and `render` writes the asked size.
#[test]
fn run_writes_frame_pngs_and_a_gif_and_render_a_still() {
    use image::AnimationDecoder;
    let dir = scratch("frames");
    let out = hooke(
        &[
            "run",
            "chain",
            "--duration",
            "1",
            "--every",
            "1000",
            "--frames",
            "f",
            "--gif",
            "a.gif",
            "--size",
            "96x72",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // 1 s at dt = 2e-4 is 5000 steps: frames 0 to 5.
    let mut names = file_names(&dir.join("f"));
    names.sort();
    assert_eq!(names.len(), 7, "{names:?}");
    assert_eq!(names[0], ".hooke-frames");
    let first = image::open(dir.join("f/frame-00000.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(first.dimensions(), (96, 72));
    let background = *first.get_pixel(0, 0);
    assert!(
        first.pixels().filter(|p| **p != background).count() > 100,
        "the frame shows something besides the background"
    );
    let gif = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("a.gif")).unwrap(),
    ))
    .unwrap();
    assert_eq!(gif.into_frames().count(), 6);

    let out = hooke(
        &[
            "render",
            "jello-cube",
            "--at",
            "0.2",
            "-o",
            "s.png",
            "--size",
            "120x90",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        image::open(dir.join("s.png"))
            .unwrap()
            .to_rgba8()
            .dimensions(),
        (120, 90)
    );
}

#[test]
fn an_obj_export_writes_a_frame_file_per_frame_with_named_objects() {
    let dir = scratch("export-obj");
    let o = hooke(
        &[
            "run",
            "cloth-table",
            "--table",
            "cylinder",
            "--steps",
            "80",
            "--every",
            "40",
            "--export",
            "objs/",
            "--format",
            "obj",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names = file_names(&dir.join("objs"));
    names.sort();
    assert_eq!(
        names,
        [
            ".hooke-frames",
            "frame-00000.obj",
            "frame-00001.obj",
            "frame-00002.obj"
        ]
    );
    let text = std::fs::read_to_string(dir.join("objs/frame-00002.obj")).unwrap();
    let objects: Vec<&str> = text.lines().filter(|l| l.starts_with("o ")).collect();
    assert_eq!(
        objects,
        [
            "o body:cloth",
            "o collider:0-ground",
            "o collider:1-cylinder"
        ]
    );
    // 32 × 32 cloth particles; 31 × 31 × 2 cloth triangles, 2 ground, 4 × 64 cylinder.
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!(count("f "), 2 * 31 * 31 + 2 + 4 * 64);
    assert_eq!(count("v "), 1024 + 3 * (2 + 4 * 64));

    // A file where the folder should be: refused before anything runs.
    std::fs::write(dir.join("taken"), "x").unwrap();
    let o = hooke(
        &["run", "chain", "--export", "taken/", "--format", "obj"],
        &dir,
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("is a file, expected a folder"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A reader that goes away early (`hooke bench cloth | head -1`) ends the program as a
/// closed pipe ends a Unix filter, status 141, without a panic's message or backtrace.
#[test]
fn a_closed_pipe_ends_the_program_quietly() {
    let dir = scratch("closed-pipe");
    let mut child = spawn(&["bench", "cloth", "--n", "32", "--steps", "400"], &dir);
    // Close the read end before the figures are printed.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(141), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}

/// `hooke check` warns of a collider keyed faster than its thickness allows per step, with
/// its speed, as it warns of a fast particle; and refuses a moving ground with its key.
#[test]
fn check_warns_of_a_collider_that_moves_too_fast_for_its_thickness() {
    let dir = scratch("fast-collider");
    let scene = |keys: &str, shape: &str| {
        format!(
            "name = \"puck\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.001\nsteps = 10\nevery = 1\n\
             [[body]]\nname = \"p\"\nmass = 0.1\n[body.shape]\nkind = \"points\"\npositions = [[0.0, 1.0, 0.0]]\n\
             [[collider]]\nshape = {shape}\nresponse = {{ kind = \"restitution\", cr = 0.0 }}\n\
             motion = {{ keys = {keys} }}\n"
        )
    };
    let puck = "{ kind = \"cylinder\", center = [3.0, 0.5, 0.0], radius = 0.02, thickness = 0.02 }";
    // 40 m/s against 20 mm: 40 mm per millisecond step, twice the thickness.
    let fast =
        "[{ t = 0.0, translate = [0.0, 0.0, 0.0] }, { t = 0.1, translate = [-4.0, 0.0, 0.0] }]";
    std::fs::write(dir.join("fast.toml"), scene(fast, puck)).unwrap();
    let out = hooke(&["check", "fast.toml"], &dir);
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &stderr(&out);
    assert!(
        text.contains("moving cylinder") && text.contains("the collider moves at up to 40.00 m/s"),
        "{text}"
    );
    std::fs::write(
        dir.join("ground.toml"),
        scene(fast, "{ kind = \"ground\", height = 0.0 }"),
    )
    .unwrap();
    let out = hooke(&["check", "ground.toml"], &dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("collider[0].motion") && stderr(&out).contains("cannot move"),
        "{}",
        stderr(&out)
    );
}

/// Issue 57: `--color`, `--range` and `--camera` on stills and animations. An animation
/// coloured by a quantity takes one range for all its frames from a first pass (said on
/// stderr), so that frame colours compare; bad values are refused with what was expected.
#[test]
fn pictures_take_a_colour_map_a_range_and_a_placed_camera() {
    let dir = scratch("colour");
    let out = hooke(
        &[
            "run",
            "chain",
            "--duration",
            "0.5",
            "--every",
            "500",
            "--gif",
            "s.gif",
            "--size",
            "96x72",
            "--color",
            "speed",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let said = stderr(&out);
    assert!(
        said.contains("a first pass over the run fixes the colour range")
            && said.contains("--color: speed (m/s) from 0 to"),
        "{said}"
    );
    let out = hooke(
        &[
            "render", "chain", "--at", "0.2", "-o", "c.png", "--size", "160x120", "--color",
            "speed", "--range", "0,10", "--camera", "90,10,3",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        image::open(dir.join("c.png"))
            .unwrap()
            .to_rgba8()
            .dimensions(),
        (160, 120)
    );
    for (flag, value, expected) in [
        ("--camera", "1,2", "expected AZIMUTH,ELEVATION,DISTANCE"),
        (
            "--camera",
            "0,95,3",
            "an elevation in degrees from -89 to 89",
        ),
        ("--camera", "0,10,-1", "a distance in metres"),
        ("--range", "5,1", "expected LO below HI"),
        ("--range", "0,inf", "within ±1e12"),
        (
            "--color",
            "heat",
            "possible values: none, strain, speed, gap",
        ),
    ] {
        let out = hooke(&["render", "chain", "-o", "x.png", flag, value], &dir);
        assert!(!out.status.success());
        assert!(
            stderr(&out).contains(expected),
            "{flag} {value}: {}",
            stderr(&out)
        );
        assert!(!dir.join("x.png").exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
