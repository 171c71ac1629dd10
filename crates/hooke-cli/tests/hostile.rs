//! Issue 54, a hostile user's trial: what the command line says and refuses when a scene or
//! an option is out of its range, a table swap would silently change a moving collider, a
//! step or its advice leaves what Hooke accepts, keys make pins jump, or a long run runs
//! into a log; and the small things (float noise, plurals) that make a message wrong.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// Writes `text` as `name` in `dir`.
fn write(dir: &std::path::Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

/// `hooke scene NAME` with `edit` applied to its text, written as `file` in `dir`.
fn edited(dir: &std::path::Path, name: &str, file: &str, edit: impl Fn(&str) -> String) {
    let out = hooke(&["scene", name], dir);
    assert!(out.status.success());
    write(dir, file, &edit(&String::from_utf8(out.stdout).unwrap()));
}

/// Runs `args` in `dir`, expecting a refusal whose message holds every one of `expect`.
fn refused(dir: &std::path::Path, args: &[&str], expect: &[&str]) {
    let out = hooke(args, dir);
    let said = stderr(&out);
    assert!(!out.status.success(), "{args:?} ran: {said}");
    assert!(!said.contains("panicked"), "{args:?}: {said}");
    for e in expect {
        assert!(said.contains(e), "{args:?}: expected {e:?} in {said}");
    }
}

#[test]
fn keys_out_of_their_range_are_refused_with_the_key() {
    let dir = scratch("ranges");
    let cases: [(&str, &str, &str, &[&str]); 6] = [
        (
            "translate",
            "translate = [2.5, 0.0, 0.0]",
            "translate = [1e308, 0.0, 0.0]",
            &["collider[1].motion.keys[1].translate[0]", "1e308", "±1e6"],
        ),
        (
            "rotate",
            "rotate = [0.0, 90.0, 0.0]",
            "rotate = [0.0, 1e300, 0.0]",
            &[
                "collider[1].motion.keys[1].rotate[1]",
                "1e300",
                "an angle in degrees",
            ],
        ),
        (
            "radius",
            "radius = 0.15",
            "radius = 1e9",
            &["collider[1].shape.radius", "1000000000"],
        ),
        (
            "stiffness",
            "ks = 400.0",
            "ks = 1e308",
            &["body[0].springs.structural.ks", "1e308", "N/m"],
        ),
        (
            "damping",
            "kd = 0.02",
            "kd = 1e308",
            &["body[0].springs.structural.kd", "N·s/m"],
        ),
        (
            "mass",
            "mass = 0.0008",
            "mass = 1e308",
            &["body[0].mass", "a mass in kg"],
        ),
    ];
    for (tag, from, to, expect) in cases {
        let file = format!("{tag}.toml");
        edited(&dir, "puck-sweep", &file, |t| {
            assert!(t.contains(from), "{tag}: {from} not in the scene");
            t.replacen(from, to, 1)
        });
        refused(&dir, &["check", &file], expect);
        refused(&dir, &["run", &file, "--steps", "1"], expect);
    }
    for (key, value, expect) in [
        ("density", "1e308", "body[0].material.density"),
        ("stretch", "1e308", "body[0].material.stretch"),
        ("bending", "1e308", "body[0].material.bending"),
        ("damping", "1e308", "body[0].material.damping"),
    ] {
        edited(&dir, "tablecloth", "m.toml", |t| {
            t.replace(
                "preset = \"cotton\"",
                &format!("preset = \"cotton\"\n{key} = {value}"),
            )
        });
        refused(&dir, &["check", "m.toml"], &[expect]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_moving_collider_is_no_table_to_swap() {
    let dir = scratch("swap");
    refused(
        &dir,
        &["run", "puck-sweep", "--table", "cylinder", "--steps", "1"],
        &["--table", "collider[1] moves by keys"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_ground_that_moves_is_refused_naming_every_shape_that_can() {
    let dir = scratch("ground-motion");
    edited(&dir, "hanging-cloth", "g.toml", |t| {
        format!(
            "{t}\n[collider.motion]\nkeys = [{{ t = 0.0, translate = [0.0, 0.0, 0.0] }}, \
             {{ t = 1.0, translate = [0.0, 1.0, 0.0] }}]\n"
        )
    });
    refused(
        &dir,
        &["run", "g.toml", "--steps", "1"],
        &[
            "collider[0].motion",
            "a mesh, a box, a cylinder or a sphere",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn starts_that_make_no_sense_are_refused() {
    let dir = scratch("starts");
    // A ball through the flat cloth at its start.
    let ball = "\n[[collider]]\nshape = { kind = \"sphere\", center = [0.0, 2.0, 0.0], radius = 0.2 }\n\
                response = { kind = \"restitution\", cr = 0.0, friction = 0.3 }\n";
    edited(&dir, "hanging-cloth", "through.toml", |t| {
        format!("{t}{ball}")
    });
    refused(
        &dir,
        &["run", "through.toml", "--steps", "1"],
        &[
            "body[0] 'cloth'",
            "collider[1] (sphere)",
            "start the body outside",
        ],
    );
    // A flat cloth beside a box, whose inside is what is free: moved in onto its face, the
    // cloth would be crushed into a line (block descent froze such a start).
    edited(&dir, "hanging-cloth", "column.toml", |t| {
        format!(
            "{t}\n[[collider]]\nshape = {{ kind = \"box\", min = [-2.0, 0.0, -0.2], max = [-0.6, 3.0, 0.2] }}\n\
             response = {{ kind = \"restitution\", cr = 0.0, friction = 0.3 }}\n"
        )
    });
    refused(
        &dir,
        &["run", "column.toml", "--steps", "1"],
        &["collider[1] (box)", "too much of the body"],
    );
    // A ball that swallows the cloth: its surface is 1e5 m away.
    edited(&dir, "hanging-cloth", "swallowed.toml", |t| {
        format!("{t}{}", ball.replace("radius = 0.2", "radius = 1e5"))
    });
    refused(
        &dir,
        &["run", "swallowed.toml", "--steps", "1"],
        &["collider[1] (sphere)", "too much of the body"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn pins_keyed_away_from_their_start_are_warned_about() {
    let dir = scratch("pin-jump");
    for (tag, keys, expect) in [
        (
            "later",
            "[{ t = 0.5, translate = [0.0, 0.3, 0.0] }, { t = 1.0, translate = [0.0, 0.5, 0.0] }]",
            "its first key, at t = 0.5 s, holds before it",
        ),
        (
            "before",
            "[{ t = -2.0, translate = [0.0, 0.0, 0.0] }, { t = -1.0, translate = [0.0, 1.0, 0.0] }]",
            "every key is before t = 0",
        ),
    ] {
        let file = format!("{tag}.toml");
        edited(&dir, "hanging-cloth", &file, |t| {
            t.replace(
                "pins = [0, 24]",
                &format!("pins = [0, 24]\npin_motion = {{ keys = {keys} }}"),
            )
        });
        let out = hooke(&["run", &file, "--steps", "2"], &dir);
        let said = stderr(&out);
        assert!(out.status.success(), "{tag}: {said}");
        assert!(
            said.contains("warning") && said.contains("body[0] 'cloth'") && said.contains(expect),
            "{tag}: {said}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The step a divergence advises is half the start's stable estimate (what `hooke check`
/// says), not the far smaller one of the exploded state, and one `--dt` takes.
#[test]
fn the_advised_step_is_one_hooke_accepts() {
    let dir = scratch("advice");
    let out = hooke(&["run", "chain", "--dt", "0.01", "--steps", "2000"], &dir);
    let said = stderr(&out);
    assert!(!out.status.success(), "{said}");
    let advised: f64 = said
        .split("dt = ")
        .filter_map(|s| s.split(" s").next())
        .filter_map(|s| s.parse().ok())
        .filter(|&dt: &f64| dt < 0.01)
        .last()
        .unwrap_or_else(|| panic!("no advice in {said}"));
    assert!((1e-15..0.01).contains(&advised), "{said}");
    let check = hooke(&["check", "chain"], &dir);
    let stable: f64 = String::from_utf8_lossy(&check.stdout)
        .lines()
        .find(|l| l.trim_start().starts_with("symplectic"))
        .and_then(|l| l.split("dt < ").nth(1))
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!(
        advised <= stable && advised >= 0.25 * stable,
        "{advised} {stable}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `hooke ARGS` in `dir`, its stderr a log that gets a line of progress after every step.
fn with_progress_lines(dir: &Path, args: &[&str]) -> Output {
    hooke_in(dir)
        .args(args)
        .env("HOOKE_PROGRESS_SECONDS", "0")
        .output()
        .unwrap()
}

#[test]
fn a_long_run_into_a_log_says_how_far_it_got() {
    let dir = scratch("progress");
    let out = with_progress_lines(&dir, &["run", "chain", "--steps", "50"]);
    let said = stderr(&out);
    assert!(out.status.success(), "{said}");
    assert!(said.contains("chain: step 50 of 50 (100 %)"), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A drape repeat stops when the specimen settles, so its progress counts to `--longest`
/// as a most, not as what is left (issue 71).
#[test]
fn a_drapes_progress_says_its_time_left_is_at_most() {
    let dir = scratch("drape-progress");
    let out = with_progress_lines(
        &dir,
        &["drape", "silk", "--repeats", "1", "--longest", "0.02"],
    );
    let said = stderr(&out);
    assert!(
        said.contains("drape silk, repeat 1 of 1: step 1 of at most ")
            && said.contains(" s elapsed, at most ")
            && !said.contains("about"),
        "{said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_new_step_keeps_the_frame_interval_and_messages_carry_no_float_noise() {
    let dir = scratch("every");
    // cloth-table takes a frame every 40 steps of 2.5e-4 s: 1/60 s is a frame a step.
    let out = hooke(
        &[
            "run",
            "cloth-table",
            "--integrator",
            "implicit",
            "--dt",
            "0.01",
            "--duration",
            "0.5",
            "--gif",
            "t.gif",
            "--size",
            "32x24",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("t.gif")).unwrap(),
    ))
    .map(|d| image::AnimationDecoder::into_frames(d).count())
    .unwrap();
    // 0.5 s at 0.01 s is 50 steps, a frame each and frame 0; a GIF plays them in real
    // time, one each two hundredths of a second (viewers slow shorter delays down).
    assert_eq!(
        frames, 26,
        "0.5 s of frames 0.01 s apart: 25 slots of 0.02 s and frame 0"
    );
    let out = hooke(&["run", "chain", "--duration", "2.3"], &dir);
    assert!(
        stderr(&out).contains("(2.3 s simulated)"),
        "{}",
        stderr(&out)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_report_through_a_link_to_nothing_says_so() {
    let dir = scratch("dangling");
    std::os::unix::fs::symlink("nowhere", dir.join("dang")).unwrap();
    refused(
        &dir,
        &["report", "dang/sub", "--quick"],
        &["dang is a symbolic link to nothing"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn one_thread_is_one_thread() {
    let dir = scratch("one-thread");
    let out = hooke(
        &["bench", "scene", "chain", "--steps", "10", "--threads", "1"],
        &dir,
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(said.contains("on 1 thread ("), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Block descent is not for volumetric bodies: `hooke check` says so for a lattice, with
/// the integrator to use instead (issue 56: Newton), whose own promises and stopping rule
/// it states.
#[test]
fn check_says_block_descent_is_not_for_a_jelly() {
    let dir = scratch("check-jelly");
    let out = hooke(&["check", "jello-cube", "--integrator", "vbd"], &dir);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("warning: body 'jelly' is a volumetric lattice")
            && said.contains("--integrator newton"),
        "{said}"
    );
    let out = hooke(&["check", "cloth-table", "--integrator", "vbd"], &dir);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("volumetric"));
    let out = hooke(&["check", "jello-cube", "--integrator", "newton"], &dir);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("newton guarantees: stability at any dt")
            && said.contains("after 100 iterations")
            && !said.contains("volumetric"),
        "{said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 60: Ctrl-C stops a large step under way, whatever its tolerance: Newton at a
/// tolerance no step meets and a budget of 100 000 iterations was deaf to it for minutes.
#[test]
fn an_interrupt_stops_a_newton_step_under_way() {
    let dir = scratch("newton-interrupt");
    let mut child = spawn(
        &[
            "run",
            "cloth-table",
            "--integrator",
            "newton",
            "--dt",
            "0.016666666666666666",
            "--tolerance",
            "1e-12",
            "--iterations",
            "100000",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    // Frame 0 is written before the first step starts; give the step time to be under way.
    wait_for("the trajectory", || !temporaries(&dir).is_empty());
    std::thread::sleep(std::time::Duration::from_secs(2));
    interrupt(&child);
    // The project's bound for a hung process, not a slow machine (`wait_for`'s): the step
    // itself would take hours; the interrupt is seen within a few products.
    wait_for("the run to stop after the interrupt", || {
        child.try_wait().unwrap().is_some()
    });
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    assert!(csv.lines().count() > 1, "frame 0 was kept");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 60: `hooke check` names the integrator to use at any step, and its promises name
/// the bodies they cover: at a display frame, Newton for the jelly cube (a lattice), block
/// descent for a chain on a table (which keeps a point's millimetre from it); at the jelly
/// cube's own step, its own symplectic Euler, whose stable step it no longer calls too
/// small; and a penalty wall is said to be kept by no integrator.
#[test]
fn check_recommends_an_integrator_for_any_step_and_names_the_bodies_it_promises() {
    let dir = scratch("check-recommends");
    let check = |args: &[&str]| {
        let out = hooke(args, &dir);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        (
            String::from_utf8_lossy(&out.stdout).into_owned(),
            stderr(&out),
        )
    };
    let (said, _) = check(&["check", "jello-cube", "--dt", "0.016666666666666666"]);
    assert!(
        said.contains("recommended at dt = 0.016666666666666666 s: newton"),
        "{said}"
    );
    assert!(
        said.contains("'jelly' (a lattice) keeps 1.00 mm as points"),
        "{said}"
    );
    let (said, warned) = check(&["check", "jello-cube"]);
    assert!(
        said.contains("recommended at dt = 0.00025 s: symplectic"),
        "{said}"
    );
    assert!(
        !warned.contains("exceeds the estimated stable step"),
        "{warned}"
    );
    edited(&dir, "chain", "beads.toml", |text| {
        format!(
            "{text}\n[[collider]]\n[collider.shape]\nkind = \"mesh\"\npath = \
             \"builtin:table.obj\"\n[collider.response]\nkind = \"stick\"\n"
        )
    });
    let (said, _) = check(&["check", "beads.toml", "--dt", "0.016666666666666666"]);
    assert!(said.contains(": vbd ("), "{said}");
    assert!(
        said.contains("no particle of any body crosses a still restitution or stick collider"),
        "{said}"
    );
    assert!(said.contains("(a chain) keeps"), "{said}");
    let world = root().join("assets/worlds/jello.w");
    let (said, _) = check(&[
        "check",
        world.to_str().unwrap(),
        "--dt",
        "0.016666666666666666",
    ]);
    assert!(said.contains(": newton ("), "{said}");
    assert!(
        said.contains("no integrator keeps particles out of collider[0]"),
        "{said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `hooke drape`'s bad inputs: an unknown fabric, a size the standard does not name, a
/// coefficient outside 0–1, no repeats, a material file with a wrong key or a missing one,
/// a specimen mesh that is not the meter's disc; each refused before any run, naming what
/// was wrong, and no picture written.
#[test]
fn the_drape_meter_refuses_what_it_cannot_measure() {
    let dir = scratch("drape-bad");
    refused(
        &dir,
        &["drape", "velvet"],
        &["velvet", "not a preset", "cotton"],
    );
    refused(
        &dir,
        &["drape", "cotton", "--size", "25"],
        &["24, 30 or 36 cm", "25"],
    );
    refused(
        &dir,
        &["drape", "cotton", "--fit-dc", "1.5"],
        &["--fit-dc", "1.5"],
    );
    refused(&dir, &["drape", "cotton", "--repeats", "0"], &["--repeats"]);
    // Negative numbers reach the option's own check, not clap's "unexpected argument".
    refused(
        &dir,
        &["drape", "cotton", "--seed", "-1"],
        &["--seed", "whole number from 0", "'-1'"],
    );
    refused(
        &dir,
        &["drape", "cotton", "--bending", "-1"],
        &["--bending", "≥ 0"],
    );
    // Forward Euler diverges on the undamped membrane at the meter's own step; the message
    // gives that step to four digits, not as 0.00008324200421703758.
    let out = hooke(
        &["drape", "cotton", "--integrator", "euler", "--repeats", "1"],
        &dir,
    );
    let said = stderr(&out);
    let longest_digits = said
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(
        !out.status.success() && said.contains("diverged") && longest_digits <= 6,
        "{said}"
    );
    refused(&dir, &["drape", "cotton", "--dt=0"], &["--dt", "above 0"]);
    write(
        &dir,
        "typo.toml",
        "[material]\ndensity = 0.15\nstrech = 1000.0\n",
    );
    refused(&dir, &["drape", "typo.toml"], &["typo.toml", "strech"]);
    write(
        &dir,
        "short.toml",
        "[material]\ndensity = 0.15\nstretch = 1000.0\n",
    );
    refused(&dir, &["drape", "short.toml"], &["shear"]);
    write(
        &dir,
        "square.obj",
        "v 0 0 0\nv 0.3 0 0\nv 0.3 0 0.3\nv 0 0 0.3\nf 1 2 3 4\n",
    );
    refused(
        &dir,
        &[
            "drape",
            "cotton",
            "--mesh",
            "square.obj",
            "--top",
            "top.png",
        ],
        &["square.obj", "disc 30 cm across"],
    );
    assert!(!dir.join("top.png").exists());
}
