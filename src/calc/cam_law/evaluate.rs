//! The `/v1/cam-law/evaluate` computation (spec §8b): build the law, its exact peaks, knots and
//! jumps, and the requested curves.

use super::catalogue::NamedLaw;
use super::input::{EvaluateInput, LawChoice};
use super::law::{BoundaryConditions, JUMP_REL_TOL, Jump, Quantity, SevenSegmentLaw};
use super::wire::{Curves, EvaluateRequest, EvaluateResponse, PeaksOut, Warning};
use crate::calc::common::ResponseSize;
use crate::calc::{CalcFailure, ProblemClass};
use crate::numerics::Budget;

/// Validate, compute and build the wire response of `POST /v1/cam-law/evaluate`.
///
/// The work is `O(N)` in the number of abscissae (≤ 200 000 points, a few ms), so the budget's
/// clock is not polled; its response limit is checked before evaluating.
///
/// # Errors
/// [`CalcFailure`] with every offending field (JSON pointers into the request) for invalid input;
/// `LAW_OVERFLOW` / `NON_FINITE_RESULT` when the law's values would overflow f64.
pub fn run(req: EvaluateRequest, budget: &Budget) -> Result<EvaluateResponse, CalcFailure> {
    let input = EvaluateInput::try_from(req)?;
    response_size(&input).check(budget)?;
    let response = compute(&input)?;
    ensure_finite(&response)?;
    Ok(response)
}

/// Upper estimate of the answer's size from the validated request (checked before computing):
/// fixed fields (law, peaks, knots, jumps) and the curves, one number per abscissa for `x` and
/// each requested quantity.
#[must_use]
pub fn response_size(input: &EvaluateInput) -> ResponseSize {
    let n = input.xs.as_ref().map_or(0, Vec::len) as u64;
    let series = 1 + input.quantities.len() as u64;
    ResponseSize::fixed(8 * 1024).numbers("/abscissa", n * series)
}

/// Evaluate a validated request.
///
/// # Errors
/// `LAW_OVERFLOW` when the law's peaks overflow f64.
pub fn compute(input: &EvaluateInput) -> Result<EvaluateResponse, CalcFailure> {
    let bc = &input.bc;
    let mut warnings = input.warnings.clone();
    let ds = bc.s_b - bc.s_a;
    if ds == 0.0 && bc.zero_end_rates() {
        warnings.push(Warning::NonIdentifiable);
    }
    match input.law {
        LawChoice::SevenSegment {
            coefficients,
            named,
        } => {
            let law = SevenSegmentLaw::try_new(&coefficients, bc)?;
            let p = law.peaks();
            let a_tol = JUMP_REL_TOL * p.a_max_abs.max(bc.a_a.abs()).max(bc.a_b.abs());
            if ds != 0.0 && (ds.signum() * law.a1() < -a_tol || ds.signum() * law.a2() > a_tol) {
                warnings.push(Warning::PeakSignUnusual);
            }
            let curves = input.xs.as_ref().map(|xs| {
                let mut c = empty_curves(xs);
                for &q in &input.quantities {
                    let mut out = vec![0.0; xs.len()];
                    law.eval_quantity_into(xs, q, &mut out);
                    set(&mut c, q, out);
                }
                c
            });
            Ok(EvaluateResponse {
                law: named,
                coefficients: Some(law.coefficients().to_vec()),
                durations: Some(law.durations().to_vec()),
                knots: Some(law.knots().to_vec()),
                peaks: PeaksOut {
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
                acceleration_jumps: law.jumps(),
                curves,
                warnings,
                units: input.units.clone(),
            })
        }
        LawChoice::ClosedForm(named) => Ok(closed_form(named, input, warnings)),
    }
}

/// Physical scales `(Δt, Δs, Δs/Δt, Δs/Δt², Δs/Δt³)`.
fn scales(bc: &BoundaryConditions) -> [f64; 5] {
    let dt = bc.t_b - bc.t_a;
    let ds = bc.s_b - bc.s_a;
    [dt, ds, ds / dt, ds / dt / dt, ds / dt / dt / dt]
}

/// A named law outside the 7-segment class, from its closed form (zero end rates).
fn closed_form(named: NamedLaw, input: &EvaluateInput, warnings: Vec<Warning>) -> EvaluateResponse {
    let bc = &input.bc;
    let [dt, ds, kv, ka, kj] = scales(bc);
    let f = named.peak_factors();
    let peaks = PeaksOut {
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
        let mut c = empty_curves(xs);
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
            set(&mut c, q, out);
        }
        c
    });
    EvaluateResponse {
        law: Some(named),
        coefficients: None,
        durations: None,
        knots: None,
        peaks,
        acceleration_jumps: jumps,
        curves,
        warnings,
        units: input.units.clone(),
    }
}

fn empty_curves(xs: &[f64]) -> Curves {
    Curves {
        x: xs.to_vec(),
        s: None,
        v: None,
        a: None,
        j: None,
    }
}

fn set(c: &mut Curves, q: Quantity, values: Vec<f64>) {
    let slot = match q {
        Quantity::S => &mut c.s,
        Quantity::V => &mut c.v,
        Quantity::A => &mut c.a,
        Quantity::J => &mut c.j,
    };
    *slot = Some(values);
}

/// Every f64 of the response must be finite (JSON cannot carry NaN/Inf, and a silent NaN is a bug).
fn ensure_finite(r: &EvaluateResponse) -> Result<(), CalcFailure> {
    let mut bad: Option<&'static str> = None;
    let mut check = |name: &'static str, xs: &[f64]| {
        if bad.is_none() && !xs.iter().all(|x| x.is_finite()) {
            bad = Some(name);
        }
    };
    check("coefficients", r.coefficients.as_deref().unwrap_or(&[]));
    check("durations", r.durations.as_deref().unwrap_or(&[]));
    for k in r.knots.as_deref().unwrap_or(&[]) {
        check("knots", &[k.x, k.s, k.v, k.a_left, k.a_right]);
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
    for j in &r.acceleration_jumps {
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
    match bad {
        None => Ok(()),
        Some(name) => Err(CalcFailure::general(
            ProblemClass::TooLarge,
            "NON_FINITE_RESULT",
            format!(
                "the law's {name} overflow f64 for these boundary conditions (interval too short for this rise or these end rates)"
            ),
        )),
    }
}
