//! What a large step's solve leaves unsolved, said to the user: the steps that ended at
//! their iteration budget, counted at a run's end, and a run whose energy grew because its
//! steps were not solved, stopped with advice that solves them further.

mod common;

use common::*;
/// A large-step run whose steps end at the solver's budget says how many and which came
/// first, at its end: every one of a hanging cloth's steps with a budget of one sweep, none
/// with a budget its steps never reach, and never for an explicit integrator, which has no
/// budget.
#[test]
fn a_run_says_how_many_steps_ended_at_the_solvers_budget() {
    let dir = scratch("unsolved");
    let run = |extra: &[&str]| {
        let mut args = vec!["run", "hanging-cloth", "--steps", "12"];
        args.extend_from_slice(extra);
        let out = hooke(&args, &dir);
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
        stderr(&out)
    };
    let vbd = ["--integrator", "vbd", "--dt", "0.016666666666666666"];
    let starved = run(&[&vbd[..], &["--iterations", "1"]].concat());
    assert!(
        starved.contains("note: vbd ended 12 of 12 steps at its budget of 1 iteration ")
            && starved.contains("the first at step 1 ")
            && starved.contains("--iterations"),
        "{starved}"
    );
    let fed = run(&[&vbd[..], &["--iterations", "5000", "--tolerance", "0.5"]].concat());
    assert!(!fed.contains("budget"), "{fed}");
    let explicit = run(&["--integrator", "symplectic"]);
    assert!(!explicit.contains("note:"), "{explicit}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 1 m cotton sheet of 32 × 32 pinned along one edge, swinging down from level: under
/// block descent at 1/60 s and its defaults, the unsolved steps gain energy and the run
/// stops; the error names the step's budget and tolerance and how to solve further, and
/// with that advice taken (a tolerance of 1 mm/s, 400 iterations) the same scene runs to
/// its end.
#[test]
fn a_run_whose_unsolved_steps_gain_energy_says_how_to_solve_them() {
    let dir = scratch("unsolved-energy");
    let pins: Vec<String> = (0..32).map(|i| i.to_string()).collect();
    std::fs::write(
        dir.join("sheet.toml"),
        format!(
            "name = \"sheet\"\n[simulation]\nintegrator = \"vbd\"\n\
             dt = 0.016666666666666666\nduration = 1.0\nevery = 60\n\
             gravity = [0.0, -9.81, 0.0]\n[[body]]\nname = \"sheet\"\n\
             origin = [0.0, 2.0, 0.0]\npins = [{}]\nthickness = 0.005\n\
             self_collision = false\n\
             shape = {{ kind = \"grid\", size = [32, 32], spacing = {} }}\n\
             material = {{ preset = \"cotton\" }}\n",
            pins.join(", "),
            1.0 / 31.0
        ),
    )
    .unwrap();
    let out = hooke(&["run", "sheet.toml"], &dir);
    let said = stderr(&out);
    assert!(!out.status.success(), "{said}");
    assert!(
        said.contains("diverged at step")
            && said.contains("the vbd step ended at its budget of 24 iterations")
            && said.contains("can gain energy")
            && said.contains("--tolerance")
            && said.contains("--integrator newton"),
        "{said}"
    );
    let out = hooke(
        &[
            "run",
            "sheet.toml",
            "--tolerance",
            "0.001",
            "--iterations",
            "400",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let check = hooke(&["check", "sheet.toml"], &dir);
    let said = String::from_utf8_lossy(&check.stdout);
    assert!(
        said.contains("vbd does not guarantee: a solved step, and so stability")
            && !said.contains("vbd guarantees: stability"),
        "{said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
