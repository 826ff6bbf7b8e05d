//! Wire types of `POST /v1/irefc-efficiency` (spec `irefc_efficiency.md`, "JSON example" is the contract).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::irefc::wire::{CHI, GeometryOut, R2_MM, RB_MM, Warning, Z2};

/// Loss model.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = irefc::efficiency::EfficiencyModel)]
#[serde(rename_all = "snake_case")]
pub enum EfficiencyModel {
    /// The paper's equations exactly as printed (signed slip speed); reproduces its Table 1.
    #[default]
    PaperTable,
    /// The paper's equations with |Vs| in the sliding loss (what the paper's text says).
    PaperAbs,
    /// NOT in the paper: rigid-body relative speeds in the carrier frame (pure rolling at the crown, slip at
    /// the cam); physically consistent speeds, about (Z2+1)/2 times the paper's.
    RigidBody,
}

impl EfficiencyModel {
    /// Wire name.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::PaperTable => "paper_table",
            Self::PaperAbs => "paper_abs",
            Self::RigidBody => "rigid_body",
        }
    }
}

/// Optional outputs.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::efficiency::EfficiencyInclude)]
#[serde(deny_unknown_fields)]
pub struct EfficiencyInclude {
    /// Per-element table (default true).
    pub elements: Option<bool>,
}

/// Request of `POST /v1/irefc-efficiency`. Configuration: carrier input, crown fixed, cam output.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::efficiency::IrefcEfficiencyRequest)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
#[schema(example = json!({"r2_mm":20,"Z2":26,"chi":1.4,"rb_mm":2,"power_W":1500,"speed_rpm":1500,
    "rolling_friction_mm":1.0,"sliding_friction":0.1,"model":"paper_table","phase_deg":0,"n_phase":1,
    "include":{"elements":true}}))]
pub struct IrefcEfficiencyRequest {
    /// Cage generating (pitch) circle radius r2 \[mm\].
    #[rule(range = R2_MM)]
    #[schema(example = 20.0)]
    pub r2_mm: f64,
    /// Number of rolling elements Z2 [–].
    #[serde(rename = "Z2")]
    #[rule(range = Z2)]
    #[schema(example = 26)]
    pub z2: i64,
    /// Displacement coefficient χ (rc = χ·r2) [–].
    #[rule(range = CHI)]
    #[schema(example = 1.4)]
    pub chi: f64,
    /// Rolling element radius rb \[mm\]; must be below rb_overlap and rb_undercut.
    #[rule(range = RB_MM)]
    #[schema(example = 2.0)]
    pub rb_mm: f64,
    /// Input (motor) power P_in \[W\]; give this or `input_torque_Nm`, not both.
    #[serde(rename = "power_W")]
    #[rule(range = POWER_W)]
    #[schema(example = 1500.0)]
    pub power_w: Option<f64>,
    /// Input torque M_in [N·m]; alternative to `power_W`.
    #[serde(rename = "input_torque_Nm")]
    #[rule(range = INPUT_TORQUE_NM)]
    #[schema(example = 9.549297)]
    pub input_torque_nm: Option<f64>,
    /// Input shaft (carrier) speed n \[rpm\].
    #[rule(range = SPEED_RPM)]
    #[schema(example = 1500.0)]
    pub speed_rpm: f64,
    /// Rolling-friction lever arm μ \[mm\] (default 1.0, the paper's 0.001 m).
    #[rule(range = ROLLING_FRICTION_MM)]
    #[schema(example = 1.0)]
    pub rolling_friction_mm: Option<f64>,
    /// Sliding friction coefficient f_s [–] (default 0.1, the paper's).
    #[rule(range = SLIDING_FRICTION)]
    #[schema(example = 0.1)]
    pub sliding_friction: Option<f64>,
    /// "paper_table" (default), "paper_abs" or "rigid_body".
    #[schema(nullable = false)]
    pub model: Option<EfficiencyModel>,
    /// Cage phase: element k at φ2 = phase + 360k/Z2 \[deg\], in [0, 360/Z2) (default 0, the paper);
    /// the upper end depends on `Z2`.
    #[rule(range = PHASE_DEG)]
    #[schema(example = 0.0)]
    pub phase_deg: Option<f64>,
    /// Number of equally spaced cage phases to average over (1 = the paper; default 1).
    #[rule(range = N_PHASE)]
    #[schema(example = 1)]
    pub n_phase: Option<u32>,
    /// Optional outputs.
    #[schema(nullable = false)]
    pub include: Option<EfficiencyInclude>,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for IrefcEfficiencyRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// One loaded element (efficiency paper Table 1 row).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::EfficiencyElement)]
pub struct EfficiencyElement {
    /// Element index k (paper row k + 1).
    pub k: u32,
    /// Element angle φ2 \[deg\].
    pub phi2_deg: f64,
    /// Pitch point to element centre L \[mm\] (eq. 7, corrected).
    #[serde(rename = "L_mm")]
    pub l_mm: f64,
    /// Pitch point to cam contact LA = L − rb \[mm\] (eq. 8).
    #[serde(rename = "LA_mm")]
    pub la_mm: f64,
    /// Pitch point to crown contact LB = L + rb \[mm\] (eq. 8).
    #[serde(rename = "LB_mm")]
    pub lb_mm: f64,
    /// Element force R \[N\].
    #[serde(rename = "R_N")]
    pub r_n: f64,
    /// Slip speed at the cam contact [m/s] (paper models: Vs of eq. 14, signed; rigid_body: vs).
    #[serde(rename = "Vs_m_s")]
    pub vs_m_s: f64,
    /// Element rotation rate [rad/s] (paper: ωb = V23/rb; rigid_body: spin relative to the cage).
    pub omega_b_rad_s: f64,
    /// Friction power at the cam contact A \[W\] (eq. 18).
    #[serde(rename = "NSA_W")]
    pub nsa_w: f64,
    /// Friction power at the crown contact B \[W\] (eq. 19).
    #[serde(rename = "NSB_W")]
    pub nsb_w: f64,
    /// NSA + NSB \[W\] (eq. 22).
    #[serde(rename = "NS_W")]
    pub ns_w: f64,
    /// 1 − NS/P_in (eq. 21).
    pub eta_k: f64,
    /// rigid_body only: element rolling rate on the cam [rad/s].
    #[serde(rename = "Omega_A_rad_s", skip_serializing_if = "Option::is_none")]
    pub omega_a_rad_s: Option<f64>,
    /// rigid_body only: element rolling rate on the crown [rad/s].
    #[serde(rename = "Omega_B_rad_s", skip_serializing_if = "Option::is_none")]
    pub omega_b_roll_rad_s: Option<f64>,
}

/// Totals over the loaded elements.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::EfficiencyTotals)]
pub struct EfficiencyTotals {
    /// Σ NS \[W\].
    #[serde(rename = "NS_total_W")]
    pub ns_total_w: f64,
    /// Largest element loss \[W\].
    #[serde(rename = "NS_max_W")]
    pub ns_max_w: f64,
    /// Element index with the largest loss.
    pub k_at_max: u32,
    /// Π η_k (eq. 23); null when some η_k ≤ 0.
    pub eta_product: Option<f64>,
    /// 1 − Σ NS/P_in (energy balance).
    pub eta_linear: f64,
    /// P_in − Σ NS \[W\].
    #[serde(rename = "P_out_W")]
    pub p_out_w: f64,
}

/// Mean, minimum and maximum over the cage phases.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::Stat)]
pub struct Stat {
    /// Mean (midpoint rule over the phase).
    pub mean: f64,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
}

/// Mean, minimum and maximum over the cage phases, null where undefined.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::NullableStat)]
pub struct NullableStat {
    /// Mean (midpoint rule over the phase); null when undefined.
    pub mean: Option<f64>,
    /// Minimum; null when undefined.
    pub min: Option<f64>,
    /// Maximum; null when undefined.
    pub max: Option<f64>,
}

/// Statistics over `n_phase` equally spaced cage phases (midpoints).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::PhaseStats)]
pub struct PhaseStats {
    /// Phases evaluated.
    pub n_phase: u32,
    /// Σ NS \[W\].
    #[serde(rename = "NS_total_W")]
    pub ns_total_w: Stat,
    /// η product; its fields are null when some phase has an η_k ≤ 0.
    pub eta_product: NullableStat,
    /// η from the energy balance.
    pub eta_linear: Stat,
}

/// Cost.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::EfficiencyMeta)]
pub struct EfficiencyMeta {
    /// Wall-clock compute time \[ms\].
    pub compute_ms: f64,
}

/// Response of `POST /v1/irefc-efficiency`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::efficiency::IrefcEfficiencyResponse)]
pub struct IrefcEfficiencyResponse {
    /// Loss model used.
    pub model: EfficiencyModel,
    /// Always "carrier_in/crown_fixed/cam_out".
    pub configuration: String,
    /// Derived geometry.
    pub geometry: GeometryOut,
    /// Input speed ω1 = 2π·n/60 [rad/s].
    pub omega1_rad_s: f64,
    /// Input torque M_in [N·m].
    #[serde(rename = "M_in_Nm")]
    pub m_in_nm: f64,
    /// Input power P_in \[W\].
    #[serde(rename = "P_in_W")]
    pub p_in_w: f64,
    /// Lossless cam torque M_in·(Z2−1)/2 [N·m].
    #[serde(rename = "T_cam_Nm")]
    pub t_cam_nm: f64,
    /// Cam (output) speed 2ω1/(Z2−1) [rad/s] (eq. 13; opposite to the input).
    pub omega_cam_rad_s: f64,
    /// Fmax of the element set \[N\].
    #[serde(rename = "Fmax_N")]
    pub fmax_n: f64,
    /// Per-element table (`include.elements`, default on).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<Vec<EfficiencyElement>>,
    /// Totals at `phase_deg`.
    pub totals: EfficiencyTotals,
    /// Phase statistics (n_phase > 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub phase_stats: Option<PhaseStats>,
    /// Warnings.
    pub warnings: Vec<Warning>,
    /// Cost.
    pub meta: EfficiencyMeta,
}

/// Input power P_in \[W\]: 0 < P ≤ 1e8 (spec).
pub const POWER_W: Range = Range::FINITE.gt(0.0).max(1e8);
/// Input torque M_in [N·m]: 0 < M ≤ 1e7 (the stress endpoint's torque scale).
pub const INPUT_TORQUE_NM: Range = Range::FINITE.gt(0.0).max(1e7);
/// Input speed \[rpm\]: 0 < n ≤ 1e6 (spec).
pub const SPEED_RPM: Range = Range::FINITE.gt(0.0).max(1e6);
/// Rolling-friction lever arm μ \[mm\]: 0 ≤ μ ≤ 10 (spec).
pub const ROLLING_FRICTION_MM: Range = Range::closed(0.0, 10.0);
/// Sliding friction coefficient f_s [–]: 0 ≤ f_s ≤ 1.
pub const SLIDING_FRICTION: Range = Range::closed(0.0, 1.0);
/// Cage phase \[deg\]: ≥ 0; the upper end 360/Z2 (exclusive) depends on Z2 (a cross-field rule,
/// [`phase_deg_range`]).
pub const PHASE_DEG: Range = Range::FINITE.min(0.0);
/// Number of cage phases averaged (spec).
pub const N_PHASE: Range = Range::int(1, 10_000);

/// The cage phase range of a design with `z2` elements \[deg\]: [0, 360/Z2).
#[must_use]
pub fn phase_deg_range(z2: u32) -> Range {
    PHASE_DEG.lt(360.0 / f64::from(z2))
}
