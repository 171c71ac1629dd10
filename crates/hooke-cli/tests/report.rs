//! `hooke report` in a real browser: a quick report is written, then headless Chromium
//! loads the page from disk (no server, no network), every image on it must have loaded,
//! nothing may fail in the console, and screenshots are saved (a laptop-sized one in
//! light mode, a phone-sized one in dark mode) under `target/report-screenshots/` for a
//! person to look at. The numbers are checked in `report.json` too.
//!
//! Needs `chromium` (`cargo xtask test` installs it from Debian's packages). Without it the
//! test fails with what to install, unless `HOOKE_SKIP_BROWSER` is set.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn browser() -> Option<&'static str> {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|b| {
            Command::new("sh")
                .args(["-c", &format!("command -v {b}")])
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

fn target() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target")
}

/// Headless Chromium on `page` with `args`; a profile folder of its own, so runs do not
/// share state.
fn chromium(browser: &str, profile: &Path, page: &Path, args: &[&str]) -> Output {
    Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
            // Time enough for the page's images to load before the DOM is read; virtual
            // time, so a loaded machine waits longer instead of reading too early.
            "--virtual-time-budget=20000",
            &format!("--user-data-dir={}", profile.display()),
        ])
        .args(args)
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap()
}

#[test]
fn the_report_page_loads_in_chromium_with_every_image_and_no_console_error() {
    let Some(browser) = browser() else {
        assert!(
            std::env::var_os("HOOKE_SKIP_BROWSER").is_some(),
            "the report test needs Chromium: run the tests with `cargo xtask test`, which \
             installs it (apt-get install chromium), or set HOOKE_SKIP_BROWSER=1 to skip it"
        );
        eprintln!("skipped: HOOKE_SKIP_BROWSER is set and Chromium is not installed");
        return;
    };
    let dir = std::env::temp_dir().join(format!("hooke-report-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_hooke"))
        .args(["report", "--quick"])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "hooke report failed:\n{stderr}");
    assert!(stderr.contains("every check passed"), "{stderr}");

    // The numbers: fitted orders within 0.1, no failure listed.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["failures"].as_array().unwrap().len(), 0);
    let sweeps = json["convergence"].as_array().unwrap();
    assert_eq!(
        sweeps.len(),
        hooke_core::Integrator::ALL.len(),
        "one sweep per integrator"
    );
    for s in sweeps {
        let (slope, expected) = (
            s["slope"].as_f64().unwrap(),
            s["expected"].as_f64().unwrap(),
        );
        assert!(
            (slope - expected).abs() <= 0.1,
            "{}: slope {slope}, order {expected}",
            s["integrator"]
        );
    }

    let page = dir.join("index.html");
    let shots = target().join("report-screenshots");
    std::fs::create_dir_all(&shots).unwrap();
    let profile = dir.join("chromium-profile");
    let dom = chromium(browser, &profile, &page, &["--dump-dom"]);
    let html = String::from_utf8_lossy(&dom.stdout);
    let console = String::from_utf8_lossy(&dom.stderr);
    // The page's script writes how many images loaded: all of them, and there are many.
    let counted = html
        .split("data-images=\"")
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .unwrap_or_else(|| panic!("the page never finished loading:\n{console}"));
    let (loaded, all) = counted.split_once('/').unwrap();
    assert_eq!(loaded, all, "images loaded: {counted}\n{console}");
    assert!(
        all.parse::<usize>().unwrap() >= 15,
        "only {all} images on the page"
    );
    let errors: Vec<&str> = console
        .lines()
        .filter(|l| l.contains("CONSOLE") || l.contains("Uncaught") || l.contains("Failed to load"))
        .collect();
    assert!(
        errors.is_empty(),
        "the console says:\n{}",
        errors.join("\n")
    );
    for section in [
        "Convergence",
        "Closed forms",
        "Energy",
        "Scenes",
        "Jello worlds",
        "Determinism",
    ] {
        assert!(html.contains(section), "no section {section}");
    }
    assert!(html.contains("Every check passed"));

    // Screenshots to look at: a laptop in light mode, a phone in dark mode.
    for (name, size, extra) in [
        ("laptop-light.png", "1280,4000", None),
        ("phone-dark.png", "390,5000", Some("--force-dark-mode")),
    ] {
        let path = shots.join(name);
        let _ = std::fs::remove_file(&path);
        let mut args = vec![
            format!("--screenshot={}", path.display()),
            format!("--window-size={size}"),
        ];
        args.extend(extra.map(String::from));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let shot = chromium(browser, &profile, &page, &args);
        assert!(
            path.is_file(),
            "no screenshot {}:\n{}",
            path.display(),
            String::from_utf8_lossy(&shot.stderr)
        );
        let image = image::open(&path).unwrap().to_rgb8();
        // Not a blank page: the plots and stills give it many colours.
        let mut colours: Vec<[u8; 3]> = image.pixels().step_by(97).map(|p| p.0).collect();
        colours.sort_unstable();
        colours.dedup();
        assert!(
            colours.len() > 50,
            "{name} looks blank ({} colours)",
            colours.len()
        );
        eprintln!("screenshot: {}", path.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
