//! A cloth given as a material in SI units (`[body.material]`, docs/physics.md §1.1): its
//! particles' masses and its springs derived for the grid's spacing, so that the same
//! material is the same cloth at any resolution.

use crate::error::{BuildError, invalid};
use crate::generators::Lattice;
use crate::spec::{MaterialSpec, Positive};
use hooke_core::{Spring, SpringKind};

/// A material with every value known, in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Areal density, kg/m².
    pub density: f64,
    /// Membrane stiffness of the structural springs per unit width, N/m.
    pub stretch: f64,
    /// Membrane shear stiffness (of the diagonal springs), N/m.
    pub shear: f64,
    /// Bending rigidity per unit width `B`, N·m.
    pub bending: f64,
    /// Stiffness-proportional damping: each membrane spring's `kd` is this times its `ks`, s.
    pub damping: f64,
}

/// A material file's text (a `[material]` table, as `hooke drape FILE.toml` reads it) as
/// its spec; `path` only names it in the error, which says what TOML found wrong and where.
///
/// ```
/// use std::path::Path;
/// let spec = hooke_scene::material::parse_material_file(
///     "[material]\npreset = \"cotton\"\nbending = 2e-6\n",
///     Path::new("m.toml"),
/// )
/// .unwrap();
/// assert_eq!(spec.resolve("material").unwrap().bending, 2e-6);
/// assert!(hooke_scene::material::parse_material_file("[material]\nmass = 1\n", Path::new("m.toml"))
///     .unwrap_err()
///     .starts_with("m.toml: "));
/// ```
pub fn parse_material_file(text: &str, path: &std::path::Path) -> Result<MaterialSpec, String> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct File {
        material: MaterialSpec,
    }
    toml::from_str::<File>(text)
        .map(|f| f.material)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// A named material and where its figures come from.
pub struct Preset {
    /// The name `preset = "…"` takes.
    pub name: &'static str,
    /// Its values.
    pub material: Material,
    /// What the values are and where they come from.
    pub source: &'static str,
}

/// The presets. Values are rounded, typical figures for the fabric class from Kawabata-type
/// (KES-F) measurements as summarised by Kawabata & Niwa (J. Textile Inst. 80, 1989) and
/// Peirce's cantilever (1930), not one fabric's measurement: areal density, bending rigidity
/// `B` (1 gf·cm²/cm = 9.81e-5 N·m), an initial tensile and a shear stiffness per unit width.
pub const PRESETS: [Preset; 4] = [
    Preset {
        name: "cotton",
        material: Material {
            density: 0.15,
            stretch: 1000.0,
            shear: 50.0,
            bending: 5e-6,
            damping: 1e-5,
        },
        source: "plain-weave cotton shirting: 150 g/m², B ≈ 0.05 gf·cm²/cm",
    },
    Preset {
        name: "silk",
        material: Material {
            density: 0.06,
            stretch: 500.0,
            shear: 20.0,
            bending: 1e-6,
            damping: 1e-5,
        },
        source: "silk crêpe de chine: 60 g/m², B ≈ 0.01 gf·cm²/cm",
    },
    Preset {
        name: "wool",
        material: Material {
            density: 0.25,
            stretch: 2000.0,
            shear: 100.0,
            bending: 2e-5,
            damping: 1e-5,
        },
        source: "worsted wool suiting: 250 g/m², B ≈ 0.2 gf·cm²/cm",
    },
    Preset {
        name: "denim",
        material: Material {
            density: 0.4,
            stretch: 5000.0,
            shear: 300.0,
            bending: 1e-4,
            damping: 1e-5,
        },
        source: "denim twill: 400 g/m², B ≈ 1 gf·cm²/cm",
    },
];

impl MaterialSpec {
    /// The material with its preset's values under the keys given, or an error naming
    /// the keys still missing (or the unknown preset).
    pub fn resolve(&self, key: &str) -> Result<Material, BuildError> {
        let base = match &self.preset {
            Some(name) => Some(
                PRESETS
                    .iter()
                    .find(|p| p.name == name)
                    .map(|p| p.material)
                    .ok_or_else(|| {
                        let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
                        invalid(
                            format!("{key}.preset"),
                            format!("expected one of {}, found \"{name}\"", names.join(", ")),
                        )
                    })?,
            ),
            None => None,
        };
        let mut missing = Vec::new();
        let mut pick = |name: &'static str, given: Option<f64>, preset: Option<f64>| {
            given.or(preset).unwrap_or_else(|| {
                missing.push(name);
                0.0
            })
        };
        let get = |p: Option<Positive>| p.map(Positive::get);
        let material = Material {
            density: pick("density", get(self.density), base.map(|b| b.density)),
            stretch: pick("stretch", get(self.stretch), base.map(|b| b.stretch)),
            shear: pick("shear", self.shear.map(|s| s.get()), base.map(|b| b.shear)),
            bending: pick(
                "bending",
                self.bending.map(|s| s.get()),
                base.map(|b| b.bending),
            ),
            damping: pick(
                "damping",
                self.damping.map(|s| s.get()),
                base.map(|b| b.damping),
            ),
        };
        if !missing.is_empty() {
            return Err(invalid(
                key.to_string(),
                format!(
                    "missing {} (or give a preset: {})",
                    missing.join(", "),
                    PRESETS
                        .iter()
                        .map(|p| p.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        Ok(material)
    }
}

impl Material {
    /// Each particle's mass for a grid of `size` particles `h` apart: the density times
    /// the area it stands for (`h²` inside, half on an edge, a quarter at a corner).
    pub fn masses(&self, size: [usize; 2], h: f64) -> Vec<f64> {
        let share = |k: usize, n: usize| {
            if n == 1 {
                1.0
            } else if k == 0 || k + 1 == n {
                0.5
            } else {
                1.0
            }
        };
        let mut out = Vec::with_capacity(size[0] * size[1]);
        for i in 0..size[0] {
            for j in 0..size[1] {
                out.push(self.density * h * h * share(i, size[0]) * share(j, size[1]));
            }
        }
        out
    }

    /// How many springs [`Material::springs`] gives for a grid of `size` (saturating).
    pub fn spring_count(&self, [nx, nz]: [usize; 2]) -> u64 {
        let (nx, nz) = (nx as u64, nz as u64);
        let lines = |a: u64, b: u64, gap: u64| a.saturating_mul(b.saturating_sub(gap));
        let structural = lines(nx, nz, 1).saturating_add(lines(nz, nx, 1));
        let shear = 2u64.saturating_mul(lines(nx.saturating_sub(1), nz, 1));
        let bending = if self.bending > 0.0 {
            3u64.saturating_mul(lines(nx, nz, 2).saturating_add(lines(nz, nx, 2)))
        } else {
            0
        };
        structural.saturating_add(shear).saturating_add(bending)
    }

    /// The springs of a grid of `size` particles `h` apart, indices offset by `offset`:
    /// * structural springs of stiffness `stretch` (half along an edge, which stands for
    ///   a strip half as wide) and shear springs of stiffness `shear` on both diagonals,
    ///   each with `kd = damping · ks`;
    /// * per three consecutive particles `a, b, c` along a grid line, the quadratic bending
    ///   energy `½ k |x_a - 2 x_b + x_c|²` with `k = B / h²` (half along an edge), written
    ///   exactly as three zero-rest-length springs: `2k` on `a–b` and `b–c`, `-k` on `a–c`
    ///   (`|u + v|² = 2|u|² + 2|v|² - |u - v|²`), undamped. An element with `a` and `b`
    ///   pinned and `c` free (or the reverse) is a clamped edge: of the length `h` it
    ///   stands for, only the free half bends, so its `k` is doubled (which makes the
    ///   cantilever's error second order in `h`, docs/physics.md §1.1).
    ///
    /// `pinned` tells, by index within the body, which particles are pinned.
    pub fn springs(
        &self,
        size: [usize; 2],
        h: f64,
        offset: usize,
        pinned: &dyn Fn(usize) -> bool,
    ) -> Vec<Spring> {
        let lattice = Lattice {
            size: [size[0], 1, size[1]],
        };
        let local = |i: usize, j: usize| lattice.index([i, 0, j]);
        let id = |i: usize, j: usize| (offset + local(i, j)) as u32;
        let edge = |k: usize, n: usize| n > 1 && (k == 0 || k + 1 == n);
        let mut out = Vec::new();
        let mut push = |i: u32, j: u32, rest: f64, ks: f64, kd: f64, kind: SpringKind| {
            out.push(Spring {
                i,
                j,
                rest,
                ks,
                kd,
                kind,
            });
        };
        let [nx, nz] = size;
        for i in 0..nx {
            for j in 0..nz {
                // Along x (a line of constant j) and along z (constant i).
                if i + 1 < nx {
                    let ks = self.stretch * if edge(j, nz) { 0.5 } else { 1.0 };
                    let kd = self.damping * ks;
                    push(id(i, j), id(i + 1, j), h, ks, kd, SpringKind::Structural);
                }
                if j + 1 < nz {
                    let ks = self.stretch * if edge(i, nx) { 0.5 } else { 1.0 };
                    let kd = self.damping * ks;
                    push(id(i, j), id(i, j + 1), h, ks, kd, SpringKind::Structural);
                }
            }
        }
        let diagonal = h * std::f64::consts::SQRT_2;
        let kd = self.damping * self.shear;
        for i in 0..nx.saturating_sub(1) {
            for j in 0..nz.saturating_sub(1) {
                push(
                    id(i, j),
                    id(i + 1, j + 1),
                    diagonal,
                    self.shear,
                    kd,
                    SpringKind::Shear,
                );
                push(
                    id(i + 1, j),
                    id(i, j + 1),
                    diagonal,
                    self.shear,
                    kd,
                    SpringKind::Shear,
                );
            }
        }
        let k = self.bending / (h * h);
        let offset = offset as u32;
        let mut bend = |[a, b, c]: [usize; 3], k: f64| {
            let clamped = pinned(b) && (pinned(a) != pinned(c));
            let k = if clamped { 2.0 * k } else { k };
            let [a, b, c] = [a, b, c].map(|p| offset + p as u32);
            push(a, b, 0.0, 2.0 * k, 0.0, SpringKind::Bend);
            push(b, c, 0.0, 2.0 * k, 0.0, SpringKind::Bend);
            push(a, c, 0.0, -k, 0.0, SpringKind::Bend);
        };
        if k > 0.0 {
            for i in 0..nx {
                for j in 0..nz {
                    if i + 2 < nx {
                        let k = k * if edge(j, nz) { 0.5 } else { 1.0 };
                        bend([local(i, j), local(i + 1, j), local(i + 2, j)], k);
                    }
                    if j + 2 < nz {
                        let k = k * if edge(i, nx) { 0.5 } else { 1.0 };
                        bend([local(i, j), local(i, j + 1), local(i, j + 2)], k);
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hooke_core::Vec3;

    fn cotton() -> Material {
        PRESETS[0].material
    }

    /// A one-body scene whose body is given by `body` (TOML lines), built.
    fn build(body: &str) -> Result<crate::Scene, String> {
        let text = format!(
            "name = \"m\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 1e-4\nsteps = 1\nevery = 1\n\
             [[body]]\nname = \"cloth\"\n{body}\n"
        );
        let spec = crate::parse_scene(&text, "m.toml").map_err(|e| e.to_string())?;
        spec.build(std::path::Path::new("."))
            .map_err(|e| e.to_string())
    }

    /// Bad materials are refused with the key and what was expected.
    #[test]
    fn bad_materials_are_refused_with_their_keys() {
        let grid = "[body.shape]\nkind = \"grid\"\nsize = [4, 4]\nspacing = 0.1\n";
        let both = build(&format!(
            "mass = 0.1\n{grid}[body.material]\npreset = \"cotton\""
        ));
        let e = both.err().unwrap();
        assert!(
            e.contains("body[0] 'cloth'.material") && e.contains("`mass`"),
            "{e}"
        );
        let springs = build(&format!(
            "{grid}[body.springs.structural]\nks = 1.0\nkd = 0.0\n[body.material]\npreset = \"silk\""
        ));
        assert!(springs.err().unwrap().contains("`springs`"));
        let unknown = build(&format!("{grid}[body.material]\npreset = \"velvet\""));
        let e = unknown.err().unwrap();
        assert!(
            e.contains("material.preset") && e.contains("cotton, silk, wool, denim"),
            "{e}"
        );
        let missing = build(&format!(
            "{grid}[body.material]\ndensity = 0.2\nstretch = 100.0"
        ));
        let e = missing.err().unwrap();
        assert!(e.contains("missing shear, bending, damping"), "{e}");
        let chain = build(
            "[body.shape]\nkind = \"chain\"\ncount = 3\nspacing = 0.1\n[body.material]\npreset = \"cotton\"",
        );
        assert!(chain.err().unwrap().contains("must be a `grid`"));
        let bare = build(grid).err().unwrap();
        assert!(bare.contains("mass") && bare.contains("material"), "{bare}");
    }

    /// A preset's key given beside it wins; the rest stay the preset's.
    #[test]
    fn a_key_overrides_its_preset() {
        let mut spec = crate::spec::MaterialSpec {
            preset: Some("denim".into()),
            ..Default::default()
        };
        spec.bending = Some(crate::spec::NonNegative::of(3e-5));
        let m = spec.resolve("k").unwrap();
        assert_eq!(m.bending, 3e-5);
        assert_eq!(m.density, PRESETS[3].material.density);
    }

    /// The masses add up to the density times the sheet's area, at any resolution.
    #[test]
    fn masses_sum_to_density_times_area() {
        for n in [2, 5, 36, 72] {
            let h = 1.0 / (n - 1) as f64;
            let total: f64 = cotton().masses([n, n], h).iter().sum();
            assert!((total - 0.15).abs() < 1e-12, "{n}: {total}");
        }
    }

    /// The three springs of a bending element hold the quadratic energy exactly: the sum of
    /// `½ ks L²` over them is `½ k |x_a - 2 x_b + x_c|²` for any positions.
    #[test]
    fn zero_length_springs_give_the_quadratic_bending_energy() {
        let m = Material {
            stretch: 0.0,
            shear: 0.0,
            ..cotton()
        };
        let h = 0.01;
        let springs: Vec<Spring> = m
            .springs([3, 1], h, 0, &|_| false)
            .into_iter()
            .filter(|s| s.kind == SpringKind::Bend)
            .collect();
        assert_eq!(springs.len(), 3);
        for size in [[3, 1], [5, 4], [36, 36]] {
            let n = cotton().springs(size, h, 0, &|_| false).len() as u64;
            assert_eq!(cotton().spring_count(size), n, "{size:?}");
        }
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.011, 0.003, -0.001),
            Vec3::new(0.019, 0.009, 0.002),
        ];
        let energy: f64 = springs
            .iter()
            .map(|s| 0.5 * s.ks * (x[s.i as usize] - x[s.j as usize]).norm_squared())
            .sum();
        // A strip one particle wide stands for a width of one spacing: no edge halving.
        let k = m.bending / (h * h);
        let exact = 0.5 * k * (x[0] - x[1] * 2.0 + x[2]).norm_squared();
        assert!(
            (energy - exact).abs() < 1e-12 * exact.max(1e-300),
            "{energy} vs {exact}"
        );
    }
}
