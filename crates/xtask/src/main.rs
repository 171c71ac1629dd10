//! `cargo xtask test`: the README's test command. It installs the system packages the tests
//! need when they are missing (the viewer test's X server, key sender and X libraries, as
//! Debian packages through `apt-get`), then runs `cargo test --workspace` with any further
//! arguments passed through.
//!
//! Plain `std`, no dependencies: it builds in a second, before anything else.

use std::path::Path;
use std::process::{Command, ExitCode};

/// A system requirement of the tests: what must exist, and the Debian package providing it.
struct Requirement {
    /// A program on the `PATH`, or an absolute path to a file.
    needs: &'static str,
    package: &'static str,
}

/// What the viewer test (`crates/hooke-cli/tests/viewer.rs`) needs: a virtual X server, a
/// key sender, and the X libraries the viewer loads at run time.
const REQUIREMENTS: [Requirement; 4] = [
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
];

const USAGE: &str = "usage: cargo xtask test [ARGS…]   set up what the tests need, then `cargo test --workspace ARGS…`
       cargo xtask setup           only install the missing system packages";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("test") => setup().and_then(|()| test(&args[1..])),
        Some("setup") => setup().map(|()| ExitCode::SUCCESS),
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
            "the viewer test needs the packages {} and this machine has no apt-get: install \
             them with its package manager, or set HOOKE_SKIP_VIEWER=1 to skip that one test",
            missing.join(" ")
        ));
    }
    eprintln!(
        "xtask: installing {} (Debian packages the viewer test needs)",
        missing.join(" ")
    );
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
                "apt-get {} failed ({status}); install {} yourself, or set HOOKE_SKIP_VIEWER=1",
                args[0],
                missing.join(" ")
            ))
        }
    };
    apt(&["update", "-qq"])?;
    let mut install = vec!["install", "-y", "-qq"];
    install.extend(&missing);
    apt(&install)
}

/// `cargo test --workspace` with `args`, with this cargo.
fn test(args: &[String]) -> Result<ExitCode, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["test", "--workspace"])
        .args(args)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    Ok(match status.code() {
        Some(0) => ExitCode::SUCCESS,
        Some(code) => ExitCode::from(u8::try_from(code).unwrap_or(1)),
        None => ExitCode::FAILURE,
    })
}
