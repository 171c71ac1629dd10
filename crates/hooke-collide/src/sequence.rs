//! A vertex animation given as an OBJ sequence: one OBJ per frame, named by a pattern whose
//! run of `#` stands for the frame number (`arm_####.obj` reads `arm_0001.obj`,
//! `arm_0002.obj`, …), as Blender's OBJ exporter (with *Animation*), Houdini, Maya and
//! Marvelous Designer write them. Each file's vertices, in its order, are one sample of a
//! vertex cache (`VertexCache::read` takes such a pattern): the first frame found is sample
//! 0, and the frames must follow each other with no number missing and keep the first
//! one's vertices and faces.

use crate::obj::MeshError;
use crate::polygons::PolygonMesh;
use hooke_core::Vec3;
use std::path::{Path, PathBuf};

/// Frames a sequence may hold: past this the run would spend its memory on the collider.
const MOST_FRAMES: usize = 100_000;

fn refuse(path: &Path, reason: String) -> MeshError {
    MeshError::Cache {
        path: path.to_path_buf(),
        reason,
    }
}

/// The text before and after the run of `#` in `pattern`'s file name, and the run's length;
/// `None` when the name has no `#`.
fn split(pattern: &Path) -> Option<(String, String, usize)> {
    let name = pattern.file_name()?.to_str()?;
    let start = name.find('#')?;
    let len = name[start..].chars().take_while(|&c| c == '#').count();
    Some((
        name[..start].to_string(),
        name[start + len..].to_string(),
        len,
    ))
}

/// Whether `path` names an OBJ sequence: its file name holds a `#`.
pub fn is_sequence(path: &Path) -> bool {
    split(path).is_some()
}

/// The frame number `name` has under the pattern `(prefix, suffix, width)`: its digits
/// between the two, at least `width` of them and zero-padded to exactly that (`0012` for
/// `####`, and `12345` beyond it).
fn frame_number(name: &str, (prefix, suffix, width): (&str, &str, usize)) -> Option<u64> {
    let digits = name.strip_prefix(prefix)?.strip_suffix(suffix)?;
    let canonical = digits.len() >= width
        && digits.bytes().all(|b| b.is_ascii_digit())
        && (digits.len() == width || !digits.starts_with('0'));
    if !canonical {
        return None;
    }
    digits.parse().ok()
}

/// The files of the sequence `pattern` in frame order, with their numbers. Refused, naming
/// the pattern: a second run of `#`, a folder that cannot be read, no file that matches,
/// more than 100 000 frames, and a number missing between the first and the last (naming
/// the file that is not there).
pub fn sequence_files(pattern: &Path) -> Result<Vec<(u64, PathBuf)>, MeshError> {
    let Some((prefix, suffix, width)) = split(pattern) else {
        return Err(refuse(
            pattern,
            "expected a file name with a run of '#'".into(),
        ));
    };
    if suffix.contains('#') {
        return Err(refuse(
            pattern,
            "its name has two runs of '#'; expected one, which stands for the frame number".into(),
        ));
    }
    let dir = match pattern.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let entries = std::fs::read_dir(&dir).map_err(|source| MeshError::Io {
        path: dir.clone(),
        source,
    })?;
    let mut frames: Vec<(u64, PathBuf)> = entries
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let n = frame_number(&name, (&prefix, &suffix, width))?;
            Some((n, pattern.with_file_name(name)))
        })
        .collect();
    frames.sort();
    let Some(&(first, _)) = frames.first() else {
        return Err(refuse(
            pattern,
            format!(
                "no file matches it (expected files named {prefix}{}{suffix} …, the '#' \
                 standing for the frame number padded with zeros to {width} digits)",
                "0".repeat(width.saturating_sub(1)) + "1"
            ),
        ));
    };
    if frames.len() > MOST_FRAMES {
        return Err(refuse(
            pattern,
            format!(
                "{} files match it; a sequence holds at most {MOST_FRAMES} frames",
                frames.len()
            ),
        ));
    }
    for (k, (n, _)) in frames.iter().enumerate() {
        let want = first + k as u64;
        if *n != want {
            let missing = pattern.with_file_name(format!("{prefix}{want:0width$}{suffix}"));
            return Err(refuse(
                pattern,
                format!(
                    "frame {want} is missing ({} is not there, between frames {first} and {}); \
                     expected every frame from the first to the last",
                    missing.display(),
                    frames.last().map_or(first, |f| f.0)
                ),
            ));
        }
    }
    Ok(frames)
}

/// The samples of the OBJ sequence `pattern`: each file's vertices in its order, for a
/// mesh of `vertices` vertices. Refused as [`sequence_files`] refuses, and naming the file:
/// one that is not a valid OBJ (with its line), one whose vertex count is not the mesh's,
/// one whose faces are not the first frame's (the topology changes between frames).
pub(crate) fn read_frames(pattern: &Path, vertices: usize) -> Result<Vec<Vec<Vec3>>, MeshError> {
    let files = sequence_files(pattern)?;
    let mut first_faces: Option<(PathBuf, Vec<Vec<u32>>)> = None;
    let mut samples = Vec::with_capacity(files.len());
    for (_, path) in &files {
        // Room for a mesh's faces (about twice its vertices), not for a file of another.
        let mesh = PolygonMesh::load(path, 4 * vertices + 16)?;
        if mesh.positions.len() != vertices {
            return Err(refuse(
                path,
                format!(
                    "it has {} vertices; the mesh has {vertices} (expected every frame of the \
                     sequence to hold the mesh's vertices, in the file's order)",
                    mesh.positions.len()
                ),
            ));
        }
        let faces: Vec<Vec<u32>> = mesh.faces.into_iter().map(|f| f.corners).collect();
        match &first_faces {
            None => first_faces = Some((path.clone(), faces)),
            Some((first, want)) if *want != faces => {
                return Err(refuse(
                    path,
                    format!(
                        "its faces are not those of {} (the first frame): the topology changes \
                         between frames; expected the same faces in every frame",
                        first.display()
                    ),
                ));
            }
            Some(_) => {}
        }
        samples.push(mesh.positions);
    }
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder of its own under the system's temporary one.
    fn folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("hooke-seq-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A triangle lifted by `y` m, as an OBJ.
    fn triangle(y: f64) -> String {
        format!("v 0 {y} 0\nv 1 {y} 0\nv 0 {y} 1\nf 1 2 3\n")
    }

    #[test]
    fn frames_are_read_in_number_order() {
        let dir = folder("order");
        for (n, y) in [(9, 0.0), (10, 1.0), (11, 3.0)] {
            std::fs::write(dir.join(format!("tri_{n:04}.obj")), triangle(y)).unwrap();
        }
        std::fs::write(dir.join("tri_0012.mtl"), "").unwrap();
        std::fs::write(dir.join("tri_00013.obj"), triangle(9.0)).unwrap();
        let samples = read_frames(&dir.join("tri_####.obj"), 3).unwrap();
        let heights: Vec<f64> = samples.iter().map(|s| s[2].y).collect();
        assert_eq!(heights, [0.0, 1.0, 3.0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_gap_a_count_or_faces_that_change_are_refused_by_name() {
        let dir = folder("bad");
        let pattern = dir.join("tri_##.obj");
        let read = || read_frames(&pattern, 3);
        let said = read().unwrap_err().to_string();
        assert!(said.contains("no file matches it"), "{said}");
        std::fs::write(dir.join("tri_01.obj"), triangle(0.0)).unwrap();
        std::fs::write(dir.join("tri_03.obj"), triangle(0.0)).unwrap();
        let said = read().unwrap_err().to_string();
        assert!(
            said.contains("frame 2 is missing") && said.contains("tri_02.obj"),
            "{said}"
        );
        std::fs::write(dir.join("tri_02.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 1\n").unwrap();
        let said = read().unwrap_err().to_string();
        assert!(
            said.contains("tri_02.obj") && said.contains("it has 2 vertices"),
            "{said}"
        );
        std::fs::write(
            dir.join("tri_02.obj"),
            triangle(0.0).replace("f 1 2 3", "f 1 3 2"),
        )
        .unwrap();
        let said = read().unwrap_err().to_string();
        assert!(
            said.contains("tri_02.obj") && said.contains("topology"),
            "{said}"
        );
        std::fs::write(dir.join("tri_02.obj"), "v 0 0 0\nv 1 x 0\n").unwrap();
        let said = read().unwrap_err().to_string();
        assert!(said.contains("tri_02.obj:2:"), "{said}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
