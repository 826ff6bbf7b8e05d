//! The Bezier motion law of spec §3.2: control polygons of φ, φ', φ'', φ''' and their stable
//! evaluation (de Casteljau; never the monomial basis).

/// Binomial coefficient `C(n, k)` as f64 (exact for the degrees used here, n ≤ 62).
#[must_use]
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut c = 1.0_f64;
    for i in 0..k {
        // Exact: every partial product is an integer C(n, i+1)·…, below 2^53 for n ≤ 62.
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c.round()
}

/// A rest-to-rest Bezier motion law (spec §3.2): degree `n_s = 2m + p + 1`, the first and last
/// `m + 1` displacement ordinates pinned to 0 and `Phi`, `p` free interior ordinates γ.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierLaw {
    /// Order of the derivatives forced to zero at both ends, `m`.
    pub m: usize,
    /// Motion time `T` \[s\].
    pub t: f64,
    /// Displacement control ordinates `S_0..S_{n_s}` \[rad\].
    pub s: Vec<f64>,
    /// Velocity control ordinates `V_0..V_{n_s−1}` [rad/s].
    pub v: Vec<f64>,
    /// Acceleration control ordinates `A_0..A_N`, `N = n_s − 2` [rad/s²].
    pub a: Vec<f64>,
    /// Jerk control ordinates `J_0..J_{N−1}` [rad/s³].
    pub j: Vec<f64>,
}

impl BezierLaw {
    /// The law with `S_0..S_m = 0`, `S_{m+j} = γ_j`, `S_{m+p+1}..S_{n_s} = Phi`.
    #[must_use]
    pub fn new(m: usize, phi: f64, gamma: &[f64], t: f64) -> Self {
        let s = control_ordinates(m, phi, gamma);
        let v = derivative_polygon(&s, t);
        let a = derivative_polygon(&v, t);
        let j = derivative_polygon(&a, t);
        Self { m, t, s, v, a, j }
    }

    /// Degree `n_s` of φ.
    #[must_use]
    pub fn degree(&self) -> usize {
        self.s.len() - 1
    }

    /// Degree `N = n_s − 2` of φ''.
    #[must_use]
    pub fn accel_degree(&self) -> usize {
        self.a.len() - 1
    }

    /// `[φ, φ', φ'', φ''']` at time `t` ∈ [0, T].
    #[must_use]
    pub fn eval(&self, t: f64) -> [f64; 4] {
        let lam = (t / self.t).clamp(0.0, 1.0);
        [
            de_casteljau(&self.s, lam),
            de_casteljau(&self.v, lam),
            de_casteljau(&self.a, lam),
            de_casteljau(&self.j, lam),
        ]
    }
}

/// `S` for given `m`, `Phi` and γ (spec §3.2).
#[must_use]
pub fn control_ordinates(m: usize, phi: f64, gamma: &[f64]) -> Vec<f64> {
    let mut s = vec![0.0; m + 1];
    s.extend_from_slice(gamma);
    s.extend(std::iter::repeat_n(phi, m + 1));
    s
}

/// Control polygon of the time derivative of a Bezier polynomial of degree `n = y.len() − 1` on
/// `[0, T]`: `n/T (y_{i+1} − y_i)` (paper Eqs. 18–19). Empty for a constant.
#[must_use]
pub fn derivative_polygon(y: &[f64], t: f64) -> Vec<f64> {
    let n = y.len().saturating_sub(1);
    let f = n as f64 / t;
    y.windows(2).map(|w| f * (w[1] - w[0])).collect()
}

/// Value of the Bezier polynomial with ordinates `c` at `λ` ∈ [0, 1] by de Casteljau (0 for an
/// empty polygon).
#[must_use]
pub fn de_casteljau(c: &[f64], lam: f64) -> f64 {
    let n = c.len();
    if n == 0 {
        return 0.0;
    }
    // A small stack buffer for the usual degrees (zeroing 64 slots per call cost more than the
    // recurrence itself at N ≈ 6), the large one up to 63, the basis sum beyond.
    if n <= 16 {
        let mut b = [0.0; 16];
        b[..n].copy_from_slice(c);
        casteljau_in_place(&mut b[..n], lam)
    } else if n <= 64 {
        let mut b = [0.0; 64];
        b[..n].copy_from_slice(c);
        casteljau_in_place(&mut b[..n], lam)
    } else {
        bernstein_sum(c, lam)
    }
}

/// Value and first derivative d/dλ of the Bezier polynomial with ordinates `c` at `λ` ∈ [0, 1]
/// from one de Casteljau pass: the last two points `b0`, `b1` of the penultimate level give the
/// value `(1−λ)·b0 + λ·b1` and the derivative `n·(b1 − b0)` (`(c_0, 0)` for a single ordinate,
/// `(0, 0)` for none).
#[must_use]
pub fn de_casteljau_slope(c: &[f64], lam: f64) -> (f64, f64) {
    let n = c.len();
    if n < 2 {
        return (c.first().copied().unwrap_or(0.0), 0.0);
    }
    let mut small = [0.0; 16];
    let mut large = Vec::new();
    let b = if n <= small.len() {
        small[..n].copy_from_slice(c);
        &mut small[..n]
    } else {
        large.extend_from_slice(c);
        &mut large[..]
    };
    let mu = 1.0 - lam;
    for r in 1..n - 1 {
        for i in 0..n - r {
            b[i] = mu * b[i] + lam * b[i + 1];
        }
    }
    (mu * b[0] + lam * b[1], (n - 1) as f64 * (b[1] - b[0]))
}

/// De Casteljau's recurrence on `b` (overwritten); returns the value at `λ`.
fn casteljau_in_place(b: &mut [f64], lam: f64) -> f64 {
    let n = b.len();
    let mu = 1.0 - lam;
    for r in 1..n {
        for i in 0..n - r {
            b[i] = mu * b[i] + lam * b[i + 1];
        }
    }
    b[0]
}

/// Value of the Bezier polynomial with ordinates `c` at `λ` ∈ [0, 1] in O(n): the nested
/// (Horner) form of `(1−λ)^n Σ C(n,i) c_i s^i`, `s = λ/(1−λ)`, mirrored for λ > ½ so that
/// `s ≤ 1` (the stepping of the time history evaluates φ'' this way, at every quadrature node).
#[must_use]
pub fn bernstein_horner(c: &[f64], lam: f64) -> f64 {
    if c.is_empty() {
        return 0.0;
    }
    let n = c.len() - 1;
    let (s, base, rev) = if lam <= 0.5 {
        (lam / (1.0 - lam), 1.0 - lam, false)
    } else {
        ((1.0 - lam) / lam, lam, true)
    };
    let coef = |i: usize| if rev { c[n - i] } else { c[i] };
    let mut acc = coef(n);
    for i in (0..n).rev() {
        acc = coef(i) + s * acc * (n - i) as f64 / (i + 1) as f64;
    }
    // n ≤ 62 fits i32.
    acc * base.powi(n as i32)
}

/// `Σ c_i B(n, i, λ)` summed term by term (fallback for polygons longer than de Casteljau's
/// stack buffer; not used for the degrees the endpoint admits).
fn bernstein_sum(c: &[f64], lam: f64) -> f64 {
    let n = c.len() - 1;
    let mut vals = vec![0.0; n + 1];
    bernstein_all(n, lam, &mut vals);
    c.iter().zip(&vals).map(|(c, b)| c * b).sum()
}

/// All Bernstein basis values `B(n, i, λ)`, i = 0..n, into `out` (length n + 1), by the
/// triangular recurrence (no binomials, no powers; stable for λ ∈ [0, 1]).
pub fn bernstein_all(n: usize, lam: f64, out: &mut [f64]) {
    let mu = 1.0 - lam;
    out[0] = 1.0;
    for j in 1..=n {
        let mut saved = 0.0;
        for o in &mut out[..j] {
            let tmp = *o;
            *o = saved + mu * tmp;
            saved = lam * tmp;
        }
        out[j] = saved;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One pass gives de Casteljau's value and n times the value of the difference polygon
    /// (the derivative), for short polygons and past the stack buffer.
    #[test]
    fn value_and_slope_match_the_difference_polygon() {
        for len in 0..=20_usize {
            let c: Vec<f64> = (0..len)
                .map(|i| ((i * 7 + 3) % 11) as f64 - 5.0 + 0.1 * i as f64)
                .collect();
            let scale = c.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
            let d: Vec<f64> = c.windows(2).map(|w| w[1] - w[0]).collect();
            for k in 0..=16 {
                let lam = f64::from(k) / 16.0;
                let (v, s) = de_casteljau_slope(&c, lam);
                assert_eq!(
                    v.to_bits(),
                    de_casteljau(&c, lam).to_bits(),
                    "len {len} λ {lam}"
                );
                let exact = len.saturating_sub(1) as f64 * de_casteljau(&d, lam);
                assert!(
                    (s - exact).abs() <= 1e-12 * scale * len.max(1) as f64,
                    "len {len} λ {lam}: {s} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn basis_sums_to_one_and_matches_binomials() {
        let mut b = vec![0.0; 6];
        bernstein_all(5, 0.3, &mut b);
        let sum: f64 = b.iter().sum();
        assert!((sum - 1.0).abs() < 1e-15);
        for (i, bi) in b.iter().enumerate() {
            let exact = binomial(5, i) * 0.3_f64.powi(i as i32) * 0.7_f64.powi(5 - i as i32);
            assert!((bi - exact).abs() < 1e-15);
        }
    }

    #[test]
    fn horner_matches_de_casteljau() {
        let c: Vec<f64> = (0..31).map(|i| f64::from(i).sin() * 3.0).collect();
        for k in 0..=20 {
            let lam = f64::from(k) / 20.0;
            let a = de_casteljau(&c, lam);
            let b = bernstein_horner(&c, lam);
            assert!((a - b).abs() < 1e-12, "{lam}: {a} vs {b}");
        }
    }

    #[test]
    fn paper_polygon_sizes() {
        let law = BezierLaw::new(2, 1.0, &[0.25, 0.5, 0.75], 1.0);
        assert_eq!((law.s.len(), law.v.len(), law.a.len()), (9, 8, 7));
        let [p0, v0, a0, _] = law.eval(0.0);
        let [p1, v1, a1, _] = law.eval(1.0);
        assert!(p0.abs() < 1e-15 && v0.abs() < 1e-15 && a0.abs() < 1e-15);
        assert!((p1 - 1.0).abs() < 1e-15 && v1.abs() < 1e-14 && a1.abs() < 1e-13);
    }
}
