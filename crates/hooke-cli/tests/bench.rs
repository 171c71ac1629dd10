//! `hooke bench` as scripts read it: the cloth workload's figures, a large step timed from
//! its start with how well it solved, block descent's time split into parts that sum to the
//! whole, and the self-contact pair list's builds counted.

mod common;

use common::*;

/// Issue 55: `hooke bench scene --json` says, for block descent, iterations and detections
/// per step, the final update's speed (median and largest), the steps at the budget, and
/// where the wall time went, in parts that sum to the whole.
#[test]
fn a_block_descent_bench_splits_its_time_into_parts_that_sum_to_the_whole() {
    let dir = scratch("bench-split");
    let out = hooke(
        &[
            "bench",
            "scene",
            "chain",
            "--integrator",
            "vbd",
            "--dt",
            "0.016666666666666666",
            "--steps",
            "20",
            "--tolerance",
            "0.02",
            "--json",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let figures: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "vbd_iterations_per_step",
        "vbd_detections_per_step",
        "median_final_speed",
        "largest_final_speed",
        "capped_steps",
    ] {
        assert!(figures[key].is_number(), "{key}: {figures}");
    }
    assert_eq!(figures["tolerance"], 0.02);
    let split = &figures["time_split"];
    let parts: f64 = [
        "detection",
        "sweeps",
        "coarse_correction",
        "acceleration",
        "rest",
    ]
    .iter()
    .map(|k| split[k].as_f64().unwrap())
    .sum();
    let seconds = figures["seconds"].as_f64().unwrap();
    assert!(
        (parts - seconds).abs() <= 1e-9 * seconds,
        "{parts} vs {seconds}"
    );
    // The per-sweep and per-detection figures are the split's parts over the counts.
    let steps = figures["steps"].as_f64().unwrap();
    let free = figures["free_particles"].as_f64().unwrap();
    let iterations = figures["vbd_iterations_per_step"].as_f64().unwrap() * steps;
    let detections = figures["vbd_detections_per_step"].as_f64().unwrap() * steps;
    let sweep = split["sweep_ns_per_particle"].as_f64().unwrap();
    let detection = split["detection_ms"].as_f64().unwrap();
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs().max(1e-12);
    assert!(
        near(
            sweep,
            1e9 * split["sweeps"].as_f64().unwrap() / (iterations * free)
        ),
        "{split}"
    );
    assert!(
        near(
            detection,
            1e3 * split["detection"].as_f64().unwrap() / detections
        ),
        "{split}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `hooke bench scene --json` counts block descent's self-contact pair-list builds: a cloth
/// builds its list at its first detection and at most once per detection after, and the
/// builds' time is a part of the detection's; a chain, with no surface, builds none.
#[test]
fn a_block_descent_bench_counts_its_pair_list_builds() {
    let dir = scratch("bench-builds");
    let bench = |scene: &str| -> serde_json::Value {
        let out = hooke(
            &[
                "bench",
                "scene",
                scene,
                "--integrator",
                "vbd",
                "--dt",
                "0.016666666666666666",
                "--steps",
                "10",
                "--json",
            ],
            &dir,
        );
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let flag = bench("flag");
    let split = &flag["time_split"];
    let steps = flag["steps"].as_f64().unwrap();
    let builds = split["pair_list_builds_per_step"].as_f64().unwrap() * steps;
    let detections = flag["vbd_detections_per_step"].as_f64().unwrap() * steps;
    assert!(builds >= 1.0 && builds <= detections, "{flag}");
    assert!((builds - builds.round()).abs() < 1e-9, "{flag}");
    let building = split["pair_list_building"].as_f64().unwrap();
    assert!(
        building > 0.0 && building <= split["detection"].as_f64().unwrap(),
        "{flag}"
    );
    let chain = bench("chain");
    assert_eq!(chain["time_split"]["pair_list_builds_per_step"], 0.0);
    assert_eq!(chain["time_split"]["pair_list_building"], 0.0);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `hooke bench cloth --json` prints the workload's figures as one object. Its centre
/// particle, far from the pins with every spring at rest, falls as a free particle does
/// under symplectic Euler, `g dt² n(n+1)/2` after `n` steps.
#[test]
fn bench_cloth_prints_the_workload_figures_as_json() {
    let dir = scratch("bench");
    let out = hooke(
        &["bench", "cloth", "--n", "16", "--threads", "2", "--json"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let figures: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    let number = |key: &str| {
        figures[key]
            .as_f64()
            .unwrap_or_else(|| panic!("no number '{key}' in {text}"))
    };
    assert_eq!(number("n"), 16.0);
    assert_eq!(number("steps"), 200.0);
    assert_eq!(number("threads"), 2.0);
    // 2N(N-1) + 2(N-1)² + 2N(N-2) springs.
    assert_eq!(
        number("springs"),
        (2 * 16 * 15 + 2 * 15 * 15 + 2 * 16 * 14) as f64
    );
    let seconds = number("seconds");
    let rate = number("spring_updates_per_s");
    assert!((rate * seconds / (number("springs") * 200.0) - 1.0).abs() < 1e-9);
    assert!((number("steps_per_s") * seconds / 200.0 - 1.0).abs() < 1e-9);
    assert!(number("fastest_step_s") <= number("median_step_s"));
    assert!(number("median_step_s") <= seconds);
    let drop = 1.0 - number("center_y");
    let free_fall = 9.81 * 1e-5 * 1e-5 * (200.0 * 201.0 / 2.0);
    assert!(
        (drop / free_fall - 1.0).abs() < 1e-6,
        "centre fell {drop:e} m, a free particle {free_fall:e} m"
    );
}

#[test]
fn bench_scene_times_a_large_step_run_from_its_start_and_says_how_well_it_solved() {
    let dir = scratch("bench-scene");
    let json = |args: &[&str]| -> serde_json::Value {
        let out = hooke(args, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_str(String::from_utf8_lossy(&out.stdout).trim()).unwrap()
    };
    // Block descent at a display frame, for the scene's whole run: 0.2 s is 12 steps.
    let mut scene = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    scene
        .set("simulation.duration", toml::Value::Float(0.2))
        .unwrap();
    scene
        .set("simulation.integrator", toml::Value::String("vbd".into()))
        .unwrap();
    scene
        .set("simulation.dt", toml::Value::Float(1.0 / 60.0))
        .unwrap();
    std::fs::write(dir.join("short.toml"), hooke_scene::to_toml(&scene)).unwrap();
    let f = json(&[
        "bench",
        "scene",
        "short.toml",
        "--threads",
        "2",
        "--residual",
        "--json",
    ]);
    assert_eq!(f["from_start"], true, "{f}");
    assert_eq!(f["steps"], 12, "{f}");
    let iterations = f["iterations_per_step"].as_f64().unwrap();
    let cap = hooke_core::Integrator::Vbd.iteration_cap().unwrap() as f64;
    assert!((1.0..=cap).contains(&iterations), "{f}");
    let capped = f["capped_steps"].as_u64().unwrap();
    assert!(capped <= 12, "{f}");
    // Uncapped steps met the stopping rule in fewer sweeps than the cap.
    if capped == 0 {
        assert!(iterations < cap, "{f}");
    }
    let residual = f["max_residual"].as_f64().unwrap();
    assert!(residual.is_finite() && residual >= 0.0, "{f}");
    // The process's peak memory: at least the particles' positions and velocities, less
    // than a cloth this size could need.
    if cfg!(target_os = "linux") {
        let mib = f["peak_resident_mib"].as_f64().unwrap();
        assert!((1.0..2048.0).contains(&mib), "{f}");
    }
    // An explicit scheme is timed after its warm-up and has no solver to cap.
    let f = json(&[
        "bench",
        "scene",
        "chain",
        "--steps",
        "50",
        "--threads",
        "1",
        "--json",
    ]);
    assert_eq!(f["from_start"], false, "{f}");
    assert_eq!(f["capped_steps"], 0, "{f}");
    // The residual is measured only when asked for (it costs a pass per step).
    assert!(f["max_residual"].is_null(), "{f}");
}
