//! Loss maps (bilinear in speed × torque, clamped to the axes), the conversion of efficiency maps
//! to loss maps (spec §8 item 2) and torque envelopes of map / constant motors (spec §5.4).

// Plain products instead of `mul_add`: without FMA hardware in the target (the default x86-64
// baseline) `mul_add` is a libm call, ~10x slower in these per-interval loops, and plain
// arithmetic follows the rounding of the spec's reference implementation.

/// A rectangular map of values on (speed [rad/s], torque [N·m]) axes, row-major by speed.
#[derive(Debug, Clone)]
pub struct Grid2 {
    /// Speed axis [rad/s], strictly increasing.
    pub speed: Vec<f64>,
    /// Torque axis [N·m], strictly increasing.
    pub torque: Vec<f64>,
    /// values[i * torque.len() + j] at (speed\[i\], torque\[j\]).
    pub values: Vec<f64>,
}

/// Cell index and weight of `x` on a strictly increasing axis, clamped to the axis.
fn locate(axis: &[f64], x: f64) -> (usize, f64) {
    let n = axis.len();
    if n < 2 || x <= axis[0] {
        return (0, 0.0);
    }
    if x >= axis[n - 1] {
        return (n - 2, 1.0);
    }
    // axis[0] < x < axis[n-1]: partition_point is in 1..n.
    let i = axis.partition_point(|&v| v <= x) - 1;
    (i, (x - axis[i]) / (axis[i + 1] - axis[i]))
}

impl Grid2 {
    /// Bilinear interpolation at (w, t), clamped to the axes (no extrapolation, spec §8 item 3).
    #[must_use]
    pub fn lookup(&self, w: f64, t: f64) -> f64 {
        let nt = self.torque.len();
        if self.speed.len() < 2 || nt < 2 {
            return self.values.first().copied().unwrap_or(0.0);
        }
        let (i, u) = locate(&self.speed, w);
        let (j, s) = locate(&self.torque, t);
        let v = |a: usize, b: usize| self.values[a * nt + b];
        let lo = v(i, j) + (v(i, j + 1) - v(i, j)) * s;
        let hi = v(i + 1, j) + (v(i + 1, j + 1) - v(i + 1, j)) * s;
        lo + (hi - lo) * u
    }

    /// Smallest and largest torque on the axis.
    #[must_use]
    pub fn torque_range(&self) -> (f64, f64) {
        (
            self.torque.first().copied().unwrap_or(0.0),
            self.torque.last().copied().unwrap_or(0.0),
        )
    }
}

/// Result of converting an efficiency map into a loss map.
#[derive(Debug, Clone)]
pub struct ConvertedMap {
    /// The loss map \[W\] on a signed torque axis with a T = 0 column and an n = 0 row.
    pub loss: Grid2,
    /// Warnings (extrapolated T = 0 losses, ignored η at T = 0 or n = 0).
    pub warnings: Vec<String>,
}

/// Convert an efficiency map to a loss map at its own grid points (spec §8 item 2):
/// L = |P_m|(1/η − 1) at T > 0, n > 0; a T = 0 column by linear extrapolation from the first two
/// positive torque columns (clipped at 0; constant if only one exists); an n = 0 row equal to the
/// first positive-speed row; mirrored for T < 0 unless a generating table is given (then the T = 0
/// column is the mean of both extrapolations). Speeds in rad/s, `eff[i][j]` at (speed\[i\], torque\[j\]).
#[must_use]
pub fn efficiency_to_loss(
    speed: &[f64],
    torque: &[f64],
    eff: &[Vec<f64>],
    eff_gen: Option<&[Vec<f64>]>,
) -> ConvertedMap {
    let mut warnings = vec![
        "efficiency map converted to a loss map at its own grid points before interpolation (spec §8 item 2)"
            .to_owned(),
    ];
    let pos_cols: Vec<usize> = (0..torque.len()).filter(|&j| torque[j] > 0.0).collect();
    let pos_rows: Vec<usize> = (0..speed.len()).filter(|&i| speed[i] > 0.0).collect();
    if torque.first().is_some_and(|&t| t <= 0.0) {
        warnings.push(
            "efficiency values at T = 0 ignored (zero power): T = 0 losses extrapolated".to_owned(),
        );
    } else {
        warnings.push(
            "losses at T = 0 extrapolated linearly from the first two torque columns".to_owned(),
        );
    }
    if speed.first().is_some_and(|&n| n <= 0.0) {
        warnings.push("efficiency values at n = 0 ignored (zero power): n = 0 losses copied from the first speed".to_owned());
    }
    // Loss rows for positive speeds, positive torques.
    let loss_rows = |tab: &[Vec<f64>]| -> Vec<(Vec<f64>, f64)> {
        pos_rows
            .iter()
            .map(|&i| {
                let row: Vec<f64> = pos_cols
                    .iter()
                    .map(|&j| {
                        let p = torque[j] * speed[i];
                        let eta = tab[i][j];
                        p.abs() * (1.0 / eta - 1.0)
                    })
                    .collect();
                let l0 = extrapolate_zero(
                    &pos_cols.iter().map(|&j| torque[j]).collect::<Vec<_>>(),
                    &row,
                );
                (row, l0)
            })
            .collect()
    };
    let mot = loss_rows(eff);
    let gen_rows = eff_gen.map(loss_rows);
    let tpos: Vec<f64> = pos_cols.iter().map(|&j| torque[j]).collect();
    let mut axis_t: Vec<f64> = tpos.iter().rev().map(|t| -t).collect();
    axis_t.push(0.0);
    axis_t.extend_from_slice(&tpos);
    let mut axis_w = vec![0.0];
    axis_w.extend(pos_rows.iter().map(|&i| speed[i]));
    let build_row = |k: usize| -> Vec<f64> {
        let (m_row, m0) = &mot[k];
        let (g_row, zero) = match &gen_rows {
            Some(g) => (&g[k].0, 0.5 * (m0 + g[k].1)),
            None => (m_row, *m0),
        };
        let mut out: Vec<f64> = g_row.iter().rev().copied().collect();
        out.push(zero);
        out.extend_from_slice(m_row);
        out
    };
    let mut values = Vec::with_capacity(axis_w.len() * axis_t.len());
    if !mot.is_empty() {
        let first = build_row(0);
        values.extend_from_slice(&first);
        for k in 0..mot.len() {
            values.extend(build_row(k));
        }
    }
    ConvertedMap {
        loss: Grid2 {
            speed: axis_w,
            torque: axis_t,
            values,
        },
        warnings,
    }
}

/// Loss at T = 0 by linear extrapolation from the first two columns, clipped at 0.
fn extrapolate_zero(t: &[f64], l: &[f64]) -> f64 {
    match (t, l) {
        ([t1, t2, ..], [l1, l2, ..]) => {
            let slope = (l2 - l1) / (t2 - t1);
            (*l1 - slope * *t1).max(0.0)
        }
        (_, [l1, ..]) => *l1,
        _ => 0.0,
    }
}

/// Torque envelope of a constant or map motor.
#[derive(Debug, Clone)]
pub enum Envelope {
    /// T_max(ω) = min(t_peak, p_peak/ω).
    TorquePower {
        /// Peak torque [N·m].
        t_peak: f64,
        /// Peak power \[W\].
        p_peak: f64,
    },
    /// Table, linear in speed, held constant outside.
    Table {
        /// Speeds [rad/s].
        speed: Vec<f64>,
        /// T_max [N·m].
        t_max: Vec<f64>,
    },
}

impl Envelope {
    /// T_max at ω [rad/s] (ignoring n_max; the caller applies it).
    #[must_use]
    pub fn t_max(&self, w: f64) -> f64 {
        match self {
            Self::TorquePower { t_peak, p_peak } => {
                if w > 0.0 {
                    t_peak.min(p_peak / w)
                } else {
                    *t_peak
                }
            }
            Self::Table { speed, t_max } => crate::numerics::grid::interp_clamped(speed, t_max, w),
        }
    }

    /// Largest torque of the envelope (at any speed).
    #[must_use]
    pub fn peak(&self) -> f64 {
        match self {
            Self::TorquePower { t_peak, .. } => *t_peak,
            Self::Table { t_max, .. } => t_max.iter().copied().fold(0.0, f64::max),
        }
    }
}
