//! `cargo xtask test`: the README's test command. It installs what the tests need when it is
//! missing — the viewer test's X server, key sender and X libraries as Debian packages
//! through `apt-get`; the pinned Python packages of `python/requirements-test.txt` into a
//! virtual environment, `target/python` — builds and installs the `hooke` Python package
//! there, runs `cargo test --workspace` with any further arguments passed through and
//! `HOOKE_PYTHON` naming that environment's Python, then the Python package's tests with
//! pytest; and the Blender extension's tests in `target/blender` with bpy from pip
//! (`blender/requirements-test.txt`).
//!
//! Plain `std`, no dependencies: it builds in a second, before anything else.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

/// A system requirement of the tests: what must exist, and the Debian package providing it.
struct Requirement {
    /// A program on the `PATH`, or an absolute path to a file.
    needs: &'static str,
    package: &'static str,
}

/// What the viewer test (`crates/hooke-cli/tests/viewer.rs`) needs: a virtual X server, a
/// key sender, and the X libraries the viewer loads at run time; and the browser the report
/// test (`crates/hooke-cli/tests/report.rs`) renders the report's page in.
const REQUIREMENTS: [Requirement; 5] = [
    Requirement {
        needs: "Xvfb",
        package: "xvfb",
    },
    Requirement {
        needs: "xdotool",
        package: "xdotool",
    },
    Requirement {
        needs: "/usr/lib/x86_64-linux-gnu/libX11.so.6",
        package: "libx11-6",
    },
    Requirement {
        needs: "/usr/lib/x86_64-linux-gnu/libXcursor.so.1",
        package: "libxcursor1",
    },
    Requirement {
        needs: "chromium",
        package: "chromium",
    },
];

const USAGE: &str = "usage: cargo xtask test [ARGS…]   set up what the tests need, then `cargo test --workspace ARGS…`
       cargo xtask setup           only install what the tests need";

/// The Python packages the tests need, pinned.
const REQUIREMENTS_TXT: &str = "python/requirements-test.txt";
/// What the Blender extension's tests need (bpy, which pins numpy below 2: an environment
/// of its own).
const BLENDER_REQUIREMENTS_TXT: &str = "blender/requirements-test.txt";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("test") => setup()
            .and_then(|()| python())
            .and_then(|python| test(&args[1..], &python)),
        Some("setup") => setup().and_then(|()| python()).map(|_| ExitCode::SUCCESS),
        Some("-h" | "--help") => {
            println!("{USAGE}");
            Ok(ExitCode::SUCCESS)
        }
        _ => Err(USAGE.to_string()),
    };
    result.unwrap_or_else(|e| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    })
}

/// Whether `needs` is present: an existing absolute path, or a program on the `PATH`.
fn present(needs: &str) -> bool {
    if needs.starts_with('/') {
        return Path::new(needs).exists();
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path).any(|dir| dir.join(needs).is_file())
}

/// Installs the Debian packages of the missing requirements, with `sudo` when not root.
fn setup() -> Result<(), String> {
    let missing: Vec<&str> = REQUIREMENTS
        .iter()
        .filter(|r| !present(r.needs))
        .map(|r| r.package)
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    if !present("apt-get") {
        return Err(format!(
            "the viewer and report tests need the packages {} and this machine has no \
             apt-get: install them with its package manager, or set HOOKE_SKIP_VIEWER=1 and \
             HOOKE_SKIP_BROWSER=1 to skip those tests",
            missing.join(" ")
        ));
    }
    eprintln!(
        "xtask: installing {} (Debian packages the viewer and report tests need)",
        missing.join(" ")
    );
    apt_install(&missing)
        .map_err(|e| format!("{e}; or set HOOKE_SKIP_VIEWER=1 and HOOKE_SKIP_BROWSER=1"))
}

/// Installs Debian `packages` with apt-get, through `sudo` when not root.
fn apt_install(packages: &[&str]) -> Result<(), String> {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    let apt = |args: &[&str]| {
        let mut command = if root {
            Command::new("apt-get")
        } else {
            let mut c = Command::new("sudo");
            c.arg("apt-get");
            c
        };
        let status = command
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .status()
            .map_err(|e| format!("cannot run apt-get: {e}"))?;
        if status.success() {
            Ok(())
        } else {
            Err(format!(
                "apt-get {} failed ({status}); install {} yourself",
                args[0],
                packages.join(" ")
            ))
        }
    };
    apt(&["update", "-qq"])?;
    let mut install = vec!["install", "-y", "-qq"];
    install.extend(packages);
    apt(&install)
}

/// The workspace root (this crate is `crates/xtask`).
fn root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    root.canonicalize().unwrap_or(root)
}

/// Runs `program args`, failing with `what` when it does not succeed.
fn run(program: &Path, args: &[&str], what: &str) -> Result<(), String> {
    let status = Command::new(program)
        .args(args)
        .status()
        .map_err(|e| format!("{what}: cannot run {}: {e}", program.display()))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!(
            "{what}: {} {} failed ({status})",
            program.display(),
            args.join(" ")
        ))
    }
}

/// The Python of the virtual environment `target/python`, created and given the pinned
/// packages of [`REQUIREMENTS_TXT`] unless it already has them.
fn python() -> Result<PathBuf, String> {
    environment("python", REQUIREMENTS_TXT)
}

/// The Python of the virtual environment `target/NAME`, created and given the pinned
/// packages of `requirements` (relative to the root) unless it already has them.
fn environment(name: &str, requirements: &str) -> Result<PathBuf, String> {
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root().join("target"), PathBuf::from);
    let env = target.join(name);
    let python = env.join("bin/python");
    let requirements_path = root().join(requirements);
    // A stamp of the requirements installed: pip is asked again only when they change.
    let stamp = env.join("hooke-requirements.txt");
    let wanted = std::fs::read_to_string(&requirements_path)
        .map_err(|e| format!("cannot read {}: {e}", requirements_path.display()))?;
    if python.exists() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == wanted) {
        return Ok(python);
    }
    if !python.exists() {
        if !present("python3") && present("apt-get") {
            eprintln!("xtask: installing python3 (Debian packages the Python tests need)");
            apt_install(&["python3", "python3-venv"])?;
        }
        if !present("python3") {
            return Err(
                "the Python tests and export checks need python3 (3.9 or newer): install it, or set \
                        HOOKE_SKIP_PYTHON=1 and run cargo test --workspace"
                    .into(),
            );
        }
        eprintln!("xtask: creating the Python environment {}", env.display());
        let env_text = env.to_string_lossy().into_owned();
        if run(
            Path::new("python3"),
            &["-m", "venv", &env_text],
            "python3 -m venv",
        )
        .is_err()
        {
            // Debian's Python keeps venv in a package of its own.
            if present("apt-get") {
                apt_install(&["python3-venv"])?;
            }
            run(
                Path::new("python3"),
                &["-m", "venv", &env_text],
                "python3 -m venv",
            )?;
        }
    }
    eprintln!("xtask: installing the tests' Python packages ({requirements})");
    let requirements_text = requirements_path.to_string_lossy().into_owned();
    run(
        &python,
        &[
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "-r",
            &requirements_text,
        ],
        "pip install",
    )?;
    std::fs::write(&stamp, wanted).map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    Ok(python)
}

/// Builds the `hooke` Python package (`python/`, maturin) and installs it into the
/// environment of `python`, whose `bin` holds maturin.
fn install_package(python: &Path) -> Result<(), String> {
    eprintln!("xtask: building and installing the hooke Python package (python/)");
    let bin = python.parent().unwrap_or(Path::new("."));
    let path = std::env::var_os("PATH").unwrap_or_default();
    let path = std::env::join_paths(
        std::iter::once(bin.to_path_buf()).chain(std::env::split_paths(&path)),
    )
    .map_err(|e| format!("PATH: {e}"))?;
    let status = Command::new(python)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(["--no-build-isolation", "--force-reinstall", "--no-deps"])
        .arg(root().join("python"))
        .env("PATH", path)
        .status()
        .map_err(|e| format!("cannot run pip: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("pip install ./python failed ({status})"))
    }
}

/// `cargo test --workspace --no-fail-fast` with `args`, with this cargo and `python` as
/// `HOOKE_PYTHON`; then, when no arguments narrowed the run, the Python package's tests with
/// pytest. Every suite runs even when an earlier one fails (a failing test binary does not
/// stop the others), and the failures are listed together at the end.
fn test(args: &[String], python: &Path) -> Result<ExitCode, String> {
    let mut failed: Vec<String> = Vec::new();
    let installed = install_package(python);
    if let Err(e) = &installed {
        failed.push(format!("building the Python package: {e}"));
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["test", "--workspace", "--no-fail-fast"])
        .args(args)
        .env("HOOKE_PYTHON", python)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        failed.push(format!(
            "cargo test --workspace ({status}): the failing tests and test binaries are listed \
             above"
        ));
    }
    if !args.is_empty() {
        eprintln!(
            "xtask: arguments given, so python/tests did not run (run them with no arguments)"
        );
    } else if installed.is_ok() {
        // The command the bit-for-bit tests compare with: the one cargo test just built.
        let target = std::env::var_os("CARGO_TARGET_DIR")
            .map_or_else(|| root().join("target"), PathBuf::from);
        let status = Command::new(python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            .arg(root().join("python/tests"))
            .env("HOOKE_BIN", target.join("debug/hooke"))
            .current_dir(root())
            .status()
            .map_err(|e| format!("cannot run pytest: {e}"))?;
        if !status.success() {
            failed.push(format!(
                "pytest python/tests ({status}): the failing tests are listed above"
            ));
        }
    }
    if args.is_empty()
        && let Err(e) = blender()
    {
        failed.push(e);
    }
    if failed.is_empty() {
        eprintln!("xtask: every test suite passed");
        return Ok(ExitCode::SUCCESS);
    }
    eprintln!("xtask: {} suite(s) failed:", failed.len());
    for f in &failed {
        eprintln!("  - {f}");
    }
    Ok(ExitCode::FAILURE)
}

/// The Blender extension's tests (`blender/tests`, pytest with bpy from pip, in the
/// environment `target/blender`), driving a release build of hooke: a bake runs it twice
/// per scene, which a debug build takes minutes for. `HOOKE_SKIP_BLENDER=1` skips them.
fn blender() -> Result<(), String> {
    if std::env::var_os("HOOKE_SKIP_BLENDER").is_some() {
        eprintln!("xtask: HOOKE_SKIP_BLENDER is set, so blender/tests did not run");
        return Ok(());
    }
    let python = environment("blender", BLENDER_REQUIREMENTS_TXT)
        .map_err(|e| format!("setting up the Blender tests: {e}; or set HOOKE_SKIP_BLENDER=1"))?;
    eprintln!("xtask: building hooke (release) for the Blender tests");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--release", "-p", "hooke-cli"])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build --release -p hooke-cli ({status})"));
    }
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root().join("target"), PathBuf::from);
    let status = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root().join("blender/tests"))
        .env("HOOKE_BIN", target.join("release/hooke"))
        .current_dir(root())
        .status()
        .map_err(|e| format!("cannot run pytest: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!(
            "pytest blender/tests ({status}): the failing tests are listed above"
        ))
    }
}
