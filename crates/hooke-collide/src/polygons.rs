//! Reading an OBJ file as the user wrote it, for a body made from it: every vertex in the
//! file's order, faces as polygons (triangles, quads, n-gons) of position indices, texture
//! coordinates per corner, and the groups each face belongs to.
//!
//! tobj reads and checks the file. It re-indexes each object's vertices in the order faces
//! first use them (and `single_index` would split vertices at UV seams), so the position
//! indices the faces name, which a body must keep to hand its vertices back in the user's
//! order, are read from the same lines as the checks that name a line in their errors.

use crate::obj::{MeshError, coordinates, excerpt, joined, resolve, statements};
use hooke_core::Vec3;
use std::io::Cursor;
use std::path::Path;

/// One face: its corners as position indices (0-based, in the file's order of `v` lines),
/// the texture coordinate of each corner if the face gives them, the 1-based line it is on,
/// and the groups (`g` names and the `o` name) it belongs to, as indices into
/// [`PolygonMesh::groups`].
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Position indices, counter-clockwise as written.
    pub corners: Vec<u32>,
    /// Texture coordinate indices, one per corner, when the face gives them all.
    pub uvs: Option<Vec<u32>>,
    /// 1-based line of the `f` statement.
    pub line: usize,
    /// Indices into [`PolygonMesh::groups`].
    pub groups: Vec<u32>,
}

/// An OBJ file's vertices and faces, as written.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonMesh {
    /// Positions in the file's order, in the file's coordinates.
    pub positions: Vec<Vec3>,
    /// The 1-based line of each position.
    pub position_lines: Vec<usize>,
    /// Texture coordinates (`vt`), in the file's order.
    pub texcoords: Vec<[f64; 2]>,
    /// Faces in the file's order.
    pub faces: Vec<Polygon>,
    /// Group and object names, in the order they first appear.
    pub groups: Vec<String>,
}

impl PolygonMesh {
    /// Reads `path` (see [`PolygonMesh::parse`]).
    pub fn load(path: &Path, limit: usize) -> Result<Self, MeshError> {
        let text = hooke_core::text::read_text(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path, limit)
    }

    /// Parses OBJ text; `path` only names it in errors. Refuses, naming the line: a vertex
    /// without three finite coordinates, or beyond the world's extent; a face of fewer than
    /// three corners or naming a vertex or texture coordinate the file does not have; more
    /// than `limit` vertices or faces (checked before they are stored).
    pub fn parse(text: &str, path: &Path, limit: usize) -> Result<Self, MeshError> {
        let mut mesh = PolygonMesh::default();
        let mut current: Vec<u32> = Vec::new();
        let mut object: Option<u32> = None;
        let statements = statements(text);
        for (n, line) in &statements {
            let (n, line) = (*n, line.as_ref());
            let bad = |reason: String| MeshError::Line {
                path: path.to_path_buf(),
                line: n + 1,
                reason,
                text: excerpt(line.trim()),
            };
            let mut words = line.split_whitespace();
            match words.next() {
                Some("v") => {
                    if mesh.positions.len() >= limit {
                        return Err(bad(format!(
                            "more than {limit} vertices, the most a body may have"
                        )));
                    }
                    let needs = "a vertex needs x, y and z";
                    let p = coordinates(words.take(3), 3, "vertex", needs, path, (n + 1, line))?;
                    mesh.positions.push(Vec3::new(p[0], p[1], p[2]));
                    mesh.position_lines.push(n + 1);
                }
                Some("vt") => {
                    let needs = "a texture coordinate needs u";
                    let p = coordinates(words.take(2), 1, "texture", needs, path, (n + 1, line))?;
                    mesh.texcoords
                        .push([p[0], p.get(1).copied().unwrap_or(0.0)]);
                }
                Some("g") => {
                    current = words.map(|name| group(&mut mesh.groups, name)).collect();
                }
                Some("o") => {
                    let name = words.collect::<Vec<_>>().join(" ");
                    object = Some(group(&mut mesh.groups, &name));
                }
                Some("f") => {
                    if mesh.faces.len() >= limit {
                        return Err(bad(format!(
                            "more than {limit} faces, the most a body may have"
                        )));
                    }
                    let mut corners = Vec::new();
                    let mut uvs = Vec::new();
                    for c in words {
                        let mut parts = c.split('/');
                        let v = parts.next().unwrap_or("");
                        corners.push(resolve(v, mesh.positions.len()).ok_or_else(|| {
                            bad(format!(
                                "face vertex '{}' does not name one of the {} vertices before \
                                 this line",
                                excerpt(c),
                                mesh.positions.len()
                            ))
                        })?);
                        match parts.next() {
                            Some(t) if !t.is_empty() => {
                                uvs.push(resolve(t, mesh.texcoords.len()).ok_or_else(|| {
                                    bad(format!(
                                        "face corner '{}' names a texture coordinate the file \
                                         does not have before this line ({} so far)",
                                        excerpt(c),
                                        mesh.texcoords.len()
                                    ))
                                })?)
                            }
                            _ => {}
                        }
                    }
                    if corners.len() < 3 {
                        return Err(bad(format!(
                            "a face needs at least 3 vertices, found {}",
                            corners.len()
                        )));
                    }
                    let full = uvs.len() == corners.len();
                    let mut groups = current.clone();
                    groups.extend(object);
                    mesh.faces.push(Polygon {
                        corners,
                        uvs: full.then_some(uvs),
                        line: n + 1,
                        groups,
                    });
                }
                _ => {}
            }
        }
        if mesh.faces.is_empty() {
            return Err(MeshError::Empty {
                path: path.to_path_buf(),
            });
        }
        // tobj reads the same text: anything it refuses is refused here too, and it must
        // count the same faces.
        let options = tobj::LoadOptions {
            triangulate: false,
            single_index: false,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj_buf(
            &mut Cursor::new(joined(text, &statements).as_ref()),
            &options,
            |_| Ok(Default::default()),
        )
        .map_err(|e| MeshError::Obj {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let faces: usize = models
            .iter()
            .map(|m| {
                if m.mesh.face_arities.is_empty() {
                    m.mesh.indices.len() / 3
                } else {
                    m.mesh.face_arities.len()
                }
            })
            .sum();
        if faces != mesh.faces.len() {
            return Err(MeshError::Obj {
                path: path.to_path_buf(),
                reason: format!(
                    "tobj reads {faces} faces where the lines hold {}",
                    mesh.faces.len()
                ),
            });
        }
        Ok(mesh)
    }
}

/// The index of group `name`, added if new.
fn group(groups: &mut Vec<String>, name: &str) -> u32 {
    match groups.iter().position(|g| g == name) {
        Some(k) => k as u32,
        None => {
            groups.push(name.to_string());
            (groups.len() - 1) as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<PolygonMesh, String> {
        PolygonMesh::parse(text, Path::new("m.obj"), 1000).map_err(|e| e.to_string())
    }

    /// A seam (two texture coordinates at one vertex) keeps one vertex; quads stay quads;
    /// groups are kept per face; the file's order is the vertices' order.
    #[test]
    fn faces_keep_the_files_vertices_across_uv_seams() {
        let m = parse(
            "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n\
             g hem\nf 1/1 2/2 3/3 4/4\ng body\nf 2/5 5/1 3/2\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.faces[0].corners, vec![0, 1, 2, 3]);
        assert_eq!(m.faces[1].corners, vec![1, 4, 2]);
        assert_eq!(m.faces[1].uvs, Some(vec![4, 0, 1]));
        assert_eq!(m.groups, vec!["hem".to_string(), "body".to_string()]);
        assert_eq!(m.faces[0].groups, vec![0]);
        assert_eq!(m.faces[1].line, 14);
    }

    /// A line ending in a backslash continues on the next (the OBJ format's continuation,
    /// CRLF endings too): the face is one quad, and a bad corner after it names the line
    /// its statement starts on.
    #[test]
    fn a_continued_line_is_one_statement() {
        let m = parse(
            "v 0 0 0\r\nv 1 0 0\r\nv 1 0 1 \\\r\n\r\nv 0 0 1\r\nf 1 2 \\\r\n 3 4\r\nf 1 2 3\r\n",
        )
        .unwrap();
        assert_eq!(
            m.positions.len(),
            4,
            "the empty line continues the third vertex"
        );
        assert_eq!(m.faces[0].corners, vec![0, 1, 2, 3]);
        assert_eq!(m.faces[1].line, 8);
        let m = parse("v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 \\\n 3 4\nf 1 2 3\n").unwrap();
        assert_eq!(m.faces[0].corners, vec![0, 1, 2, 3]);
        assert_eq!(m.faces[1].line, 7);
        let e = parse("v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 \\\n 9\n").unwrap_err();
        assert!(e.contains("m.obj:4") && e.contains("'9'"), "{e}");
    }

    /// Bad lines are refused with their line number.
    #[test]
    fn bad_lines_name_their_line() {
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n").unwrap_err();
        assert!(e.contains("m.obj:3"), "{e}");
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert!(e.contains("m.obj:4") && e.contains("'7'"), "{e}");
        let e = parse("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(e.contains("m.obj:3") && e.contains("at least 3"), "{e}");
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -3\nf 1/9 2/9 3/9\n").unwrap_err();
        assert!(e.contains("m.obj:5") && e.contains("texture"), "{e}");
        let e = parse("v 0 0 0\n").unwrap_err();
        assert!(e.contains("no triangles"), "{e}");
        let many = "v 0 0 0\n".repeat(1001);
        assert!(
            parse(&many)
                .unwrap_err()
                .contains("more than 1000 vertices")
        );
    }
}
