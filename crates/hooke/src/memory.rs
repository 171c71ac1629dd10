//! The memory a run may use: the least of what the machine has available now
//! (`MemAvailable` in `/proc/meminfo`), the process's address-space limit (`ulimit -v`) and
//! its control group's memory limit; or a budget set with `HOOKE_MAX_MEMORY` (bytes, or
//! with a `K`, `M` or `G` suffix). Scenes whose estimated footprint exceeds it are refused
//! before they are built.

use crate::error::{Result, bail_input};
use hooke_scene::footprint::Footprint;

/// The environment variable that sets the budget.
pub const BUDGET_VAR: &str = "HOOKE_MAX_MEMORY";

/// Parses `123`, `512K`, `300M`, `2.5G` (binary multiples) into bytes.
///
/// ```
/// use hooke::memory::parse_bytes;
/// assert_eq!(parse_bytes("2G"), Some(2 << 30));
/// assert_eq!(parse_bytes("1.5k"), Some(1536));
/// assert_eq!(parse_bytes("-1"), None);
/// ```
pub fn parse_bytes(text: &str) -> Option<u64> {
    let text = text.trim();
    let (number, unit) = match text.char_indices().last()? {
        (i, c) if c.is_ascii_alphabetic() => (&text[..i], c.to_ascii_uppercase()),
        _ => (text, 'B'),
    };
    let scale = match unit {
        'B' => 1u64,
        'K' => 1 << 10,
        'M' => 1 << 20,
        'G' => 1 << 30,
        'T' => 1 << 40,
        _ => return None,
    };
    let x: f64 = number.trim().parse().ok()?;
    (x.is_finite() && x >= 0.0 && x * (scale as f64) < u64::MAX as f64)
        .then_some((x * scale as f64) as u64)
}

/// Bytes the machine has available now (Linux), if known.
fn available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The soft address-space limit (`ulimit -v`), if one is set.
fn address_space_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

/// What the control group (cgroup v2) still allows, if it has a limit.
fn cgroup_room() -> Option<u64> {
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{name}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let max = read("memory.max")?;
    Some(max.saturating_sub(read("memory.current").unwrap_or(0)))
}

/// The least of the known limits, and which it is.
fn machine_budget() -> Option<(u64, &'static str)> {
    [
        available().map(|b| (b, "available memory")),
        address_space_limit().map(|b| (b, "address-space limit (ulimit -v)")),
        cgroup_room().map(|b| (b, "control group's memory limit")),
    ]
    .into_iter()
    .flatten()
    .min_by_key(|(b, _)| *b)
}

/// The budget and where it came from.
pub fn budget() -> Result<Option<(u64, &'static str)>> {
    match std::env::var(BUDGET_VAR) {
        Ok(text) => match parse_bytes(&text) {
            Some(b) => Ok(Some((b, BUDGET_VAR))),
            None => bail_input!(
                "{BUDGET_VAR}={text}: expected a number of bytes, optionally with K, M or G \
                 (such as 4G)"
            ),
        },
        Err(_) => Ok(machine_budget()),
    }
}

/// Bytes as people read them: `512 KB`, `3.4 MB`, `7.2 GB`.
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    match bytes {
        0..1024 => format!("{bytes} B"),
        1024..1_048_576 => format!("{:.0} KB", b / 1024.0),
        1_048_576..1_073_741_824 => format!("{:.1} MB", b / 1_048_576.0),
        _ => format!("{:.1} GB", b / 1_073_741_824.0),
    }
}

/// Refuses to read a scene file whose parsing alone would exceed the budget.
pub fn check_reading(path: &std::path::Path, need: u64) -> Result<()> {
    let Some((budget, source)) = budget()? else {
        return Ok(());
    };
    if need > budget {
        let len = std::fs::metadata(path).map_or(0, |m| m.len());
        bail_input!(
            "{}: reading this {} file would need about {}, more than the {} of {source}",
            path.display(),
            human(len),
            human(need),
            human(budget)
        );
    }
    Ok(())
}

/// Refuses a scene whose footprint exceeds the budget, naming what it would need and the
/// key to change.
pub fn check(name: &str, footprint: &Footprint) -> Result<()> {
    let Some((budget, source)) = budget()? else {
        return Ok(());
    };
    let need = footprint.bytes();
    if need <= budget {
        return Ok(());
    }
    let key = footprint
        .largest
        .as_ref()
        .map(|(k, b)| {
            let advice = if k.ends_with(".path") {
                "use a mesh with fewer vertices"
            } else if k.ends_with(".spacing") {
                "make the spacing larger"
            } else {
                "make it smaller"
            };
            format!("; most of it is {k} ({}): {advice}", human(*b))
        })
        .unwrap_or_default();
    bail_input!(
        "scene '{name}' would need about {} ({} particles, {} springs), more than the {} of \
         {source}{key}",
        human(need),
        count(footprint.particles),
        count(footprint.springs),
        human(budget)
    )
}

/// A count that may have saturated while it was estimated.
fn count(n: u64) -> String {
    if n == u64::MAX {
        format!("more than {:.1e}", u64::MAX as f64)
    } else {
        n.to_string()
    }
}
