//! Angle conventions shared by every module: wrapping to a half-open interval and unwrapping a
//! sampled angle along a sweep.

use std::f64::consts::{PI, TAU};

/// Wraps an angle \[rad\] to (−π, π]. Angles already inside are returned unchanged (bit for bit).
#[must_use]
pub fn wrap_pi(theta: f64) -> f64 {
    if theta > -PI && theta <= PI {
        return theta;
    }
    let t = (theta + PI).rem_euclid(TAU) - PI;
    if t <= -PI { t + TAU } else { t }
}

/// Wraps an angle \[rad\] to [0, 2π). Angles already inside are returned unchanged.
#[must_use]
pub fn wrap_2pi(theta: f64) -> f64 {
    if (0.0..TAU).contains(&theta) {
        return theta;
    }
    let t = theta.rem_euclid(TAU);
    // rem_euclid can round up to exactly TAU for tiny negative inputs.
    if t >= TAU { 0.0 } else { t }
}

/// Wraps an angle \[rad\] to (−180°, 180°] and converts it to degrees.
#[must_use]
pub fn wrap_deg(theta: f64) -> f64 {
    let d = wrap_pi(theta).to_degrees();
    if d <= -180.0 { d + 360.0 } else { d }
}

/// Unwraps samples of an angle \[rad\] in place: each step is moved by a multiple of 2π so that it
/// differs from the previous sample by at most π (the continuous branch along a sweep).
pub fn unwrap_in_place(angles: &mut [f64]) {
    let mut offset = 0.0;
    let mut prev: Option<f64> = None;
    for a in angles.iter_mut() {
        let raw = *a;
        if let Some(p) = prev {
            let d = raw + offset - p;
            offset -= TAU * (d / TAU).round();
        }
        *a = raw + offset;
        prev = Some(*a);
    }
}

/// Sine and cosine of an angle given in degrees, `(sin, cos)`, exact at every multiple of 90°
/// (`sin_cos_deg(90.0) == (1.0, 0.0)`, not `cos(π/2) ≈ 6e-17`) and for any finite argument: the
/// angle is reduced modulo 360° first (exact in floating point), then to the nearest multiple of
/// 90° plus a remainder in [−45°, 45°]. Zero results are `+0.0`.
#[must_use]
#[inline]
pub fn sin_cos_deg(deg: f64) -> (f64, f64) {
    // `%` is exact and the identity below 360° in magnitude: skip its libm call there (sweeps).
    let d = if deg.abs() < 360.0 { deg } else { deg % 360.0 };
    let q = (d / 90.0).round();
    let r = d - 90.0 * q;
    let (s, c) = if r == 0.0 {
        (0.0, 1.0)
    } else {
        r.to_radians().sin_cos()
    };
    // q is a whole number in [−4, 4] (|d| < 360): the cast is exact.
    match (q as i64).rem_euclid(4) {
        1 => (c, 0.0 - s),
        2 => (0.0 - s, 0.0 - c),
        3 => (0.0 - c, s),
        _ => (s, c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_pi_range() {
        assert!((wrap_pi(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(-PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(0.1) - 0.1).abs() < 1e-17);
        assert!((wrap_pi(-7.0) - (-7.0 + TAU)).abs() < 1e-12);
    }

    #[test]
    fn wrap_2pi_range() {
        assert!((wrap_2pi(-0.5) - (TAU - 0.5)).abs() < 1e-12);
        assert!(wrap_2pi(-1e-300) < TAU);
        assert!((wrap_2pi(7.0) - (7.0 - TAU)).abs() < 1e-12);
    }

    #[test]
    fn wrap_deg_range() {
        assert!((wrap_deg(PI) - 180.0).abs() < 1e-12);
        assert!((wrap_deg(-PI) - 180.0).abs() < 1e-12);
        assert!((wrap_deg(-0.5 * PI) + 90.0).abs() < 1e-12);
    }

    #[test]
    fn sin_cos_deg_is_exact_at_quadrants() {
        for (d, s, c) in [
            (0.0, 0.0, 1.0),
            (90.0, 1.0, 0.0),
            (180.0, 0.0, -1.0),
            (270.0, -1.0, 0.0),
            (-90.0, -1.0, 0.0),
            (720.0, 0.0, 1.0),
            (-450.0, -1.0, 0.0),
        ] {
            let (gs, gc) = sin_cos_deg(d);
            assert!(
                gs.to_bits() == f64::to_bits(s) && gc.to_bits() == f64::to_bits(c),
                "{d}: {gs} {gc}"
            );
        }
        for i in -800..800 {
            let d = f64::from(i) * 0.7 + 0.013;
            let (s, c) = sin_cos_deg(d);
            let (es, ec) = d.to_radians().sin_cos();
            assert!((s - es).abs() < 1e-14 && (c - ec).abs() < 1e-14, "{d}");
        }
    }

    #[test]
    fn unwrap_follows_the_branch() {
        let n = 50;
        let truth: Vec<f64> = (0..n).map(|i| 0.4 * f64::from(i)).collect();
        let mut wrapped: Vec<f64> = truth.iter().map(|&t| wrap_pi(t)).collect();
        unwrap_in_place(&mut wrapped);
        for (a, b) in wrapped.iter().zip(&truth) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
