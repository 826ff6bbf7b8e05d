//! Grids, finite-difference derivatives and table interpolation: the uniform grid and numpy's
//! second-order `gradient` (the motion-law fit derives a missing channel with them, its spec §3.3),
//! and clamped linear interpolation in a tabulated curve (battery OCV, motor envelopes, AC factors).

/// The uniform grid `x_k = start + k·(end − start)/(count − 1)`, `k = 0..count−1` (spec §2).
///
/// The last point is pinned to `end` exactly, as numpy's `linspace` does.
#[must_use]
pub fn linspace(start: f64, end: f64, count: usize) -> Vec<f64> {
    match count {
        0 => Vec::new(),
        1 => vec![start],
        _ => {
            // usize → f64 is exact for every accepted count (≤ 200 000 < 2^53).
            let step = (end - start) / (count - 1) as f64;
            let mut xs: Vec<f64> = (0..count)
                .map(|k| {
                    let kf = k as f64;
                    kf.mul_add(step, start)
                })
                .collect();
            if let Some(last) = xs.last_mut() {
                *last = end;
            }
            xs
        }
    }
}

/// Second-order finite-difference derivative `dy/dx`, equivalent to numpy's
/// `gradient(y, x, edge_order=2)` (spec §3.3 item 2).
///
/// Interior points use the three-point formula weighted for the (possibly non-uniform) spacing;
/// both ends use the one-sided second-order formulas. As numpy does, a grid whose spacings are all
/// bit-identical uses the uniform-step formulas. `x` must be strictly increasing and `x.len() ==
/// y.len() >= 3`; shorter inputs give a zero derivative (the fit never asks for them: N ≥ 8).
#[must_use]
pub fn gradient(y: &[f64], x: &[f64]) -> Vec<f64> {
    let n = y.len().min(x.len());
    let mut out = vec![0.0; n];
    if n < 3 {
        return out;
    }
    let h0 = x[1] - x[0];
    let uniform = x
        .windows(2)
        .all(|w| (w[1] - w[0]).to_bits() == h0.to_bits());
    if uniform {
        let h = h0;
        for i in 1..n - 1 {
            out[i] = (y[i + 1] - y[i - 1]) / (2.0 * h);
        }
        out[0] = (-1.5f64).mul_add(y[0], 2.0f64.mul_add(y[1], -0.5 * y[2])) / h;
        out[n - 1] = 1.5f64.mul_add(y[n - 1], (-2.0f64).mul_add(y[n - 2], 0.5 * y[n - 3])) / h;
        return out;
    }
    for i in 1..n - 1 {
        let hs = x[i] - x[i - 1];
        let hd = x[i + 1] - x[i];
        // numpy: (hs² y[i+1] + (hd² − hs²) y[i] − hd² y[i−1]) / (hs hd (hd + hs)), written
        // with numpy's coefficient order so round-off matches closely.
        let a = -hd / (hs * (hd + hs));
        let b = (hd - hs) / (hd * hs);
        let c = hs / (hd * (hd + hs));
        out[i] = a.mul_add(y[i - 1], b.mul_add(y[i], c * y[i + 1]));
    }
    {
        let dx1 = x[1] - x[0];
        let dx2 = x[2] - x[1];
        let a = -(2.0f64.mul_add(dx1, dx2)) / (dx1 * (dx1 + dx2));
        let b = (dx1 + dx2) / (dx1 * dx2);
        let c = -dx1 / (dx2 * (dx1 + dx2));
        out[0] = a.mul_add(y[0], b.mul_add(y[1], c * y[2]));
    }
    {
        let dx1 = x[n - 2] - x[n - 3];
        let dx2 = x[n - 1] - x[n - 2];
        let a = dx2 / (dx1 * (dx1 + dx2));
        let b = -(dx2 + dx1) / (dx1 * dx2);
        let c = 2.0f64.mul_add(dx2, dx1) / (dx2 * (dx1 + dx2));
        out[n - 1] = a.mul_add(y[n - 3], b.mul_add(y[n - 2], c * y[n - 1]));
    }
    out
}

/// Linear interpolation in a strictly increasing table, held constant outside.
#[must_use]
pub fn interp_clamped(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len().min(ys.len());
    if n == 0 {
        return 0.0;
    }
    if x <= xs[0] {
        return ys[0];
    }
    if x >= xs[n - 1] {
        return ys[n - 1];
    }
    // xs[0] < x < xs[n-1]: the index is in 1..n.
    let i = xs[..n].partition_point(|&v| v <= x);
    let (x0, x1, y0, y1) = (xs[i - 1], xs[i], ys[i - 1], ys[i]);
    let s = (x - x0) / (x1 - x0);
    y0 + (y1 - y0) * s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_pins_both_ends() {
        let xs = linspace(0.0, 1.0, 300);
        assert_eq!(xs.len(), 300);
        assert!(xs[0].abs() < 1e-300 && (xs[299] - 1.0).abs() < 1e-300);
        assert!(xs.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn gradient_is_exact_on_quadratics_uniform_and_not() {
        let xs = linspace(0.0, 2.0, 11);
        let y: Vec<f64> = xs.iter().map(|x| 3.0 * x * x - x + 2.0).collect();
        for (d, x) in gradient(&y, &xs).iter().zip(&xs) {
            assert!((d - (6.0 * x - 1.0)).abs() < 1e-12, "{d} at {x}");
        }
        let xs: Vec<f64> = (0..12).map(|k| f64::from(k).powf(1.3) * 0.1).collect();
        let y: Vec<f64> = xs.iter().map(|x| 3.0 * x * x - x + 2.0).collect();
        for (d, x) in gradient(&y, &xs).iter().zip(&xs) {
            assert!((d - (6.0 * x - 1.0)).abs() < 1e-11, "{d} at {x}");
        }
    }
}
