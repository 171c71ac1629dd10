//! The report's folder, which the report must know to be its own before it writes there.
//!
//! * **Whose it is.** A folder is a report's when it holds the marker `.hooke-report` (a
//!   plain file saying so, written before any of the report's files), or, from reports
//!   written before the marker, a `report.json` whose content is a report's. A new or empty
//!   folder is taken. Anything else is the user's and is refused, whatever its file names.
//! * **Every name checked first.** Each name the report will write is looked at before the
//!   first check runs (see [`crate::output::named`]): a link, a folder or a device there
//!   refuses the report at once, not after minutes of checks.
//! * **All or the earlier report.** The pictures, plots, `report.json` and the page are
//!   kept in memory while the checks run and written only at the end, each renamed into
//!   place, the page last. An interrupted report leaves the earlier report (or nothing), and
//!   the same command runs again into the same folder.

use crate::Result;
use crate::error::bail_output;
use crate::output::{check_named, named, write_named};
use std::io::Read;
use std::path::Path;

/// The file that says a folder is a report's.
pub(crate) const MARKER: &str = ".hooke-report";

/// What the marker holds.
const MARKER_TEXT: &str = "hooke report: this folder is written by `hooke report`\n";

/// The option named in messages.
const FLAG: &str = "report";

/// The page.
pub(crate) const PAGE: &str = "index.html";

/// Every number of the report.
pub(crate) const JSON: &str = "report.json";

/// The plots of the convergence section.
pub(crate) const CONVERGENCE: &str = "convergence.svg";

/// The plot of the stability section.
pub(crate) const STABILITY: &str = "stability.svg";

/// The energy plot of built-in scene `name`.
pub(crate) fn energy_file(name: &str) -> String {
    format!("energy-{name}.svg")
}

/// Scene `name`'s picture of `kind` (`still`, `golden`, `diff`, `strain`).
pub(crate) fn scene_file(name: &str, kind: &str) -> String {
    format!("scene-{name}-{kind}.png")
}

/// The drape test's view from above of preset `name`.
pub(crate) fn drape_file(name: &str) -> String {
    format!("drape-{name}.png")
}

/// The drape test's plot of DC against the overhang.
pub(crate) const DRAPE_SWEEP: &str = "drape-sweep.svg";

/// Every name a report of the built-in `scenes` writes into its folder, the marker first.
fn names(scenes: &[&str]) -> Vec<String> {
    let mut out = vec![
        MARKER.to_string(),
        PAGE.into(),
        JSON.into(),
        CONVERGENCE.into(),
        STABILITY.into(),
    ];
    out.extend(
        hooke_scene::builtin::BUILTINS
            .iter()
            .map(|(n, _)| energy_file(n)),
    );
    for name in scenes {
        out.extend(["still", "golden", "diff", "strain"].map(|k| scene_file(name, k)));
    }
    out.extend(
        hooke_scene::material::PRESETS
            .iter()
            .map(|p| drape_file(p.name)),
    );
    out.push(DRAPE_SWEEP.into());
    out
}

/// The files of a report being made, held until [`Pending::commit`].
#[derive(Default)]
pub(crate) struct Pending {
    files: Vec<(String, Vec<u8>)>,
}

impl Pending {
    /// Keeps file `name` to be written with the rest.
    pub(crate) fn add(&mut self, name: impl Into<String>, bytes: impl Into<Vec<u8>>) {
        self.files.push((name.into(), bytes.into()));
    }

    /// Writes every file into `dir`: the marker first (so that a folder holding any of the
    /// report's files is known for a report's), the page last. When a write fails (a full
    /// disk) in a folder that held no earlier report, what this commit wrote is removed
    /// again, the marker last: a failed new report leaves no half of itself.
    pub(crate) fn commit(self, dir: &Path, scenes: &[&str]) -> Result<()> {
        let allowed = names(scenes);
        let fresh = !is_report(dir);
        let mut written: Vec<String> = Vec::new();
        let mut write = |name: &str, bytes: &[u8]| {
            write_named(&dir.join(name), FLAG, bytes)?;
            written.push(name.to_string());
            Ok::<(), crate::Error>(())
        };
        let result = write(MARKER, MARKER_TEXT.as_bytes()).and_then(|()| {
            for (name, bytes) in &self.in_order() {
                debug_assert!(allowed.contains(name), "{name} was not checked beforehand");
                write(name, bytes)?;
            }
            Ok(())
        });
        if result.is_err() && fresh {
            for name in written.iter().rev() {
                let _ = std::fs::remove_file(dir.join(name));
            }
        }
        result
    }
}

impl Pending {
    /// The files in the order they are written: pictures and plots, then `report.json`,
    /// then the page, so that the page never shows numbers its files do not hold.
    fn in_order(mut self) -> Vec<(String, Vec<u8>)> {
        self.files
            .sort_by_key(|(n, _)| (n == JSON || n == PAGE, n == PAGE));
        self.files
    }
}

/// Refuses `dir` unless it is new, empty (but for hooke's own hidden files) or an earlier
/// report's, or when any name a report of `scenes` writes there holds something the report
/// may not replace; before any check runs.
pub(crate) fn check(dir: &Path, scenes: &[&str]) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let others: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with(".hooke-"))
        .collect();
    if !others.is_empty() && !is_report(dir) {
        let mut shown: Vec<&str> = others.iter().map(String::as_str).collect();
        shown.sort_unstable();
        shown.truncate(3);
        bail_output!(
            "{FLAG} {}: the folder holds other files ({}{}) and is not an earlier report's; \
             choose a new or empty folder, or an earlier report's",
            dir.display(),
            shown.join(", "),
            if others.len() > 3 { ", …" } else { "" }
        );
    }
    for name in names(scenes) {
        check_named(&dir.join(name), FLAG)?;
    }
    Ok(())
}

/// Whether `dir` holds an earlier report: its marker, or a `report.json` that reads as one.
fn is_report(dir: &Path) -> bool {
    let read = |name: &str| -> Option<String> {
        // Opened without following a link, and only a plain file of this user's.
        let mut file = named::open_existing(&dir.join(name), FLAG).ok()?;
        let mut text = String::new();
        (&mut file).take(1 << 24).read_to_string(&mut text).ok()?;
        Some(text)
    };
    if read(MARKER).is_some_and(|t| t == MARKER_TEXT) {
        return true;
    }
    read(JSON)
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| {
            [
                "hooke_version",
                "convergence",
                "scenes",
                "worlds",
                "failures",
            ]
            .iter()
            .all(|k| v.get(k).is_some())
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresh(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hooke-rf-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_user_page_and_a_report_json_of_theirs_are_not_taken_for_a_report() {
        let dir = fresh("user");
        std::fs::write(dir.join("index.html"), "<p>mine</p>").unwrap();
        std::fs::write(dir.join("report.json"), "{\"sales\": 3}").unwrap();
        let e = check(&dir, &["chain"]).unwrap_err().to_string();
        assert!(e.contains("not an earlier report's"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_marked_folder_is_a_report_and_its_names_are_checked() {
        let dir = fresh("marked");
        std::fs::write(dir.join(MARKER), MARKER_TEXT).unwrap();
        std::fs::write(dir.join(scene_file("chain", "still")), "old").unwrap();
        check(&dir, &["chain"]).unwrap();
        // A forged marker that says something else is not the marker.
        std::fs::write(dir.join(MARKER), "mine").unwrap();
        assert!(check(&dir, &["chain"]).is_err());
        std::fs::write(dir.join(MARKER), MARKER_TEXT).unwrap();
        // A page that is a folder is refused before anything runs.
        std::fs::create_dir(dir.join(PAGE)).unwrap();
        let e = check(&dir, &["chain"]).unwrap_err().to_string();
        assert!(e.contains("index.html") && e.contains("a folder"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn files_are_written_marker_first_and_page_last() {
        let dir = fresh("commit");
        let mut p = Pending::default();
        p.add(PAGE, "page");
        p.add(JSON, "{}");
        p.add(CONVERGENCE, "svg");
        p.add(STABILITY, "svg");
        let order: Vec<String> = Pending {
            files: p.files.clone(),
        }
        .in_order()
        .into_iter()
        .map(|(n, _)| n)
        .collect();
        assert_eq!(order, [CONVERGENCE, STABILITY, JSON, PAGE]);
        p.commit(&dir, &["chain"]).unwrap();
        assert!(is_report(&dir));
        assert_eq!(std::fs::read_to_string(dir.join(PAGE)).unwrap(), "page");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Issue 54: a new report whose last write fails (here the page's name is taken by a
    /// folder; on a full disk, any write) leaves no marker or picture behind.
    #[test]
    fn a_failed_new_report_takes_back_what_it_wrote() {
        let dir = fresh("failed");
        std::fs::create_dir(dir.join(PAGE)).unwrap();
        let mut p = Pending::default();
        p.add(PAGE, "page");
        p.add(JSON, "{}");
        p.add(scene_file("chain", "still"), "png");
        assert!(p.commit(&dir, &["chain"]).is_err());
        let mut left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [PAGE], "left behind: {left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
