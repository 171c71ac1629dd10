//! What someone else put in a folder Hooke writes is never written through: a symbolic link,
//! a hard link, a FIFO or a device at any name Hooke chooses there (the folder lock, frames,
//! a folder export's files, the demo's stills, the report's page, data and pictures) refuses
//! the run with the path named, and is left as it was, its target unchanged. A report never
//! replaces a user's page, and one interrupted at any point runs again into its folder.

mod common;

use common::*;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::Path;

/// Something planted at a name, and a look at it afterwards.
#[derive(Clone, Copy, Debug)]
enum Plant {
    /// A symbolic link to the victim file.
    Link,
    /// A second name of the victim file.
    HardLink,
    /// A named pipe.
    Fifo,
    /// A symbolic link to `/dev/null`.
    DeviceLink,
    /// A symbolic link to nowhere.
    Dangling,
}

const PLANTS: [Plant; 5] = [
    Plant::Link,
    Plant::HardLink,
    Plant::Fifo,
    Plant::DeviceLink,
    Plant::Dangling,
];

/// Plants `plant` at `at`, the victim being `victim`.
fn plant(plant: Plant, at: &Path, victim: &Path) {
    match plant {
        Plant::Link => std::os::unix::fs::symlink(victim, at).unwrap(),
        Plant::HardLink => std::fs::hard_link(victim, at).unwrap(),
        Plant::Fifo => {
            let made = std::process::Command::new("mkfifo")
                .arg(at)
                .status()
                .unwrap();
            assert!(made.success());
        }
        Plant::DeviceLink => std::os::unix::fs::symlink("/dev/null", at).unwrap(),
        Plant::Dangling => std::os::unix::fs::symlink(at.with_extension("nowhere"), at).unwrap(),
    }
}

/// What stands at `at` now: its kind, inode and link target.
fn look(at: &Path) -> (bool, bool, u64, Option<std::path::PathBuf>) {
    let m = std::fs::symlink_metadata(at).unwrap();
    (
        m.file_type().is_symlink(),
        m.file_type().is_fifo(),
        m.ino(),
        std::fs::read_link(at).ok(),
    )
}

/// Runs `args` in a fresh folder where `name` (relative, inside the output folder `out`,
/// created first) holds each kind of plant in turn, and checks that the run refused with the
/// path named, and left the plant and the victim as they were.
fn refused_at(case: &str, out: &str, name: &str, args: &[&str]) {
    refused_in(case, (out, false), name, args);
}

/// [`refused_at`] with the output folder `out` marked as a folder of hooke's frames when
/// `marked`: frames there are hooke's to replace, but never through a plant.
fn refused_in(case: &str, (out, marked): (&str, bool), name: &str, args: &[&str]) {
    for kind in PLANTS {
        let dir = scratch(&format!("planted-{case}-{kind:?}"));
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        std::fs::create_dir_all(dir.join(out)).unwrap();
        let at = dir.join(out).join(name);
        if marked {
            // A folder hooke wrote frames into (and recorded them in its marker), whose
            // frame `name` was then replaced by the plant.
            let first = hooke(args, &dir);
            assert!(first.status.success(), "{case}: {}", stderr(&first));
            let _ = std::fs::remove_file(&at);
        }
        plant(kind, &at, &victim);
        let before = look(&at);
        let run = hooke(args, &dir);
        let said = stderr(&run);
        assert_ne!(run.status.code(), Some(0), "{case} {kind:?}: ran: {said}");
        assert!(
            said.contains(&format!("{out}/{name}")) || said.contains(name),
            "{case} {kind:?}: the message names no path: {said}"
        );
        assert_eq!(look(&at), before, "{case} {kind:?}: the plant was touched");
        assert_eq!(
            std::fs::read_to_string(&victim).unwrap(),
            "precious",
            "{case} {kind:?}: the victim was written"
        );
        assert!(
            temporaries(&dir).is_empty(),
            "{case} {kind:?}: left temporaries"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_planted_lock_is_never_opened_through() {
    let frames = [
        "run", "chain", "--steps", "10", "--every", "5", "--frames", "fr",
    ];
    refused_at("lock-frames", "fr", ".hooke-lock", &frames);
    let report = ["report", "rep", "--quick"];
    refused_at("lock-report", "rep", ".hooke-lock", &report);
    let demo = ["demo", "--out", "dm"];
    refused_at("lock-demo", "dm", ".hooke-lock", &demo);
}

#[test]
fn planted_frames_exports_stills_and_report_files_are_never_written_through() {
    let frames = [
        "run", "chain", "--steps", "10", "--every", "5", "--frames", "fr",
    ];
    for marked in [false, true] {
        refused_in("frame", ("fr", marked), "frame-00001.png", &frames);
        for (format, name) in [("ply", "frame-00000.ply"), ("obj", "frame-00002.obj")] {
            let args = [
                "run", "chain", "--steps", "10", "--every", "5", "--export", "ex/", "--format",
                format,
            ];
            refused_in(&format!("export-{format}"), ("ex", marked), name, &args);
        }
    }
    refused_at("demo", "dm", "3-jello-cube.png", &["demo", "--out", "dm"]);
    refused_at(
        "demo-gif",
        "dm",
        "hanging-cloth.gif",
        &["demo", "--out", "dm"],
    );
    for name in [
        "index.html",
        "report.json",
        ".hooke-report",
        "scene-chain-diff.png",
    ] {
        refused_at("report", "rep", name, &["report", "rep", "--quick"]);
    }
}

#[test]
fn a_stale_lock_of_an_ended_run_is_replaced_not_rewritten() {
    let dir = scratch("stale-lock");
    std::fs::create_dir_all(dir.join("fr")).unwrap();
    let lock = dir.join("fr/.hooke-lock");
    std::fs::write(&lock, "process 4194305 (hooke run)").unwrap();
    // Held open here: what the ended run wrote must survive, since the new run removes the
    // stale file and creates its own instead of truncating it.
    let mut stale = std::fs::File::open(&lock).unwrap();
    let run = hooke(
        &[
            "run", "chain", "--steps", "10", "--every", "5", "--frames", "fr",
        ],
        &dir,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(!lock.exists(), "the lock is removed at the end");
    let mut said = String::new();
    std::io::Read::read_to_string(&mut stale, &mut said).unwrap();
    assert_eq!(said, "process 4194305 (hooke run)");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_users_page_is_never_replaced_and_a_bad_report_path_fails_before_any_check() {
    let dir = scratch("report-folders");
    std::fs::create_dir_all(dir.join("web")).unwrap();
    std::fs::write(dir.join("web/index.html"), "<p>mine</p>").unwrap();
    std::fs::write(dir.join("web/report.json"), "{\"sales\": 3}").unwrap();
    let out = hooke(&["report", "web", "--quick"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("not an earlier report"),
        "{}",
        stderr(&out)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("web/index.html")).unwrap(),
        "<p>mine</p>"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("web/report.json")).unwrap(),
        "{\"sales\": 3}"
    );
    // Paths that cannot be a report's folder: each says what it is, with status 2.
    std::fs::write(dir.join("file"), "x").unwrap();
    std::os::unix::fs::symlink(dir.join("nowhere"), dir.join("dangling")).unwrap();
    for (path, says) in [
        ("file", "is a file"),
        ("dangling", "symbolic link to nothing"),
        ("/dev/null", "is a device"),
        ("-", "standard output cannot hold a folder"),
    ] {
        let out = hooke(&["report", path, "--quick"], &dir);
        assert_eq!(out.status.code(), Some(2), "{path}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{path}: {}", stderr(&out));
    }
    // An earlier report's folder whose page became a folder: refused before any check, its
    // report.json untouched.
    let rep = dir.join("rep");
    std::fs::create_dir_all(rep.join("index.html")).unwrap();
    std::fs::write(
        rep.join(".hooke-report"),
        "hooke report: this folder is written by `hooke report`\n",
    )
    .unwrap();
    std::fs::write(rep.join("report.json"), "{\"earlier\": true}").unwrap();
    let out = hooke(&["report", "rep"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("index.html"), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(rep.join("report.json")).unwrap(),
        "{\"earlier\": true}"
    );
    assert!(temporaries(&dir).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_interrupted_first_report_runs_again_into_its_folder() {
    let dir = scratch("report-interrupted");
    let first = Watched::spawn(&["report", "rnew", "--quick"], &dir);
    // The checks are running once the folder is held.
    wait_for("the report's lock", || {
        dir.join("rnew/.hooke-lock").exists()
    });
    interrupt(&first.child);
    let mut child = first.child;
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let left: Vec<String> = file_names(&dir.join("rnew"))
        .into_iter()
        .filter(|n| !n.starts_with(".hooke-"))
        .collect();
    assert!(left.is_empty(), "an interrupted report left {left:?}");
    let again = hooke(&["report", "rnew", "--quick"], &dir);
    assert_eq!(again.status.code(), Some(0), "{}", stderr(&again));
    assert!(dir.join("rnew/index.html").is_file());
    // And again, over its own earlier report.
    let third = hooke(&["report", "rnew", "--quick"], &dir);
    assert_eq!(third.status.code(), Some(0), "{}", stderr(&third));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A report that cannot find the references it compares with (golden images, the worlds'
/// locked trajectories, the course worlds: files of a clone, not of the installed program)
/// stops before any check with status 2, says what it looked for and where, and writes
/// nothing.
#[test]
fn a_report_without_its_references_says_where_it_looked_and_writes_nothing() {
    let dir = scratch("report-references");
    let empty = dir.join("not-a-clone");
    std::fs::create_dir_all(&empty).unwrap();
    let out = hooke_in(&dir)
        .args(["report", "rep", "--quick"])
        .env("HOOKE_REPOSITORY", &empty)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let says = stderr(&out);
    for part in ["golden/", "not-a-clone", "HOOKE_REPOSITORY"] {
        assert!(says.contains(part), "no {part:?} in: {says}");
    }
    assert!(!dir.join("rep").exists(), "a report folder was made");
    let _ = std::fs::remove_dir_all(&dir);
}
