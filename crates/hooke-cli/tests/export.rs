//! `hooke run --export`: every format read back by a reader that is not Hooke's and compared
//! with the run's trajectory, frame by frame. USD is opened with Pixar's own module
//! (`usd-core`) and the point cache with the layout Blender reads, both from
//! `tests/python/check_export.py`; PLY frames with the `ply-rs-bw` parser, the point
//! cache's mesh with `tobj`. A long export's memory does not grow with its frame count, and
//! an interrupted export ends at a complete frame.
//!
//! The Python checks need `usd-core` and `numpy`: `cargo xtask test` installs them in a
//! virtual environment and passes its interpreter as `HOOKE_PYTHON`; without them the tests
//! that use them fail and say so, unless `HOOKE_SKIP_PYTHON` is set.

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python that can run the checks: `HOOKE_PYTHON`, or `python3` if it has `pxr` and
/// `numpy`; `None` only when the user chose to skip them.
fn python() -> Option<PathBuf> {
    let usable = |p: &Path| {
        Command::new(p)
            .args(["-c", "import pxr, numpy"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if let Some(p) = std::env::var_os("HOOKE_PYTHON").map(PathBuf::from) {
        assert!(
            usable(&p),
            "HOOKE_PYTHON={} cannot import pxr and numpy",
            p.display()
        );
        return Some(p);
    }
    if usable(Path::new("python3")) {
        return Some("python3".into());
    }
    assert!(
        std::env::var_os("HOOKE_SKIP_PYTHON").is_some(),
        "the export checks need Python with usd-core and numpy: run the tests with \
         `cargo xtask test`, which installs them, or set HOOKE_SKIP_PYTHON=1 to skip them"
    );
    eprintln!("skipped: HOOKE_SKIP_PYTHON is set");
    None
}

/// Runs `check_export.py KIND FILE CSV EXTRA` and returns what it printed.
fn check(python: &Path, kind: &str, file: &Path, csv: &Path, extra: &str) -> String {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_export.py");
    let out = Command::new(python)
        .arg(script)
        .args([
            kind.as_ref(),
            file.as_os_str(),
            csv.as_os_str(),
            extra.as_ref(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{kind} check of {}: {text}{}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    text
}

/// `hooke run ARGS` in `dir`, which must succeed.
fn run(args: &[&str], dir: &Path) -> String {
    let out = hooke(args, dir);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    stderr(&out)
}

/// The trajectory CSV's positions per frame.
fn positions(csv: &Path) -> Vec<Vec<[f64; 3]>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut frames: Vec<Vec<[f64; 3]>> = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let frame: usize = f[0].parse().unwrap();
        if frames.len() <= frame {
            frames.resize(frame + 1, Vec::new());
        }
        let x = |k: usize| f[k].parse::<f64>().unwrap();
        frames[frame].push([x(3), x(4), x(5)]);
    }
    frames
}

#[test]
fn cloth_table_as_usd_opens_in_usd_core_with_the_trajectory_at_every_time_code() {
    let Some(python) = python() else { return };
    let dir = scratch("export-usd");
    // The whole scene: 301 frames at 100 frames/s.
    let said = run(
        &[
            "run",
            "cloth-table",
            "--export",
            "cloth.usda",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    assert!(
        said.contains("export: cloth.usda (301 frames at 100 frames/s)"),
        "{said}"
    );
    let out = check(
        &python,
        "usd",
        &dir.join("cloth.usda"),
        &dir.join("t.csv"),
        "100",
    );
    assert!(out.contains("301 time codes, prims ['Mesh']"), "{out}");
    // Chains become curves, loose particles points, a jelly a mesh of its skin.
    for (scene, prim, fps) in [
        ("chain", "BasisCurves", "125"),
        ("single-spring", "Points", "25"),
        ("jello-cube", "Mesh", "100"),
    ] {
        let stage = format!("{scene}.usda");
        run(
            &[
                "run",
                scene,
                "--steps",
                "400",
                "--every",
                "40",
                "--export",
                &stage,
                "--trajectory",
                "s.csv",
            ],
            &dir,
        );
        let out = check(&python, "usd", &dir.join(&stage), &dir.join("s.csv"), fps);
        assert!(
            out.contains(&format!("11 time codes, prims ['{prim}']")),
            "{scene}: {out}"
        );
    }
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `v` lines of an OBJ file: the points a Mesh Cache modifier maps the cache onto, in
/// the cache's order.
fn text_vertices(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines().filter(|l| l.starts_with("v ")).count()
}

#[test]
fn a_point_cache_matches_the_trajectory_and_its_mesh_loads_with_tobj() {
    let Some(python) = python() else { return };
    let dir = scratch("export-pc2");
    let said = run(
        &[
            "run",
            "flag",
            "--steps",
            "800",
            "--every",
            "40",
            "--export",
            "flag.pc2",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    assert!(
        said.contains("21 samples of body flag, 600 points"),
        "{said}"
    );
    let out = check(
        &python,
        "pc2",
        &dir.join("flag.pc2"),
        &dir.join("t.csv"),
        "0",
    );
    assert!(out.contains("pc2: 21 samples of 600 points equal"), "{out}");
    let (models, _) = tobj::load_obj(dir.join("flag.obj"), &tobj::LoadOptions::default()).unwrap();
    let mesh = &models[0].mesh;
    assert_eq!(models[0].name, "body:flag");
    assert_eq!(
        mesh.positions.len(),
        3 * 600,
        "one OBJ vertex per cached point"
    );
    assert_eq!(text_vertices(&dir.join("flag.obj")), 600);
    assert_eq!(mesh.indices.len(), 3 * 2 * 29 * 19);
    // OBJ keeps the f64 digits. tobj numbers vertices by first use in a face, so compare
    // corner by corner, face by face: its corners against the file's own `f` lines.
    let first = &positions(&dir.join("t.csv"))[0];
    let text = std::fs::read_to_string(dir.join("flag.obj")).unwrap();
    let faces: Vec<usize> = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .flat_map(|l| l.split(' ').map(|i| i.parse::<usize>().unwrap() - 1))
        .collect();
    assert_eq!(faces.len(), mesh.indices.len());
    for (corner, (&ours, &theirs)) in faces.iter().zip(&mesh.indices).enumerate() {
        let v = &mesh.positions[3 * theirs as usize..3 * theirs as usize + 3];
        assert_eq!(v, &first[ours], "corner {corner}");
    }
    // Another body by name; a name the scene lacks is refused with the ones it has.
    let o = hooke(
        &["run", "flag", "--export", "x.pc2", "--body", "sail"],
        &dir,
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("--body sail: scene flag has no such body; it has flag"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Two cloths, one dropped onto the other, in one scene: each a 6 × 6 grid.
const TWO_CLOTHS: &str = include_str!("../../../tests/fixtures/two-cloths.toml");

/// `(points, samples)` of a point cache's header.
fn pc2_header(path: &Path) -> (i32, i32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..12], b"POINTCACHE2\0");
    let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    (int(16), int(28))
}

/// `--export DIR/ --format pc2` writes each body's cache from one run, the same bytes as
/// that body's own `.pc2` export; a body whose name cannot be a file's, or a mesh of the
/// user's where a cache's would go, refuses the run before anything is written.
#[test]
fn a_folder_of_point_caches_holds_every_body_of_one_run() {
    let dir = scratch("export-pc2-folder");
    std::fs::write(dir.join("two.toml"), TWO_CLOTHS).unwrap();
    let said = run(
        &["run", "two.toml", "--export", "caches/", "--format", "pc2"],
        &dir,
    );
    assert!(said.contains("samples of body under"), "{said}");
    for body in ["under", "over"] {
        let cache = dir.join("caches").join(format!("{body}.pc2"));
        assert_eq!(pc2_header(&cache), (36, 11), "{body}");
        assert_eq!(text_vertices(&cache.with_extension("obj")), 36);
        run(
            &["run", "two.toml", "--export", "alone.pc2", "--body", body],
            &dir,
        );
        assert!(
            std::fs::read(&cache).unwrap() == std::fs::read(dir.join("alone.pc2")).unwrap(),
            "{body}: the folder's cache differs from the body's own export"
        );
    }
    // The upper cloth lies on the lower one at the end: the two were simulated together.
    let last = |body: &str| {
        let bytes = std::fs::read(dir.join("caches").join(format!("{body}.pc2"))).unwrap();
        let at = 32 + 10 * 36 * 12 + 14 * 12 + 4;
        f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
    };
    let (over, under) = (last("over"), last("under"));
    assert!(over > under + 0.004 && under < 0.01, "{over} {under}");
    let named = TWO_CLOTHS.replace("name = \"over\"", "name = \"a/b\"");
    std::fs::write(dir.join("named.toml"), named).unwrap();
    let o = hooke(
        &["run", "named.toml", "--export", "n/", "--format", "pc2"],
        &dir,
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("body 'a/b' cannot name its cache, it holds a path separator"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("n").exists());
    std::fs::create_dir(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/over.obj"), "v 0 0 0\n").unwrap();
    let o = hooke(
        &["run", "two.toml", "--export", "mine/", "--format", "pc2"],
        &dir,
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("was not written by an earlier export"),
        "{}",
        stderr(&o)
    );
    assert_eq!(file_names(&dir.join("mine")), ["over.obj"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ply_frames_read_back_with_the_ply_crate() {
    use hooke::export::ply::{PlyFace, PlyVertex};
    use ply_rs_bw::parser::Parser;
    let dir = scratch("export-ply");
    let said = run(
        &[
            "run",
            "cloth-pile",
            "--steps",
            "400",
            "--every",
            "100",
            "--export",
            "plys/",
            "--format",
            "ply",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    assert!(said.contains("export: 5 PLY frames in plys/"), "{said}");
    let expected = positions(&dir.join("t.csv"));
    for (frame, x) in expected.iter().enumerate() {
        let path = dir.join(format!("plys/frame-{frame:05}.ply"));
        let mut f = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
        let header = Parser::<PlyVertex>::new().read_header(&mut f).unwrap();
        assert_eq!(
            header.encoding,
            ply_rs_bw::ply::Encoding::BinaryLittleEndian
        );
        let vertex = &header.elements["vertex"];
        let vertices = Parser::<PlyVertex>::new()
            .read_payload_for_element(&mut f, vertex, &header)
            .unwrap();
        let faces = Parser::<PlyFace>::new()
            .read_payload_for_element(&mut f, &header.elements["face"], &header)
            .unwrap();
        assert_eq!(vertices.len(), 1024);
        assert_eq!(faces.len(), 2 * 31 * 31);
        for (k, (v, p)) in vertices.iter().zip(x).enumerate() {
            // PLY stores the f32 nearest each f64.
            assert_eq!(v.x, p.map(|c| c as f32), "frame {frame}, vertex {k}");
            let n = (v.n[0] * v.n[0] + v.n[1] * v.n[1] + v.n[2] * v.n[2]).sqrt();
            assert!(
                (n - 1.0).abs() < 1e-5,
                "frame {frame}, vertex {k}: |n| = {n}"
            );
        }
        assert!(faces.iter().all(|f| f.vertex_indices.len() == 3
            && f.vertex_indices.iter().all(|&i| (0..1024).contains(&i))));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Peak resident memory of `hooke ARGS` in `dir`, in KiB, from the kernel's accounting of
/// the finished child (Python's `resource.getrusage`).
fn peak_kib(args: &[&str], dir: &Path) -> u64 {
    let script = "import resource, subprocess, sys\n\
                  r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n\
                  assert r.returncode == 0, r\n\
                  print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)";
    let out = Command::new("python3")
        .args(["-c", script, env!("CARGO_BIN_EXE_hooke")])
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().parse().unwrap()
}

#[test]
fn a_long_export_does_not_grow_in_memory_with_its_frames() {
    let dir = scratch("export-memory");
    // 1201 frames of 625 points (about 50 MB of stage) against 3 frames of the same run.
    let few = peak_kib(
        &[
            "run",
            "hanging-cloth",
            "--steps",
            "1200",
            "--every",
            "600",
            "--export",
            "few.usda",
        ],
        &dir,
    );
    let many = peak_kib(
        &[
            "run",
            "hanging-cloth",
            "--steps",
            "1200",
            "--every",
            "1",
            "--export",
            "many.usda",
        ],
        &dir,
    );
    let size = std::fs::metadata(dir.join("many.usda")).unwrap().len();
    assert!(size > 40_000_000, "the long stage is {size} bytes");
    assert!(
        many < few + 16 * 1024,
        "peak memory {many} KiB with 1201 frames, {few} KiB with 3: it grows with the frames"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_interrupted_usd_export_ends_at_a_complete_frame() {
    let Some(python) = python() else { return };
    let dir = scratch("export-interrupt");
    let child = spawn(
        &[
            "run",
            "cloth-table",
            "--duration",
            "1000",
            "--export",
            "c.usda",
            "--trajectory",
            "t.csv",
        ],
        &dir,
    );
    // Under way once the trajectory being written holds three frames of the 1024-particle
    // cloth (its temporary file; about 70 bytes a row).
    wait_for("three frames", || {
        std::fs::read_dir(&dir).is_ok_and(|d| {
            d.flatten().any(|e| {
                e.file_name().to_string_lossy().ends_with(".tmp")
                    && e.metadata().is_ok_and(|m| m.len() > 3 * 1024 * 70)
            })
        })
    });
    interrupt(&child);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    // The stage and the trajectory end at the same frame, and the stage opens.
    let frames = positions(&dir.join("t.csv")).len();
    assert!(frames > 2, "{frames} frames before the interrupt");
    let said = check(
        &python,
        "usd",
        &dir.join("c.usda"),
        &dir.join("t.csv"),
        "100",
    );
    assert!(said.contains(&format!("{frames} time codes")), "{said}");
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_paths_that_make_no_sense_are_refused_before_the_run() {
    let dir = scratch("export-refused");
    for (args, expected) in [
        (
            vec!["--export", "run.fbx"],
            "expected a file ending in .usda or .pc2, or a folder ending in /",
        ),
        (
            vec!["--export", "frames/"],
            "a folder export needs --format ply, --format obj or --format pc2",
        ),
        (
            vec!["--export", "run.usda", "--format", "ply"],
            "only folder exports (--export DIR/) take a format",
        ),
        (
            vec!["--export", "run.usda", "--body", "chain"],
            "--body: only a .pc2 export holds one body",
        ),
        (
            vec!["--export", "missing/run.usda"],
            "the folder missing does not exist",
        ),
        (vec!["--format", "obj"], "--export"),
    ] {
        let mut all = vec!["run", "chain"];
        all.extend(&args);
        let o = hooke(&all, &dir);
        assert!(!o.status.success(), "{args:?} was accepted");
        assert!(stderr(&o).contains(expected), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    }
    assert!(file_names(&dir).is_empty(), "{:?}", file_names(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A moving collider's USD prim carries its pose as time samples: read back with `pxr`, the
/// puck keyed 1.4 m along x (and turned 90° about y) between 0.05 s and 0.15 s sits at its
/// start in frame 0 and 1.4 m along at the last frame, its transform turned; a still
/// collider has none. The OBJ frames hold it where it is too.
#[test]
fn a_moving_collider_is_time_sampled_in_usd_and_posed_in_obj_frames() {
    let Some(python) = python() else { return };
    let dir = scratch("export-moving");
    let scene = "name = \"puck\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.001\nsteps = 200\nevery = 50\n\
                 [[body]]\nname = \"p\"\nmass = 0.1\n[body.shape]\nkind = \"points\"\npositions = [[0.0, 3.0, 0.0]]\n\
                 [[collider]]\nshape = { kind = \"ground\", height = 0.0 }\nresponse = { kind = \"stick\" }\n\
                 [[collider]]\nshape = { kind = \"cylinder\", center = [-1.0, 0.5, 0.0], radius = 0.2, thickness = 0.2 }\n\
                 response = { kind = \"restitution\", cr = 0.0 }\n\
                 motion = { keys = [{ t = 0.05, translate = [0.0, 0.0, 0.0] }, { t = 0.15, translate = [1.4, 0.0, 0.0], rotate = [0.0, 90.0, 0.0] }] }\n";
    std::fs::write(dir.join("puck.toml"), scene).unwrap();
    run(&["run", "puck.toml", "--export", "puck.usda"], &dir);
    let script = r#"
import sys
from pxr import Usd, UsdGeom
stage = Usd.Stage.Open(sys.argv[1])
puck = stage.GetPrimAtPath("/World/colliders/c1_cylinder")
ground = stage.GetPrimAtPath("/World/colliders/c0_ground")
first, last = stage.GetStartTimeCode(), stage.GetEndTimeCode()
xf = UsdGeom.Xformable(puck)
m0 = xf.ComputeLocalToWorldTransform(first)
m1 = xf.ComputeLocalToWorldTransform(last)
# The puck's pivot (-1, 0.5, 0) is carried to (0.4, 0.5, 0); the x axis turned to -z.
p0 = m0.Transform((-1.0, 0.5, 0.0))
p1 = m1.Transform((-1.0, 0.5, 0.0))
x1 = m1.TransformDir((1.0, 0.0, 0.0))
print("start %.9f %.9f %.9f" % tuple(p0))
print("end %.9f %.9f %.9f" % tuple(p1))
print("xaxis %.9f %.9f %.9f" % tuple(x1))
print("ground samples", len(UsdGeom.Xformable(ground).GetOrderedXformOps()))
"#;
    let out = Command::new(&python)
        .args(["-c", script])
        .arg(dir.join("puck.usda"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("start -1.000000000 0.500000000 0.000000000"),
        "{text}"
    );
    assert!(
        text.contains("end 0.400000000 0.500000000 0.000000000"),
        "{text}"
    );
    assert!(
        text.contains("xaxis 0.000000000 0.000000000 -1.000000000"),
        "{text}"
    );
    assert!(text.contains("ground samples 0"), "{text}");
    // OBJ: the puck's vertices at the last frame are 1.4 m along from the first frame's.
    run(
        &["run", "puck.toml", "--export", "frames/", "--format", "obj"],
        &dir,
    );
    let mean_x = |f: &str| {
        let text = std::fs::read_to_string(dir.join("frames").join(f)).unwrap();
        let mut in_puck = false;
        let xs: Vec<f64> = text
            .lines()
            .filter_map(|l| {
                if l.starts_with("o ") {
                    in_puck = l.contains("cylinder");
                }
                let v = l.strip_prefix("v ").filter(|_| in_puck)?;
                v.split(' ').next()?.parse().ok()
            })
            .collect();
        xs.iter().sum::<f64>() / xs.len() as f64
    };
    let moved = mean_x("frame-00004.obj") - mean_x("frame-00000.obj");
    assert!(
        (moved - 1.4).abs() < 1e-9,
        "the exported puck moved {moved} m"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
