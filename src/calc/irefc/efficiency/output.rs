//! The one place that builds the wire response of `POST /v1/irefc-efficiency` from the domain
//! output: geometry, warnings, per-element table, totals and phase statistics.

use std::time::Instant;

use super::CONFIGURATION;
use super::compute::{self, EfficiencyOutput, PhaseTotals};
use super::input::{EfficiencyInput, ROLLING_FRICTION_HIGH_MM};
use super::wire::{
    EfficiencyElement, EfficiencyMeta, EfficiencyTotals, IrefcEfficiencyResponse, NullableStat,
    PhaseStats, Stat,
};
use crate::calc::irefc::error::IrefcError;
use crate::calc::irefc::output::geometry_warnings;
use crate::calc::irefc::wire::{GeometryOut, MM, Warning};

/// Builds the response (`meta.compute_ms` counted from `t0`, the request's arrival).
///
/// # Errors
/// [`IrefcError::NonFinite`] when the geometry's wire form overflows f64 (absurd scales).
pub fn respond(
    inp: &EfficiencyInput,
    out: &EfficiencyOutput,
    t0: Instant,
) -> Result<IrefcEfficiencyResponse, IrefcError> {
    let g = &inp.geometry;
    let geometry = GeometryOut::from_geometry(g, None);
    if !geometry.is_finite() {
        return Err(IrefcError::NonFinite {
            quantity: "geometry",
            phi_deg: None,
        });
    }
    let t = &out.phase.totals;
    let mut warnings = geometry_warnings(g);
    let mu_mm = inp.mu * MM;
    if mu_mm > ROLLING_FRICTION_HIGH_MM {
        warnings.push(Warning::new(
            "ROLLING_FRICTION_HIGH",
            format!(
                "rolling friction lever arm {mu_mm} mm exceeds {ROLLING_FRICTION_HIGH_MM} mm; rolling loss dominates"
            ),
        ));
    }
    let neg = t.negative_loss || out.stats.is_some_and(|s| s.negative_loss);
    if neg {
        warnings.push(Warning::new(
            "NEGATIVE_LOSS",
            "an element loss is negative: the signed slip speed of \"paper_table\" makes sliding 'gain' power; use model \"paper_abs\"",
        ));
    }
    if exceeds(t, inp.p_in) || out.stats.is_some_and(|s| s.losses_exceed_input) {
        warnings.push(Warning::new(
            "LOSSES_EXCEED_INPUT",
            format!(
                "friction losses {} W reach the input power {} W (or some element's eta_k <= 0); eta_product is null where undefined",
                t.ns_total, inp.p_in
            ),
        ));
    }
    let elements = inp.elements.then(|| {
        out.phase
            .elements
            .iter()
            .map(|e| EfficiencyElement {
                k: e.k,
                phi2_deg: e.phi.to_degrees(),
                l_mm: e.l * MM,
                la_mm: e.la * MM,
                lb_mm: e.lb * MM,
                r_n: e.r,
                vs_m_s: e.vs,
                omega_b_rad_s: e.omega_b,
                nsa_w: e.nsa,
                nsb_w: e.nsb,
                ns_w: e.ns,
                eta_k: e.eta,
                omega_a_rad_s: e.omega_a_roll,
                omega_b_roll_rad_s: e.omega_b_roll,
            })
            .collect()
    });
    let phase_stats = out.stats.map(|s| PhaseStats {
        n_phase: inp.n_phase,
        ns_total_w: stat(s.ns_total),
        eta_product: NullableStat {
            mean: s.eta_product.map(|x| x.mean),
            min: s.eta_product.map(|x| x.min),
            max: s.eta_product.map(|x| x.max),
        },
        eta_linear: stat(s.eta_linear),
    });
    Ok(IrefcEfficiencyResponse {
        model: inp.model,
        configuration: CONFIGURATION.to_owned(),
        geometry,
        omega1_rad_s: inp.omega1,
        m_in_nm: inp.m_in,
        p_in_w: inp.p_in,
        t_cam_nm: out.t_cam,
        omega_cam_rad_s: out.omega_cam,
        fmax_n: out.phase.fmax,
        elements,
        totals: EfficiencyTotals {
            ns_total_w: t.ns_total,
            ns_max_w: t.ns_max,
            k_at_max: t.k_at_max,
            eta_product: t.eta_product,
            eta_linear: t.eta_linear,
            p_out_w: inp.p_in - t.ns_total,
        },
        phase_stats,
        warnings,
        meta: EfficiencyMeta {
            compute_ms: t0.elapsed().as_secs_f64() * 1e3,
        },
    })
}

fn exceeds(t: &PhaseTotals, p_in: f64) -> bool {
    t.eta_product.is_none() || t.ns_total >= p_in
}

const fn stat(s: compute::Stats) -> Stat {
    Stat {
        mean: s.mean,
        min: s.min,
        max: s.max,
    }
}
