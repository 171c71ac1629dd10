//! Reading triangle meshes from Wavefront OBJ text with `tobj`, and placing them in the world.

use hooke_core::{SANE_BOUND, Vec3};
use nalgebra::Rotation3;
use std::borrow::Cow;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// One object (`o` or `g` group) of an OBJ file, triangulated, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPart {
    /// The object's name in the file (may be empty).
    pub name: String,
    /// Vertex positions, metres.
    pub vertices: Vec<Vec3>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Where a mesh sits in the world: `p_world = R (S p) + t`.
///
/// `rotate` holds Euler angles in degrees about x, then y, then z (applied in that order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Translation `t`, metres.
    pub translate: Vec3,
    /// Rotation about x, y, z in degrees.
    pub rotate: Vec3,
    /// Per-axis scale `S`.
    pub scale: Vec3,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            translate: Vec3::zeros(),
            rotate: Vec3::zeros(),
            scale: Vec3::repeat(1.0),
        }
    }
}

impl Placement {
    /// Maps a point from the mesh's frame to the world.
    pub fn apply(&self, p: &Vec3) -> Vec3 {
        let r = self.rotate.map(f64::to_radians);
        let rotation = Rotation3::from_euler_angles(r.x, r.y, r.z);
        rotation * p.component_mul(&self.scale) + self.translate
    }
}

/// Why a mesh could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be read.
    #[error("cannot read mesh {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// tobj refused the text.
    #[error("{path}: not a valid OBJ mesh: {reason}")]
    Obj {
        /// The file.
        path: PathBuf,
        /// tobj's reason.
        reason: String,
    },
    /// A vertex coordinate is NaN or infinite.
    /// A malformed `v` or `f` line.
    #[error("{path}:{line}: {reason}: '{text}'")]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was expected.
        reason: String,
        /// The line.
        text: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{path}:{line}: vertex coordinate is not a finite number: '{text}'")]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// 1-based line of the `v` statement.
        line: usize,
        /// The line as written.
        text: String,
    },
    /// The file holds no triangle.
    #[error(
        "{path}: the mesh has no triangles (expected at least one 'f' line with 3 or more vertices)"
    )]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A solid was needed but a part is open or inconsistently oriented.
    #[error(
        "{path}: object '{part}' is not a closed, consistently oriented surface \
         ({detail}); a solid collider needs one"
    )]
    NotClosed {
        /// The file.
        path: PathBuf,
        /// The object's name.
        part: String,
        /// What is wrong.
        detail: String,
    },
    /// A vertex cache (PC2 or OBJ sequence) that cannot animate its mesh.
    #[error("{path}: {reason}")]
    Cache {
        /// The file.
        path: PathBuf,
        /// What was expected.
        reason: String,
    },
    /// parry could not build the mesh.
    #[error("{path}: object '{part}': {reason}")]
    Build {
        /// The file.
        path: PathBuf,
        /// The object's name.
        part: String,
        /// parry's reason.
        reason: String,
    },
}

/// Reads an OBJ file and places it.
pub fn load_obj(path: &Path, placement: &Placement) -> Result<Vec<MeshPart>, MeshError> {
    let text = hooke_core::text::read_text(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj(&text, path, placement)
}

/// Parses OBJ text (`path` only names it in errors) and places it.
pub fn parse_obj(
    text: &str,
    path: &Path,
    placement: &Placement,
) -> Result<Vec<MeshPart>, MeshError> {
    // tobj parses NaN happily and reports no lines, so vertices and faces are checked here
    // first, each error with its line; nor does it join continued lines, so it reads the
    // statements joined.
    let statements = statements(text);
    let vertices = statements
        .iter()
        .filter(|(_, l)| l.split_whitespace().next() == Some("v"))
        .count();
    for (n, line) in &statements {
        let (n, line) = (*n, line.as_ref());
        let mut words = line.split_whitespace();
        let bad = |reason: String| MeshError::Line {
            path: path.to_path_buf(),
            line: n + 1,
            reason,
            text: excerpt(line.trim()),
        };
        match words.next() {
            Some("v") => {
                coordinates(
                    words.take(3),
                    3,
                    "vertex",
                    "a vertex needs x, y and z",
                    path,
                    (n + 1, line),
                )?;
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(bad(format!(
                        "a face needs at least 3 vertices, found {}",
                        corners.len()
                    )));
                }
                for c in corners {
                    let index = c.split('/').next().unwrap_or("");
                    if resolve(index, vertices).is_none() {
                        return Err(bad(format!(
                            "face vertex '{}' does not name one of the file's {vertices} vertices",
                            excerpt(c)
                        )));
                    }
                }
            }
            _ => {}
        }
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let text = joined(text, &statements);
    let (models, _materials) =
        tobj::load_obj_buf(&mut Cursor::new(text.as_ref()), &options, |_| {
            Ok(Default::default())
        })
        .map_err(|e| MeshError::Obj {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    let parts: Vec<MeshPart> = models
        .into_iter()
        .filter(|m| !m.mesh.indices.is_empty())
        .map(|m| MeshPart {
            name: m.name,
            vertices: m
                .mesh
                .positions
                .chunks_exact(3)
                .map(|c| placement.apply(&Vec3::new(c[0], c[1], c[2])))
                .collect(),
            triangles: m
                .mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        })
        .collect();
    if parts.is_empty() {
        return Err(MeshError::Empty {
            path: path.to_path_buf(),
        });
    }
    let far = parts
        .iter()
        .flat_map(|p| &p.vertices)
        .find(|v| v.amax().is_nan() || v.amax() > SANE_BOUND);
    if let Some(v) = far {
        return Err(MeshError::Obj {
            path: path.to_path_buf(),
            reason: format!(
                "a placed vertex lies at ({}, {}, {}), beyond {} m of the origin; check the \
                 collider's translate and scale",
                hooke_core::Num(v.x),
                hooke_core::Num(v.y),
                hooke_core::Num(v.z),
                hooke_core::Num(SANE_BOUND)
            ),
        });
    }
    Ok(parts)
}

/// A 1-based OBJ index among `count` items (negative ones count back from the last),
/// 0-based; `None` when it names none of them.
pub(crate) fn resolve(word: &str, count: usize) -> Option<u32> {
    let i = word.parse::<i64>().ok()?;
    let k = if i > 0 && i as usize <= count {
        i as usize - 1
    } else if i < 0 && i.unsigned_abs() as usize <= count {
        count - i.unsigned_abs() as usize
    } else {
        return None;
    };
    u32::try_from(k).ok()
}

/// The first `need` numbers of a `what` statement (`vertex`: `v x y z`), each finite and
/// within the world's extent; `needs` says what is missing when there are fewer. Errors
/// name `path` and the statement's 1-based line, echoing its text.
pub(crate) fn coordinates<'a>(
    words: impl Iterator<Item = &'a str>,
    need: usize,
    what: &str,
    needs: &str,
    path: &Path,
    (line, text): (usize, &str),
) -> Result<Vec<f64>, MeshError> {
    let bad = |reason: String| MeshError::Line {
        path: path.to_path_buf(),
        line,
        reason,
        text: excerpt(text.trim()),
    };
    let words: Vec<&str> = words.collect();
    if words.len() < need {
        return Err(bad(needs.to_string()));
    }
    words
        .into_iter()
        .map(|w| match w.parse::<f64>() {
            Ok(x) if x.abs() <= SANE_BOUND => Ok(x),
            Ok(x) if x.is_finite() => Err(bad(format!(
                "{what} coordinate {} is beyond {} m, the extent of a simulated world",
                hooke_core::Num(x),
                hooke_core::Num(SANE_BOUND)
            ))),
            Ok(_) => Err(MeshError::NonFinite {
                path: path.to_path_buf(),
                line,
                text: excerpt(text.trim()),
            }),
            Err(_) => Err(bad(format!("'{}' is not a number", excerpt(w)))),
        })
        .collect()
}

/// The statements of OBJ text, each with its first line's 0-based index: a line ending in a
/// backslash (the format's line continuation) is joined to the next with a space.
pub(crate) fn statements(text: &str) -> Vec<(usize, Cow<'_, str>)> {
    let mut out: Vec<(usize, Cow<'_, str>)> = Vec::new();
    let mut open = false;
    for (n, line) in text.lines().enumerate() {
        let (body, continues) = match line.trim_end().strip_suffix('\\') {
            Some(body) => (body, true),
            None => (line, false),
        };
        match out.last_mut() {
            Some((_, joined)) if open => {
                let joined = joined.to_mut();
                joined.push(' ');
                joined.push_str(body);
            }
            _ if continues => out.push((n, Cow::Owned(body.to_string()))),
            _ => out.push((n, Cow::Borrowed(line))),
        }
        open = continues;
    }
    out
}

/// `text` with its continued lines joined, as [`statements`] read it (`text` itself when
/// none continues): what tobj, which does not join them, is given.
pub(crate) fn joined<'a>(text: &'a str, statements: &[(usize, Cow<'_, str>)]) -> Cow<'a, str> {
    if statements.iter().any(|(_, l)| matches!(l, Cow::Owned(_))) {
        Cow::Owned(
            statements
                .iter()
                .map(|(_, l)| l.as_ref())
                .collect::<Vec<_>>()
                .join("\n"),
        )
    } else {
        Cow::Borrowed(text)
    }
}

/// Characters of a line echoed in an error.
const EXCERPT_CHARS: usize = 80;

/// At most [`EXCERPT_CHARS`] characters of `text`, with `…` where it was cut.
pub(crate) fn excerpt(text: &str) -> String {
    hooke_core::excerpt(text, EXCERPT_CHARS)
}
