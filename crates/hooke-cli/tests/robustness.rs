//! What an unlucky or hostile user does to `hooke`: points its output at folders and
//! missing places, hands it numbers no scene can use, asks for scenes larger than the
//! machine (interrupts are in `interrupts.rs`). Each case gets a clear refusal or a correct
//! result; nothing is lost, nothing is left behind, nothing panics.

mod common;

use common::*;
use std::path::{Path, PathBuf};

/// Output paths that cannot take the file are refused before a (here endless) run starts,
/// and no temporary file appears, neither beside the target nor in its parent.
#[test]
fn unusable_output_paths_are_refused_before_the_run() {
    let dir = scratch("paths");
    std::fs::write(dir.join("file.txt"), "mine").unwrap();
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let here = dir.to_string_lossy().into_owned();
    let endless = ["run", "chain", "--steps", "1000000000"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--trajectory", &here], "is a folder"),
        (vec!["--trajectory", "out/"], "is a folder"),
        (vec!["--trajectory", "out"], "is a folder"),
        (vec!["--trajectory", "missing/t.csv"], "does not exist"),
        (vec!["--gif", "a.png"], "ending in .gif"),
        (vec!["--gif", "out"], "is a folder"),
        (vec!["--frames", "file.txt"], "expected a folder"),
        (
            vec!["--export", "file.txt/", "--format", "obj"],
            "expected a folder",
        ),
        (vec!["--export", "out"], "a folder export needs --format"),
        (vec!["--export", "missing/run.usda"], "does not exist"),
        (vec!["--export", "run.abc"], "ending in .usda or .pc2"),
    ];
    for (extra, expect) in cases {
        let args: Vec<&str> = endless.iter().copied().chain(extra).collect();
        let out = hooke(&args, &dir);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(stderr(&out).contains(expect), "{args:?}: {}", stderr(&out));
    }
    for (output, expect) in [
        ("z.jpg", "ending in .png"),
        ("out", "is a folder"),
        (".", "is a folder"),
        ("missing/z.png", "does not exist"),
    ] {
        let out = hooke(&["render", "chain", "--at", "1e5", "-o", output], &dir);
        assert_eq!(out.status.code(), Some(1), "{output}");
        assert!(stderr(&out).contains(expect), "{output}: {}", stderr(&out));
    }
    let out = hooke(&["demo", "--out", "file.txt"], &dir);
    assert!(
        stderr(&out).contains("expected a folder"),
        "{}",
        stderr(&out)
    );
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["file.txt", "out"]);
    assert_eq!(count_files(&dir.join("out"), "tmp"), 0);
    // `--trajectory DIR` would have written `.DIR.<pid>.tmp` into DIR's parent.
    let name = dir.file_name().unwrap().to_string_lossy().into_owned();
    let parent_leftovers: Vec<_> = std::fs::read_dir(dir.parent().unwrap())
        .unwrap()
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(&format!(".{name}."))
        })
        .collect();
    assert!(parent_leftovers.is_empty(), "{parent_leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Numbers no picture or scene can use are refused where they enter, naming the option or
/// the file and line, with no panic and no output file.
#[test]
fn bad_numbers_are_refused_without_a_panic() {
    let dir = scratch("numbers");
    std::fs::write(
        dir.join("far.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 0 1e200\nf 1 2 3\n",
    )
    .unwrap();
    let scene = hooke(&["scene", "single-spring"], &dir);
    let text = String::from_utf8(scene.stdout).unwrap();
    let far: String = text
        .lines()
        .map(|l| match l.starts_with("origin = ") {
            true => "origin = [1e300, 0.0, 0.0]\n".to_string(),
            false => format!("{l}\n"),
        })
        .collect();
    assert!(far.contains("1e300"));
    std::fs::write(dir.join("far.toml"), far).unwrap();
    let render = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = vec!["render", "chain", "-o", "z.png"];
        v.extend_from_slice(extra);
        v
    };
    let run = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = vec!["run", "chain", "--trajectory", "t.csv"];
        v.extend_from_slice(extra);
        v
    };
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (render(&["--zoom", "0"]), "--zoom"),
        (render(&["--zoom", "nan"]), "--zoom"),
        (render(&["--zoom", "-1"]), "--zoom"),
        (render(&["--zoom", "inf"]), "--zoom"),
        (render(&["--yaw", "nan"]), "--yaw"),
        (render(&["--pitch", "90"]), "--pitch"),
        (render(&["--supersample", "0"]), "--supersample"),
        (render(&["--supersample", "100"]), "--supersample"),
        (render(&["--size", "0x0"]), "--size"),
        (render(&["--at", "1e300"]), "--at 1e300 s"),
        (render(&["--at", "-1"]), "--at"),
        (render(&["--at", "nan"]), "--at"),
        (run(&["--zoom", "0", "--frames", "d"]), "--zoom"),
        (run(&["--dt", "nan"]), "--dt"),
        (run(&["--dt", "0"]), "--dt"),
        (run(&["--dt", "-1"]), "--dt"),
        (run(&["--dt", "1e300"]), "--dt: 1e300 s is a step no solver"),
        (run(&["--duration", "1e300"]), "1e300 s"),
        (run(&["--steps", "0"]), "--steps"),
        (run(&["--every", "0"]), "--every"),
        (
            vec![
                "run",
                "cloth-table",
                "--table",
                "far.obj",
                "--trajectory",
                "t.csv",
            ],
            "far.obj:3: vertex coordinate 1e200 is beyond",
        ),
        (vec!["run", "far.toml", "--trajectory", "t.csv"], "origin"),
    ];
    for (args, expect) in cases {
        let out = hooke(&args, &dir);
        let e = stderr(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(!e.contains("panicked"), "{args:?}: {e}");
        assert!(e.contains(expect), "{args:?}: expected '{expect}' in: {e}");
        // Numbers far from 1 print in scientific form, not as hundreds of digits.
        assert!(e.lines().all(|l| l.chars().count() < 400), "{args:?}: {e}");
    }
    assert!(!dir.join("z.png").exists() && !dir.join("t.csv").exists());
    let out = hooke_in(&dir)
        .args(["run", "chain", "--steps", "1"])
        .env("HOOKE_MAX_MEMORY", "lots")
        .output()
        .unwrap();
    assert!(
        stderr(&out).contains("HOOKE_MAX_MEMORY=lots"),
        "{}",
        stderr(&out)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A small scene file asking for the largest lattice is refused in a moment when it would
/// exceed the memory budget, with what it needs and the key to change; within the budget
/// the same machinery lets ordinary scenes through.
#[test]
fn scenes_larger_than_the_memory_budget_are_refused_before_building() {
    let dir = scratch("memory");
    let scene = hooke(&["scene", "jello-cube"], &dir);
    let text = String::from_utf8(scene.stdout).unwrap();
    assert!(text.contains("size = [8, 8, 8]"));
    std::fs::write(
        dir.join("huge.toml"),
        text.replace("size = [8, 8, 8]", "size = [161, 161, 161]"),
    )
    .unwrap();
    let out = hooke_in(&dir)
        .args(["run", "huge.toml", "--trajectory", "t.csv"])
        .env("HOOKE_MAX_MEMORY", "1G")
        .output()
        .unwrap();
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    for expect in [
        "would need about",
        "4173281 particles",
        "1.0 GB of HOOKE_MAX_MEMORY",
        "body[0] 'jelly'.shape.size",
    ] {
        assert!(e.contains(expect), "expected '{expect}' in: {e}");
    }
    assert!(!dir.join("t.csv").exists());
    // A file whose parsing alone exceeds the budget is not read at all.
    let pairs = "[[body.springs.pairs]]\ni = 0\nj = 1\nks = 1.0\nkd = 0.0\n".repeat(40_000);
    std::fs::write(dir.join("pairs.toml"), format!("{text}{pairs}")).unwrap();
    let out = hooke_in(&dir)
        .args(["run", "pairs.toml", "--steps", "1"])
        .env("HOOKE_MAX_MEMORY", "20M")
        .output()
        .unwrap();
    let e = stderr(&out);
    assert!(
        e.contains("pairs.toml: reading this ") && e.contains("MB file would need about"),
        "{e}"
    );
    let out = hooke_in(&dir)
        .args(["run", "jello-cube", "--steps", "10"])
        .env("HOOKE_MAX_MEMORY", "1G")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Small things a user notices: stale frames of a longer earlier run are cleared from a
/// frame folder, "1 frame" is singular, a `--table` path is relative to where the command
/// runs (not to the scene file), tiny numbers in a trajectory are short.
#[test]
fn frame_folders_plurals_table_paths_and_tiny_numbers() {
    let dir = scratch("small");
    let run = |args: &[&str]| {
        let out = hooke(args, &dir);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        stderr(&out)
    };
    run(&[
        "run", "chain", "--steps", "100", "--every", "10", "--frames", "f", "--size", "32x24",
    ]);
    assert_eq!(count_files(&dir.join("f"), "png"), 11);
    std::fs::write(dir.join("f/notes.png.txt"), "mine").unwrap();
    let e = run(&[
        "run", "chain", "--steps", "40", "--every", "10", "--frames", "f", "--size", "32x24",
    ]);
    assert!(e.contains("removed 11 frames"), "{e}");
    assert_eq!(count_files(&dir.join("f"), "png"), 5);
    assert!(
        dir.join("f/notes.png.txt").exists(),
        "only frames are removed"
    );

    let e = run(&[
        "run",
        "chain",
        "--steps",
        "5",
        "--every",
        "10",
        "--trajectory",
        "t.csv",
    ]);
    assert!(e.contains("(1 frame)"), "{e}");

    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let scene = hooke(&["scene", "cloth-table"], &dir);
    std::fs::write(dir.join("sub/mine.toml"), scene.stdout).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes");
    std::fs::copy(root.join("square-table.obj"), dir.join("t.obj")).unwrap();
    run(&["run", "sub/mine.toml", "--table", "./t.obj", "--steps", "2"]);
    let out = hooke(
        &[
            "run",
            "sub/mine.toml",
            "--table",
            "sub/t.obj",
            "--steps",
            "2",
        ],
        &dir,
    );
    assert!(
        stderr(&out).contains("--table sub/t.obj: no such file"),
        "{}",
        stderr(&out)
    );

    let single = String::from_utf8(hooke(&["scene", "single-spring"], &dir).stdout).unwrap();
    assert!(single.contains("velocity = [0.0, 0.0, 0.0]"), "{single}");
    std::fs::write(
        dir.join("tiny.toml"),
        single.replacen(
            "velocity = [0.0, 0.0, 0.0]",
            "velocity = [2.5e-30, 0.0, 0.0]",
            1,
        ),
    )
    .unwrap();
    run(&[
        "run",
        "tiny.toml",
        "--steps",
        "1",
        "--trajectory",
        "tiny.csv",
    ]);
    let csv = std::fs::read_to_string(dir.join("tiny.csv")).unwrap();
    // Particle 0 is pinned (its velocity zeroed); particle 1 keeps the tiny one.
    let free = csv.lines().nth(2).unwrap();
    assert!(
        free.starts_with("0,0,1,") && free.contains(",2.5e-30,"),
        "{free}"
    );
    for field in csv.lines().skip(1).flat_map(|l| l.split(',')) {
        assert!(field.len() <= 24, "'{field}' is longer than a shortest f64");
        field.parse::<f64>().unwrap();
    }
    let _ = std::fs::remove_dir_all(&dir);
}

mod picture_arguments {
    use hooke_cli::args::{parse_size, picture_from_args};
    use proptest::prelude::*;

    const OPTIONS: [&str; 7] = [
        "--zoom",
        "--yaw",
        "--pitch",
        "--supersample",
        "--size",
        "--style",
        "--at",
    ];
    const VALUES: [&str; 24] = [
        "0", "-0", "nan", "NaN", "inf", "-inf", "1e300", "-1e300", "1e-300", "90", "-90", "89",
        "0.001", "1000", "1001", "-1", "0x0", "8x8", "40x30", "8193x8", "solid", "springs", "",
        "x",
    ];

    fn value() -> impl Strategy<Value = String> {
        prop_oneof![
            proptest::sample::select(VALUES.to_vec()).prop_map(str::to_string),
            any::<f64>().prop_map(|x| x.to_string()),
            (-5i64..5).prop_map(|k| k.to_string()),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

        /// Any arguments to the picture path are refused or give a picture of the asked
        /// size; none panics (the same check as the `args` fuzz target, on every CI run).
        #[test]
        fn arguments_are_refused_or_drawn_at_their_size(
            scene in proptest::sample::select(vec!["single-spring", "chain", "jello-cube"]),
            pairs in proptest::collection::vec((proptest::sample::select(OPTIONS.to_vec()), value()), 0..4),
        ) {
            let mut args = vec![scene.to_string()];
            for (option, value) in &pairs {
                args.push(option.to_string());
                args.push(value.clone());
            }
            if !args.iter().any(|a| a == "--size") {
                args.extend(["--size".to_string(), "40x30".to_string()]);
            }
            let result = std::panic::catch_unwind(|| picture_from_args(&args, 50));
            prop_assert!(result.is_ok(), "{args:?} panicked");
            if let Ok(Ok(image)) = result {
                let i = args.iter().position(|a| a == "--size").unwrap();
                let size = parse_size(&args[i + 1]).unwrap();
                prop_assert_eq!(image.dimensions(), size, "{:?}", args);
            }
        }
    }

    /// The ordinary arguments draw the scene: not only background.
    #[test]
    fn ordinary_arguments_draw_something() {
        let args: Vec<String> = [
            "chain", "--size", "40x30", "--zoom", "0.8", "--pitch", "-30",
        ]
        .map(str::to_string)
        .to_vec();
        let image = picture_from_args(&args, 50).unwrap();
        let corner = *image.get_pixel(0, 0);
        let differing = image.pixels().filter(|p| **p != corner).count();
        assert!(
            differing > 20,
            "only {differing} pixels differ from the background"
        );
    }
}
