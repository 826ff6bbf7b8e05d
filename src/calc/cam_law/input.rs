//! The rules between fields of an [`EvaluateRequest`] (spec §2, §8b), turning it into an
//! [`EvaluateInput`]. Every per-field rule (ranges, lengths, exactly one of `coefficients`/`law`
//! and of `values`/`grid`) is declared on the wire types and checked at the door; what is left here
//! is what JSON Schema cannot state, each rule with its own code ([`CROSS_FIELD_RULES`]).

use super::catalogue::NamedLaw;
use super::law::{
    BoundaryConditions, LawError, LawNotice, MIN_RELATIVE_INTERVAL, Quantity,
    normalize_coefficients,
};
use super::wire::{AbscissaIn, ConstraintsIn, EvaluateRequest, Units};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/cam-law/evaluate`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid COEFFICIENT_SUM ["/coefficients", "/normalize"]
        "The coefficients sum to 1 within 1e-3, unless `normalize` is true (then any positive sum).";
    invalid EMPTY_PULSE ["/coefficients"]
        "Both acceleration pulses are non-empty: c0 + c1 + c2 and c4 + c5 + c6 each at least 1e-9 of the sum.";
    invalid ABSCISSA_ORDER ["/abscissa/values/*", "/abscissa/grid/end"]
        "Abscissae strictly increase; a grid's `end` is greater than its `start`.";
    invalid SEGMENT_INTERVAL ["/constraints/t_a", "/constraints/t_b"]
        "t_b > t_a (each defaulting to the first/last abscissa, else 0 and 1), and t_b − t_a exceeds \
         1e-12·max(|t_a|, |t_b|) so the knots stay distinct.";
    invalid ABSCISSA_OUTSIDE ["/abscissa/values/*", "/abscissa/grid/start", "/abscissa/grid/end",
        "/constraints/t_a", "/constraints/t_b"]
        "Every abscissa lies in [t_a, t_b] within 1e-9·(t_b − t_a) (values within that tolerance are clamped).";
    invalid CLOSED_FORM_RATES ["/law", "/constraints/v_a", "/constraints/v_b", "/constraints/a_a",
        "/constraints/a_b"]
        "A named law outside the 7-segment class (constant_velocity, cubic, polynomial_*, \
         double_harmonic) requires zero end velocities and accelerations.";
    too_large LAW_OVERFLOW ["/constraints"]
        "The law's peaks stay finite in f64 (a very short interval with a large rise or large end rates overflows).";
    too_large NON_FINITE_RESULT ["/constraints", "/abscissa"]
        "Every reported number is finite in f64.";
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

/// Coefficients must sum to 1 within this unless `normalize` is set (spec §2).
pub const SUM_TOL: f64 = 1e-3;

/// Sums closer to 1 than this are round-off of printed decimals: renormalized without a warning.
pub const SUM_SILENT_TOL: f64 = 1e-12;

/// Abscissae up to this fraction of Δt outside `[t_a, t_b]` are clamped, farther ones rejected
/// (spec §2).
pub const ABSCISSA_TOL: f64 = 1e-9;

/// Which law to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawChoice {
    /// The general 7-segment law with these (validated, not yet normalized) coefficients;
    /// `named` is set when they come from a named law of the class.
    SevenSegment {
        /// Coefficients as given (non-negative, both pulses non-empty).
        coefficients: [f64; 7],
        /// The named law they stand for, if any.
        named: Option<NamedLaw>,
    },
    /// A named law outside the 7-segment class (closed form, zero end rates).
    ClosedForm(NamedLaw),
}

/// A validated evaluate request.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluateInput {
    /// The law.
    pub law: LawChoice,
    /// Boundary conditions, defaults applied.
    pub bc: BoundaryConditions,
    /// Abscissae exactly as given (grid materialized); `None` without an `abscissa`.
    pub xs: Option<Vec<f64>>,
    /// Requested quantities, deduplicated, in the order s, v, a, j.
    pub quantities: Vec<Quantity>,
    /// Warnings raised during validation (`coefficients_renormalized`).
    pub warnings: Vec<LawNotice>,
    /// Unit labels to echo.
    pub units: Option<Units>,
}

enum Abscissa {
    Values(Vec<f64>),
    Grid { start: f64, end: f64, count: usize },
}

impl Abscissa {
    fn first_last(&self) -> Option<(f64, f64)> {
        match self {
            Self::Values(v) => Some((*v.first()?, *v.last()?)),
            Self::Grid { start, end, .. } => Some((*start, *end)),
        }
    }

    fn materialize(self) -> Vec<f64> {
        match self {
            Self::Values(v) => v,
            Self::Grid { start, end, count } => {
                let last = count - 1;
                // count ≤ 200 000, so the usize → f64 conversions are exact.
                let step = (end - start) / last as f64;
                let mut xs: Vec<f64> = (0..count).map(|k| start + step * k as f64).collect();
                xs[last] = end;
                xs
            }
        }
    }
}

fn check_abscissa(v: &mut Validator, a: Option<AbscissaIn>) -> Option<Abscissa> {
    // Exactly one of `values`/`grid`, lengths and ranges: checked at the door.
    let a = a?;
    if let Some(values) = a.values {
        if let Some(i) = values.windows(2).position(|w| w[1] <= w[0]) {
            rule!(v, ABSCISSA_ORDER, format!("/abscissa/values/{}", i + 1);
                "abscissae must be strictly increasing, got {} after {} at index {i}",
                values[i + 1], values[i]);
            return None;
        }
        return Some(Abscissa::Values(values));
    }
    let g = a.grid?;
    if g.end <= g.start {
        rule!(v, ABSCISSA_ORDER, "/abscissa/grid/end";
            "must be > start = {}, got {}", g.start, g.end);
        return None;
    }
    // count ≤ MAX_POINTS (checked at the door): the conversion is exact.
    let count = usize::try_from(g.count).ok()?;
    Some(Abscissa::Grid {
        start: g.start,
        end: g.end,
        count,
    })
}

/// Validate the coefficients; returns them (as given) and whether a renormalization warning is due.
fn check_coefficients(v: &mut Validator, c: &[f64], normalize: bool) -> Option<([f64; 7], bool)> {
    // Seven non-negative numbers: checked at the door.
    let arr = <[f64; 7]>::try_from(c).ok()?;
    let sum: f64 = arr.iter().sum();
    if !normalize && (sum - 1.0).abs() > SUM_TOL {
        rule!(v, COEFFICIENT_SUM, "/coefficients";
            "coefficients must sum to 1 within {SUM_TOL} (or set normalize: true), got sum {sum}");
        return None;
    }
    match normalize_coefficients(&arr) {
        Ok(_) => Some((arr, (sum - 1.0).abs() > SUM_SILENT_TOL)),
        Err(LawError::EmptyFirstPulse { area }) => {
            rule!(v, EMPTY_PULSE, "/coefficients";
                "the first acceleration pulse (c0, c1, c2) is empty: normalized area {area:e} < 1e-9");
            None
        }
        Err(LawError::EmptySecondPulse { area }) => {
            rule!(v, EMPTY_PULSE, "/coefficients";
                "the second acceleration pulse (c4, c5, c6) is empty: normalized area {area:e} < 1e-9");
            None
        }
        Err(e) => {
            rule!(v, EMPTY_PULSE, "/coefficients"; "{}", e.to_string());
            None
        }
    }
}

/// The law: coefficients (validated as given) xor a named law; a renormalization warning goes to
/// `warnings`.
fn law(
    v: &mut Validator,
    req: &EvaluateRequest,
    warnings: &mut Vec<LawNotice>,
) -> Option<LawChoice> {
    // Exactly one of the two: checked at the door.
    match (&req.coefficients, req.law) {
        (Some(_), Some(_)) | (None, None) => None,
        (Some(c), None) => check_coefficients(v, c, req.normalize).map(|(coefficients, warn)| {
            if warn {
                warnings.push(LawNotice::CoefficientsRenormalized);
            }
            LawChoice::SevenSegment {
                coefficients,
                named: None,
            }
        }),
        (None, Some(named)) => Some(match named.seven_segment_coefficients() {
            Some(coefficients) => LawChoice::SevenSegment {
                coefficients,
                named: Some(named),
            },
            None => LawChoice::ClosedForm(named),
        }),
    }
}

/// The boundary conditions, defaults applied (`t_a`, `t_b` from the abscissa's `ends` where
/// given); returns them and whether they are valid.
fn boundary(
    v: &mut Validator,
    c: &ConstraintsIn,
    ends: Option<(f64, f64)>,
) -> (BoundaryConditions, bool) {
    let bc = BoundaryConditions {
        t_a: c.t_a.or(ends.map(|e| e.0)).unwrap_or(0.0),
        t_b: c.t_b.or(ends.map(|e| e.1)).unwrap_or(1.0),
        s_a: c.s_a.unwrap_or(0.0),
        s_b: c.s_b.unwrap_or(1.0),
        v_a: c.v_a.unwrap_or(0.0),
        v_b: c.v_b.unwrap_or(0.0),
        a_a: c.a_a.unwrap_or(0.0),
        a_b: c.a_b.unwrap_or(0.0),
    };
    // Every given value and every abscissa is within BOUNDARY_VALUE (the door), so the defaulted
    // values are too.
    let mut bc_ok = true;
    let defaulted = |given: Option<f64>, what: &str| {
        if given.is_some() {
            String::new()
        } else {
            format!(" (defaulted to the {what})")
        }
    };
    if bc.t_b <= bc.t_a {
        rule!(v, SEGMENT_INTERVAL, "/constraints/t_b";
            "t_b must be > t_a = {}{}, got {}{}", bc.t_a, defaulted(c.t_a, "first abscissa"),
            bc.t_b, defaulted(c.t_b, "last abscissa"));
        bc_ok = false;
    } else if bc.t_b - bc.t_a <= MIN_RELATIVE_INTERVAL * bc.t_a.abs().max(bc.t_b.abs()) {
        rule!(v, SEGMENT_INTERVAL, "/constraints/t_b";
            "t_b - t_a = {:e} is too short to resolve knots at this offset (must exceed {MIN_RELATIVE_INTERVAL:e}·max(|t_a|, |t_b|))",
            bc.t_b - bc.t_a);
        bc_ok = false;
    }
    (bc, bc_ok)
}

/// A named law outside the 7-segment class has zero end rates only.
fn closed_form_rates(v: &mut Validator, law: Option<&LawChoice>, bc: &BoundaryConditions) {
    let Some(LawChoice::ClosedForm(named)) = law else {
        return;
    };
    for (name, value) in [
        ("v_a", bc.v_a),
        ("v_b", bc.v_b),
        ("a_a", bc.a_a),
        ("a_b", bc.a_b),
    ] {
        ensure_rule!(v, value == 0.0 || !value.is_finite(),
            CLOSED_FORM_RATES, format!("/constraints/{name}");
            "must be 0 for the named law `{}`, which is outside the 7-segment class (only zero end rates), got {value}",
            named.wire_name());
    }
}

/// Every abscissa within `[t_a, t_b]` (to [`ABSCISSA_TOL`]·Δt).
fn abscissa_within(v: &mut Validator, a: &Abscissa, bc: &BoundaryConditions) {
    let tol = ABSCISSA_TOL * (bc.t_b - bc.t_a);
    let (lo, hi) = (bc.t_a - tol, bc.t_b + tol);
    let range = || format!("[t_a, t_b] = [{}, {}] (tolerance {tol:e})", bc.t_a, bc.t_b);
    match a {
        Abscissa::Values(xs) => {
            let mut bad = xs
                .iter()
                .enumerate()
                .filter(|(_, x)| !(lo..=hi).contains(*x));
            if let Some((i, x)) = bad.next() {
                let more = bad.count();
                let tail = if more > 0 {
                    format!(" ({more} more outside)")
                } else {
                    String::new()
                };
                rule!(v, ABSCISSA_OUTSIDE, format!("/abscissa/values/{i}");
                    "abscissa {x} lies outside {}{tail}", range());
            }
        }
        Abscissa::Grid { start, end, .. } => {
            ensure_rule!(v, *start >= lo, ABSCISSA_OUTSIDE, "/abscissa/grid/start";
                "grid start {start} lies outside {}", range());
            ensure_rule!(v, *end <= hi, ABSCISSA_OUTSIDE, "/abscissa/grid/end";
                "grid end {end} lies outside {}", range());
        }
    }
}

impl TryFrom<EvaluateRequest> for EvaluateInput {
    type Error = CalcFailure;

    fn try_from(req: EvaluateRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let mut warnings = Vec::new();
        let law = law(&mut v, &req, &mut warnings);
        let abscissa = check_abscissa(&mut v, req.abscissa);
        let ends = abscissa.as_ref().and_then(Abscissa::first_last);
        let (bc, bc_ok) = boundary(&mut v, &req.constraints, ends);
        closed_form_rates(&mut v, law.as_ref(), &bc);
        if let (true, Some(a)) = (bc_ok, &abscissa) {
            abscissa_within(&mut v, a, &bc);
        }
        v.finish()?;
        // `finish` succeeded and the door admitted exactly one of `coefficients`/`law`.
        let Some(law) = law else {
            return Err(crate::calc::rules::door_skipped("/coefficients"));
        };
        let requested = req.quantities.unwrap_or_else(|| Quantity::ALL.to_vec());
        let quantities = Quantity::ALL
            .into_iter()
            .filter(|q| requested.contains(q))
            .collect();
        Ok(Self {
            law,
            bc,
            xs: abscissa.map(Abscissa::materialize),
            quantities,
            warnings,
            units: req.units,
        })
    }
}
