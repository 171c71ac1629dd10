//! Fitting a fabric's bending rigidity to a measured drape coefficient: bisection on the
//! logarithm of the rigidity, each try a run of the meter.

use crate::error::Result;
use hooke_scene::material::Material;

/// What [`fit_bending`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The bending rigidity, N·m: the last one tried, inside the final bracket.
    pub bending: f64,
    /// The mean DC it gave.
    pub dc: f64,
    /// The final bracket, N·m: DC was below the target at the first, above at the second.
    pub bracket: (f64, f64),
    /// Materials tried.
    pub evaluations: usize,
}

impl Fit {
    /// Whether the target lies outside what the fit's range of `B` gives: one end of the
    /// bracket never moved from the range's ([`FIT_RANGE`]: every DC tried was on one side
    /// of the target) and the last DC is more than a jump's height (0.02) from the target.
    pub fn outside(&self, target: f64) -> bool {
        let at_end = |b: f64, end: f64| (b / end - 1.0).abs() < 1e-9;
        (at_end(self.bracket.0, FIT_RANGE.0) || at_end(self.bracket.1, FIT_RANGE.1))
            && (self.dc - target).abs() > 0.02
    }
}

/// The range of bending rigidity `fit_bending` searches, N·m.
pub const FIT_RANGE: (f64, f64) = (1e-7, 1e-3);

/// The bending rigidity that gives `target` DC with `material`'s other values, by
/// bisection on `log B` between 0.1 and 1000 µN·m (DC rises with `B`) until the bracket
/// is within `tolerance` relative, or DC within 0.002 of the target; `evaluate` gives the
/// mean DC of a material. Where the node count jumps DC is not smooth in `B`, and the DC
/// reached may differ from the target by a jump's height: [`Fit::dc`] says what it was.
pub fn fit_bending(
    target: f64,
    material: &Material,
    tolerance: f64,
    evaluate: &mut dyn FnMut(&Material) -> Result<f64>,
) -> Result<Fit> {
    let (mut lo, mut hi) = (FIT_RANGE.0.ln(), FIT_RANGE.1.ln());
    let mut fit = Fit {
        bending: f64::NAN,
        dc: f64::NAN,
        bracket: (lo.exp(), hi.exp()),
        evaluations: 0,
    };
    while (hi - lo) > tolerance.ln_1p() {
        let mid = 0.5 * (lo + hi);
        let m = Material {
            bending: mid.exp(),
            ..*material
        };
        let dc = evaluate(&m)?;
        fit.bending = m.bending;
        fit.dc = dc;
        fit.evaluations += 1;
        if (dc - target).abs() < 0.002 {
            break;
        }
        if dc < target {
            lo = mid;
        } else {
            hi = mid;
        }
        fit.bracket = (lo.exp(), hi.exp());
    }
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cotton-like fabric whose rigidity the fits set.
    fn fabric() -> Material {
        Material {
            density: 0.15,
            stretch: 1000.0,
            shear: 50.0,
            bending: 0.0,
            damping: 1e-5,
        }
    }

    /// A target above (or below) every DC the range of B gives is said to lie outside
    /// it; one inside is not.
    #[test]
    fn a_target_no_rigidity_reaches_is_outside_the_fit() {
        let dc = |b: f64| 0.4 + 0.1 * (b / 1e-5).ln().tanh();
        let base = fabric();
        for (target, outside) in [(0.9, true), (0.2, true), (0.45, false)] {
            let fit = fit_bending(target, &base, 0.02, &mut |m| Ok(dc(m.bending))).unwrap();
            assert_eq!(fit.outside(target), outside, "{target}: {fit:?}");
        }
    }

    /// On a DC that rises smoothly with B the bisection finds the rigidity that gives
    /// the target within its tolerance, in about log₂(ln 10⁴ / ln 1.02) ≈ 9 tries.
    #[test]
    fn the_fit_recovers_a_rigidity_from_a_rising_coefficient() {
        let truth = 7.3e-6;
        let dc = |b: f64| 1.0 - 1.0 / (1.0 + (b / 2e-5).powf(0.8));
        let base = fabric();
        let fit = fit_bending(dc(truth), &base, 0.02, &mut |m| Ok(dc(m.bending))).unwrap();
        assert!((fit.bending / truth - 1.0).abs() < 0.03, "{fit:?}");
        assert!(fit.evaluations <= 10, "{fit:?}");
        assert!(
            fit.bracket.0 <= truth && truth <= fit.bracket.1 * 1.0001,
            "{fit:?}"
        );
    }
}
