//! The quantities a picture can colour the bodies by (`--color`): each particle's strain,
//! speed or gap, the colour map and legend each is shown with, and its default range.

use hooke_core::{SpringKind, Vec3};
use hooke_render::{ColorMap, Legend, Rgb};
use hooke_scene::Scene;

/// What colours the bodies' surfaces and beads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ColorBy {
    /// The bodies' own colours.
    #[default]
    None,
    /// Each structural spring's `(length − rest) / rest`, averaged to its two particles, in
    /// percent, on a diverging map centred on 0 (stretched red, compressed blue).
    Strain,
    /// Each particle's speed, m/s, on viridis.
    Speed,
    /// Each particle's distance to the nearest collider surface, m, on viridis, with the
    /// bodies' contact thickness marked.
    Gap,
}

/// The farthest a gap is looked for, metres: farther shows as this.
const FARTHEST_GAP: f64 = 1.0;

impl ColorBy {
    /// The quantity named `none`, `strain`, `speed` or `gap` (any case).
    pub fn from_name(name: &str) -> Option<Self> {
        match name.to_ascii_lowercase().as_str() {
            "none" => Some(Self::None),
            "strain" => Some(Self::Strain),
            "speed" => Some(Self::Speed),
            "gap" => Some(Self::Gap),
            _ => None,
        }
    }

    /// Its map: diverging for strain, viridis otherwise.
    pub fn map(self) -> ColorMap {
        if self == Self::Strain {
            ColorMap::Coolwarm
        } else {
            ColorMap::Viridis
        }
    }

    /// The legend's title: the quantity and its unit.
    pub fn title(self) -> &'static str {
        match self {
            Self::None => "",
            Self::Strain => "strain (%)",
            Self::Speed => "speed (m/s)",
            Self::Gap => "gap (m)",
        }
    }

    /// Each particle's value (`None`: nothing to colour).
    pub fn values(self, scene: &Scene) -> Option<Vec<f64>> {
        let p = scene.simulation.particles();
        match self {
            Self::None => None,
            Self::Speed => Some(p.v.iter().map(|v| v.norm()).collect()),
            Self::Strain => Some(strain(scene)),
            Self::Gap => Some(p.x.iter().map(|x| gap(scene, x)).collect()),
        }
    }

    /// The range a still of `scene` shows `values` with when none is given: from 0 (strain:
    /// centred on 0, symmetric) to the largest magnitude rounded up to 1, 2 or 5 times a
    /// power of ten. A gap's range ends at ten contact thicknesses at most (and two at
    /// least), so that the thickness, where contacts act, takes a tenth of the bar or more
    /// rather than vanishing under its bottom label.
    pub fn default_range(self, scene: &Scene, values: &[f64]) -> (f64, f64) {
        let mut largest = values
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let thickness = largest_thickness(scene);
        if self == Self::Gap && thickness > 0.0 {
            largest = largest.min(10.0 * thickness).max(2.0 * thickness);
        }
        let top = nice(largest);
        if self == Self::Strain {
            (-top, top)
        } else {
            (0.0, top)
        }
    }

    /// The legend for `range`, with the contact thickness marked on a gap's.
    pub fn legend(self, scene: &Scene, range: (f64, f64)) -> Legend {
        let thickness = largest_thickness(scene);
        Legend {
            map: self.map(),
            range,
            title: self.title().to_string(),
            mark: (self == Self::Gap && thickness > 0.0).then(|| (thickness, "h".to_string())),
        }
    }

    /// Each particle's colour: its value's place in `range` on the map.
    pub fn colors(self, values: &[f64], (lo, hi): (f64, f64)) -> Vec<Rgb> {
        let span = hi - lo;
        values
            .iter()
            .map(|v| {
                let t = if span > 0.0 { (v - lo) / span } else { 0.5 };
                self.map().at(t)
            })
            .collect()
    }
}

/// The largest contact thickness of the scene's bodies, metres (0: none has one).
fn largest_thickness(scene: &Scene) -> f64 {
    scene
        .bodies
        .iter()
        .map(|b| b.thickness)
        .fold(0.0f64, f64::max)
}

/// The smallest of 1, 2, 5 times a power of ten at or above `x` (1e-9 for 0).
fn nice(x: f64) -> f64 {
    if !(x.is_finite() && x > 1e-9) {
        return 1e-9;
    }
    let power = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&v| v >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * power)
}

/// Per particle, the mean strain of its structural springs (all its springs when it has no
/// structural one, as a chain's), in percent; 0 for a particle without springs.
fn strain(scene: &Scene) -> Vec<f64> {
    let x = &scene.simulation.particles().x;
    let springs = &scene.simulation.model().springs;
    let mut sum = vec![(0.0, 0u32); x.len()];
    let mut any = vec![(0.0, 0u32); x.len()];
    for s in springs {
        let (i, j) = (s.i as usize, s.j as usize);
        let e = ((x[i] - x[j]).norm() - s.rest) / s.rest * 100.0;
        if !e.is_finite() {
            continue;
        }
        for k in [i, j] {
            any[k].0 += e;
            any[k].1 += 1;
            if s.kind == SpringKind::Structural {
                sum[k].0 += e;
                sum[k].1 += 1;
            }
        }
    }
    sum.iter()
        .zip(&any)
        .map(|(&(s, n), &(a, m))| {
            if n > 0 {
                s / n as f64
            } else if m > 0 {
                a / m as f64
            } else {
                0.0
            }
        })
        .collect()
}

/// The distance from `x` to the nearest collider surface (0 inside one), at most
/// [`FARTHEST_GAP`].
fn gap(scene: &Scene, x: &Vec3) -> f64 {
    let mut nearest = FARTHEST_GAP;
    for slot in &scene.simulation.model().colliders {
        if slot.shape.inside(x) {
            return 0.0;
        }
        slot.shape.contacts_within(x, FARTHEST_GAP, &mut |c| {
            nearest = nearest.min((FARTHEST_GAP - c.depth).max(0.0));
        });
    }
    nearest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_round_up_to_one_two_or_five() {
        assert_eq!(nice(0.7), 1.0);
        assert_eq!(nice(1.0), 1.0);
        assert_eq!(nice(1.3), 2.0);
        assert_eq!(nice(3.0), 5.0);
        assert_eq!(nice(0.012), 0.02);
        let cloth = crate::source::build("cloth-table", &Default::default()).unwrap();
        assert_eq!(
            ColorBy::Strain.default_range(&cloth, &[-0.3, 1.2]),
            (-2.0, 2.0)
        );
        assert_eq!(
            ColorBy::Speed.default_range(&cloth, &[0.3, 4.2]),
            (0.0, 5.0)
        );
        // A gap's range shows the 5 mm thickness: ten of them at most, two at least.
        assert_eq!(
            ColorBy::Gap.default_range(&cloth, &[0.001, 0.9]),
            (0.0, 0.05)
        );
        assert_eq!(
            ColorBy::Gap.default_range(&cloth, &[0.001, 0.004]),
            (0.0, 0.01)
        );
    }
}
