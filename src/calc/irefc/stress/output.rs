//! The one place that builds the wire response of `POST /v1/irefc-stress` from the domain output
//! (single design or sweep records), and the estimates of its size checked before computing.

use std::time::Instant;

use super::compute::{self, ComboOutcome, DesignResult, SweepResult, WheelMaxResult};
use super::input::{SingleInput, SweepInput};
use super::wire::{
    Curves, ElementOut, MaxOut, Reason, StressMeta, StressMode, StressSingleResponse,
    StressSweepResponse, SweepMeta, SweepRecord, WheelMax,
};
use crate::calc::common::{ResponseSize, Shard, ShardOut};
use crate::calc::irefc::error::IrefcError;
use crate::calc::irefc::geometry::Geometry;
use crate::calc::irefc::output::geometry_warnings;
use crate::calc::irefc::wire::{GeometryOut, MM, Warning};
use crate::numerics::SolverReport;

/// Pascals per MPa.
const MPA: f64 = 1e6;

/// Upper estimate of a single-design answer (before computing): fixed fields, then the element
/// table (Z2 rows), the curves ((N/stride + 2) points × 6 series) and the profiles (2 wheels ×
/// profile_points × 2 coordinates).
#[must_use]
pub fn single_size(s: &SingleInput) -> ResponseSize {
    let n = s.params.n_intervals as u64;
    let mut size = ResponseSize::fixed(8 * 1024);
    if s.elements {
        size = size.bytes("/include/elements", u64::from(s.design.z2) * (5 * 25 + 80));
    }
    if let Some(stride) = s.curves_stride {
        let points = n / (stride.max(1) as u64) + 2;
        size = size
            .numbers("/curves_stride", 6 * points)
            .bytes("/curves_stride", 200);
    }
    if let Some(p) = s.profile_points {
        size = size
            .numbers("/profile_points", 4 * u64::from(p))
            .bytes("/profile_points", 6 * u64::from(p));
    }
    size
}

/// Bytes of one sweep record at most: 15 numbers, their names, a reason message and warning
/// codes.
const SWEEP_RECORD_BYTES: u64 = 1536;

/// Upper estimate of a sweep answer: fixed fields and one record per combination of the shard.
#[must_use]
pub fn sweep_size(s: &SweepInput, shard: Shard) -> ResponseSize {
    let records = shard.range(s.len()).len() as u64;
    ResponseSize::fixed(8 * 1024).bytes("/sweep", records.saturating_mul(SWEEP_RECORD_BYTES))
}

/// Builds the single-design response (`meta.compute_ms` counted from `t0`, before computing).
///
/// # Errors
/// [`IrefcError::NonFinite`] when the geometry's wire form overflows f64 (absurd scales).
pub fn respond_single(
    inp: &SingleInput,
    r: &DesignResult,
    t0: Instant,
) -> Result<StressSingleResponse, IrefcError> {
    let g = &r.geometry;
    let geometry = GeometryOut::from_geometry(g, inp.profile_points);
    if !geometry.is_finite() {
        return Err(IrefcError::NonFinite {
            quantity: "geometry",
            phi_deg: None,
        });
    }
    let mut warnings = geometry_warnings(g);
    if r.n_intervals > inp.params.n_intervals {
        warnings.push(Warning::new(
            "GRID_REFINED",
            format!(
                "phase_exact with refine: the maximum search used {} grid intervals ({} deg) instead of {} so that every load-sharing ripple (period 360/Z2 deg) is resolved",
                r.n_intervals,
                180.0 / r.n_intervals as f64,
                inp.params.n_intervals
            ),
        ));
    }
    let elements = inp.elements.then(|| {
        r.forces
            .elements
            .iter()
            .map(|e| ElementOut {
                k: e.k,
                phi2_deg: e.phi.to_degrees(),
                alpha_deg: e.alpha.to_degrees(),
                h_mm: e.h * MM,
                f_n: e.f,
            })
            .collect()
    });
    let curves = r.curves.as_ref().map(|c| Curves {
        phi2_deg: c.phi.iter().map(|v| v.to_degrees()).collect(),
        f_n: c.f.clone(),
        sigma_cam_mpa: c.sigma_cam.iter().map(|v| v / MPA).collect(),
        sigma_crown_mpa: c.sigma_crown.iter().map(|v| v / MPA).collect(),
        rho_cam_mm: c.rho_cam.iter().map(|v| v.map(|x| x * MM)).collect(),
        rho_crown_mm: c.rho_crown.iter().map(|v| v.map(|x| x * MM)).collect(),
    });
    let p = &inp.params;
    Ok(StressSingleResponse {
        mode: StressMode::Single,
        geometry,
        t_cam_nm: r.t_cam,
        t_crown_nm: r.t_crown,
        t_in_nm: r.t_in,
        e_star_mpa: r.e_star / MPA,
        lb_mm: r.lb * MM,
        fmax_n: r.forces.fmax,
        sum_h2_mm2: r.forces.sum_h2 * MM * MM,
        elements,
        max: MaxOut {
            cam: wheel_max(&r.cam, p.subsurface),
            crown: wheel_max(&r.crown, p.subsurface),
            overall: r.governing().map(|m| m.wheel.name().to_owned()),
        },
        curves,
        warnings,
        meta: StressMeta {
            step_deg: p.step_deg,
            refine: p.refine,
            load_sharing: p.load_sharing,
            n_grid: r.n_intervals as u64 + 1,
            evaluations: r.evaluations,
            compute_ms: t0.elapsed().as_secs_f64() * 1e3,
        },
    })
}

/// Wire form of one wheel's maximum.
fn wheel_max(m: &WheelMaxResult, subsurface: bool) -> WheelMax {
    let pt = m.point.as_ref();
    WheelMax {
        phi2_deg: m.phi.map(f64::to_degrees),
        sigma_mpa: m.sigma / MPA,
        f_n: m.f,
        h_mm: pt.map(|a| a.lever_arm(m.wheel) * MM),
        alpha_deg: pt.map(|a| a.alpha.to_degrees()),
        l_mm: pt.map(|a| a.l * MM),
        rho_mm: pt.and_then(|a| a.rho(m.wheel)).map(|r| r * MM),
        b_mm: m.b * MM,
        tau_max_mpa: subsurface.then_some(compute::TAU_MAX_RATIO * m.sigma / MPA),
        tau_depth_mm: subsurface.then_some(compute::TAU_DEPTH_RATIO * m.b * MM),
    }
}

/// Builds the sweep response from the outcomes of the combinations `offset..` (all of them, or a
/// shard's block, described by `shard` when the request gave one): records in order,
/// `best`/`worst` as global indices, `meta.compute_ms` counted from `t0` (before computing).
#[must_use]
pub fn respond_sweep(
    inp: &SweepInput,
    offset: usize,
    res: &SweepResult,
    shard: Option<ShardOut>,
    t0: Instant,
) -> StressSweepResponse {
    let mut records = Vec::with_capacity(res.outcomes.len());
    let (mut n_valid, mut n_invalid, mut n_not) = (0u64, 0u64, 0u64);
    let mut worst: Option<(usize, f64)> = None;
    let mut best: Option<(usize, f64)> = None;
    for (k, o) in res.outcomes.iter().enumerate() {
        let i = offset + k;
        let d = inp.design(i);
        let base = |valid: bool, reason: Option<Reason>, g: Option<&Geometry>| SweepRecord {
            z2: d.z2,
            chi: d.chi,
            rb_mm: d.rb * MM,
            r2_mm: d.r2 * MM,
            valid,
            reason,
            fmax_n: None,
            sigma_cam_max_mpa: None,
            phi2_cam_deg: None,
            sigma_crown_max_mpa: None,
            phi2_crown_deg: None,
            sigma_max_mpa: None,
            governing: None,
            f_at_max_n: None,
            rho_at_max_mm: None,
            min_profile_radius_mm: g
                .map(|g| g.min_profile_radius() * MM)
                .filter(|v| v.is_finite()),
            warnings: g
                .map(|g| g.warnings().iter().map(|w| w.code().to_owned()).collect())
                .unwrap_or_default(),
        };
        let rec = match o {
            ComboOutcome::Valid(r) => {
                n_valid += 1;
                let rec = valid_record(base(true, None, Some(&r.geometry)), r);
                let s = rec.sigma_max_mpa.unwrap_or(0.0);
                if worst.is_none_or(|(_, w)| s > w) {
                    worst = Some((i, s));
                }
                if best.is_none_or(|(_, b)| s < b) {
                    best = Some((i, s));
                }
                rec
            }
            ComboOutcome::Invalid {
                code,
                message,
                geometry,
            } => {
                n_invalid += 1;
                let mut rec = base(
                    false,
                    Some(Reason {
                        code: (*code).to_owned(),
                        message: message.clone(),
                    }),
                    None,
                );
                rec.min_profile_radius_mm =
                    Some(geometry.min_profile_radius() * MM).filter(|v| v.is_finite());
                rec
            }
            ComboOutcome::NotEvaluated => {
                n_invalid += 1;
                n_not += 1;
                base(
                    false,
                    Some(Reason {
                        code: "NOT_EVALUATED".to_owned(),
                        message: "not evaluated: the time or evaluation budget ran out first"
                            .to_owned(),
                    }),
                    None,
                )
            }
        };
        records.push(rec);
    }
    let mut warnings = inp.warnings.clone();
    if n_not > 0 {
        warnings.push(Warning::new(
            "SWEEP_INCOMPLETE",
            format!(
                "{n_not} of {} combinations were not evaluated before the budget ran out",
                records.len()
            ),
        ));
    }
    let p = &inp.params;
    let elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
    StressSweepResponse {
        mode: StressMode::Sweep,
        worst: worst.map(|w| w.0),
        best: best.map(|b| b.0),
        shard: shard.map(Box::new),
        n_valid,
        n_invalid,
        n_not_evaluated: n_not,
        warnings,
        meta: SweepMeta {
            step_deg: p.step_deg,
            refine: p.refine,
            load_sharing: p.load_sharing,
            n_grid: p.n_intervals as u64 + 1,
            n_combinations: records.len() as u64,
            threads: res.threads,
            compute_ms: elapsed_ms,
            solver: SolverReport {
                stop_reason: res.stop_reason,
                iterations: res.evaluated,
                evaluations: res.evaluated,
                elapsed_ms,
            },
        },
        records,
    }
}

/// Fill the result fields of a valid record.
fn valid_record(mut rec: SweepRecord, r: &DesignResult) -> SweepRecord {
    rec.fmax_n = Some(r.forces.fmax);
    rec.sigma_cam_max_mpa = Some(r.cam.sigma / MPA);
    rec.phi2_cam_deg = r.cam.phi.map(f64::to_degrees);
    rec.sigma_crown_max_mpa = Some(r.crown.sigma / MPA);
    rec.phi2_crown_deg = r.crown.phi.map(f64::to_degrees);
    rec.sigma_max_mpa = Some(r.cam.sigma.max(r.crown.sigma) / MPA);
    let gov = r.governing();
    rec.governing = gov.map(|m| m.wheel.name().to_owned());
    rec.f_at_max_n = Some(gov.map_or(0.0, |m| m.f));
    rec.rho_at_max_mm = gov
        .and_then(|m| m.point.and_then(|a| a.rho(m.wheel)))
        .map(|v| v * MM);
    rec
}
