//! Each integrator on the built-in `single-spring` against the damped oscillator's closed
//! form: the error at a sweep of step sizes and its fitted order, and the step at which the
//! scheme goes unstable against linear stability theory and `hooke check`'s estimate.

use crate::Result;
use hooke_core::Integrator;
use hooke_scene::Overrides;
use hooke_scene::builtin::{SINGLE_SPRING_KD, SINGLE_SPRING_KS};
use serde::Serialize;

/// Standard gravity, m/s² (docs/physics.md §1): written here, not read from the scene, so
/// that a scene with another gravity fails the comparison.
pub(crate) const G: f64 = 9.81;
/// The single spring's mass (kg), rest length (m), anchor height and release height (m).
const MASS: f64 = 1.0;
const REST: f64 = 1.0;
const ANCHOR: f64 = 2.0;
const RELEASE: f64 = 0.5;
/// Simulated time over which the error is the largest difference, s.
const SPAN: f64 = 2.0;

/// The order each scheme has (docs/physics.md §4).
pub(crate) fn expected_order(i: Integrator) -> f64 {
    match i {
        Integrator::Midpoint => 2.0,
        Integrator::Rk4 => 4.0,
        _ => 1.0,
    }
}

/// The mass's height at time `t` by the closed form: released at rest `RELEASE`, it
/// oscillates about `ANCHOR − REST − m g / k` with damping ratio `ζ = kd / (2 √(k m))`.
pub(crate) fn exact_height(t: f64) -> f64 {
    let (k, c, m) = (SINGLE_SPRING_KS, SINGLE_SPRING_KD, MASS);
    let rest = ANCHOR - REST - m * G / k;
    let omega = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let a = RELEASE - rest;
    rest + a * (-zeta * omega * t).exp() * ((wd * t).cos() + zeta * omega / wd * (wd * t).sin())
}

/// One integrator's sweep.
#[derive(Serialize)]
pub(crate) struct Sweep {
    pub(crate) integrator: String,
    /// `(dt, largest height error over the span)`.
    pub(crate) points: Vec<(f64, f64)>,
    pub(crate) slope: f64,
    pub(crate) expected: f64,
    /// The step beyond which theory says the scheme grows on this spring (`inf`: never).
    pub(crate) theory_limit: f64,
    /// The step beyond which it grew here (`inf`: stable at every step tried).
    pub(crate) measured_limit: f64,
    /// `hooke check`'s estimate: the scheme's stability radius over ω_max.
    pub(crate) check_limit: f64,
}

/// How far a fitted order may lie from the scheme's.
pub(crate) const SLOPE_TOLERANCE: f64 = 0.1;
/// How far the measured stability limit may lie from theory's, as a share.
pub(crate) const STABILITY_TOLERANCE: f64 = 0.05;

impl Sweep {
    /// Whether the fitted order is the scheme's (NaN is not).
    pub(crate) fn order_agrees(&self) -> bool {
        (self.slope - self.expected).abs() <= SLOPE_TOLERANCE
    }

    /// Whether the step it went unstable at is theory's (for a scheme theory says never
    /// goes unstable: it never did).
    pub(crate) fn stability_agrees(&self) -> bool {
        if self.theory_limit.is_finite() {
            (self.measured_limit / self.theory_limit - 1.0).abs() <= STABILITY_TOLERANCE
        } else {
            self.measured_limit.is_infinite()
        }
    }
}

/// The steps of each scheme's sweep: small enough to be in its asymptotic range, large
/// enough to stay above round-off.
fn steps_for(i: Integrator, quick: bool) -> Vec<f64> {
    let (first, count) = match i {
        Integrator::Rk4 => (1.25e-3, 5),
        Integrator::Midpoint => (5e-4, 5),
        Integrator::Symplectic => (2.5e-4, 5),
        _ => (1e-4, 5),
    };
    let count = if quick { count - 2 } else { count };
    // Quick sweeps keep the largest steps: cheaper, and still asymptotic.
    let skip = 5 - count;
    (skip..5).map(|k| first * f64::powi(2.0, k)).collect()
}

/// Runs `single-spring` with `integrator` at `dt` for `steps` steps, calling `each` with
/// the time and the mass's height after every step; `None` when it diverged.
fn run(i: Integrator, dt: f64, steps: u64, mut each: impl FnMut(f64, f64)) -> Result<Option<()>> {
    let overrides = Overrides {
        integrator: Some(i),
        dt: Some(dt),
        steps: Some(steps),
        ..Overrides::default()
    };
    let mut scene = crate::source::build("single-spring", &overrides)?;
    for n in 1..=steps {
        crate::interrupt::check(&scene.simulation)?;
        if scene.simulation.step().is_err() {
            return Ok(None);
        }
        each(n as f64 * dt, scene.simulation.particles().x[1].y);
    }
    Ok(Some(()))
}

/// The largest height error over [`SPAN`] at step `dt`.
fn error_at(i: Integrator, dt: f64) -> Result<f64> {
    let steps = (SPAN / dt).round() as u64;
    let mut worst: f64 = 0.0;
    let finished = run(i, dt, steps, |t, y| {
        worst = worst.max((y - exact_height(t)).abs())
    })?;
    Ok(if finished.is_some() {
        worst
    } else {
        f64::INFINITY
    })
}

/// Least-squares slope of `ln e` over `ln dt`.
pub(crate) fn fitted_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(d, e)| (d.ln(), e.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// The spectral radius of one step of the scheme on `x'' + 2ζω x' + ω² x = 0` at step `h`.
fn amplification(i: Integrator, h: f64, omega: f64, zeta: f64) -> f64 {
    // The eigenvalues λ = ω(−ζ ± i√(1 − ζ²)); a one-step method multiplies by R(hλ).
    let (re, im) = (-zeta * omega * h, omega * h * (1.0 - zeta * zeta).sqrt());
    let poly = |coefficients: &[f64]| {
        // Σ c_k z^k at z = re + i im.
        let (mut pr, mut pi) = (1.0, 0.0);
        let (mut sr, mut si) = (0.0, 0.0);
        for c in coefficients {
            sr += c * pr;
            si += c * pi;
            (pr, pi) = (pr * re - pi * im, pr * im + pi * re);
        }
        (sr * sr + si * si).sqrt()
    };
    match i {
        Integrator::Euler => poly(&[1.0, 1.0]),
        Integrator::Midpoint => poly(&[1.0, 1.0, 0.5]),
        Integrator::Rk4 => poly(&[1.0, 1.0, 0.5, 1.0 / 6.0, 1.0 / 24.0]),
        Integrator::Symplectic => {
            // v' = v + h(−ω² x − 2ζω v), x' = x + h v': a 2×2 matrix; its eigenvalues'
            // largest modulus.
            let (w2, c) = (omega * omega, 2.0 * zeta * omega);
            let m = [
                [1.0 - h * h * w2, h * (1.0 - h * c)],
                [-h * w2, 1.0 - h * c],
            ];
            let tr = m[0][0] + m[1][1];
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            let disc = tr * tr / 4.0 - det;
            if disc >= 0.0 {
                let s = disc.sqrt();
                (tr / 2.0 + s).abs().max((tr / 2.0 - s).abs())
            } else {
                det.sqrt()
            }
        }
        _ => 0.0,
    }
}

/// The smallest step at which the scheme's amplification exceeds 1, by a fine scan then
/// bisection; infinite for the implicit schemes.
fn theory_limit(i: Integrator) -> f64 {
    if i.stability_radius().is_infinite() {
        return f64::INFINITY;
    }
    let omega = (SINGLE_SPRING_KS / MASS).sqrt();
    let zeta = SINGLE_SPRING_KD / (2.0 * (SINGLE_SPRING_KS * MASS).sqrt());
    let grows = |h: f64| amplification(i, h, omega, zeta) > 1.0;
    let (mut lo, mut hi) = (1e-6, 1e-6);
    while !grows(hi) {
        lo = hi;
        hi *= 1.01;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if grows(mid) { hi = mid } else { lo = mid }
    }
    0.5 * (lo + hi)
}

/// Whether the single spring's swing grew over `steps` steps of `dt`: larger in the last
/// quarter than in the first, or up to the anchor. A swing that reaches the anchor leaves
/// the linear range (the spring folds over) and may stay bounded there; below it, a stable
/// scheme's swing only exceeds its start by its modified amplitude (symplectic Euler's
/// `1/√(1 − (ω dt / 2)²)`, under 2.7 until ω dt = 1.86).
fn grew(i: Integrator, dt: f64, steps: u64) -> Result<bool> {
    let rest = ANCHOR - REST - MASS * G / SINGLE_SPRING_KS;
    let (mut first, mut last, mut most) = (0.0f64, 0.0f64, 0.0f64);
    let quarter = steps / 4;
    let mut n = 0;
    let finished = run(i, dt, steps, |_, y| {
        n += 1;
        let d = (y - rest).abs();
        most = most.max(d);
        if n <= quarter {
            first = first.max(d);
        } else if n > steps - quarter {
            last = last.max(d);
        }
    })?;
    Ok(finished.is_none() || !most.is_finite() || most >= ANCHOR - rest || last > first)
}

/// The step beyond which the swing grows, bisected between a fraction and a multiple of
/// `guess` (to 1 %); infinite when it never grows up to 100× the guess.
fn measured_limit(i: Integrator, guess: f64, quick: bool) -> Result<f64> {
    let steps = if quick { 800 } else { 3000 };
    let guess = if guess.is_finite() { guess } else { 0.05 };
    let (mut lo, mut hi) = (0.5 * guess, 2.0 * guess);
    if grew(i, lo, steps)? {
        return Ok(lo);
    }
    if !grew(i, hi, steps)? {
        // Try far beyond: a scheme that never grows (backward Euler) stays bounded.
        return Ok(if grew(i, 100.0 * guess, steps)? {
            hi
        } else {
            f64::INFINITY
        });
    }
    while hi / lo > 1.01 {
        let mid = (lo * hi).sqrt();
        if grew(i, mid, steps)? {
            hi = mid
        } else {
            lo = mid
        }
    }
    Ok((lo * hi).sqrt())
}

/// Every integrator's sweep and stability limits; `tick` is called after each run group.
pub(crate) fn sweeps(quick: bool, tick: &mut dyn FnMut()) -> Result<Vec<Sweep>> {
    let check = crate::source::build("single-spring", &Overrides::default())?
        .simulation
        .stability();
    let mut out = Vec::new();
    for i in Integrator::ALL {
        let points = steps_for(i, quick)
            .into_iter()
            .map(|dt| error_at(i, dt).map(|e| (dt, e)))
            .collect::<Result<Vec<_>>>()?;
        tick();
        let theory = theory_limit(i);
        let measured = measured_limit(i, theory, quick)?;
        tick();
        out.push(Sweep {
            integrator: i.to_string(),
            slope: fitted_slope(&points),
            expected: expected_order(i),
            points,
            theory_limit: theory,
            measured_limit: measured,
            check_limit: check.max_dt(i),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closed_form_starts_at_the_release_at_rest() {
        assert!((exact_height(0.0) - RELEASE).abs() < 1e-15);
        let h = 1e-6;
        assert!((exact_height(h) - exact_height(0.0)).abs() < 1e-9);
    }

    #[test]
    fn a_fitted_slope_of_a_power_law_is_its_exponent() {
        let points: Vec<_> = [1e-3, 2e-3, 4e-3]
            .iter()
            .map(|&d: &f64| (d, 3.0 * d.powi(2)))
            .collect();
        assert!((fitted_slope(&points) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn stability_theory_gives_the_textbook_limits_without_damping() {
        // Undamped: symplectic Euler is stable up to h ω = 2, RK4 up to 2√2.
        assert!(amplification(Integrator::Symplectic, 0.199, 10.0, 0.0) <= 1.0 + 1e-12);
        assert!(amplification(Integrator::Symplectic, 0.201, 10.0, 0.0) > 1.0);
        assert!(amplification(Integrator::Rk4, 0.282, 10.0, 0.0) <= 1.0);
        assert!(amplification(Integrator::Rk4, 0.284, 10.0, 0.0) > 1.0);
        // Explicit Euler grows on an undamped spring at any step.
        assert!(amplification(Integrator::Euler, 1e-4, 10.0, 0.0) > 1.0);
    }
}
