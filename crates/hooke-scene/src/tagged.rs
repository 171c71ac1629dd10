//! Reading the `kind`-tagged tables (`[body.shape]`, a collider's `shape` and `response`)
//! through flat tables of optional keys.
//!
//! serde reads an internally tagged enum by buffering the whole table first, so toml can
//! only point an error at the table's header, and the message (`expected a finite number >
//! 0, found -1`) does not say which key. Read as a flat struct instead, a bad value is
//! reported at the value itself (the excerpt shows its key), an unknown key at the key, and
//! a key that the kind does not take, or one it misses, by name.

use crate::spec::{
    ColliderShapeSpec, Finite, Fraction, NonNegative, Positive, ResponseSpec, ShapeSpec,
};
use serde::Deserialize;

/// A key the kind needs.
fn need<T>(kind: &str, key: &str, value: Option<T>) -> Result<T, String> {
    value.ok_or_else(|| format!("kind = \"{kind}\" needs the key `{key}`"))
}

/// Refuses keys that are present but not among the kind's.
fn only(kind: &str, allowed: &[&str], present: &[(&str, bool)]) -> Result<(), String> {
    match present.iter().find(|(k, set)| *set && !allowed.contains(k)) {
        Some((key, _)) => Err(format!(
            "`{key}` is not a key of kind = \"{kind}\" (its keys: kind, {})",
            allowed.join(", ")
        )),
        None => Ok(()),
    }
}

/// `[body.shape]` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ShapeTable {
    kind: ShapeKind,
    count: Option<usize>,
    size: Option<Vec<usize>>,
    spacing: Option<Positive>,
    positions: Option<Vec<[Finite; 3]>>,
    path: Option<String>,
    scale: Option<[Positive; 3]>,
    weld: Option<Positive>,
}

#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ShapeKind {
    Chain,
    Grid,
    Lattice,
    Points,
    Mesh,
    Solid,
}

impl TryFrom<ShapeTable> for ShapeSpec {
    type Error = String;

    fn try_from(t: ShapeTable) -> Result<Self, String> {
        let present = [
            ("count", t.count.is_some()),
            ("size", t.size.is_some()),
            ("spacing", t.spacing.is_some()),
            ("positions", t.positions.is_some()),
            ("path", t.path.is_some()),
            ("scale", t.scale.is_some()),
            ("weld", t.weld.is_some()),
        ];
        let size = |kind: &str, n: usize, axes: &str| -> Result<Vec<usize>, String> {
            let size = need(kind, "size", t.size.clone())?;
            if size.len() == n {
                Ok(size)
            } else {
                Err(format!(
                    "`size` of kind = \"{kind}\": expected {n} numbers {axes}, found {}",
                    size.len()
                ))
            }
        };
        Ok(match t.kind {
            ShapeKind::Chain => {
                only("chain", &["count", "spacing"], &present)?;
                ShapeSpec::Chain {
                    count: need("chain", "count", t.count)?,
                    spacing: need("chain", "spacing", t.spacing)?,
                }
            }
            ShapeKind::Grid => {
                only("grid", &["size", "spacing"], &present)?;
                let s = size("grid", 2, "[nx, nz]")?;
                ShapeSpec::Grid {
                    size: [s[0], s[1]],
                    spacing: need("grid", "spacing", t.spacing)?,
                }
            }
            ShapeKind::Lattice => {
                only("lattice", &["size", "spacing"], &present)?;
                let s = size("lattice", 3, "[nx, ny, nz]")?;
                ShapeSpec::Lattice {
                    size: [s[0], s[1], s[2]],
                    spacing: need("lattice", "spacing", t.spacing)?,
                }
            }
            ShapeKind::Points => {
                only("points", &["positions"], &present)?;
                ShapeSpec::Points {
                    positions: need("points", "positions", t.positions)?,
                }
            }
            ShapeKind::Mesh => {
                only("mesh", &["path", "scale", "weld"], &present)?;
                ShapeSpec::Mesh {
                    path: need("mesh", "path", t.path)?,
                    scale: t.scale.unwrap_or([Positive::of(1.0); 3]),
                    weld: t.weld,
                }
            }
            ShapeKind::Solid => {
                only("solid", &["path", "scale", "spacing"], &present)?;
                ShapeSpec::Solid {
                    path: need("solid", "path", t.path)?,
                    scale: t.scale.unwrap_or([Positive::of(1.0); 3]),
                    spacing: need("solid", "spacing", t.spacing)?,
                }
            }
        })
    }
}

/// A collider's `shape` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ColliderShapeTable {
    kind: ColliderKind,
    height: Option<Finite>,
    coefficients: Option<[Finite; 4]>,
    min: Option<[Finite; 3]>,
    max: Option<[Finite; 3]>,
    center: Option<[Finite; 3]>,
    radius: Option<Positive>,
    thickness: Option<Positive>,
    path: Option<String>,
    translate: Option<[Finite; 3]>,
    rotate: Option<[Finite; 3]>,
    scale: Option<[Positive; 3]>,
}

#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ColliderKind {
    Ground,
    Plane,
    Box,
    Cylinder,
    Sphere,
    Mesh,
}

impl TryFrom<ColliderShapeTable> for ColliderShapeSpec {
    type Error = String;

    fn try_from(t: ColliderShapeTable) -> Result<Self, String> {
        let present = [
            ("height", t.height.is_some()),
            ("coefficients", t.coefficients.is_some()),
            ("min", t.min.is_some()),
            ("max", t.max.is_some()),
            ("center", t.center.is_some()),
            ("radius", t.radius.is_some()),
            ("thickness", t.thickness.is_some()),
            ("path", t.path.is_some()),
            ("translate", t.translate.is_some()),
            ("rotate", t.rotate.is_some()),
            ("scale", t.scale.is_some()),
        ];
        Ok(match t.kind {
            ColliderKind::Ground => {
                only("ground", &["height"], &present)?;
                ColliderShapeSpec::Ground {
                    height: need("ground", "height", t.height)?,
                }
            }
            ColliderKind::Plane => {
                only("plane", &["coefficients"], &present)?;
                ColliderShapeSpec::Plane {
                    coefficients: need("plane", "coefficients", t.coefficients)?,
                }
            }
            ColliderKind::Box => {
                only("box", &["min", "max"], &present)?;
                ColliderShapeSpec::Box {
                    min: need("box", "min", t.min)?,
                    max: need("box", "max", t.max)?,
                }
            }
            ColliderKind::Cylinder => {
                only("cylinder", &["center", "radius", "thickness"], &present)?;
                ColliderShapeSpec::Cylinder {
                    center: need("cylinder", "center", t.center)?,
                    radius: need("cylinder", "radius", t.radius)?,
                    thickness: need("cylinder", "thickness", t.thickness)?,
                }
            }
            ColliderKind::Sphere => {
                only("sphere", &["center", "radius"], &present)?;
                ColliderShapeSpec::Sphere {
                    center: need("sphere", "center", t.center)?,
                    radius: need("sphere", "radius", t.radius)?,
                }
            }
            ColliderKind::Mesh => {
                only("mesh", &["path", "translate", "rotate", "scale"], &present)?;
                ColliderShapeSpec::Mesh {
                    path: need("mesh", "path", t.path)?,
                    translate: t.translate.unwrap_or([Finite::of(0.0); 3]),
                    rotate: t.rotate.unwrap_or([Finite::of(0.0); 3]),
                    scale: t.scale.unwrap_or([Positive::of(1.0); 3]),
                }
            }
        })
    }
}

/// A collider's `response` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ResponseTable {
    kind: ResponseKind,
    kc: Option<NonNegative>,
    dc: Option<NonNegative>,
    cr: Option<Fraction>,
    friction: Option<NonNegative>,
}

#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ResponseKind {
    Penalty,
    Restitution,
    Stick,
}

impl TryFrom<ResponseTable> for ResponseSpec {
    type Error = String;

    fn try_from(t: ResponseTable) -> Result<Self, String> {
        let present = [
            ("kc", t.kc.is_some()),
            ("dc", t.dc.is_some()),
            ("cr", t.cr.is_some()),
            ("friction", t.friction.is_some()),
        ];
        Ok(match t.kind {
            ResponseKind::Penalty => {
                only("penalty", &["kc", "dc"], &present)?;
                ResponseSpec::Penalty {
                    kc: need("penalty", "kc", t.kc)?,
                    dc: need("penalty", "dc", t.dc)?,
                }
            }
            ResponseKind::Restitution => {
                only("restitution", &["cr", "friction"], &present)?;
                ResponseSpec::Restitution {
                    cr: need("restitution", "cr", t.cr)?,
                    friction: t.friction.unwrap_or(NonNegative::of(0.0)),
                }
            }
            ResponseKind::Stick => {
                only("stick", &[], &present)?;
                ResponseSpec::Stick
            }
        })
    }
}
