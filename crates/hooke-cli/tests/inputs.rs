//! Files as users have them (issue 71): text saved by a Windows editor (a byte-order mark,
//! CRLF line ends), a device or a pipe named as an input, a user's own OBJ beside the PC2
//! an export writes, and the drape test's pictures. Each is read as its user meant or
//! refused at once, naming the file and why; nothing of the user's is replaced.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// A quad sheet of 3×3 vertices, 0.2 m wide, as OBJ text with `\n` line ends.
const SHEET: &str = "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0 0 0.1\nv 0.1 0 0.1\nv 0.2 0 0.1\n\
v 0 0 0.2\nv 0.1 0 0.2\nv 0.2 0 0.2\nf 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\nf 5 6 9 8\n";

/// A scene with one cloth made from the mesh at `path`, stepped 50 times.
fn scene(path: &str) -> String {
    format!(
        "name = \"sheet\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.0002\nsteps = 50\n\
         every = 10\n[[body]]\nname = \"cloth\"\norigin = [0.0, 1.0, 0.0]\npins = [0]\n\
         [body.shape]\nkind = \"mesh\"\npath = \"{path}\"\n[body.material]\npreset = \"cotton\"\n"
    )
}

/// `text` as a Windows editor saves it: a byte-order mark and CRLF line ends.
fn windows(text: &str) -> Vec<u8> {
    let mut bytes = b"\xef\xbb\xbf".to_vec();
    bytes.extend(text.replace('\n', "\r\n").into_bytes());
    bytes
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// The same cloth, scene and world read from files saved with a byte-order mark and CRLF
/// give the same bits as from plain files.
#[test]
fn a_byte_order_mark_and_crlf_change_nothing() {
    let dir = scratch("bom");
    std::fs::write(dir.join("plain.obj"), SHEET).unwrap();
    std::fs::write(dir.join("marked.obj"), windows(SHEET)).unwrap();
    std::fs::write(dir.join("plain.toml"), scene("plain.obj")).unwrap();
    std::fs::write(dir.join("marked.toml"), windows(&scene("marked.obj"))).unwrap();
    for name in ["plain", "marked"] {
        ok(&hooke(
            &[
                "run",
                &format!("{name}.toml"),
                "--trajectory",
                &format!("{name}.csv"),
                "--export",
                &format!("{name}-cache.pc2"),
            ],
            &dir,
        ));
    }
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert_eq!(read("plain.csv"), read("marked.csv"));
    assert_eq!(read("plain-cache.pc2"), read("marked-cache.pc2"));
    // Nine points per sample: every vertex of the file, none skipped.
    let pc2 = read("marked-cache.pc2");
    assert_eq!(i32::from_le_bytes(pc2[16..20].try_into().unwrap()), 9);

    let world = std::fs::read_to_string(root().join("assets/worlds/jello.w")).unwrap();
    std::fs::write(dir.join("plain.w"), &world).unwrap();
    std::fs::write(dir.join("marked.w"), windows(&world)).unwrap();
    for name in ["plain", "marked"] {
        let (w, csv) = (format!("{name}.w"), format!("{name}-w.csv"));
        ok(&hooke(
            &["run", &w, "--steps", "20", "--trajectory", &csv],
            &dir,
        ));
    }
    assert_eq!(read("plain-w.csv"), read("marked-w.csv"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// A device, a pipe with no writer and a folder named as a mesh are refused at once, by
/// `check` and `run` alike, naming the path and what it is.
#[test]
fn devices_and_pipes_named_as_inputs_are_refused_before_they_are_read() {
    let dir = scratch("devices");
    let fifo = dir.join("pipe.obj");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    std::fs::create_dir(dir.join("folder.obj")).unwrap();
    for (path, what) in [
        ("/dev/zero", "a character device"),
        ("pipe.obj", "a named pipe"),
        ("folder.obj", "a folder"),
    ] {
        std::fs::write(dir.join("s.toml"), scene(path)).unwrap();
        for command in ["check", "run"] {
            // A read of /dev/zero would not end, and a pipe would block: a run still going
            // after the suite's wait (300 s, a hung process, not a speed) is the failure.
            let mut child = spawn(&[command, "s.toml"], &dir);
            wait_for(&format!("{command} {path} to end"), || {
                child.try_wait().unwrap().is_some()
            });
            let o = child.wait_with_output().unwrap();
            let e = stderr(&o);
            assert!(!o.status.success(), "{command} {path}");
            assert!(
                e.contains(path) && e.contains(what),
                "{command} {path}: {e}"
            );
        }
    }
    let o = hooke(&["drape", "/dev/zero"], &dir);
    assert!(stderr(&o).contains("a character device"), "{}", stderr(&o));
    std::fs::remove_dir_all(dir).unwrap();
}

/// `hooke run flag --export flag.pc2` in a folder holding the user's own `flag.obj` leaves
/// it as it is and says so; an earlier export's own mesh is replaced.
#[test]
fn an_export_never_replaces_the_users_own_obj_beside_its_pc2() {
    let dir = scratch("pc2-mesh");
    std::fs::write(dir.join("flag.obj"), SHEET).unwrap();
    let args = ["run", "flag", "--export", "flag.pc2", "--duration", "0.02"];
    let o = hooke(&args, &dir);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("flag.obj"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(dir.join("flag.obj")).unwrap(),
        SHEET
    );
    assert!(!dir.join("flag.pc2").exists());
    std::fs::remove_file(dir.join("flag.obj")).unwrap();
    ok(&hooke(&args, &dir));
    ok(&hooke(&args, &dir));
    // Changed by hand since: no longer the export's.
    let mesh = dir.join("flag.obj");
    let edited = std::fs::read_to_string(&mesh)
        .unwrap()
        .replacen("v ", "v  ", 1);
    std::fs::write(&mesh, &edited).unwrap();
    assert!(!hooke(&args, &dir).status.success());
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), edited);
    std::fs::remove_dir_all(dir).unwrap();
}

/// The drape test's pictures are checked before the first repeat: one path for both, a
/// link, and a target no drape coefficient can have are refused.
#[test]
fn the_drape_tests_outputs_and_target_are_checked_before_it_runs() {
    let dir = scratch("drape-args");
    let same = hooke(
        &["drape", "silk", "--top", "a.png", "--still", "a.png"],
        &dir,
    );
    assert!(stderr(&same).contains("same file"), "{}", stderr(&same));
    std::os::unix::fs::symlink(dir.join("elsewhere.png"), dir.join("link.png")).unwrap();
    let link = hooke(&["drape", "silk", "--top", "link.png"], &dir);
    assert!(stderr(&link).contains("symbolic link"), "{}", stderr(&link));
    assert!(!Path::new(&dir.join("elsewhere.png")).exists());
    for target in ["1.0", "0", "0.2"] {
        let o = hooke(&["drape", "silk", "--fit-dc", target], &dir);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("--fit-dc"), "{}", stderr(&o));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A disc saved as one 48-sided face, which a fan splits into slivers.
fn ngon() -> String {
    let n = 48;
    let mut obj = String::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        obj += &format!("v {} 0 {}\n", 0.15 * a.cos(), 0.15 * a.sin());
    }
    obj += "f";
    for k in 1..=n {
        obj += &format!(" {k}");
    }
    obj + "\n"
}

/// `check` on a cloth whose mesh has slivers names the mesh's shortest and longest edges
/// and the slivers to remesh; with a collider that moves, it recommends one large step and
/// does not warn against its own recommendation.
#[test]
fn check_names_a_meshs_slivers_and_recommends_one_large_step() {
    let dir = scratch("slivers");
    std::fs::write(dir.join("disc.obj"), ngon()).unwrap();
    let scene = "name = \"disc\"\n[simulation]\nintegrator = \"vbd\"\ndt = 0.016666666666666666\n\
                 duration = 1.0\nevery = 6\n[[body]]\nname = \"disc\"\norigin = [0.0, 1.0, 0.0]\n\
                 [body.shape]\nkind = \"mesh\"\npath = \"disc.obj\"\n[body.material]\n\
                 preset = \"silk\"\n";
    std::fs::write(dir.join("still.toml"), scene).unwrap();
    let ball = "[[collider]]\nshape = { kind = \"sphere\", center = [0.0, 0.5, 0.0], radius = 0.1 }\n\
                response = { kind = \"restitution\", cr = 0.0, friction = 0.3 }\n\
                motion = { keys = [{ t = 0.0, translate = [0.0, 0.0, 0.0] }, \
                { t = 1.0, translate = [0.0, 0.5, 0.0] }] }\n";
    std::fs::write(dir.join("moving.toml"), format!("{scene}{ball}")).unwrap();
    let o = hooke(&["check", "still.toml"], &dir);
    ok(&o);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        out.contains("edges run from") && out.contains("slivers") && out.contains("remesh"),
        "{out}"
    );
    let o = hooke(&["check", "moving.toml"], &dir);
    ok(&o);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let recommended = out.lines().find(|l| l.starts_with("recommended")).unwrap();
    assert!(recommended.contains(": vbd ("), "{recommended}");
    assert!(
        !out.contains("warning: newton with a moving collider"),
        "{out}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
