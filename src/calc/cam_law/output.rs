//! The one place that builds the wire response of `POST /v1/cam-law/evaluate` from the domain
//! output (and the wire forms of the domain findings and curves, shared with the fit).

use super::compute::{EvaluateOutput, EvaluatedPeaks};
use super::input::EvaluateInput;
use super::law::{LawNotice, SampledCurves};
use super::wire::{Curves, EvaluateResponse, PeaksOut, Warning};
use crate::calc::common::ResponseSize;

impl From<LawNotice> for Warning {
    fn from(n: LawNotice) -> Self {
        match n {
            LawNotice::CoefficientsRenormalized => Self::CoefficientsRenormalized,
            LawNotice::NonIdentifiable => Self::NonIdentifiable,
            LawNotice::PeakSignUnusual => Self::PeakSignUnusual,
            LawNotice::DerivedChannelNoiseGain => Self::DerivedChannelNoiseGain,
            LawNotice::SegmentBelowResolution => Self::SegmentBelowResolution,
            LawNotice::BudgetExhausted => Self::BudgetExhausted,
        }
    }
}

impl From<SampledCurves> for Curves {
    fn from(c: SampledCurves) -> Self {
        Self {
            x: c.x,
            s: c.s,
            v: c.v,
            a: c.a,
            j: c.j,
        }
    }
}

/// The wire codes of domain findings, in order.
#[must_use]
pub fn warnings(notices: &[LawNotice]) -> Vec<Warning> {
    notices.iter().map(|&n| Warning::from(n)).collect()
}

fn peaks(p: EvaluatedPeaks) -> PeaksOut {
    PeaksOut {
        a1: p.a1,
        a2: p.a2,
        a_max_abs: p.a_max_abs,
        v_max_abs: p.v_max_abs,
        x_at_v_max: p.x_at_v_max,
        jerk_max_abs_finite: p.jerk_max_abs_finite,
        peak_factors: p.peak_factors,
    }
}

/// Builds the response (the request's unit labels echoed).
#[must_use]
pub fn respond(input: &EvaluateInput, out: EvaluateOutput) -> EvaluateResponse {
    let (coefficients, durations, knots) = match out.class {
        Some(c) => (Some(c.coefficients), Some(c.durations), Some(c.knots)),
        None => (None, None, None),
    };
    EvaluateResponse {
        law: out.law,
        coefficients,
        durations,
        knots,
        peaks: peaks(out.peaks),
        acceleration_jumps: out.jumps,
        curves: out.curves.map(Curves::from),
        warnings: warnings(&out.warnings),
        units: input.units.clone(),
    }
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
