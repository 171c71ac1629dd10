//! What the report compares against: the golden stills (`golden/<name>.png`), the worlds'
//! locked trajectories (`tests/snapshots/validation__worlds__world_<name>.snap`) and the
//! course worlds themselves (`assets/worlds/<name>.w`). They belong to the repository, where
//! the validation suite updates them, so the report reads them from a clone at run time
//! (a packaged crate carries no file from outside its folder): from `HOOKE_REPOSITORY`
//! when set, otherwise from the clone this library was built in, or from the current
//! folder or one above it.

use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// The course worlds the report runs.
pub(crate) const WORLDS: [&str; 5] = ["jello", "gravity", "moveLeft", "rotate", "skewedCorner"];

/// The environment variable naming the clone to read the references from.
pub(crate) const REPOSITORY_VAR: &str = "HOOKE_REPOSITORY";

/// A folder holding every reference the report needs.
pub(crate) struct References {
    root: PathBuf,
}

/// The files of a clone the report reads, relative to its root.
fn needed(scenes: &[&str]) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = scenes.iter().map(|s| golden_path(s)).collect();
    for w in WORLDS {
        out.push(snapshot_path(w));
        out.push(world_path(w));
    }
    out
}

fn golden_path(scene: &str) -> PathBuf {
    Path::new("golden").join(format!("{scene}.png"))
}

fn snapshot_path(world: &str) -> PathBuf {
    Path::new("tests/snapshots").join(format!("validation__worlds__world_{world}.snap"))
}

fn world_path(world: &str) -> PathBuf {
    Path::new("assets/worlds").join(format!("{world}.w"))
}

impl References {
    /// The first place holding every reference for `scenes`, or an error naming what was
    /// looked for, where, and how to point the report at a clone.
    pub(crate) fn find(scenes: &[&str]) -> Result<Self> {
        let candidates: Vec<PathBuf> = match std::env::var_os(REPOSITORY_VAR) {
            Some(dir) => vec![PathBuf::from(dir)],
            None => {
                let built_in = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
                let here = std::env::current_dir().unwrap_or_default();
                std::iter::once(built_in)
                    .chain(here.ancestors().map(Path::to_path_buf))
                    .collect()
            }
        };
        let files = needed(scenes);
        let missing_in = |root: &Path| files.iter().find(|f| !root.join(f).is_file()).cloned();
        let mut tried = Vec::new();
        for root in candidates {
            match missing_in(&root) {
                None => return Ok(Self { root }),
                Some(file) => tried.push(format!("{} (no {})", root.display(), file.display())),
            }
        }
        Err(Error::input(format!(
            "hooke report compares with the references of a Hooke clone (golden/, \
             tests/snapshots/ and assets/worlds/) and found them in none of: {}; run it inside \
             a clone of the repository, or set {REPOSITORY_VAR} to one",
            tried.join(", ")
        )))
    }

    fn read(&self, file: &Path) -> Result<Vec<u8>> {
        let path = self.root.join(file);
        std::fs::read(&path).map_err(|e| {
            Error::from(e).context(format!(
                "report: cannot read the reference {}",
                path.display()
            ))
        })
    }

    fn text(&self, file: &Path) -> Result<String> {
        let path = self.root.join(file);
        String::from_utf8(self.read(file)?)
            .map_err(|_| Error::input(format!("{}: expected UTF-8 text", path.display())))
    }

    /// Scene `scene`'s golden still, PNG bytes.
    pub(crate) fn golden(&self, scene: &str) -> Result<Vec<u8>> {
        self.read(&golden_path(scene))
    }

    /// World `world`'s locked trajectory (an insta snapshot).
    pub(crate) fn snapshot(&self, world: &str) -> Result<String> {
        self.text(&snapshot_path(world))
    }

    /// World `world`'s `.w` text.
    pub(crate) fn world(&self, world: &str) -> Result<String> {
        self.text(&world_path(world))
    }
}
