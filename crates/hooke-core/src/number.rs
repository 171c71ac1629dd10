//! Numbers as people read them: the shortest decimal that reads back to the same `f64`,
//! plain for everyday magnitudes and scientific far from 1 (`1e300`, `2.5e-7`, not
//! 300 digits or 80 characters of zeros).

use std::fmt;

/// An `f64` displayed in its shortest round-trip digits: plain (`0.25`, `1500`) for
/// magnitudes from 1e-5 up to 1e16, as ryu does, and outside that range in whichever of
/// plain and scientific form is shorter. Parsing the text with `str::parse::<f64>` gives
/// the same bits.
///
/// ```
/// use hooke_core::Num;
/// assert_eq!(Num(0.25).to_string(), "0.25");
/// assert_eq!(Num(1e300).to_string(), "1e300");
/// assert_eq!(Num(-2.5e-20).to_string(), "-2.5e-20");
/// assert_eq!(Num(1500.0).to_string(), "1500");
/// assert_eq!(Num(f64::NAN).to_string(), "NaN");
/// let x = 1.0 / 3.0e15;
/// assert_eq!(Num(x).to_string().parse::<f64>().unwrap(), x);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if !x.is_finite() || x == 0.0 {
            return write!(f, "{x}");
        }
        // Both forms are Rust's shortest round-trip digits; only the exponent differs.
        if (1e-5..1e16).contains(&x.abs()) {
            return write!(f, "{x}");
        }
        let plain = x.to_string();
        let scientific = format!("{x:e}");
        f.write_str(if scientific.len() < plain.len() {
            &scientific
        } else {
            &plain
        })
    }
}

/// An `f64` to four significant digits for messages, where the last bits are noise to a
/// reader (`2.3` for `2.3000000000000003`): plain from 1e-4 up to 1e9, scientific outside,
/// trailing zeros dropped. Not for values that must read back exactly: [`Num`] is.
///
/// ```
/// use hooke_core::Approx;
/// assert_eq!(Approx(2.3000000000000003).to_string(), "2.3");
/// assert_eq!(Approx(0.041666666666666685).to_string(), "0.04167");
/// assert_eq!(Approx(99999.29856).to_string(), "99999");
/// assert_eq!(Approx(2.7755575615628914e-17).to_string(), "2.776e-17");
/// assert_eq!(Approx(-1.5e12).to_string(), "-1.5e12");
/// assert_eq!(Approx(0.0).to_string(), "0");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Approx(pub f64);

impl fmt::Display for Approx {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if !x.is_finite() || x == 0.0 {
            return write!(f, "{x}");
        }
        let trim = |t: String| -> String {
            if t.contains('.') {
                t.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                t
            }
        };
        if (1e-4..1e9).contains(&x.abs()) {
            // Four significant digits: decimals after the point from the magnitude.
            let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
            return f.write_str(&trim(format!("{x:.digits$}")));
        }
        let text = format!("{x:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        write!(f, "{}e{exponent}", trim(mantissa.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shorter_form_is_chosen_and_reads_back_exactly() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let x = f64::from_bits(seed);
            if !x.is_finite() {
                continue;
            }
            let text = Num(x).to_string();
            assert_eq!(
                text.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{text}"
            );
            let plain = x.to_string();
            let scientific = format!("{x:e}");
            if !(1e-5..1e16).contains(&x.abs()) {
                assert_eq!(text.len(), plain.len().min(scientific.len()), "{x:e}");
            } else {
                assert_eq!(text, plain);
            }
        }
        assert_eq!(Num(1e-4).to_string(), "0.0001");
        assert_eq!(Num(1000.0).to_string(), "1000");
        assert_eq!(Num(1.2345e-6).to_string(), "1.2345e-6");
        assert_eq!(Num(123456789012345680.0).to_string(), "123456789012345680");
        assert_eq!(Num(2e17).to_string(), "2e17");
    }
}
