//! Monotone piecewise cubic Hermite interpolation (PCHIP; Fritsch & Carlson, "Monotone piecewise
//! cubic interpolation", SIAM J. Numer. Anal. 17 (1980) 238–246), with the slopes of
//! scipy's `PchipInterpolator`: weighted harmonic means inside, the shape-preserving three-point
//! formula at the ends. The interpolant is monotone wherever the data are, never overshoots them,
//! and is constant beyond the end points.

/// A PCHIP interpolant through `(x_k, y_k)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Pchip {
    x: Vec<f64>,
    y: Vec<f64>,
    d: Vec<f64>,
}

/// Why the points cannot be interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PchipError {
    /// Fewer than two points.
    #[error("at least two points are needed")]
    TooFewPoints,
    /// The abscissae are not strictly increasing (or not finite) at this index.
    #[error("abscissae must be finite and strictly increasing (index {0})")]
    NotIncreasing(usize),
    /// An ordinate is not finite at this index.
    #[error("ordinates must be finite (index {0})")]
    NonFinite(usize),
}

impl Pchip {
    /// The interpolant through the points.
    ///
    /// # Errors
    /// Fewer than two points, abscissae not finite and strictly increasing, ordinates not finite.
    pub fn new(x: &[f64], y: &[f64]) -> Result<Self, PchipError> {
        let n = x.len().min(y.len());
        if n < 2 {
            return Err(PchipError::TooFewPoints);
        }
        if let Some(i) = (0..n).find(|&i| !x[i].is_finite() || (i > 0 && x[i] <= x[i - 1])) {
            return Err(PchipError::NotIncreasing(i));
        }
        if let Some(i) = (0..n).find(|&i| !y[i].is_finite()) {
            return Err(PchipError::NonFinite(i));
        }
        let h: Vec<f64> = (0..n - 1).map(|k| x[k + 1] - x[k]).collect();
        let delta: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
        let mut d = vec![0.0; n];
        if n == 2 {
            d[0] = delta[0];
            d[1] = delta[0];
        } else {
            for k in 1..n - 1 {
                let (a, b) = (delta[k - 1], delta[k]);
                if a * b > 0.0 {
                    let w1 = 2.0 * h[k] + h[k - 1];
                    let w2 = h[k] + 2.0 * h[k - 1];
                    d[k] = (w1 + w2) / (w1 / a + w2 / b);
                }
            }
            d[0] = edge(h[0], h[1], delta[0], delta[1]);
            d[n - 1] = edge(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
        }
        Ok(Self {
            x: x[..n].to_vec(),
            y: y[..n].to_vec(),
            d,
        })
    }

    /// The interpolant at `t` (the end values beyond the end points).
    #[must_use]
    pub fn eval(&self, t: f64) -> f64 {
        let n = self.x.len();
        if t <= self.x[0] {
            return self.y[0];
        }
        if t >= self.x[n - 1] {
            return self.y[n - 1];
        }
        let k = self.x.partition_point(|&v| v <= t).clamp(1, n - 1) - 1;
        let h = self.x[k + 1] - self.x[k];
        let s = (t - self.x[k]) / h;
        let (y0, y1, d0, d1) = (self.y[k], self.y[k + 1], self.d[k], self.d[k + 1]);
        // h00 = 1 − h01: written as y0 + h01·(y1 − y0), exact on flat segments.
        let h10 = s * (1.0 - s) * (1.0 - s);
        let h01 = s * s * (3.0 - 2.0 * s);
        let h11 = s * s * (s - 1.0);
        y0 + h01 * (y1 - y0) + h * (h10 * d0 + h11 * d1)
    }
}

/// The shape-preserving three-point end slope (scipy `PchipInterpolator._edge_case`).
fn edge(h0: f64, h1: f64, m0: f64, m1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if d.signum() != m0.signum() || m0 == 0.0 {
        0.0
    } else if m0.signum() != m1.signum() && d.abs() > 3.0 * m0.abs() {
        3.0 * m0
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_stays_monotone() {
        let p = Pchip::new(&[0.0, 1.0, 2.0, 3.0], &[0.0, 0.0, 1.0, 1.0]).unwrap();
        assert_eq!((p.eval(1.0)).to_bits(), f64::to_bits(0.0));
        assert_eq!((p.eval(2.0)).to_bits(), f64::to_bits(1.0));
        let mut last = -1.0;
        for i in 0..=300 {
            let v = p.eval(f64::from(i) / 100.0);
            assert!((0.0..=1.0).contains(&v) && v >= last, "{i} {v} {last}");
            last = v;
        }
        assert_eq!((p.eval(-5.0)).to_bits(), f64::to_bits(0.0));
        assert_eq!((p.eval(9.0)).to_bits(), f64::to_bits(1.0));
    }

    #[test]
    fn matches_scipy() {
        // scipy 1.17.1: PchipInterpolator([0, 1, 3, 4], [0, 2, 3, 7])(x)
        let p = Pchip::new(&[0.0, 1.0, 3.0, 4.0], &[0.0, 2.0, 3.0, 7.0]).unwrap();
        let cases = [
            (0.5, 1.205_357_142_857_142_8),
            (2.0, 2.471_042_471_042_471),
            (3.5, 4.475_788_288_288_288),
        ];
        for (t, e) in cases {
            assert!((p.eval(t) - e).abs() < 1e-12, "{t}: {}", p.eval(t));
        }
        assert!(Pchip::new(&[0.0, 0.0], &[1.0, 2.0]).is_err());
    }
}
