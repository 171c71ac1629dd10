//! `hooke bench scene --json` as scripts read it: block descent's time split into parts that
//! sum to the whole, and the self-contact pair list's builds counted.

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
