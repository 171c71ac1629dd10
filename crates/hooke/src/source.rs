//! Turning a SCENE argument (built-in name, `.toml` scene or `.w` world) into a scene.

use crate::error::{Context, Result, bail_input};
use hooke_scene::builtin::BUILTINS;
use hooke_scene::{BuildError, Overrides, Scene, SceneSpec, TableOverride};
use std::path::{Path, PathBuf};

/// Where a scene came from.
pub struct Source {
    /// The description.
    pub spec: SceneSpec,
    /// Folder that relative paths inside it are resolved against.
    pub base: PathBuf,
    /// The scene file or world it was read from; `None` for a built-in.
    pub file: Option<PathBuf>,
}

impl Source {
    /// The files the scene is built from, each with what to call it in a message: the scene
    /// file or world, and the mesh files it names (after any `--table`).
    pub fn inputs(&self) -> Vec<(String, PathBuf)> {
        let mut files: Vec<(String, PathBuf)> = self
            .file
            .iter()
            .map(|f| ("the scene file".to_string(), f.clone()))
            .collect();
        files.extend(
            self.spec
                .input_files(&self.base)
                .into_iter()
                .map(|(key, path)| (format!("the mesh of {key}"), path)),
        );
        files
    }
}

/// Reads the scene named by `arg`.
pub fn read(arg: &str) -> Result<Source> {
    let path = Path::new(arg);
    // A folder named like a built-in (`mkdir chain`) does not hide the built-in.
    if path.is_dir() && hooke_scene::builtin::builtin(arg).is_none() {
        bail_input!(
            "{arg} is a folder; expected a built-in scene name, a .toml scene or a .w world"
        );
    }
    let is_file = path.extension().is_some_and(|e| e == "toml" || e == "w") || path.is_file();
    if !is_file {
        let spec = hooke_scene::builtin::builtin(arg).with_context(|| {
            let names: Vec<&str> = BUILTINS.iter().map(|b| b.0).collect();
            format!(
                "no built-in scene '{arg}' and no such file; built-in scenes: {}",
                names.join(", ")
            )
        })?;
        return Ok(Source {
            spec,
            base: PathBuf::from("."),
            file: None,
        });
    }
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if let Ok(meta) = std::fs::metadata(path) {
        let need = hooke_scene::footprint::reading_bytes(extension, meta.len());
        crate::memory::check_reading(path, need)?;
    }
    let spec = match path.extension().and_then(|e| e.to_str()) {
        Some("w") => hooke_scene::world::load_world(path)?
            .to_scene(&stem(path))
            .with_context(|| format!("{}", path.display()))?,
        Some("toml") => hooke_scene::load_scene(path)?,
        _ => bail_input!(
            "{}: expected a scene file ending in .toml or a jello world ending in .w",
            path.display()
        ),
    };
    Ok(Source {
        spec,
        base,
        file: Some(path.to_path_buf()),
    })
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "world".into(), |s| s.to_string_lossy().into_owned())
}

/// `--table VALUE` as the scene crate's [`TableOverride`]: `cylinder`, `builtin:NAME`, or
/// an OBJ file relative to the current folder (made absolute here, since the scene crate
/// resolves mesh paths against the scene file's folder).
pub fn table(value: &str) -> Result<TableOverride> {
    if value == "cylinder" {
        return Ok(TableOverride::Cylinder);
    }
    if value.starts_with("builtin:") {
        return Ok(TableOverride::Mesh(value.to_string()));
    }
    let path = Path::new(value);
    if path.is_dir() {
        bail_input!(
            "--table {value}: is a folder; expected an OBJ mesh file, builtin:NAME or `cylinder`"
        );
    }
    if !path.is_file() {
        bail_input!(
            "--table {value}: no such file (expected an OBJ mesh, builtin:NAME or `cylinder`)"
        );
    }
    let full = std::env::current_dir()?.join(path);
    Ok(TableOverride::Mesh(full.to_string_lossy().into_owned()))
}

/// Builds larger than this show a spinner (on a terminal) or say that they take a while.
const ANNOUNCE_BYTES: u64 = 256 << 20;

/// Reads and builds the scene named by `arg` with command-line overrides. A scene whose
/// estimated memory exceeds the budget ([`crate::memory`]) is refused before it is built.
pub fn build(arg: &str, overrides: &Overrides) -> Result<Scene> {
    build_from(read(arg)?, arg, overrides)
}

/// [`build`] for a scene already read (and perhaps edited) from `arg`.
pub fn build_from(source: Source, arg: &str, overrides: &Overrides) -> Result<Scene> {
    build_prepared(prepare(source, arg, overrides)?, arg)
}

/// A scene read from `arg` with the command line's overrides applied: what
/// [`build_prepared`] builds, and whose [`Source::inputs`] a run checks its outputs against.
pub fn prepare(mut source: Source, arg: &str, overrides: &Overrides) -> Result<Source> {
    // The overrides come from the command line: name its options, not the scene's keys.
    overrides.apply(&mut source.spec).map_err(|e| {
        let e = match e {
            BuildError::Invalid { key, message } => BuildError::Invalid {
                key: match key.as_str() {
                    "simulation.dt" => "--dt".into(),
                    "simulation.duration" => "--duration".into(),
                    "simulation.tolerance" => "--tolerance".into(),
                    "table" => "--table".into(),
                    _ => key,
                },
                message,
            },
            other => other,
        };
        crate::Error::from(e).context(format!("scene '{arg}'"))
    })?;
    Ok(source)
}

/// Builds a scene [`prepare`]d from `arg`. A scene whose estimated memory exceeds the budget
/// ([`crate::memory`]) is refused before it is built.
pub fn build_prepared(source: Source, arg: &str) -> Result<Scene> {
    let footprint = source.spec.footprint(&source.base);
    crate::memory::check(arg, &footprint)?;
    let large = footprint.bytes() >= ANNOUNCE_BYTES;
    let spinner = if large {
        crate::progress::reporter().build(&format!(
            "building scene '{arg}': {} particles, {} springs, about {}",
            footprint.particles,
            footprint.springs,
            crate::memory::human(footprint.bytes())
        ))
    } else {
        Box::new(crate::progress::Hidden)
    };
    let mut scene = source
        .spec
        .build(&source.base)
        .with_context(|| format!("scene '{arg}'"));
    spinner.finish();
    if let Ok(scene) = &mut scene {
        // A large step under way ends at an interrupt, so that Ctrl-C is answered within a
        // fraction of a second whatever its tolerance (the driver then stops at the last
        // complete frame).
        scene.simulation.set_cancel(crate::interrupt::requested);
    }
    if let Ok(scene) = &scene {
        for warning in scene.warnings() {
            eprintln!("warning: scene '{arg}': {warning}");
        }
    }
    scene
}
