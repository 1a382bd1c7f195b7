//! Numbers for people: fixed decimals without "-0.00", and uncertainties with enough digits to be
//! non-zero when they are.

/// `x` with `decimals` decimals; a value that rounds to zero prints without a minus sign.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

/// `x` with its sign and `decimals` decimals ("+0.12", "-0.12"); a value that rounds to zero
/// prints as "0.00".
pub fn signed(x: f64, decimals: usize) -> String {
    let s = fixed(x, decimals);
    if s.bytes().all(|b| b == b'0' || b == b'.') || s.starts_with('-') {
        s
    } else {
        format!("+{s}")
    }
}

/// An uncertainty (≥ 0) with at least `min_decimals` decimals and as many more as its first
/// significant digit needs: 0.004 → "0.004", 0.0004 → "0.0004", 0.04 → "0.04" (two minimum), 0 → "0.00".
pub fn uncertainty(x: f64, min_decimals: usize) -> String {
    // Below a microkelvin a ± is rounding noise (a uniform room's 1e-12 K), not a digit to show.
    if !(x.is_finite() && x >= 1e-6) {
        return fixed(0.0, min_decimals);
    }
    let first_digit = (-x.log10()).ceil().max(0.0) as usize;
    fixed(x, first_digit.clamp(min_decimals, 9))
}

/// A point's coordinates, "(x, y, z)" with 2 decimals.
pub fn xyz(p: &[f64; 3]) -> String {
    format!(
        "({}, {}, {})",
        fixed(p[0], 2),
        fixed(p[1], 2),
        fixed(p[2], 2)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vanishing_uncertainty_is_zero_at_the_least_decimals() {
        assert_eq!(uncertainty(3e-13, 3), "0.000");
        assert_eq!(uncertainty(0.0004, 3), "0.0004");
        assert_eq!(uncertainty(f64::NAN, 2), "0.00");
    }

    #[test]
    fn no_negative_zero() {
        assert_eq!(fixed(-0.001, 2), "0.00");
        assert_eq!(fixed(-0.0, 2), "0.00");
        assert_eq!(fixed(-0.006, 2), "-0.01");
        assert_eq!(fixed(-1.234, 1), "-1.2");
        assert_eq!(xyz(&[-0.004, 1.0, -2.5]), "(0.00, 1.00, -2.50)");
        assert_eq!(signed(-0.001, 2), "0.00");
        assert_eq!(signed(0.123, 2), "+0.12");
        assert_eq!(signed(-0.126, 2), "-0.13");
    }

    #[test]
    fn uncertainties_show_their_first_digit() {
        assert_eq!(uncertainty(0.004, 2), "0.004");
        assert_eq!(uncertainty(0.0004, 2), "0.0004");
        assert_eq!(uncertainty(0.04, 2), "0.04");
        assert_eq!(uncertainty(0.009, 2), "0.009");
        assert_eq!(uncertainty(0.123, 2), "0.12");
        assert_eq!(uncertainty(0.0, 2), "0.00");
        assert_eq!(uncertainty(3.0, 2), "3.00");
    }
}
