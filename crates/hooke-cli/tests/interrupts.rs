//! Interrupts, as users send them: Ctrl-C once or twice, at any stage. A run stops at a
//! complete frame with status 130; its trajectory, frame folder and animation end at the
//! same frame, and no temporary file is left behind.

mod common;

use common::*;
use std::path::PathBuf;
use std::time::Duration;

/// Two interrupts in a row (what `timeout` and an impatient user send) stop the run at a
/// complete frame: the trajectory, the frame folder and the GIF all end at the same frame,
/// the exit status is 130 and no temporary file remains. Repeated at different moments,
/// since the failure this guards against was a race.
#[test]
fn two_interrupts_keep_every_complete_frame() {
    const PARTICLES: usize = 625; // hanging-cloth
    for round in 0..4u64 {
        let dir = scratch(&format!("twice-{round}"));
        let child = spawn(
            &[
                "run",
                "hanging-cloth",
                "--steps",
                "100000000",
                "--every",
                "10",
                "--trajectory",
                "t.csv",
                "--frames",
                "f",
                "--gif",
                "a.gif",
                "--size",
                "64x48",
            ],
            &dir,
        );
        wait_for("frames", || count_files(&dir.join("f"), "png") >= 3);
        std::thread::sleep(Duration::from_millis(37 * round));
        interrupt(&child);
        interrupt(&child);
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
        let csv = std::fs::read_to_string(dir.join("t.csv")).unwrap();
        let rows = csv.lines().count() - 1;
        assert!(rows >= 3 * PARTICLES, "round {round}: {rows} rows");
        assert_eq!(rows % PARTICLES, 0, "round {round}: a partial frame");
        let frames = rows / PARTICLES;
        assert_eq!(count_files(&dir.join("f"), "png"), frames, "round {round}");
        // A frame every 10 steps of 2.5e-4 s.
        assert_eq!(
            gif_frames(&dir.join("a.gif")),
            shown(frames, 10.0 * 2.5e-4),
            "round {round}"
        );
        assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// `render`, `demo` and `bench` stop on Ctrl-C with the same status as `run`, writing no
/// partial image and leaving no temporary file (the viewer's test covers `view`).
#[test]
fn render_and_demo_stop_on_interrupt_with_status_130() {
    let dir = scratch("render-int");
    // Each is interrupted once it is under way: the still once it has said how many steps
    // it takes, the demo once its first still is written.
    let still_announced = |w: &Watched| w.wait_to_say("Ctrl-C stops");
    let demo_started = |_: &Watched| {
        wait_for("the demo's first still", || {
            dir.join("d/1-single-spring.png").exists()
        })
    };
    type UnderWay<'a> = &'a dyn Fn(&Watched);
    let cases: [(&[&str], UnderWay); 2] = [
        (
            &["render", "chain", "--at", "1e6", "-o", "z.png"],
            &still_announced,
        ),
        (&["demo", "--out", "d"], &demo_started),
    ];
    for (args, under_way) in cases {
        let watched = Watched::spawn(args, &dir);
        under_way(&watched);
        interrupt(&watched.child);
        let (status, said) = watched.finish();
        assert_eq!(status.code(), Some(130), "{args:?}: {said}");
        assert!(said.contains("interrupted at step"), "{said}");
    }
    assert!(!dir.join("z.png").exists());
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    let _ = std::fs::remove_dir_all(&dir);
}

/// One Ctrl-C ends a command at a stage that asks for none: `check` of a million-particle
/// cloth, interrupted while it builds, exits with 130 and says so (it once built on, and
/// a second and a third were needed).
#[test]
fn one_interrupt_ends_a_build_and_a_check() {
    let dir = scratch("build-int");
    std::fs::write(
        dir.join("big.toml"),
        "name = \"big\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.0001\n\
         duration = 1.0\nevery = 100\n[[body]]\nname = \"cloth\"\nmass = 1e-6\n\
         [body.shape]\nkind = \"grid\"\nsize = [1000, 1000]\nspacing = 0.001\n\
         [body.springs.structural]\nks = 300.0\nkd = 0.02\n",
    )
    .unwrap();
    let watched = Watched::spawn(&["check", "big.toml"], &dir);
    watched.wait_to_say("this takes a while");
    interrupt(&watched.child);
    let (status, said) = watched.finish();
    assert_eq!(status.code(), Some(130), "{said}");
    assert!(said.trim_end().ends_with("interrupted"), "{said}");
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The GIF is encoded frame by frame: after hundreds of 400×300 frames (half a megabyte
/// each as pixels) the process's peak memory is still a fraction of what holding them would
/// take, and the GIF it leaves on Ctrl-C has every frame the folder has.
#[cfg(target_os = "linux")]
#[test]
fn gif_frames_are_encoded_as_they_come() {
    const FRAMES: usize = 300;
    const FRAME_BYTES: usize = 400 * 300 * 4;
    let dir = scratch("gif");
    let child = spawn(
        &[
            "run",
            "chain",
            "--steps",
            "1000000000",
            "--every",
            "1",
            "--size",
            "400x300",
            "--supersample",
            "1",
            "--frames",
            "f",
            "--gif",
            "a.gif",
        ],
        &dir,
    );
    let peak_kb = || -> usize {
        let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).unwrap();
        let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    wait_for("frames", || count_files(&dir.join("f"), "png") >= FRAMES);
    let peak = peak_kb() * 1024;
    interrupt(&child);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    let held = FRAMES * FRAME_BYTES;
    assert!(
        peak * 3 < held,
        "peak {peak} bytes after {FRAMES} frames: frames are being held ({held} bytes)"
    );
    let frames = count_files(&dir.join("f"), "png");
    // A frame every step of the chain's 2e-4 s.
    assert_eq!(gif_frames(&dir.join("a.gif")), shown(frames, 2e-4));
    let _ = std::fs::remove_dir_all(&dir);
}

/// An interrupted demo keeps the animation it was writing, ended at its last whole frame.
#[test]
fn an_interrupted_demo_keeps_its_animation_up_to_the_last_frame() {
    let dir = scratch("demo-gif");
    let watched = Watched::spawn(&["demo", "--out", "d", "--size", "160x120"], &dir);
    // The animation follows the hanging cloth's still; it is under way once its temporary
    // file holds a few frames.
    wait_for("the animation to be under way", || {
        dir.join("d/4-hanging-cloth.png").exists()
            && std::fs::read_dir(dir.join("d")).is_ok_and(|d| {
                d.flatten().any(|e| {
                    e.file_name().to_string_lossy().ends_with(".tmp")
                        && e.metadata().is_ok_and(|m| m.len() > 4096)
                })
            })
    });
    interrupt(&watched.child);
    let (status, said) = watched.finish();
    assert_eq!(status.code(), Some(130), "{said}");
    let frames = gif_frames(&dir.join("d/hanging-cloth.gif"));
    assert!(frames >= 1, "{frames} frames");
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    let _ = std::fs::remove_dir_all(&dir);
}
