//! A vertex animation read from a PC2 point cache (Blender's Mesh Cache format, the one
//! `hooke run --export NAME.pc2` writes), or from an OBJ sequence ([`crate::sequence`]):
//! per sample, one position per vertex of a mesh, in the mesh file's vertex order.
//!
//! The format, little-endian: the 12 bytes `POINTCACHE2\0`, `i32` version 1, `i32` point
//! count, `f32` start frame, `f32` sampling (frames per sample), `i32` sample count, then
//! each sample's points as `f32` triples. Sample `k` is at `k · sampling / fps` seconds
//! from the scene's start: like Blender's Mesh Cache modifier at its defaults, the header's
//! start frame is not read (Hooke writes 0, Blender's exporter the first frame it wrote).
//! Between samples a vertex moves on the straight line; before the first and after the
//! last it holds, as keys do.

use crate::obj::{MeshError, Placement};
use hooke_core::{SANE_BOUND, Vec3};
use std::path::Path;

/// The header's first 12 bytes.
const MAGIC: &[u8; 12] = b"POINTCACHE2\0";
/// The header's length.
const HEADER: usize = 32;

/// Positions of a mesh's vertices over time, sampled at even times.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexCache {
    /// Per sample, every vertex's position (placed in the world), metres.
    samples: Vec<Vec<Vec3>>,
    /// Seconds between samples.
    interval: f64,
}

fn refuse(path: &Path, reason: String) -> MeshError {
    MeshError::Cache {
        path: path.to_path_buf(),
        reason,
    }
}

impl VertexCache {
    /// Reads the PC2 file at `path` for a mesh of `vertices` vertices, played at `fps`
    /// frames per second, each point placed by `placement` as the mesh is.
    ///
    /// Refused, naming the file and what was expected: a path that is not a regular file,
    /// a header that is not PC2's, a point count other than the mesh's, a sampling that is
    /// not a positive number, a length other than the header's samples hold (a cache cut
    /// short or with bytes after it), and a coordinate that is not a finite number or lies
    /// beyond the world's extent (naming its sample and vertex).
    ///
    /// A path whose file name holds a run of `#` is an OBJ sequence instead, a file per
    /// sample ([`crate::sequence_files`]): refused, naming the file, when a frame is
    /// missing, holds another vertex count or other faces than the first, or is not OBJ.
    pub fn read(
        path: &Path,
        vertices: usize,
        fps: f64,
        placement: &Placement,
    ) -> Result<Self, MeshError> {
        if crate::sequence::is_sequence(path) {
            let frames = crate::sequence::read_frames(path, vertices)?;
            let placed = frames
                .iter()
                .map(|f| f.iter().map(|p| placement.apply(p)).collect())
                .collect();
            return Ok(Self::from_samples(placed, 1.0 / fps));
        }
        let bytes = hooke_core::text::read_bytes(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&bytes, path, vertices, fps, placement)
    }

    /// [`VertexCache::read`] on bytes in memory; `path` only names them in errors.
    pub fn parse(
        bytes: &[u8],
        path: &Path,
        vertices: usize,
        fps: f64,
        placement: &Placement,
    ) -> Result<Self, MeshError> {
        if bytes.len() < HEADER || &bytes[..12] != MAGIC {
            return Err(refuse(
                path,
                "not a PC2 point cache (expected a file starting with 'POINTCACHE2' and a \
                 32-byte header, as Blender's and Hooke's exporters write)"
                    .into(),
            ));
        }
        let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let float = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let (version, points, sampling, count) = (int(12), int(16), float(24), int(28));
        if version != 1 {
            return Err(refuse(
                path,
                format!("PC2 version {version}; expected version 1"),
            ));
        }
        if usize::try_from(points).ok() != Some(vertices) {
            return Err(refuse(
                path,
                format!(
                    "it holds {points} points a sample; the mesh has {vertices} vertices \
                     (expected the cache of this mesh, its vertices in the file's order)"
                ),
            ));
        }
        if !(sampling.is_finite() && sampling > 0.0) {
            return Err(refuse(
                path,
                format!("its sampling is {sampling} frames a sample; expected a positive number"),
            ));
        }
        let Ok(count) = usize::try_from(count) else {
            return Err(refuse(
                path,
                format!("its header gives {count} samples; expected at least one"),
            ));
        };
        let expected = (count as u128) * (vertices as u128) * 12 + HEADER as u128;
        if count == 0 || bytes.len() as u128 != expected {
            return Err(refuse(
                path,
                if count == 0 {
                    "its header gives 0 samples; expected at least one".into()
                } else {
                    format!(
                        "{} bytes, but {count} samples of {vertices} points take {expected} \
                         (the cache was cut short or has bytes after it)",
                        bytes.len()
                    )
                },
            ));
        }
        let mut samples = Vec::with_capacity(count);
        for k in 0..count {
            let mut sample = Vec::with_capacity(vertices);
            for v in 0..vertices {
                let at = HEADER + 12 * (k * vertices + v);
                let p = Vec3::new(
                    f64::from(float(at)),
                    f64::from(float(at + 4)),
                    f64::from(float(at + 8)),
                );
                if !p.iter().all(|c| c.is_finite() && c.abs() < SANE_BOUND) {
                    return Err(refuse(
                        path,
                        format!(
                            "sample {k}, vertex {v}: ({}, {}, {}) is not a position (expected \
                             finite coordinates within {SANE_BOUND:e} m)",
                            p.x, p.y, p.z
                        ),
                    ));
                }
                sample.push(placement.apply(&p));
            }
            samples.push(sample);
        }
        Ok(Self::from_samples(samples, f64::from(sampling) / fps))
    }

    /// The cache of `samples` (at least one, each placed), `interval` seconds apart.
    fn from_samples(samples: Vec<Vec<Vec3>>, interval: f64) -> Self {
        Self { samples, interval }
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether it has no sample (never: a cache read has at least one).
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The number of vertices a sample has.
    pub fn vertices(&self) -> usize {
        self.samples[0].len()
    }

    /// Seconds between samples.
    pub fn interval(&self) -> f64 {
        self.interval
    }

    /// The fastest any vertex moves between two samples, m/s (zero for one sample).
    pub fn speed(&self) -> f64 {
        self.samples
            .windows(2)
            .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| (b - a).norm()))
            .fold(0.0, f64::max)
            / self.interval
    }

    /// The time of the last sample, seconds.
    pub fn duration(&self) -> f64 {
        self.interval * (self.samples.len() - 1) as f64
    }

    /// Sample `k`'s positions.
    pub fn sample(&self, k: usize) -> &[Vec3] {
        &self.samples[k]
    }

    /// The times of the samples strictly between `t0` and `t1`, where a vertex's straight
    /// path turns.
    pub fn turns(&self, t0: f64, t1: f64) -> impl Iterator<Item = f64> + '_ {
        (0..self.samples.len())
            .map(|k| self.interval * k as f64)
            .filter(move |&t| t > t0 && t < t1)
    }

    /// The spans between samples, `(start, end)` in seconds.
    pub fn spans(&self) -> Vec<(f64, f64)> {
        (1..self.samples.len())
            .map(|k| (self.interval * (k - 1) as f64, self.interval * k as f64))
            .collect()
    }

    /// Every vertex's position at time `t`, into `out`.
    pub fn at(&self, t: f64, out: &mut Vec<Vec3>) {
        let last = self.samples.len() - 1;
        let s = (t / self.interval).clamp(0.0, last as f64);
        let k = (s.floor() as usize).min(last);
        out.clear();
        if k == last || s == k as f64 {
            out.extend_from_slice(&self.samples[k]);
            return;
        }
        let w = s - k as f64;
        out.extend(
            self.samples[k]
                .iter()
                .zip(&self.samples[k + 1])
                .map(|(a, b)| a + (b - a) * w),
        );
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A PC2 of `samples` (each a list of points), sampling 1.
    pub(crate) fn pc2(samples: &[Vec<[f32; 3]>]) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.extend(1i32.to_le_bytes());
        b.extend((samples[0].len() as i32).to_le_bytes());
        b.extend(0f32.to_le_bytes());
        b.extend(1f32.to_le_bytes());
        b.extend((samples.len() as i32).to_le_bytes());
        for s in samples {
            for p in s {
                for c in p {
                    b.extend(c.to_le_bytes());
                }
            }
        }
        b
    }

    fn read(bytes: &[u8], vertices: usize) -> Result<VertexCache, MeshError> {
        VertexCache::parse(
            bytes,
            Path::new("arm.pc2"),
            vertices,
            24.0,
            &Placement::default(),
        )
    }

    #[test]
    fn positions_are_interpolated_between_samples_and_held_outside() {
        let c = read(&pc2(&[vec![[0.0, 0.0, 0.0]], vec![[2.4, 0.0, 0.0]]]), 1).unwrap();
        let mut x = Vec::new();
        c.at(0.5 / 24.0, &mut x);
        assert!((x[0].x - 1.2).abs() < 1e-6, "{x:?}");
        c.at(-1.0, &mut x);
        assert_eq!(x[0].x, 0.0);
        c.at(10.0, &mut x);
        assert!((x[0].x - 2.4).abs() < 1e-6);
        assert_eq!(c.spans(), vec![(0.0, 1.0 / 24.0)]);
    }

    #[test]
    fn a_cache_that_does_not_fit_its_mesh_or_header_is_refused_by_name() {
        let good = pc2(&[vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]]);
        let e = read(&good, 3).unwrap_err().to_string();
        assert!(
            e.contains("arm.pc2") && e.contains("2 points") && e.contains("3 vertices"),
            "{e}"
        );
        let e = read(&good[..good.len() - 4], 2).unwrap_err().to_string();
        assert!(e.contains("cut short"), "{e}");
        let e = read(b"OBJ v 0 0 0", 2).unwrap_err().to_string();
        assert!(e.contains("not a PC2"), "{e}");
        let mut nan = good.clone();
        nan[HEADER + 12..HEADER + 16].copy_from_slice(&f32::NAN.to_le_bytes());
        let e = read(&nan, 2).unwrap_err().to_string();
        assert!(e.contains("sample 0, vertex 1"), "{e}");
        let mut zero = good;
        zero[24..28].copy_from_slice(&0f32.to_le_bytes());
        let e = read(&zero, 2).unwrap_err().to_string();
        assert!(e.contains("sampling"), "{e}");
    }
}
