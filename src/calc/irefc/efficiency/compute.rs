//! Slip speeds, friction power and mesh efficiency per rolling element (spec `irefc_efficiency.md`,
//! "Algorithm"; efficiency paper eqs 7–23).

use super::input::{EfficiencyInput, EfficiencyModel};
use crate::calc::irefc::error::IrefcError;
use crate::calc::irefc::geometry::Geometry;
use crate::calc::irefc::stress::compute::element_forces;
use crate::numerics::Budget;

/// One loaded element \[SI\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementLoss {
    /// Element index k.
    pub k: u32,
    /// φ2 \[rad\].
    pub phi: f64,
    /// L \[m\].
    pub l: f64,
    /// LA = L − rb \[m\].
    pub la: f64,
    /// LB = L + rb \[m\].
    pub lb: f64,
    /// Element force R \[N\].
    pub r: f64,
    /// Slip speed at A [m/s] (paper Vs, or rigid-body vs).
    pub vs: f64,
    /// Element rotation rate [rad/s] (paper ωb, or rigid-body spin relative to the cage).
    pub omega_b: f64,
    /// Rigid body: rolling rate on the cam Ω_A [rad/s].
    pub omega_a_roll: Option<f64>,
    /// Rigid body: rolling rate on the crown Ω_B [rad/s].
    pub omega_b_roll: Option<f64>,
    /// Loss at A \[W\].
    pub nsa: f64,
    /// Loss at B \[W\].
    pub nsb: f64,
    /// NSA + NSB \[W\].
    pub ns: f64,
    /// 1 − NS/P_in.
    pub eta: f64,
}

/// Totals of one cage phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseTotals {
    /// Σ NS \[W\].
    pub ns_total: f64,
    /// Largest NS \[W\].
    pub ns_max: f64,
    /// k of the largest NS.
    pub k_at_max: u32,
    /// Π η_k; `None` if some η_k ≤ 0.
    pub eta_product: Option<f64>,
    /// 1 − Σ NS/P_in.
    pub eta_linear: f64,
    /// Whether some NSA or NS is negative (signed slip of "paper_table").
    pub negative_loss: bool,
}

/// Losses of one cage phase.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseLosses {
    /// Fmax \[N\].
    pub fmax: f64,
    /// Elements.
    pub elements: Vec<ElementLoss>,
    /// Totals.
    pub totals: PhaseTotals,
}

/// Mean/min/max.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
}

/// Phase statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseStatistics {
    /// Σ NS \[W\].
    pub ns_total: Stats,
    /// η product (`None` if some phase has no product).
    pub eta_product: Option<Stats>,
    /// η linear.
    pub eta_linear: Stats,
    /// Whether any phase had a negative loss.
    pub negative_loss: bool,
    /// Whether any phase had losses ≥ input.
    pub losses_exceed_input: bool,
}

/// Output of the efficiency computation.
#[derive(Debug, Clone, PartialEq)]
pub struct EfficiencyOutput {
    /// Lossless cam torque [N·m].
    pub t_cam: f64,
    /// Cam speed 2ω1/(Z2−1) [rad/s].
    pub omega_cam: f64,
    /// The requested phase.
    pub phase: PhaseLosses,
    /// Over `n_phase` phases (n_phase > 1).
    pub stats: Option<PhaseStatistics>,
}

/// Loss of one element in `model` (spec step 5). `r` [N], `l` [m]; returns (vs, ωb, Ω_A, Ω_B, NSA, NSB).
fn element_loss(
    g: &Geometry,
    model: EfficiencyModel,
    omega1: f64,
    mu: f64,
    fs: f64,
    r: f64,
    l: f64,
) -> (f64, f64, Option<f64>, Option<f64>, f64, f64) {
    let z = g.z2f;
    let rb = g.rb;
    let la = l - rb;
    let lb = l + rb;
    match model {
        EfficiencyModel::PaperTable | EfficiencyModel::PaperAbs => {
            let v12 = 2.0 * omega1 * la / (z * (z - 1.0));
            let v23 = 2.0 * omega1 * lb / (z * (z + 1.0));
            let vs = v12 - v23;
            let omega_b = v23 / rb;
            let slip = if model == EfficiencyModel::PaperAbs {
                vs.abs()
            } else {
                vs
            };
            let nsa = r * mu.mul_add(omega_b, fs * slip);
            let nsb = r * mu * omega_b;
            (vs, omega_b, None, None, nsa, nsb)
        }
        EfficiencyModel::RigidBody => {
            let w12 = -omega1 * (z + 1.0) / (z * (z - 1.0));
            let w32 = omega1 / z;
            let wb = w32 * lb / rb;
            let vs = w12.mul_add(la, w32 * lb);
            let om_b = omega1 * l / (z * rb);
            let om_a = wb - w12;
            let nsb = r * mu * om_b.abs();
            let nsa = r * mu.mul_add(om_a.abs(), fs * vs.abs());
            (vs, wb, Some(om_a), Some(om_b), nsa, nsb)
        }
    }
}

/// Losses at cage phase fraction `p` (spec steps 3–6).
#[must_use]
pub fn phase_losses(inp: &EfficiencyInput, t_cam: f64, p: f64) -> PhaseLosses {
    let g = &inp.geometry;
    let forces = element_forces(g, t_cam, p);
    let mut elements = Vec::with_capacity(forces.elements.len());
    let mut ns_total = 0.0;
    let mut ns_max = f64::NEG_INFINITY;
    let mut k_at_max = 0;
    let mut product = 1.0;
    let mut product_ok = true;
    let mut negative_loss = false;
    for e in &forces.elements {
        let l = g.l(e.phi);
        let (vs, omega_b, om_a, om_b, nsa, nsb) =
            element_loss(g, inp.model, inp.omega1, inp.mu, inp.fs, e.f, l);
        let ns = nsa + nsb;
        let eta = 1.0 - ns / inp.p_in;
        ns_total += ns;
        if ns > ns_max {
            ns_max = ns;
            k_at_max = e.k;
        }
        if eta <= 0.0 {
            product_ok = false;
        }
        product *= eta;
        negative_loss |= nsa < 0.0 || ns < 0.0;
        elements.push(ElementLoss {
            k: e.k,
            phi: e.phi,
            l,
            la: l - g.rb,
            lb: l + g.rb,
            r: e.f,
            vs,
            omega_b,
            omega_a_roll: om_a,
            omega_b_roll: om_b,
            nsa,
            nsb,
            ns,
            eta,
        });
    }
    PhaseLosses {
        fmax: forces.fmax,
        elements,
        totals: PhaseTotals {
            ns_total,
            ns_max,
            k_at_max,
            eta_product: product_ok.then_some(product),
            eta_linear: 1.0 - ns_total / inp.p_in,
            negative_loss,
        },
    }
}

fn stats(values: impl Iterator<Item = f64>) -> Stats {
    let mut n = 0u32;
    let mut sum = 0.0;
    let mut min = f64::INFINITY;
    let mut max = f64::NEG_INFINITY;
    for v in values {
        n += 1;
        sum += v;
        min = min.min(v);
        max = max.max(v);
    }
    Stats {
        mean: sum / f64::from(n.max(1)),
        min,
        max,
    }
}

/// Compute the efficiency (spec steps 1–7).
///
/// # Errors
/// [`IrefcError::Deadline`] if the budget runs out during the phase average; [`IrefcError::NonFinite`] on
/// overflow.
pub fn compute(inp: &EfficiencyInput, budget: &Budget) -> Result<EfficiencyOutput, IrefcError> {
    let g = &inp.geometry;
    let t_cam = inp.m_in * (g.z2f - 1.0) / 2.0;
    let omega_cam = 2.0 * inp.omega1 / (g.z2f - 1.0);
    let phase = phase_losses(inp, t_cam, inp.phase_fraction);
    let t = &phase.totals;
    for (q, v) in [
        ("Fmax", phase.fmax),
        ("NS_total", t.ns_total),
        ("eta_linear", t.eta_linear),
    ] {
        if !v.is_finite() {
            return Err(IrefcError::NonFinite {
                quantity: q,
                phi_deg: None,
            });
        }
    }
    let stats = if inp.n_phase > 1 {
        let mut all = Vec::with_capacity(inp.n_phase as usize);
        for i in 0..inp.n_phase {
            if budget.expired() {
                return Err(IrefcError::Deadline {
                    evaluations: u64::from(i),
                });
            }
            let p = (f64::from(i) + 0.5) / f64::from(inp.n_phase);
            all.push(phase_losses(inp, t_cam, p).totals);
        }
        let eta_product = all
            .iter()
            .map(|t| t.eta_product)
            .collect::<Option<Vec<f64>>>()
            .map(|v| stats(v.into_iter()));
        Some(PhaseStatistics {
            ns_total: stats(all.iter().map(|t| t.ns_total)),
            eta_product,
            eta_linear: stats(all.iter().map(|t| t.eta_linear)),
            negative_loss: all.iter().any(|t| t.negative_loss),
            losses_exceed_input: all
                .iter()
                .any(|t| t.eta_product.is_none() || t.ns_total >= inp.p_in),
        })
    } else {
        None
    };
    Ok(EfficiencyOutput {
        t_cam,
        omega_cam,
        phase,
        stats,
    })
}
