//! The `/v1/cam-law/evaluate` computation (spec §8b): build the law, its exact peaks, knots and
//! jumps, and the requested curves. No wire types.

use super::catalogue::{NamedLaw, PeakFactors};
use super::error::EvaluateError;
use super::input::{EvaluateInput, LawChoice};
use super::law::{
    BoundaryConditions, JUMP_REL_TOL, Jump, Knot, LawNotice, Quantity, SampledCurves,
    SevenSegmentLaw,
};
use crate::numerics::Budget;

/// Peaks of the evaluated law in physical units (`a1`, `a2` only for the 7-segment class;
/// `a_max_abs` and `jerk_max_abs_finite` absent when infinite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvaluatedPeaks {
    /// Peak of the first acceleration pulse `A1`.
    pub a1: Option<f64>,
    /// Peak of the second acceleration pulse `A2`.
    pub a2: Option<f64>,
    /// Largest |a|.
    pub a_max_abs: Option<f64>,
    /// Largest |v|.
    pub v_max_abs: f64,
    /// First abscissa where |v| is largest.
    pub x_at_v_max: f64,
    /// Largest finite |jerk|.
    pub jerk_max_abs_finite: Option<f64>,
    /// Appendix-A factors of a named law (zero end rates only).
    pub peak_factors: Option<PeakFactors>,
}

/// The 7-segment description of a law of the class: normalized coefficients, segment
/// durations and the 8 knots.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassLaw {
    /// Normalized coefficients `ĉ0..ĉ6`.
    pub coefficients: Vec<f64>,
    /// Segment durations `ĉ_k·Δt`.
    pub durations: Vec<f64>,
    /// Knots `t_0..t_7`.
    pub knots: Vec<Knot>,
}

/// The evaluated law.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluateOutput {
    /// The named law evaluated, when the request named one.
    pub law: Option<NamedLaw>,
    /// Coefficients, durations and knots; `None` for a named law outside the class.
    pub class: Option<ClassLaw>,
    /// Exact peaks.
    pub peaks: EvaluatedPeaks,
    /// Acceleration jumps in abscissa order.
    pub jumps: Vec<Jump>,
    /// Curves at the requested abscissae.
    pub curves: Option<SampledCurves>,
    /// Findings (validation findings first).
    pub warnings: Vec<LawNotice>,
}

/// Evaluate a validated request.
///
/// The work is `O(N)` in the number of abscissae (≤ 200 000 points, a few ms), so the budget is
/// not polled.
///
/// # Errors
/// [`EvaluateError::Law`] (`LAW_OVERFLOW`) when the law's peaks overflow f64,
/// [`EvaluateError::NonFiniteResult`] when a reported number would not be finite.
pub fn compute(input: &EvaluateInput, _budget: &Budget) -> Result<EvaluateOutput, EvaluateError> {
    let bc = &input.bc;
    let mut warnings = input.warnings.clone();
    let ds = bc.s_b - bc.s_a;
    if ds == 0.0 && bc.zero_end_rates() {
        warnings.push(LawNotice::NonIdentifiable);
    }
    let out = match input.law {
        LawChoice::SevenSegment {
            coefficients,
            named,
        } => {
            let law = SevenSegmentLaw::try_new(&coefficients, bc)?;
            let p = law.peaks();
            let a_tol = JUMP_REL_TOL * p.a_max_abs.max(bc.a_a.abs()).max(bc.a_b.abs());
            if ds != 0.0 && (ds.signum() * law.a1() < -a_tol || ds.signum() * law.a2() > a_tol) {
                warnings.push(LawNotice::PeakSignUnusual);
            }
            let curves = input.xs.as_ref().map(|xs| {
                let mut c = SampledCurves::at(xs);
                for &q in &input.quantities {
                    let mut out = vec![0.0; xs.len()];
                    law.eval_quantity_into(xs, q, &mut out);
                    c.set(q, out);
                }
                c
            });
            EvaluateOutput {
                law: named,
                class: Some(ClassLaw {
                    coefficients: law.coefficients().to_vec(),
                    durations: law.durations().to_vec(),
                    knots: law.knots().to_vec(),
                }),
                peaks: EvaluatedPeaks {
                    a1: Some(p.a1),
                    a2: Some(p.a2),
                    a_max_abs: Some(p.a_max_abs),
                    v_max_abs: p.v_max_abs,
                    x_at_v_max: p.x_at_v_max,
                    jerk_max_abs_finite: Some(p.jerk_max_abs_finite),
                    peak_factors: named
                        .filter(|_| bc.zero_end_rates())
                        .map(NamedLaw::peak_factors),
                },
                jumps: law.jumps(),
                curves,
                warnings,
            }
        }
        LawChoice::ClosedForm(named) => closed_form(named, input, warnings),
    };
    ensure_finite(&out)?;
    Ok(out)
}

/// Physical scales `(Δt, Δs, Δs/Δt, Δs/Δt², Δs/Δt³)`.
fn scales(bc: &BoundaryConditions) -> [f64; 5] {
    let dt = bc.t_b - bc.t_a;
    let ds = bc.s_b - bc.s_a;
    [dt, ds, ds / dt, ds / dt / dt, ds / dt / dt / dt]
}

/// A named law outside the 7-segment class, from its closed form (zero end rates).
fn closed_form(named: NamedLaw, input: &EvaluateInput, warnings: Vec<LawNotice>) -> EvaluateOutput {
    let bc = &input.bc;
    let [dt, ds, kv, ka, kj] = scales(bc);
    let f = named.peak_factors();
    let peaks = EvaluatedPeaks {
        a1: None,
        a2: None,
        a_max_abs: f.ca.map(|ca| ca * ka.abs()),
        v_max_abs: f.cv * kv.abs(),
        x_at_v_max: named.x_at_v_max().mul_add(dt, bc.t_a),
        jerk_max_abs_finite: f.cj.map(|cj| cj * kj.abs()),
        peak_factors: Some(f),
    };
    let mut jumps = Vec::new();
    let a0 = named.eval_normalized(0.0).a * ka;
    let a1 = named.eval_normalized(1.0).a * ka;
    let tol = JUMP_REL_TOL * peaks.a_max_abs.unwrap_or(0.0);
    if (a0 - bc.a_a).abs() > tol {
        jumps.push(Jump {
            x: bc.t_a,
            a_left: bc.a_a,
            a_right: a0,
        });
    }
    if (a1 - bc.a_b).abs() > tol {
        jumps.push(Jump {
            x: bc.t_b,
            a_left: a1,
            a_right: bc.a_b,
        });
    }
    let curves = input.xs.as_ref().map(|xs| {
        let mut c = SampledCurves::at(xs);
        for &q in &input.quantities {
            let out = xs
                .iter()
                .map(|&x| {
                    let n = named.eval_normalized((x - bc.t_a) / dt);
                    match q {
                        Quantity::S => ds.mul_add(n.s, bc.s_a),
                        Quantity::V => kv * n.v,
                        Quantity::A => ka * n.a,
                        Quantity::J => kj * n.j,
                    }
                })
                .collect();
            c.set(q, out);
        }
        c
    });
    EvaluateOutput {
        law: Some(named),
        class: None,
        peaks,
        jumps,
        curves,
        warnings,
    }
}

/// Every reported number must be finite (JSON cannot carry NaN/Inf, and a silent NaN is a bug);
/// the first offending group, in response order, names the error.
fn ensure_finite(r: &EvaluateOutput) -> Result<(), EvaluateError> {
    let mut bad: Option<&'static str> = None;
    let mut check = |name: &'static str, xs: &[f64]| {
        if bad.is_none() && !xs.iter().all(|x| x.is_finite()) {
            bad = Some(name);
        }
    };
    if let Some(class) = &r.class {
        check("coefficients", &class.coefficients);
        check("durations", &class.durations);
        for k in &class.knots {
            check("knots", &[k.x, k.s, k.v, k.a_left, k.a_right]);
        }
    }
    let p = &r.peaks;
    let opt = |o: Option<f64>| o.unwrap_or(0.0);
    check(
        "peaks",
        &[
            opt(p.a1),
            opt(p.a2),
            opt(p.a_max_abs),
            p.v_max_abs,
            p.x_at_v_max,
            opt(p.jerk_max_abs_finite),
        ],
    );
    for j in &r.jumps {
        check("acceleration_jumps", &[j.x, j.a_left, j.a_right]);
    }
    if let Some(c) = &r.curves {
        check("curves.x", &c.x);
        for (name, q) in [
            ("curves.s", &c.s),
            ("curves.v", &c.v),
            ("curves.a", &c.a),
            ("curves.j", &c.j),
        ] {
            check(name, q.as_deref().unwrap_or(&[]));
        }
    }
    bad.map_or(Ok(()), |name| Err(EvaluateError::NonFiniteResult { name }))
}
