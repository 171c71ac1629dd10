//! Outputs never replace what they must not: a device, a FIFO or standard output is
//! written through (as root, where the system would let a rename replace `/dev/null`, and as
//! an ordinary user, where the old temporary file beside it could not even be created); no
//! output replaces an input or another output, however the path is spelled; a folder of
//! frames is held by one run; thread counts are bounded; dead runs' temporaries are swept.

mod common;

use common::*;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::Path;
use std::process::{Command, Output};

/// Whether this test runs as root.
fn root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0")
}

/// `hooke ARGS` in `dir` as the unprivileged user `nobody` (through `setpriv`), when this
/// test runs as root and can drop its privileges; `None` otherwise.
fn as_nobody(args: &[&str], dir: &Path) -> Option<Output> {
    if !root() || !Path::new("/usr/bin/setpriv").exists() {
        return None;
    }
    Some(
        Command::new("/usr/bin/setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups", "--"])
            .arg(env!("CARGO_BIN_EXE_hooke"))
            .args(args)
            .current_dir(dir)
            .output()
            .unwrap(),
    )
}

/// `hooke run chain` for a hundredth of a second, its trajectory to `path`.
fn chain_to(path: &str, dir: &Path) -> Output {
    hooke(
        &["run", "chain", "--duration", "0.01", "--trajectory", path],
        dir,
    )
}

fn device(path: &str) -> (u64, u64, bool) {
    let m = std::fs::metadata(path).unwrap();
    (m.ino(), m.rdev(), m.file_type().is_char_device())
}

#[test]
fn devices_fifos_and_standard_output_are_written_through() {
    let dir = scratch("devices");
    std::fs::set_permissions(&dir, std::os::unix::fs::PermissionsExt::from_mode(0o777)).unwrap();
    let before = device("/dev/null");
    for args in [
        &[
            "run",
            "chain",
            "--duration",
            "0.01",
            "--trajectory",
            "/dev/null",
        ][..],
        &[
            "run",
            "chain",
            "--duration",
            "0.01",
            "--gif",
            "/dev/null",
            "--size",
            "32x24",
        ],
        &[
            "render",
            "chain",
            "--at",
            "0.01",
            "-o",
            "/dev/null",
            "--size",
            "32x24",
        ],
    ] {
        let out = hooke(args, &dir);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        if let Some(out) = as_nobody(args, &dir) {
            assert!(
                out.status.success(),
                "as nobody, {args:?}: {}",
                stderr(&out)
            );
        }
    }
    assert_eq!(device("/dev/null"), before);
    assert!(before.2);
    // /dev/full: the write fails and says so; the device stays.
    let full = device("/dev/full");
    let out = chain_to("/dev/full", &dir);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("No space left"), "{}", stderr(&out));
    assert_eq!(device("/dev/full"), full);

    // `-` is standard output: the whole CSV arrives there.
    let out = hooke(
        &[
            "run",
            "chain",
            "--duration",
            "0.01",
            "--every",
            "10",
            "--trajectory",
            "-",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = String::from_utf8(out.stdout).unwrap();
    assert!(csv.starts_with("frame,time,particle"), "{csv}");
    assert_eq!(csv.lines().count(), 1 + 6 * 12, "{csv}");
    // `convert` to a stream writes the other format than the input's.
    let world = root_dir().join("assets/worlds/jello.w");
    let out = hooke(&["convert", &world.to_string_lossy(), "-"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("[simulation]"));
    // /dev/stdout with standard output on a pipe is that pipe.
    let out = chain_to("/dev/stdout", &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("frame,"));

    // A FIFO: a reader gets every row, and the FIFO stays one.
    let fifo = dir.join("pipe");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = chain_to("pipe", &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = reader.join().unwrap();
    assert_eq!(rows.lines().count(), 1 + 12, "{rows}");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert_eq!(temporaries(&dir), Vec::<std::path::PathBuf>::new());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn no_output_replaces_an_input_or_another_output() {
    let dir = scratch("same-file");
    let scene = String::from_utf8(hooke(&["scene", "chain"], &dir).stdout).unwrap();
    std::fs::write(dir.join("s.toml"), &scene).unwrap();
    std::os::unix::fs::symlink("s.toml", dir.join("alias.toml")).unwrap();
    let table = std::fs::read(root_dir().join("assets/meshes/table.obj")).unwrap();
    std::fs::write(dir.join("my.obj"), &table).unwrap();
    // A scene whose table is named inside it.
    let with_table = String::from_utf8(hooke(&["scene", "cloth-table"], &dir).stdout)
        .unwrap()
        .replace("builtin:table.obj", "my.obj");
    std::fs::create_dir(dir.join("scenes")).unwrap();
    std::fs::write(dir.join("scenes/t.toml"), &with_table).unwrap();
    std::fs::rename(dir.join("my.obj"), dir.join("scenes/my.obj")).unwrap();
    std::fs::write(dir.join("s.gif"), "mine").unwrap();
    let cases: [(&[&str], &str); 9] = [
        (
            &["run", "s.toml", "--trajectory", "s.toml"],
            "which this run reads",
        ),
        (
            &["run", "s.toml", "--trajectory", "./alias.toml"],
            "which this run reads",
        ),
        (
            &[
                "run",
                "cloth-table",
                "--table",
                "scenes/my.obj",
                "--export",
                "scenes/my.pc2",
            ],
            "which this run reads",
        ),
        (
            &[
                "run",
                "scenes/t.toml",
                "--export",
                "scenes/../scenes/my.pc2",
            ],
            "which this run reads",
        ),
        (
            &["run", "chain", "--gif", "s.gif", "--trajectory", "./s.gif"],
            "same file",
        ),
        (
            &[
                "run",
                "chain",
                "--trajectory",
                "a.usda",
                "--export",
                "a.usda",
            ],
            "same file",
        ),
        (
            &["run", "chain", "--trajectory", "-", "--summary"],
            "standard output",
        ),
        (
            &["render", "s.toml", "-o", "alias.toml"],
            "expected a file name ending in .png",
        ),
        (&["convert", "s.toml", "alias.toml"], "which this run reads"),
    ];
    for (args, expect) in cases {
        let out = hooke(args, &dir);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(expect), "{args:?}: {}", stderr(&out));
    }
    // Nothing was touched.
    assert_eq!(std::fs::read_to_string(dir.join("s.toml")).unwrap(), scene);
    assert_eq!(std::fs::read(dir.join("scenes/my.obj")).unwrap(), table);
    assert_eq!(std::fs::read_to_string(dir.join("s.gif")).unwrap(), "mine");
    assert!(!dir.join("a.usda").exists() && !dir.join("scenes/my.pc2").exists());
    // A mesh in a folder of OBJ frames would be removed with them.
    std::fs::create_dir(dir.join("f")).unwrap();
    std::fs::write(dir.join("f/frame-00000.obj"), &table).unwrap();
    let out = hooke(
        &[
            "run",
            "cloth-table",
            "--table",
            "f/frame-00000.obj",
            "--export",
            "f/",
            "--format",
            "obj",
        ],
        &dir,
    );
    assert!(stderr(&out).contains("holds the mesh"), "{}", stderr(&out));
    assert_eq!(std::fs::read(dir.join("f/frame-00000.obj")).unwrap(), table);
    let _ = std::fs::remove_dir_all(&dir);
}

fn root_dir() -> std::path::PathBuf {
    common::root()
}

#[test]
fn a_frame_folder_is_held_by_one_run_at_a_time() {
    let dir = scratch("held");
    let first = Watched::spawn(
        &[
            "run",
            "hanging-cloth",
            "--steps",
            "100000000",
            "--frames",
            "f",
            "--size",
            "32x24",
        ],
        &dir,
    );
    wait_for("frames", || {
        std::fs::read_dir(dir.join("f")).is_ok_and(|d| d.count() > 3)
    });
    for frames in ["f", "./f/", "f/../f"] {
        let out = hooke(
            &["run", "chain", "--duration", "0.01", "--frames", frames],
            &dir,
        );
        assert_eq!(out.status.code(), Some(1));
        let said = stderr(&out);
        assert!(
            said.contains("being written by another run")
                && said.contains(&format!("process {}", first.child.id())),
            "{said}"
        );
    }
    // A folder export into the same folder is refused too.
    let out = hooke(
        &[
            "run",
            "chain",
            "--duration",
            "0.01",
            "--export",
            "f/",
            "--format",
            "ply",
        ],
        &dir,
    );
    assert!(stderr(&out).contains("another run"), "{}", stderr(&out));
    // Killed outright: the system releases the folder, and the next run sweeps the dead
    // run's temporary file.
    let mut child = first.child;
    child.kill().unwrap();
    child.wait().unwrap();
    std::fs::write(dir.join("f/.hooke-4194305-0.tmp"), "left by a dead run").unwrap();
    let out = hooke(
        &[
            "run",
            "chain",
            "--duration",
            "0.01",
            "--frames",
            "f",
            "--size",
            "32x24",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(temporaries(&dir), Vec::<std::path::PathBuf>::new());
    let mut names = file_names(&dir.join("f"));
    names.sort();
    assert_eq!(names, [".hooke-frames", "frame-00000.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 54: a folder of someone else's frames (a video's, extracted as `frame-%05d.png`)
/// is not Hooke's to empty: a run that would write those names is refused, naming a file,
/// and nothing in it is touched. Issue 60: a folder export of another kind keeps them and
/// says so; a planted or empty marker takes nothing; in a folder Hooke did mark, a file it
/// did not write (or one it wrote and a person changed) stays, and the run says so.
#[test]
fn a_users_frames_are_never_removed() {
    let dir = scratch("users-frames");
    let chain = ["run", "chain", "--steps", "100", "--every", "10"];
    let run = |extra: &[&str]| {
        let mut all = chain.to_vec();
        all.extend(extra);
        hooke(&all, &dir)
    };
    std::fs::create_dir_all(dir.join("f2")).unwrap();
    let mine = dir.join("f2/frame-00500.png");
    std::fs::write(&mine, "mine").unwrap();
    let out = run(&["--frames", "f2"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("frame-00500.png"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine");
    assert_eq!(file_names(&dir.join("f2")), ["frame-00500.png"]);

    // PLY frames into the same folder write none of its names: it is kept, and said.
    let out = run(&["--export", "f2/", "--format", "ply"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("kept a file named like frames"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine");
    // The next PLY run replaces exactly the frames the first wrote.
    let out = run(&["--export", "f2/", "--format", "ply"]);
    assert!(
        stderr(&out).contains("removed 11 frames"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine");

    // A frame of this run's kind that Hooke recorded, then a person edited: not Hooke's.
    let edited = dir.join("f2/frame-00003.ply");
    std::fs::write(&edited, "edited").unwrap();
    let out = run(&["--export", "f2/", "--format", "ply"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("frame-00003.ply"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&edited).unwrap(), "edited");

    // A marker Hooke did not write, empty or not, takes nothing.
    for planted in ["", "hooke: anything at all\n"] {
        std::fs::create_dir_all(dir.join("f3")).unwrap();
        std::fs::write(dir.join("f3/.hooke-frames"), planted).unwrap();
        std::fs::write(dir.join("f3/frame-00000.png"), "mine").unwrap();
        let out = run(&["--frames", "f3"]);
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        assert!(stderr(&out).contains(".hooke-frames"), "{}", stderr(&out));
        assert_eq!(
            std::fs::read_to_string(dir.join("f3/frame-00000.png")).unwrap(),
            "mine"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("f3/.hooke-frames")).unwrap(),
            planted
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn thread_counts_are_bounded_and_long_names_written() {
    let dir = scratch("threads");
    let out = hooke(&["bench", "cloth", "--n", "8", "--threads", "100000"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("expected at most"),
        "{}",
        stderr(&out)
    );
    let out = hooke_in(&dir)
        .args(["run", "chain", "--duration", "0.01"])
        .env("RAYON_NUM_THREADS", "100000")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("RAYON_NUM_THREADS"),
        "{}",
        stderr(&out)
    );
    // A 255-byte name, the longest the file system takes.
    let name = format!("{}.csv", "n".repeat(251));
    let out = hooke(
        &["run", "chain", "--duration", "0.01", "--trajectory", &name],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join(&name).exists());
    // A folder given as a table is called one.
    std::fs::create_dir(dir.join("tables")).unwrap();
    let out = hooke(&["run", "cloth-table", "--table", "tables"], &dir);
    assert!(stderr(&out).contains("is a folder"), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}
