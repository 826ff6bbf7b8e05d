//! An independent check of `bezier_motion`'s closed-form end state: the plant
//! `ψ'' + 2ξωn ψ' + ωn² ψ = −z φ''(t)`, `ψ(0) = ψ'(0) = 0`, integrated by an adaptive
//! Dormand–Prince 5(4) Runge–Kutta method (local extrapolation, FSAL, the error-per-step
//! controller of Hairer–Nørsett–Wanner), with φ'' evaluated from its Bernstein ordinates by a
//! nested form written here (nothing of the module's quadrature, transition matrix or
//! integration by parts is used). Shared by `tests/slow/stress_bezier_motion.rs` and, through
//! `#[path]`, `benches/bezier_motion.rs` (the RK45 rows of the spec §7 table).

/// The drive as the integrator sees it.
#[derive(Debug, Clone, Copy)]
pub struct Drive {
    /// Natural frequency ωn [rad/s].
    pub wn: f64,
    /// Damping ratio ξ.
    pub xi: f64,
    /// Reducer ratio z.
    pub z: f64,
}

/// `φ''(t)` from the acceleration ordinates `A_0..A_N` on `[0, T]` in O(N): for λ ≤ ½ the nested
/// form of `(1−λ)^N Σ C(N,i) A_i s^i`, `s = λ/(1−λ) ≤ 1`, mirrored for λ > ½.
#[derive(Debug, Clone)]
pub struct Forcing {
    t_end: f64,
    /// `C(N,i)·A_i`.
    fwd: Vec<f64>,
    /// `C(N,i)·A_{N−i}`.
    rev: Vec<f64>,
}

impl Forcing {
    /// The forcing of a law with acceleration ordinates `a` and duration `t_end`.
    #[must_use]
    pub fn new(a: &[f64], t_end: f64) -> Self {
        let n = a.len() - 1;
        let mut c = 1.0_f64;
        let mut binom = Vec::with_capacity(n + 1);
        for i in 0..=n {
            binom.push(c.round());
            c = c * (n - i) as f64 / (i + 1) as f64;
        }
        let fwd = a.iter().zip(&binom).map(|(a, b)| a * b).collect();
        let rev = a.iter().rev().zip(&binom).map(|(a, b)| a * b).collect();
        Self { t_end, fwd, rev }
    }

    /// `φ''(t)`, t ∈ [0, T].
    #[must_use]
    pub fn at(&self, t: f64) -> f64 {
        let lam = (t / self.t_end).clamp(0.0, 1.0);
        let (s, base, c) = if lam <= 0.5 {
            (lam / (1.0 - lam), 1.0 - lam, &self.fwd)
        } else {
            ((1.0 - lam) / lam, lam, &self.rev)
        };
        let acc = c.iter().rev().fold(0.0_f64, |acc, ci| acc * s + ci);
        acc * base.powi((c.len() - 1) as i32)
    }
}

/// Result of one integration.
#[derive(Debug, Clone, Copy)]
pub struct Integration {
    /// `[ψ(T), ψ'(T)]`.
    pub x: [f64; 2],
    /// Right-hand-side evaluations.
    pub evals: u64,
    /// Accepted steps.
    pub steps: u64,
}

/// Scales of ψ and ψ' for a law with acceleration ordinates `a`: `|z|·max|A|/ωn²` and
/// `|z|·max|A|/ωn` (the quasi-static lag and the spec §3.5b error scale).
#[must_use]
pub fn state_scale(d: &Drive, a: &[f64]) -> [f64; 2] {
    let amax = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let s = d.z.abs() * amax / d.wn;
    [s / d.wn, s]
}

/// Energy-norm distance `sqrt(Δψ'² + ωn² Δψ²)` of two end states.
#[must_use]
pub fn energy_distance(wn: f64, a: [f64; 2], b: [f64; 2]) -> f64 {
    (wn * (a[0] - b[0])).hypot(a[1] - b[1])
}

/// Energy-norm size `sqrt(ψ'² + ωn² ψ²)` of a state.
#[must_use]
pub fn energy_size(wn: f64, a: [f64; 2]) -> f64 {
    (wn * a[0]).hypot(a[1])
}

// Dormand–Prince 5(4) tableau.
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// 5th-order weights minus the embedded 4th-order ones.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339_200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Integrate the plant from rest over `[0, T]` with Dormand–Prince 5(4) at relative tolerance
/// `rtol` and absolute tolerances `rtol·scale` per component (`scale` from [`state_scale`]).
#[must_use]
pub fn rk45_end_state(d: &Drive, a: &[f64], t_end: f64, rtol: f64) -> Integration {
    let u = Forcing::new(a, t_end);
    let scale = state_scale(d, a);
    let atol = [rtol * scale[0], rtol * scale[1]];
    let (wn2, c1) = (d.wn * d.wn, 2.0 * d.xi * d.wn);
    let mut evals = 0_u64;
    let mut f = |t: f64, x: [f64; 2]| {
        evals += 1;
        [x[1], -d.z * u.at(t) - c1 * x[1] - wn2 * x[0]]
    };
    // The fastest rate of the system sets the first step; the controller does the rest.
    let fast = d.wn * (d.xi + (d.xi * d.xi - 1.0).max(0.0).sqrt()).max(1.0);
    let mut h = (0.01 / fast).min(t_end) * rtol.powf(0.2).max(1e-3);
    let (mut t, mut x) = (0.0, [0.0, 0.0]);
    let mut k = [[0.0; 2]; 7];
    k[0] = f(t, x);
    let mut steps = 0_u64;
    while t < t_end {
        let last = h >= t_end - t;
        if last {
            h = t_end - t;
        }
        for s in 1..7 {
            let mut y = x;
            for (j, kj) in k.iter().enumerate().take(s) {
                y[0] += h * A[s][j] * kj[0];
                y[1] += h * A[s][j] * kj[1];
            }
            k[s] = f(t + C[s] * h, y);
        }
        // Stage 7 is evaluated at the 5th-order solution (FSAL).
        let mut y = x;
        for (j, kj) in k.iter().enumerate().take(6) {
            y[0] += h * A[6][j] * kj[0];
            y[1] += h * A[6][j] * kj[1];
        }
        let mut err = 0.0_f64;
        for i in 0..2 {
            let e: f64 = (0..7).map(|s| E[s] * k[s][i]).sum::<f64>() * h;
            let sc = atol[i] + rtol * x[i].abs().max(y[i].abs());
            err += (e / sc) * (e / sc);
        }
        let err = (err / 2.0).sqrt();
        let grow = if err == 0.0 {
            5.0
        } else {
            (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
        };
        if err <= 1.0 {
            t = if last { t_end } else { t + h };
            x = y;
            k[0] = k[6];
            steps += 1;
        }
        h *= if err <= 1.0 { grow } else { grow.min(1.0) };
        assert!(h > 0.0 && h.is_finite(), "step size collapsed at t = {t}");
    }
    Integration { x, evals, steps }
}
