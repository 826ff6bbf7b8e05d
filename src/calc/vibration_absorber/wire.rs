//! Wire types of `POST /v1/vibration-absorber` (spec `vibration_absorber.md` §2, §5, §9). SI units
//! throughout, carried in the field names; every input has a default (the model-consistent case of
//! spec §2), so `{}` is a valid request.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::Warning;
use crate::numerics::SolverReport;

/// Beam length, positions and abscissae \[m\]: positive; positions also ≤ `beam.length_m`.
pub const LENGTH: Range = Range::FINITE.gt(0.0).max(1e3);
/// Output abscissae \[m\]: in [0, 1e3], and ≤ `beam.length_m`.
pub const ABSCISSA: Range = Range::closed(0.0, 1e3);
/// Young's modulus \[Pa\].
pub const MODULUS: Range = Range::FINITE.gt(0.0).max(1e13);
/// Density [kg/m³].
pub const DENSITY: Range = Range::FINITE.gt(0.0).max(1e6);
/// Section area \[m²\], second moment \[m⁴\], section width/thickness \[m\]: at least 1e-30 (below
/// it the bending stiffness EI underflows and the modes are not finite).
pub const SECTION: Range = Range::FINITE.min(1e-30).max(1e2);
/// Modes kept (spec §2: 1…50; mode-shape cost and overflow beyond).
pub const N_MODES: Range = Range::int(1, 50);
/// Mode index of a `{mode: k}` reference (also ≤ `beam.n_modes`).
pub const MODE_INDEX: Range = Range::int(1, 50);
/// Modal damping ratio ζ: 0 ≤ ζ < 1.
pub const DAMPING_RATIO: Range = Range::FINITE.min(0.0).lt(1.0);
/// Absorber mass \[kg\].
pub const MASS: Range = Range::FINITE.gt(0.0).max(1e6);
/// Absorber stiffness [N/m] (0 = no spring).
pub const STIFFNESS: Range = Range::closed(0.0, 1e12);
/// Absorber viscous damping [N·s/m].
pub const DAMPING: Range = Range::closed(0.0, 1e9);
/// A frequency \[Hz\] (tunings, excitation, grid ends).
pub const FREQUENCY: Range = Range::FINITE.gt(0.0).max(1e6);
/// Coil resistance \[Ω\].
pub const RESISTANCE: Range = Range::FINITE.gt(0.0).max(1e6);
/// Coil inductance \[H\] (L_c = 0 would make the coil algebraic: rejected, spec §7.6).
pub const INDUCTANCE: Range = Range::FINITE.gt(0.0).max(1e3);
/// Force constant [N/A] (≠ 0 with `active`).
pub const FORCE_CONSTANT: Range = Range::closed(-1e6, 1e6);
/// Back-EMF constant [V·s/m].
pub const BACK_EMF: Range = Range::closed(0.0, 1e6);
/// Explicit PD gains [V/m], [V·s/m].
pub const GAIN: Range = Range::closed(-1e12, 1e12);
/// Force amplitude \[N\] (impulse [N·s]).
pub const AMPLITUDE: Range = Range::closed(-1e9, 1e9);
/// Excitation phase \[rad\].
pub const PHASE: Range = Range::closed(-1e6, 1e6);
/// Frequency-grid size (spec §2: at most 1e5 points).
pub const FREQ_POINTS: Range = Range::int(1, 100_000);
/// Time horizon \[s\].
pub const T_END: Range = Range::FINITE.gt(0.0).max(1e6);
/// Output step \[s\] (also `t_end_s / dt_s ≤ 2e6`).
pub const DT: Range = Range::FINITE.gt(0.0).max(1e3);
/// Series decimation (every k-th sample).
pub const DECIMATE: Range = Range::int(1, 2_000_000);
/// Largest number of time samples `t_end_s / dt_s` (spec §2).
pub const MAX_SAMPLES: f64 = 2e6;
/// Mode-shape samples along the beam.
pub const SHAPE_POINTS: Range = Range::int(2, 10_001);
/// Largest number of output abscissae per analysis.
pub const MAX_POINTS: usize = 64;
/// Largest number of components of `excitation.harmonics` (each adds two exosystem states, so
/// the augmented system stays ≤ 103 + 32 = 135 states).
pub const MAX_HARMONICS: usize = 16;

/// Request of `POST /v1/vibration-absorber`: beam, absorber, actuator, control law, excitation and
/// the analyses wanted. Every member is optional (spec §2 defaults).
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::VibrationAbsorberRequest)]
#[serde(deny_unknown_fields)]
pub struct VibrationAbsorberRequest {
    /// The cantilever.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub beam: BeamIn,
    /// The tuned mass (absorber).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub absorber: AbsorberIn,
    /// The voice-coil actuator between absorber and beam.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub actuator: ActuatorIn,
    /// Configuration and PD law.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub control: ControlIn,
    /// The force on the beam.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub excitation: ExcitationIn,
    /// Optional analyses (none is computed unless asked).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: OutputsIn,
    /// Wall-clock budget of this request \[ms\] (capped by the service).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 10000)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    pub time_limit_ms: Option<u64>,
}

/// Uniform Euler–Bernoulli cantilever (spec §2, §3.A). Give `area_m2` and `second_moment_m4`
/// together, or `section` (rectangle), not both; default section 50 mm × 5 mm.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::BeamIn)]
#[serde(deny_unknown_fields)]
pub struct BeamIn {
    /// Length `L` \[m\], default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 1.0)]
    #[rule(range = LENGTH)]
    pub length_m: Option<f64>,
    /// Young's modulus `E` \[Pa\], default 2.1e11.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 2.1e11)]
    #[rule(range = MODULUS)]
    pub youngs_modulus_pa: Option<f64>,
    /// Density `ρ` [kg/m³], default 7850.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 7850.0)]
    #[rule(range = DENSITY)]
    pub density_kg_m3: Option<f64>,
    /// Cross-section area `A` \[m²\] (with `second_moment_m4`; exclusive with `section`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = SECTION)]
    pub area_m2: Option<f64>,
    /// Second moment of area `I` \[m⁴\] (with `area_m2`; exclusive with `section`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = SECTION)]
    pub second_moment_m4: Option<f64>,
    /// Rectangular section: `A = b·e`, `I = b·e³/12` (exclusive with `area_m2`/`second_moment_m4`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub section: Option<SectionIn>,
    /// Number of cantilever modes kept `n`, 1…50, default 3. The truncation error dominates every
    /// other error (spec §8): 0.14 % static compliance at n = 3, 0.004 % at n = 10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 3)]
    #[rule(range = N_MODES)]
    pub n_modes: Option<u32>,
    /// Modal damping ratio `ζ` (all modes), 0 ≤ ζ < 1, default 0 (the paper has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 0.0)]
    #[rule(range = DAMPING_RATIO)]
    pub modal_damping_ratio: Option<f64>,
}

/// Rectangular cross-section.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::SectionIn)]
#[serde(deny_unknown_fields)]
pub struct SectionIn {
    /// Width `b` \[m\].
    #[schema(example = 0.05)]
    #[rule(range = SECTION)]
    pub width_m: f64,
    /// Thickness `e` \[m\] (bending direction).
    #[schema(example = 0.005)]
    #[rule(range = SECTION)]
    pub thickness_m: f64,
}

/// The absorber: mass, spring and damper between the beam at `position_m` and the mass.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::AbsorberIn)]
#[serde(deny_unknown_fields)]
pub struct AbsorberIn {
    /// Mass `m_a` \[kg\], default 0.05.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 0.05)]
    #[rule(range = MASS)]
    pub mass_kg: Option<f64>,
    /// Spring stiffness `k_a` [N/m]; when omitted, `k_a = m_a (2π f)²` from the passive tuning.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = STIFFNESS)]
    pub stiffness_n_m: Option<f64>,
    /// Passive tuning frequency `f` \[Hz\] setting `k_a` (exclusive with `stiffness_n_m` and
    /// `passive_tuning_mode`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 4.14)]
    #[rule(range = FREQUENCY)]
    pub passive_tuning_hz: Option<f64>,
    /// Passive tuning to the bare-beam mode `k` (≤ `beam.n_modes`); the default is mode 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = MODE_INDEX)]
    pub passive_tuning_mode: Option<u32>,
    /// Viscous damping `b_a` [N·s/m], default 0.01 (spec §4 item 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 0.01)]
    #[rule(range = DAMPING)]
    pub damping_n_s_m: Option<f64>,
    /// Attachment abscissa `x_a` from the clamp \[m\], 0 < x_a ≤ `beam.length_m`, default the tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 1.0)]
    #[rule(range = LENGTH)]
    pub position_m: Option<f64>,
}

/// Voice-coil actuator: `u = K_c i`, `L_c di/dt = −R i − K_b ṙ + e_c`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::ActuatorIn)]
#[serde(deny_unknown_fields)]
pub struct ActuatorIn {
    /// Coil resistance `R` \[Ω\], default 1.6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 1.6)]
    #[rule(range = RESISTANCE)]
    pub resistance_ohm: Option<f64>,
    /// Coil inductance `L_c` \[H\], default 0.75e-3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 0.00075)]
    #[rule(range = INDUCTANCE)]
    pub inductance_h: Option<f64>,
    /// Force constant `K_c` [N/A], default 3.5; must not be 0 with `control.mode = active`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 3.5)]
    #[rule(range = FORCE_CONSTANT)]
    pub force_constant_n_a: Option<f64>,
    /// Back-EMF constant `K_b` [V·s/m], default 3.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 3.5)]
    #[rule(range = BACK_EMF)]
    pub back_emf_v_s_m: Option<f64>,
}

/// Configuration of the absorber.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = vibration_absorber::ControlMode)]
#[serde(rename_all = "snake_case")]
pub enum ControlMode {
    /// Bare beam: no absorber at all.
    None,
    /// Absorber with the coil open (`i ≡ 0`): a passive tuned mass damper.
    Passive,
    /// Coil short-circuited (`e_c = 0`): back-EMF damping `K_b K_c / R`.
    PassiveShorted,
    /// PD on the stroke: `e_c = −(K_p r + K_d ṙ)`.
    #[default]
    Active,
}

/// Configuration and PD law. With `active`, the gains come from `kp_v_m` + `kd_v_s_m` when both
/// are given, else from the tuning (Eq. (7)(8)): `tuning_hz`, or `tuning_mode` (bare-beam `f_k`;
/// default mode 2).
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::ControlIn)]
#[serde(deny_unknown_fields)]
pub struct ControlIn {
    /// Configuration, default `active`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub mode: ControlMode,
    /// Target frequency `f_c` \[Hz\] of the tuning (exclusive with `tuning_mode`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 26.26)]
    #[rule(range = FREQUENCY)]
    pub tuning_hz: Option<f64>,
    /// Tune to the bare-beam mode `k` (≤ `beam.n_modes`); the default is mode 2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = MODE_INDEX)]
    pub tuning_mode: Option<u32>,
    /// Explicit proportional gain `K_p` [V/m] (with `kd_v_s_m`; overrides the tuning).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = GAIN)]
    pub kp_v_m: Option<f64>,
    /// Explicit derivative gain `K_d` [V·s/m] (with `kp_v_m`; overrides the tuning).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = GAIN)]
    pub kd_v_s_m: Option<f64>,
}

/// Time law of the force.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = vibration_absorber::ExcitationType)]
#[serde(rename_all = "snake_case")]
pub enum ExcitationType {
    /// `p(t) = P0 sin(Ωt + φ0)`.
    #[default]
    Harmonic,
    /// An impulse `J = P0` [N·s] at t = 0.
    Impulse,
    /// A step `p = P0` for t ≥ 0.
    Step,
    /// No force (the time response is zero).
    None,
}

/// The force on the beam, applied at `position_m`. One harmonic: `amplitude_n`, `frequency_hz` or
/// `resonance_of_mode` (the model's bare-beam `f_k`; default mode 2) and `phase_rad`. Several
/// harmonics (spec §3.D.4): list them in `harmonics` instead (then `amplitude_n`, `frequency_hz`,
/// `resonance_of_mode` and `phase_rad` must be absent); `p(t) = Σ_j P_j sin(Ω_j t + φ_j)`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::ExcitationIn)]
#[serde(deny_unknown_fields)]
pub struct ExcitationIn {
    /// Time law, default `harmonic`.
    #[serde(
        default,
        deserialize_with = "crate::calc::rules::null_default",
        rename = "type"
    )]
    pub kind: ExcitationType,
    /// Force abscissa `x_p` \[m\], 0 < x_p ≤ `beam.length_m`, default the tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 1.0)]
    #[rule(range = LENGTH)]
    pub position_m: Option<f64>,
    /// Amplitude `P0` \[N\] (impulse: [N·s]), default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 1.0)]
    #[rule(range = AMPLITUDE)]
    pub amplitude_n: Option<f64>,
    /// Excitation frequency `Ω/2π` \[Hz\] (exclusive with `resonance_of_mode`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = FREQUENCY)]
    pub frequency_hz: Option<f64>,
    /// Excite at the bare-beam resonance of mode `k` (≤ `beam.n_modes`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 2)]
    #[rule(range = MODE_INDEX)]
    pub resonance_of_mode: Option<u32>,
    /// Phase `φ0` \[rad\], default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 0.0)]
    #[rule(range = PHASE)]
    pub phase_rad: Option<f64>,
    /// Several harmonic components at `position_m`, 1…16, each simulated exactly with its own 2×2
    /// exosystem block (type `harmonic` only; exclusive with the single-harmonic members
    /// `amplitude_n`, `frequency_hz`, `resonance_of_mode`, `phase_rad`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(min_items = 1, max_items = MAX_HARMONICS)]
    pub harmonics: Option<Vec<HarmonicIn>>,
}

/// One component `P_j sin(Ω_j t + φ_j)` of a multi-harmonic force. Give exactly one of
/// `frequency_hz` and `resonance_of_mode`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::HarmonicIn)]
#[serde(deny_unknown_fields)]
#[rules(one_of("frequency_hz", "resonance_of_mode"))]
pub struct HarmonicIn {
    /// Amplitude `P_j` \[N\].
    #[schema(example = 1.0)]
    #[rule(range = AMPLITUDE)]
    pub amplitude_n: f64,
    /// Frequency `Ω_j/2π` \[Hz\] (exclusive with `resonance_of_mode`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = FREQUENCY)]
    pub frequency_hz: Option<f64>,
    /// At the bare-beam resonance of mode `k` (≤ `beam.n_modes`; exclusive with `frequency_hz`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = MODE_INDEX)]
    pub resonance_of_mode: Option<u32>,
    /// Phase `φ_j` \[rad\], default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = PHASE)]
    pub phase_rad: Option<f64>,
}

/// The optional analyses (spec §5); each is computed only when present / true.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::OutputsIn)]
#[serde(deny_unknown_fields)]
pub struct OutputsIn {
    /// Undamped natural frequencies with and without the absorber (Table 2). O(n³).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub natural_frequencies: bool,
    /// Closed-loop eigenvalues, largest real part and stability label. O(N³).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub eigenvalues: bool,
    /// Absorber-only step responses (fixed base): settling time, overshoot, DC gain.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub ava_step: bool,
    /// Return the absorber-only step series too (with `ava_step`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub ava_step_series: bool,
    /// Absorber-only closed-loop FRF `X_a/Ref` on a grid (paper Fig. 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub ava_frequency_response: Option<GridIn>,
    /// Coupled FRF of beam deflections per unit force at `x_p`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub frequency_response: Option<FrequencyResponseIn>,
    /// Exact time response to the excitation (matrix exponential with an exosystem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub time_response: Option<TimeResponseIn>,
    /// Bare-beam mode shapes sampled along the beam.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub mode_shapes: Option<ModeShapesIn>,
}

/// Mode-shape sampling.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::ModeShapesIn)]
#[serde(deny_unknown_fields)]
pub struct ModeShapesIn {
    /// Equally spaced abscissae from the clamp to the tip, 2…10001.
    #[schema(example = 101)]
    #[rule(range = SHAPE_POINTS)]
    pub n_points: u32,
}

/// Bare-beam mode shapes `φ_k(x)` (dimensionless, `∫₀ᴸ φ_k² dx = L`, `φ_k(L) = 2(−1)^{k+1}`).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::ModeShapesOut)]
pub struct ModeShapesOut {
    /// Abscissae \[m\].
    pub x_m: Vec<f64>,
    /// `shapes[k][i] = φ_{k+1}(x_i)`.
    pub shapes: Vec<Vec<f64>>,
}

/// A frequency grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::GridIn)]
#[serde(deny_unknown_fields)]
pub struct GridIn {
    /// Lowest frequency \[Hz\].
    #[schema(example = 0.5)]
    #[rule(range = FREQUENCY)]
    pub f_min_hz: f64,
    /// Highest frequency \[Hz\], > `f_min_hz` (equal only with `n_points` = 1).
    #[schema(example = 100.0)]
    #[rule(range = FREQUENCY)]
    pub f_max_hz: f64,
    /// Number of frequencies, 1…1e5.
    #[schema(example = 400)]
    #[rule(range = FREQ_POINTS)]
    pub n_points: u32,
    /// Logarithmic spacing (default linear).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub log: bool,
}

/// Coupled frequency response request.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::FrequencyResponseIn)]
#[serde(deny_unknown_fields)]
pub struct FrequencyResponseIn {
    /// Lowest frequency \[Hz\].
    #[schema(example = 0.5)]
    #[rule(range = FREQUENCY)]
    pub f_min_hz: f64,
    /// Highest frequency \[Hz\], > `f_min_hz` (equal only with `n_points` = 1).
    #[schema(example = 100.0)]
    #[rule(range = FREQUENCY)]
    pub f_max_hz: f64,
    /// Number of frequencies, 1…1e5. Cost n_points · O(N³).
    #[schema(example = 400)]
    #[rule(range = FREQ_POINTS)]
    pub n_points: u32,
    /// Logarithmic spacing (default linear).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub log: bool,
    /// Output abscissae `x_o` \[m\], each in [0, `beam.length_m`], at most 64; default the tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = json!([1.0]))]
    #[rule(items = ABSCISSA, min_items = 1, max_items = MAX_POINTS)]
    pub points_m: Option<Vec<f64>>,
}

/// Time response request.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = vibration_absorber::TimeResponseIn)]
#[serde(deny_unknown_fields)]
pub struct TimeResponseIn {
    /// Horizon \[s\].
    #[schema(example = 10.0)]
    #[rule(range = T_END)]
    pub t_end_s: f64,
    /// Output step `h` \[s\] (the result is exact for any h; `t_end_s/dt_s` ≤ 2e6 samples). Samples
    /// are `t = k·h`, `k = 0…K`, `K = ⌈t_end_s/dt_s⌉` (a ratio within 1e-9 of an integer is that
    /// integer).
    #[schema(example = 0.001)]
    #[rule(range = DT)]
    pub dt_s: f64,
    /// Output abscissae `x_o` \[m\], each in [0, `beam.length_m`], at most 64; default the tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = json!([1.0]))]
    #[rule(items = ABSCISSA, min_items = 1, max_items = MAX_POINTS)]
    pub points_m: Option<Vec<f64>>,
    /// Return the sampled series (the biggest payload): `t_s`, `w_m` per abscissa, and with an
    /// absorber `stroke_m`, with a coil `force_n` and `current_a`, with `active` `voltage_v`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub return_series: bool,
    /// Keep every k-th sample in the series (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    #[rule(range = DECIMATE)]
    pub decimate: Option<u32>,
}

// ---------------------------------------------------------------------------------------------
// Response
// ---------------------------------------------------------------------------------------------

/// Answer of `POST /v1/vibration-absorber`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::VibrationAbsorberResponse)]
pub struct VibrationAbsorberResponse {
    /// Bare-beam modal data (always).
    pub beam: BeamOut,
    /// Absorber data (always).
    pub absorber: AbsorberOut,
    /// PD gains (configuration `active` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub gains: Option<GainsOut>,
    /// Undamped natural frequencies (`outputs.natural_frequencies`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub natural_frequencies: Option<NaturalFrequenciesOut>,
    /// Eigenvalues of the coupled system (`outputs.eigenvalues`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub closed_loop: Option<ClosedLoopOut>,
    /// Absorber-only step responses (`outputs.ava_step`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub ava_step: Option<AvaStepOut>,
    /// Absorber-only closed-loop FRF (`outputs.ava_frequency_response`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub ava_frequency_response: Option<AvaFrfOut>,
    /// Coupled FRF (`outputs.frequency_response`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub frequency_response: Option<FrfOut>,
    /// Exact time response (`outputs.time_response`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub time_response: Option<TimeOut>,
    /// Bare-beam mode shapes (`outputs.mode_shapes`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub mode_shapes: Option<ModeShapesOut>,
    /// Results returned with a caveat (marginal stability, nodes, resonance points, ...).
    pub warnings: Vec<Warning>,
    /// How the work stopped and what it cost (iterations = time steps, evaluations = matrix
    /// exponentials + complex solves).
    pub report: SolverReport,
}

/// Bare-beam modal data (spec §3.A).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::BeamOut)]
pub struct BeamOut {
    /// `β_k L`, k = 1…n.
    pub beta_l: Vec<f64>,
    /// Bare-beam natural frequencies `f_k` \[Hz\] (Euler–Bernoulli).
    pub natural_frequencies_hz: Vec<f64>,
    /// Modal mass `m = ρAL` \[kg\] (mode shapes with ∫φ² dx = L).
    pub modal_mass_kg: f64,
    /// Beam mass \[kg\].
    pub mass_kg: f64,
    /// Static compliance at the force point of the truncated model `Σ φ_k(x_p)²/(m ω_k²)` [m/N]
    /// (→ `L³/3EI` at the tip as n grows).
    pub static_compliance_m_per_n: f64,
    /// Nodes of the tuned mode (the one nearest `f_c`) \[m\]: an absorber there cannot act on it.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub tuned_mode_nodes_m: Option<Vec<f64>>,
}

/// Absorber data.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::AbsorberOut)]
pub struct AbsorberOut {
    /// Spring stiffness `k_a` in use [N/m].
    pub stiffness_n_m: f64,
    /// Passive frequency `sqrt(k_a/m_a)/2π` \[Hz\].
    pub passive_frequency_hz: f64,
    /// Mass ratio `m_a / (ρAL)`.
    pub mass_ratio: f64,
}

/// PD gains (spec §3.B).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::GainsOut)]
pub struct GainsOut {
    /// `K_p` [V/m].
    pub kp_v_m: f64,
    /// `K_d` [V·s/m].
    pub kd_v_s_m: f64,
    /// Target `f_c` \[Hz\] (absent for explicit gains).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub tuning_frequency_hz: Option<f64>,
    /// Third fixed-base root `−(R/L_c + b_a/m_a)` [1/s] (exact for tuned gains).
    pub third_pole_1_s: f64,
    /// Artificial stiffness `m_a ω_c² − k_a` [N/m]: at `f_c` in steady state `u = −k_art r`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub artificial_stiffness_n_m: Option<f64>,
}

/// Undamped natural frequencies (paper Table 2).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::NaturalFrequenciesOut)]
pub struct NaturalFrequenciesOut {
    /// Bare beam \[Hz\].
    pub without_absorber_hz: Vec<f64>,
    /// Beam + absorber mass and spring (no actuator, no damping) \[Hz\], n + 1 values.
    pub with_passive_absorber_hz: Vec<f64>,
}

/// Stability label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = vibration_absorber::Stability)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// max Re λ < −1e-9·max|λ|.
    Stable,
    /// |max Re λ| ≤ 1e-9·max|λ|.
    Marginal,
    /// max Re λ > 1e-9·max|λ|.
    Unstable,
}

/// One eigenvalue `λ = re + j·2π·im_hz`.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = vibration_absorber::Eigenvalue)]
pub struct EigenvalueOut {
    /// Real part [1/s].
    pub re_1_s: f64,
    /// Imaginary part / 2π \[Hz\].
    pub im_hz: f64,
}

/// Eigen-analysis of the coupled `A`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::ClosedLoopOut)]
pub struct ClosedLoopOut {
    /// Eigenvalues with `im_hz ≥ 0` (conjugates omitted), by ascending `im_hz`, then real part.
    pub eigenvalues: Vec<EigenvalueOut>,
    /// Largest real part [1/s].
    pub max_real_part_1_s: f64,
    /// Stability label (threshold 1e-9·max|λ|).
    pub stability: Stability,
    /// State size N.
    pub state_size: usize,
}

/// One fixed-base absorber step response.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::StepOut)]
pub struct StepOut {
    /// Settling time (2 % band, exact response, last crossing refined) \[s\]; absent when the
    /// response does not settle (undamped or integrating).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub settling_time_s: Option<f64>,
    /// Overshoot [%] = max(0, (max(y·sgn y∞) − |y∞|)/|y∞|·100): the sign of the DC gain is
    /// divided out, so a negative DC gain is measured the same way.
    pub overshoot_pct: f64,
    /// DC gain `y∞` (m/V for `xa_over_ec`, m/m for `xa_over_err`); absent without a spring
    /// (`k_a = 0`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub dc_gain: Option<f64>,
    /// Time samples \[s\] (`outputs.ava_step_series`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub t_s: Option<Vec<f64>>,
    /// Response samples (`outputs.ava_step_series`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub y: Option<Vec<f64>>,
}

/// Absorber-only step responses (paper Fig. 5).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::AvaStepOut)]
pub struct AvaStepOut {
    /// `X_a/E_c = K_c/D(s)` ("without control").
    pub xa_over_ec: StepOut,
    /// `X_a/Err = K_c(K_p + K_d s)/D(s)` ("PD in open loop"; configuration `active` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub xa_over_err: Option<StepOut>,
}

/// Absorber-only closed-loop FRF `G_cl(j2πf)` (paper Fig. 6).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::AvaFrfOut)]
pub struct AvaFrfOut {
    /// Frequencies \[Hz\].
    pub frequencies_hz: Vec<f64>,
    /// `|G_cl|` [m/m]; null where the denominator vanishes (the tuned pole on the axis).
    pub magnitude: Vec<Option<f64>>,
    /// Phase of `G_cl` \[deg\] in (−180, 180]; null as `magnitude`.
    pub phase_deg: Vec<Option<f64>>,
    /// Grid frequency of the largest `|G_cl|` \[Hz\] (the tuning `f_c` for tuned gains).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub peak_frequency_hz: Option<f64>,
}

/// Coupled frequency response.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::FrfOut)]
pub struct FrfOut {
    /// Frequencies \[Hz\].
    pub frequencies_hz: Vec<f64>,
    /// One receptance curve per output abscissa.
    pub points: Vec<FrfPointOut>,
}

/// Receptance `H(x_o, x_p, f) = w(x_o)/P` at one abscissa.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::FrfPointOut)]
pub struct FrfPointOut {
    /// Output abscissa `x_o` \[m\].
    pub x_m: f64,
    /// `|H|` [m/N] per frequency; null where `j2πf` is (numerically) an eigenvalue (undamped
    /// resonance, warning `UNDAMPED_RESONANCE`).
    pub magnitude_m_per_n: Vec<Option<f64>>,
    /// Phase of `H` \[deg\] in (−180, 180]; null as `magnitude_m_per_n`.
    pub phase_deg: Vec<Option<f64>>,
}

/// Reductions of the time response at one abscissa.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::TimePointOut)]
pub struct TimePointOut {
    /// Output abscissa `x_o` \[m\].
    pub x_m: f64,
    /// max |w| over all samples \[m\].
    pub max_abs_m: f64,
    /// max |w| over the samples with `t ≥ t_end − T` \[m\], `T` the excitation period (harmonic;
    /// with several harmonics the longest component period) or 1 s (other excitations), whole
    /// horizon if shorter.
    pub max_abs_last_period_m: f64,
    /// RMS of w over all samples \[m\].
    pub rms_m: f64,
    /// Samples of w \[m\] (`return_series`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub w_m: Option<Vec<f64>>,
}

/// Exact time response (spec §3.D.4).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = vibration_absorber::TimeOut)]
pub struct TimeOut {
    /// `expm-exosystem`: one matrix exponential of the augmented autonomous system, then
    /// `s_{k+1} = Φ s_k` (re-anchored every 1e4 steps beyond 1e5 samples).
    pub method: String,
    /// Excitation frequency \[Hz\] (single harmonic only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub excitation_frequency_hz: Option<f64>,
    /// Frequency of each component of `excitation.harmonics` \[Hz\], in request order (several
    /// harmonics only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub excitation_frequencies_hz: Option<Vec<f64>>,
    /// Number of samples (t = 0, dt, …, K·dt).
    pub n_samples: usize,
    /// Per output abscissa.
    pub points: Vec<TimePointOut>,
    /// max |stroke r| \[m\] (with an absorber).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub stroke_max_m: Option<f64>,
    /// max |u = K_c i| \[N\] (with a coil).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub force_max_n: Option<f64>,
    /// max |i| \[A\] (with a coil).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub current_max_a: Option<f64>,
    /// max |e_c| \[V\] (`active`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub voltage_max_v: Option<f64>,
    /// Sample times \[s\] of the series (`return_series`, after decimation).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub t_s: Option<Vec<f64>>,
    /// Stroke samples \[m\] (`return_series`, with an absorber).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub stroke_m: Option<Vec<f64>>,
    /// Actuator force samples `u = K_c i` \[N\] (`return_series`, with a coil).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub force_n: Option<Vec<f64>>,
    /// Coil current samples `i` \[A\] (`return_series`, with a coil).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub current_a: Option<Vec<f64>>,
    /// Control voltage samples `e_c = −(K_p r + K_d ṙ)` \[V\] (`return_series`, `active`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub voltage_v: Option<Vec<f64>>,
}
