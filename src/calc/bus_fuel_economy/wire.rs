//! Wire types of `POST /v1/bus-fuel-economy` and `POST /v1/bus-fuel-economy/motor-map`
//! (spec §3, §6 and §10; the JSON example of §10 is the contract).
//!
//! Deviations from the §10 example, all additive: every result also carries `n_intervals`,
//! `max_speed_kmh`, `n_regen_limited` and `n_envelope_fallback`; the response carries a solver
//! `report`; `comparison` names its `reference_motor`, the cycle order of `d` and the weights.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{Shard, ShardOut};
use crate::numerics::SolverReport;

// ---------------------------------------------------------------------------------------------
// Request
// ---------------------------------------------------------------------------------------------

/// Drive-cycle energy and fuel economy of a battery-electric bus for 1..8 motors over 1..16 cycles.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::BusFuelEconomyRequest)]
#[serde(deny_unknown_fields)]
pub struct BusFuelEconomyRequest {
    /// Vehicle (defaults: the paper's 12 m bus, Tables 2-3).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub vehicle: VehicleSpec,
    /// Inverter (η_Inv).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub inverter: InverterSpec,
    /// Battery model (default: constant efficiency 1).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub battery: BatterySpec,
    /// Drive cycles: built-in names `manhattan`, `hwfet`, `hdudds` or custom traces (1..16).
    #[rule(min_items = 1, max_items = MAX_CYCLES)]
    pub cycles: Vec<CycleSpec>,
    /// Traction motors to compare (1..8); the first is the reference of `fe_change_pct`.
    #[rule(min_items = 1, max_items = MAX_MOTORS)]
    pub motors: Vec<MotorSpec>,
    /// Simulation options.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub options: OptionsSpec,
    /// Simulate only block `index` of `count` near-equal contiguous blocks of the motor × cycle
    /// pairs (motor-major, as `results`): the answers of shards 0..count, merged as `shard` in
    /// the answer says, equal the unsharded answer.
    #[serde(default)]
    #[schema(nullable = false)]
    pub shard: Option<Shard>,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 2000)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for BusFuelEconomyRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Vehicle of the backward longitudinal model (§3.1, paper eq. 4-5).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::VehicleSpec)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleSpec {
    /// Curb mass \[kg\].
    #[schema(example = 12500.0)]
    #[rule(range = CURB_MASS_KG)]
    #[serde(deserialize_with = "null_vehicle_curb_mass_kg")]
    pub curb_mass_kg: f64,
    /// Number of passengers [-] (0..500).
    #[schema(example = 40)]
    #[rule(range = PASSENGERS)]
    #[serde(deserialize_with = "null_vehicle_passengers")]
    pub passengers: u32,
    /// Mass per passenger \[kg\].
    #[schema(example = 65.0)]
    #[rule(range = MASS_PER_PASSENGER_KG)]
    #[serde(deserialize_with = "null_vehicle_mass_per_passenger_kg")]
    pub mass_per_passenger_kg: f64,
    /// Frontal area A_F \[m²\].
    #[schema(example = 6.72)]
    #[rule(range = FRONTAL_AREA_M2)]
    #[serde(deserialize_with = "null_vehicle_frontal_area_m2")]
    pub frontal_area_m2: f64,
    /// Aerodynamic drag coefficient C_d [-].
    #[schema(example = 0.7)]
    #[rule(range = DRAG_COEFF)]
    #[serde(deserialize_with = "null_vehicle_drag_coeff")]
    pub drag_coeff: f64,
    /// Rolling resistance coefficient f_R [-].
    #[schema(example = 0.007)]
    #[rule(range = ROLLING_COEFF)]
    #[serde(deserialize_with = "null_vehicle_rolling_coeff")]
    pub rolling_coeff: f64,
    /// Air density ρ_air [kg/m³].
    #[schema(example = 1.28)]
    #[rule(range = AIR_DENSITY)]
    #[serde(deserialize_with = "null_vehicle_air_density")]
    pub air_density: f64,
    /// Gravitational acceleration g [m/s²].
    #[schema(example = 9.81)]
    #[rule(range = GRAVITY)]
    #[serde(deserialize_with = "null_vehicle_gravity")]
    pub gravity: f64,
    /// Wheel radius r \[m\].
    #[schema(example = 0.48)]
    #[rule(range = WHEEL_RADIUS_M)]
    #[serde(deserialize_with = "null_vehicle_wheel_radius_m")]
    pub wheel_radius_m: f64,
    /// Single fixed reduction ratio i_g [-] (service minimum 0.01).
    #[schema(example = 9.5)]
    #[rule(range = GEAR_RATIO)]
    #[serde(deserialize_with = "null_vehicle_gear_ratio")]
    pub gear_ratio: f64,
    /// Gear efficiency η_T [-], applied in both power directions (service minimum 0.01).
    #[schema(example = 0.95)]
    #[rule(range = EFFICIENCY)]
    #[serde(deserialize_with = "null_vehicle_gear_efficiency")]
    pub gear_efficiency: f64,
    /// Rotational inertia factor δ [-]: effective mass m(1+δ).
    #[schema(example = 0.0)]
    #[rule(range = FRACTION)]
    #[serde(deserialize_with = "null_vehicle_rotational_inertia_factor")]
    pub rotational_inertia_factor: f64,
    /// Constant road slope tanθ [-] (a custom cycle's own `grade` array replaces it).
    #[schema(example = 0.0)]
    #[rule(range = GRADE)]
    #[serde(deserialize_with = "null_vehicle_grade")]
    pub grade: f64,
    /// Constant auxiliary DC load \[W\].
    #[schema(example = 0.0)]
    #[rule(range = AUX_POWER_W)]
    #[serde(deserialize_with = "null_vehicle_aux_power_w")]
    pub aux_power_w: f64,
}

impl Default for VehicleSpec {
    fn default() -> Self {
        Self {
            curb_mass_kg: 12_500.0,
            passengers: 40,
            mass_per_passenger_kg: 65.0,
            frontal_area_m2: 6.72,
            drag_coeff: 0.7,
            rolling_coeff: 0.007,
            air_density: 1.28,
            gravity: 9.81,
            wheel_radius_m: 0.48,
            gear_ratio: 9.5,
            gear_efficiency: 0.95,
            rotational_inertia_factor: 0.0,
            grade: 0.0,
            aux_power_w: 0.0,
        }
    }
}

/// Inverter (§3.2).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::InverterSpec)]
#[serde(deny_unknown_fields, default)]
pub struct InverterSpec {
    /// Inverter efficiency η_Inv [-], applied in both power directions (service minimum 0.01).
    #[schema(example = 0.95)]
    #[rule(range = EFFICIENCY)]
    #[serde(deserialize_with = "null_inverter_efficiency")]
    pub efficiency: f64,
}

impl Default for InverterSpec {
    fn default() -> Self {
        Self { efficiency: 0.95 }
    }
}

/// Battery model selector (§3.3).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bus_fuel_economy::BatteryModel)]
#[serde(rename_all = "snake_case")]
pub enum BatteryModel {
    /// Constant efficiency η_Bat in both directions.
    #[default]
    Constant,
    /// Two-RC equivalent circuit (paper eq. 7-10, discharge-positive current).
    #[serde(rename = "ecm_2rc")]
    Ecm2rc,
}

/// Battery (§3.3). Fields of the other model are rejected.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::BatterySpec)]
#[serde(deny_unknown_fields)]
pub struct BatterySpec {
    /// `constant` (default) or `ecm_2rc`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub model: BatteryModel,
    /// constant: battery efficiency η_Bat [-] (default 1.0, service minimum 0.01).
    #[schema(example = 1.0)]
    #[rule(range = EFFICIENCY)]
    pub efficiency: Option<f64>,
    /// ecm_2rc: nominal voltage \[V\] (default 360), used for the charge capacity Q.
    #[schema(example = 360.0)]
    #[rule(range = NOMINAL_VOLTAGE)]
    pub nominal_voltage: Option<f64>,
    /// ecm_2rc: energy capacity \[kWh\] (default 256).
    #[schema(example = 256.0)]
    #[rule(range = CAPACITY_KWH)]
    pub capacity_kwh: Option<f64>,
    /// ecm_2rc: initial state of charge (0, 1] [-].
    #[schema(example = 0.9)]
    #[rule(range = SOC_INITIAL)]
    pub soc_initial: Option<f64>,
    /// ecm_2rc: SOC points of the open-circuit-voltage table, strictly increasing in [0, 1].
    #[rule(items = FRACTION, min_items = 2)]
    pub ocv_soc: Option<Vec<f64>>,
    /// ecm_2rc: open-circuit voltage at `ocv_soc` \[V\] (> 0).
    #[rule(items = OCV_V)]
    pub ocv_v: Option<Vec<f64>>,
    /// ecm_2rc: series resistance R0 \[Ω\] (> 0).
    #[schema(example = 0.03)]
    #[rule(range = R0_OHM)]
    pub r0_ohm: Option<f64>,
    /// ecm_2rc: first RC branch resistance R1 \[Ω\] (≥ 0).
    #[schema(example = 0.01)]
    #[rule(range = RC_OHM)]
    pub r1_ohm: Option<f64>,
    /// ecm_2rc: first RC branch capacitance C1 \[F\] (> 0).
    #[schema(example = 3000.0)]
    #[rule(range = RC_F)]
    pub c1_f: Option<f64>,
    /// ecm_2rc: second RC branch resistance R2 \[Ω\] (≥ 0).
    #[schema(example = 0.01)]
    #[rule(range = RC_OHM)]
    pub r2_ohm: Option<f64>,
    /// ecm_2rc: second RC branch capacitance C2 \[F\] (> 0).
    #[schema(example = 30000.0)]
    #[rule(range = RC_F)]
    pub c2_f: Option<f64>,
}

/// A drive cycle: a built-in name or a custom trace (§3.4).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::CycleSpec)]
#[serde(untagged)]
pub enum CycleSpec {
    /// Built-in cycle: `manhattan`, `hwfet` or `hdudds`.
    Builtin(String),
    /// Custom speed-vs-time trace.
    Custom(CustomCycle),
}

/// A custom speed trace: 2..200 000 samples, time steps in [0.001, 60] s, speeds in [0, 200] m/s.
/// Give exactly one of `speed_kmh` and `speed_mps`.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::CustomCycle)]
#[serde(deny_unknown_fields)]
#[rules(one_of("speed_kmh", "speed_mps"))]
pub struct CustomCycle {
    /// Cycle name (unique in the request, 1..64 characters).
    #[rule(min_length = 1, max_length = MAX_NAME_LEN)]
    pub name: String,
    /// Sample times \[s\].
    #[rule(items = TIME_S, min_items = 2, max_items = MAX_CYCLE_SAMPLES)]
    pub time_s: Vec<f64>,
    /// Sample speeds [km/h].
    #[rule(items = SPEED_KMH)]
    pub speed_kmh: Option<Vec<f64>>,
    /// Sample speeds [m/s].
    #[rule(items = SPEED_MPS)]
    pub speed_mps: Option<Vec<f64>>,
    /// Road slope tanθ per sample [-] in [-0.3, 0.3] (replaces the vehicle's `grade`).
    #[rule(items = GRADE)]
    pub grade: Option<Vec<f64>>,
}

/// Torque envelope given as a table: T_max linear in speed, held constant outside the table.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::EnvelopeTable)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeTable {
    /// Speeds \[rpm\], strictly increasing, first ≥ 0.
    #[rule(items = SPEED_AXIS_RPM, min_items = 2)]
    pub speed_rpm: Vec<f64>,
    /// Maximum motor torque at `speed_rpm` [N·m] (> 0).
    #[rule(items = TORQUE_NM)]
    pub t_max_nm: Vec<f64>,
}

/// Traction motor (§3.5), selected by `model`.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::MotorSpec)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum MotorSpec {
    /// Constant efficiency η_M.
    Constant(ConstantMotor),
    /// Efficiency map η(n, T); converted to a loss map at its own grid points (§8 item 2).
    EfficiencyMap(EfficiencyMapMotor),
    /// Total loss map P_loss(n, T) (recommended map form).
    LossMap(LossMapMotor),
    /// Parametric dq interior-PM synchronous motor (§5.5 item 4).
    Ipmsm(IpmsmMotor),
}

impl MotorSpec {
    /// The motor's `id`.
    #[must_use]
    pub fn id(&self) -> &str {
        match self {
            Self::Constant(m) => &m.id,
            Self::EfficiencyMap(m) => &m.id,
            Self::LossMap(m) => &m.id,
            Self::Ipmsm(m) => &m.id,
        }
    }
}

/// Constant-efficiency motor with a torque/power envelope.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::ConstantMotor)]
#[serde(deny_unknown_fields)]
pub struct ConstantMotor {
    /// Motor name (unique in the request, 1..64 characters).
    #[rule(min_length = 1, max_length = MAX_NAME_LEN)]
    pub id: String,
    /// Motor efficiency η_M [-], both directions (service minimum 0.01).
    #[schema(example = 0.93)]
    #[rule(range = EFFICIENCY)]
    pub efficiency: f64,
    /// Peak torque [N·m] (default 800; ignored when `envelope` is given).
    #[schema(example = 800.0)]
    #[rule(range = TORQUE_NM)]
    pub t_peak_nm: Option<f64>,
    /// Peak power \[W\] (default 130 000; ignored when `envelope` is given).
    #[schema(example = 130000.0)]
    #[rule(range = POWER_W)]
    pub p_peak_w: Option<f64>,
    /// Maximum speed \[rpm\] (default 5200); a cycle needing more is rejected.
    #[schema(example = 5200.0)]
    #[rule(range = N_MAX_RPM)]
    pub n_max_rpm: Option<f64>,
    /// Explicit torque envelope (replaces `t_peak_nm` / `p_peak_w`).
    #[schema(nullable = false)]
    pub envelope: Option<EnvelopeTable>,
}

/// Motor given by an efficiency map (motoring, optional generating table).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::EfficiencyMapMotor)]
#[serde(deny_unknown_fields)]
pub struct EfficiencyMapMotor {
    /// Motor name (unique in the request, 1..64 characters).
    #[rule(min_length = 1, max_length = MAX_NAME_LEN)]
    pub id: String,
    /// Speed axis \[rpm\]: strictly increasing, ≥ 2 points, first ≥ 0.
    #[rule(items = SPEED_AXIS_RPM, min_items = 2)]
    pub speed_rpm: Vec<f64>,
    /// Torque axis [N·m]: strictly increasing, ≥ 2 points, first ≥ 0.
    #[rule(items = TORQUE_AXIS_NM, min_items = 2)]
    pub torque_nm: Vec<f64>,
    /// Efficiency η\[speed\]\[torque\] in [1e-6, 1] (motoring).
    #[rule(items_items = MAP_EFFICIENCY)]
    pub efficiency: Vec<Vec<f64>>,
    /// Generating efficiency at −torque_nm, same shape (default: mirror of `efficiency`).
    #[rule(items_items = MAP_EFFICIENCY)]
    pub efficiency_gen: Option<Vec<Vec<f64>>>,
    /// Peak torque [N·m] (default 800; ignored when `envelope` is given).
    #[rule(range = TORQUE_NM)]
    pub t_peak_nm: Option<f64>,
    /// Peak power \[W\] (default 130 000; ignored when `envelope` is given).
    #[rule(range = POWER_W)]
    pub p_peak_w: Option<f64>,
    /// Maximum speed \[rpm\] (default 5200).
    #[rule(range = N_MAX_RPM)]
    pub n_max_rpm: Option<f64>,
    /// Explicit torque envelope.
    #[schema(nullable = false)]
    pub envelope: Option<EnvelopeTable>,
}

/// Motor given by a total-loss map.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::LossMapMotor)]
#[serde(deny_unknown_fields)]
pub struct LossMapMotor {
    /// Motor name (unique in the request, 1..64 characters).
    #[rule(min_length = 1, max_length = MAX_NAME_LEN)]
    pub id: String,
    /// Speed axis \[rpm\]: strictly increasing, ≥ 2 points, first ≥ 0.
    #[rule(items = SPEED_AXIS_RPM, min_items = 2)]
    pub speed_rpm: Vec<f64>,
    /// Signed torque axis [N·m]: strictly increasing, ≥ 2 points, must contain 0.
    #[rule(items = SIGNED_TORQUE_AXIS_NM, min_items = 2)]
    pub torque_nm: Vec<f64>,
    /// Total motor loss P_loss\[speed\]\[torque\] \[W\] (≥ 0).
    #[rule(items_items = LOSS_W)]
    pub loss_w: Vec<Vec<f64>>,
    /// Peak torque [N·m] (default 800; ignored when `envelope` is given).
    #[rule(range = TORQUE_NM)]
    pub t_peak_nm: Option<f64>,
    /// Peak power \[W\] (default 130 000; ignored when `envelope` is given).
    #[rule(range = POWER_W)]
    pub p_peak_w: Option<f64>,
    /// Maximum speed \[rpm\] (default 5200).
    #[rule(range = N_MAX_RPM)]
    pub n_max_rpm: Option<f64>,
    /// Explicit torque envelope.
    #[schema(nullable = false)]
    pub envelope: Option<EnvelopeTable>,
}

/// Back-EMF measurement from which ψ_m is derived: ψ_m = V_peak_phase / (p·2π·at_rpm/60).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::BackEmf)]
#[serde(deny_unknown_fields)]
pub struct BackEmf {
    /// Peak phase back-EMF \[V\].
    #[schema(example = 83.3)]
    #[rule(range = BACK_EMF)]
    pub v_peak_phase: f64,
    /// Speed of the measurement \[rpm\].
    #[schema(example = 1000.0)]
    #[rule(range = BACK_EMF)]
    pub at_rpm: f64,
}

/// AC resistance factor k_AC(f_e, T_w) of the winding (§5.5 item 4).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::AcFactorSpec)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum AcFactorSpec {
    /// k_AC = 1.
    #[serde(rename = "none")]
    NoAc(NoAcFactor),
    /// Measured or FEA k_AC(f), linear in f, clamped at the ends.
    Table(AcFactorTable),
    /// Layer-averaged Dowell factor of the slot part; end winding free of AC effect.
    Dowell(DowellSpec),
}

/// No AC effect (k_AC = 1).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::NoAcFactor)]
#[serde(deny_unknown_fields)]
pub struct NoAcFactor {}

/// k_AC table.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::AcFactorTable)]
#[serde(deny_unknown_fields)]
pub struct AcFactorTable {
    /// Electrical frequencies \[Hz\], strictly increasing, ≥ 0.
    #[rule(items = FREQ_HZ, min_items = 1)]
    pub freq_hz: Vec<f64>,
    /// k_AC at `freq_hz` [-] (≥ 1).
    #[rule(items = K_AC)]
    pub k_ac: Vec<f64>,
}

/// Dowell parameters (rectangular conductors in layers).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::DowellSpec)]
#[serde(deny_unknown_fields)]
pub struct DowellSpec {
    /// Conductor height h in the slot-depth direction \[m\].
    #[schema(example = 0.0035)]
    #[rule(range = CONDUCTOR_HEIGHT_M)]
    pub conductor_height_m: f64,
    /// Number of conductor layers m in the slot [-] (1..100).
    #[schema(example = 6)]
    #[rule(range = LAYERS)]
    #[serde(deserialize_with = "crate::calc::rules::whole")]
    pub layers: u32,
    /// Layer porosity factor (0, 1] [-].
    #[schema(example = 0.9)]
    #[rule(range = POROSITY)]
    pub porosity: f64,
    /// Active (slot) length of the winding per side L_stack \[m\].
    #[schema(example = 0.083)]
    #[rule(range = STACK_LENGTH_M)]
    pub stack_length_m: f64,
    /// End-winding length per side L_end \[m\] (≥ 0).
    #[schema(example = 0.05)]
    #[rule(range = END_LENGTH_M)]
    pub end_length_m: f64,
}

/// Iron loss P_fe = (k_h ω_e + k_e ω_e²)·|ψ|².
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::IronSpec)]
#[serde(deny_unknown_fields, default)]
pub struct IronSpec {
    /// Hysteresis coefficient k_h [W/(Wb²·rad/s)] (≥ 0).
    #[schema(example = 3.0)]
    #[rule(range = LOSS_COEFF)]
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub k_h: f64,
    /// Eddy-current coefficient k_e [W/(Wb²·(rad/s)²)] (≥ 0).
    #[schema(example = 0.03)]
    #[rule(range = LOSS_COEFF)]
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub k_e: f64,
}

/// Mechanical loss P_mech = c_fric ω_m + c_wind ω_m³.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::MechSpec)]
#[serde(deny_unknown_fields, default)]
pub struct MechSpec {
    /// Friction torque [N·m] (≥ 0).
    #[schema(example = 0.0)]
    #[rule(range = LOSS_COEFF)]
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub c_fric_nm: f64,
    /// Windage coefficient [W·s³/rad³] (≥ 0).
    #[schema(example = 0.0)]
    #[rule(range = LOSS_COEFF)]
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub c_wind: f64,
}

/// Parametric IPMSM (amplitude-invariant dq model, peak values; §5.5 item 4).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::IpmsmMotor)]
#[serde(deny_unknown_fields)]
#[rules(one_of("psi_m_wb", "back_emf"))]
pub struct IpmsmMotor {
    /// Motor name (unique in the request, 1..64 characters).
    #[rule(min_length = 1, max_length = MAX_NAME_LEN)]
    pub id: String,
    /// Pole pairs p (1..32).
    #[schema(example = 4)]
    #[rule(range = POLE_PAIRS)]
    #[serde(deserialize_with = "crate::calc::rules::whole")]
    pub pole_pairs: u32,
    /// Peak phase PM flux linkage ψ_m \[Wb\] (give this or `back_emf`).
    #[schema(example = 0.198864)]
    #[rule(range = PSI_M_WB)]
    pub psi_m_wb: Option<f64>,
    /// Back-EMF from which ψ_m is derived (give this or `psi_m_wb`).
    #[schema(nullable = false)]
    pub back_emf: Option<BackEmf>,
    /// d-axis inductance L_d \[H\] (> 0).
    #[schema(example = 0.00035)]
    #[rule(range = INDUCTANCE_H)]
    pub ld_h: f64,
    /// q-axis inductance L_q \[H\] (≥ L_d).
    #[schema(example = 0.00055)]
    #[rule(range = INDUCTANCE_H)]
    pub lq_h: f64,
    /// Phase resistance at 20 °C R_20 \[Ω\] (> 0).
    #[schema(example = 0.006)]
    #[rule(range = R_PHASE_OHM)]
    pub r_phase_20c_ohm: f64,
    /// Winding temperature T_w [°C] (default 100).
    #[schema(example = 100.0)]
    #[rule(range = WINDING_TEMP_C)]
    pub winding_temp_c: Option<f64>,
    /// Current limit [A rms] (I_pk = √2·i_max_arms).
    #[schema(example = 500.0)]
    #[rule(range = ELECTRIC_LIMIT)]
    pub i_max_arms: f64,
    /// DC-link voltage V_dc \[V\].
    #[schema(example = 360.0)]
    #[rule(range = ELECTRIC_LIMIT)]
    pub v_dc: f64,
    /// Voltage utilisation (0, 1.155] [-] (default 1.0 → V_max = V_dc/√3).
    #[schema(example = 1.0)]
    #[rule(range = VOLTAGE_UTILIZATION)]
    pub voltage_utilization: Option<f64>,
    /// Maximum speed \[rpm\]; a cycle needing more is rejected.
    #[schema(example = 5200.0)]
    #[rule(range = N_MAX_RPM)]
    pub n_max_rpm: f64,
    /// Torque cap [N·m] (default none).
    #[schema(example = 800.0)]
    #[rule(range = TORQUE_NM)]
    pub t_cap_nm: Option<f64>,
    /// Power cap \[W\] (default none).
    #[schema(example = 130000.0)]
    #[rule(range = POWER_W)]
    pub p_cap_w: Option<f64>,
    /// AC resistance factor model (default `none`).
    #[schema(nullable = false)]
    pub ac_factor: Option<AcFactorSpec>,
    /// Iron-loss coefficients (default 0).
    #[schema(nullable = false)]
    pub iron: Option<IronSpec>,
    /// Mechanical-loss coefficients (default 0).
    #[schema(nullable = false)]
    pub mech: Option<MechSpec>,
    /// Stack-length scale s (paper §3.2; needs the `dowell` AC model for the slot/end split).
    /// Not validated against data.
    #[schema(example = 1.0)]
    #[rule(range = STACK_SCALE)]
    pub stack_scale: Option<f64>,
}

/// Handling of traction demand above the motor envelope (§5.4).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bus_fuel_economy::Mode)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Follow the trace exactly; losses evaluated at the envelope; exceedances counted.
    #[default]
    Backward,
    /// Clip the motor torque to the envelope (missing traction dropped; energy-optimistic).
    Clip,
    /// Trace miss: the bus accelerates at the envelope and falls behind (FASTSim-like).
    Forward,
}

/// Motor terminal power convention (§5.6).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bus_fuel_economy::PowerConvention)]
#[serde(rename_all = "snake_case")]
pub enum PowerConvention {
    /// Paper eq. 2-3: P_el = P_m/η motoring, P_m·η generating, 0 at zero power.
    #[default]
    Paper,
    /// Additive losses: P_el = P_m + P_loss in both directions.
    Loss,
}

/// How an `ipmsm` motor's loss is evaluated.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bus_fuel_economy::MotorEval)]
#[serde(rename_all = "snake_case")]
pub enum MotorEval {
    /// Solve the dq operating point at every interval (accuracy reference).
    Direct,
    /// Precompute a loss map on `loss_map_grid`, interpolate bilinearly (default).
    LossMap,
}

/// Optional, costly outputs.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bus_fuel_economy::OutputKind)]
#[serde(rename_all = "snake_case")]
pub enum OutputKind {
    /// Energy per loss mechanism and mean motor efficiency.
    LossBreakdown,
    /// Time share per speed × torque bin over moving intervals (Fig. 15 style).
    OpHistogram,
    /// Per-interval traces (large).
    Traces,
    /// Per-motor efficiency map on `loss_map_grid`.
    EfficiencyMap,
}

/// Grid of a precomputed loss / efficiency map.
#[derive(Debug, Clone, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::GridSpec)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Speed step \[rpm\].
    #[schema(example = 250.0)]
    #[rule(range = SPEED_STEP_RPM)]
    pub speed_step_rpm: f64,
    /// Torque step [N·m].
    #[schema(example = 50.0)]
    #[rule(range = TORQUE_STEP_NM)]
    pub torque_step_nm: f64,
}

impl Default for GridSpec {
    fn default() -> Self {
        Self {
            speed_step_rpm: 250.0,
            torque_step_nm: 50.0,
        }
    }
}

/// Bins of the operating-point histogram.
#[derive(Debug, Clone, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::HistogramSpec)]
#[serde(deny_unknown_fields)]
pub struct HistogramSpec {
    /// Speed bin width \[rpm\].
    #[schema(example = 500.0)]
    #[rule(range = SPEED_BIN_RPM)]
    pub speed_bin_rpm: f64,
    /// Torque bin width [N·m].
    #[schema(example = 100.0)]
    #[rule(range = TORQUE_BIN_NM)]
    pub torque_bin_nm: f64,
}

impl Default for HistogramSpec {
    fn default() -> Self {
        Self {
            speed_bin_rpm: 500.0,
            torque_bin_nm: 100.0,
        }
    }
}

/// Simulation options (§3.6).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::OptionsSpec)]
#[serde(deny_unknown_fields)]
pub struct OptionsSpec {
    /// Envelope policy: `backward` (default), `clip` or `forward`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub mode: Mode,
    /// `paper` (default, eq. 2-3) or `loss` (additive losses).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub power_convention: PowerConvention,
    /// Split each cycle interval into k equal pieces (1..32; accuracy knob; default 1).
    #[serde(default = "default_substeps", deserialize_with = "null_substeps")]
    #[rule(range = SUBSTEPS)]
    #[schema(example = 1)]
    pub substeps: u32,
    /// Allow regenerative braking (default true).
    #[serde(
        default = "default_true",
        deserialize_with = "crate::calc::rules::null_true"
    )]
    pub regen: bool,
    /// Clip generating torque to −T_max(ω); the rest goes to the friction brakes (default true).
    #[serde(
        default = "default_true",
        deserialize_with = "crate::calc::rules::null_true"
    )]
    pub regen_limit: bool,
    /// `direct` or `loss_map` (default) evaluation of `ipmsm` motors.
    #[serde(default)]
    #[schema(nullable = false)]
    pub motor_eval: Option<MotorEval>,
    /// Grid of the precomputed ipmsm loss map and of the `efficiency_map` output
    /// (default 250 rpm × 50 N·m).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub loss_map_grid: GridSpec,
    /// Optional outputs: `loss_breakdown`, `op_histogram`, `traces`, `efficiency_map`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: Vec<OutputKind>,
    /// Bins of the `op_histogram` output (default 500 rpm × 100 N·m).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub op_histogram: HistogramSpec,
    /// Desirability weights per cycle (≥ 0, normalised; default equal, paper w1 = w2 = w3).
    #[serde(default)]
    #[rule(items = DESIRABILITY_WEIGHT)]
    pub desirability_weights: Option<Vec<f64>>,
}

fn default_substeps() -> u32 {
    1
}

fn default_true() -> bool {
    true
}

/// `null` for `options.substeps` reads as its default 1, exactly as absent.
fn null_substeps<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    Ok(Option::<u32>::deserialize(d)?.unwrap_or_else(default_substeps))
}

/// `deserialize_with` readers of fields whose default is not their type's: `null` reads as the
/// field's default (the struct's `Default`), exactly as absent.
macro_rules! null_reads_default {
    ($($name:ident: $ty:ty = $owner:ident.$field:ident;)*) => {$(
        #[doc = concat!("`null` for `", stringify!($field), "` reads as its default.")]
        fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
            Ok(Option::<$ty>::deserialize(d)?.unwrap_or_else(|| $owner::default().$field))
        }
    )*};
}

null_reads_default! {
    null_vehicle_curb_mass_kg: f64 = VehicleSpec.curb_mass_kg;
    null_vehicle_passengers: u32 = VehicleSpec.passengers;
    null_vehicle_mass_per_passenger_kg: f64 = VehicleSpec.mass_per_passenger_kg;
    null_vehicle_frontal_area_m2: f64 = VehicleSpec.frontal_area_m2;
    null_vehicle_drag_coeff: f64 = VehicleSpec.drag_coeff;
    null_vehicle_rolling_coeff: f64 = VehicleSpec.rolling_coeff;
    null_vehicle_air_density: f64 = VehicleSpec.air_density;
    null_vehicle_gravity: f64 = VehicleSpec.gravity;
    null_vehicle_wheel_radius_m: f64 = VehicleSpec.wheel_radius_m;
    null_vehicle_gear_ratio: f64 = VehicleSpec.gear_ratio;
    null_vehicle_gear_efficiency: f64 = VehicleSpec.gear_efficiency;
    null_vehicle_rotational_inertia_factor: f64 = VehicleSpec.rotational_inertia_factor;
    null_vehicle_grade: f64 = VehicleSpec.grade;
    null_vehicle_aux_power_w: f64 = VehicleSpec.aux_power_w;
    null_inverter_efficiency: f64 = InverterSpec.efficiency;
}

impl Default for OptionsSpec {
    fn default() -> Self {
        Self {
            mode: Mode::Backward,
            power_convention: PowerConvention::Paper,
            substeps: 1,
            regen: true,
            regen_limit: true,
            motor_eval: None,
            loss_map_grid: GridSpec::default(),
            outputs: Vec::new(),
            op_histogram: HistogramSpec::default(),
            desirability_weights: None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Response
// ---------------------------------------------------------------------------------------------

/// Result of `POST /v1/bus-fuel-economy`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::BusFuelEconomyResponse)]
pub struct BusFuelEconomyResponse {
    /// One entry per motor × cycle (motor-major, request order).
    pub results: Vec<CycleResult>,
    /// Relative FE change and desirability (only with ≥ 2 motors).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub comparison: Option<Comparison>,
    /// Efficiency maps per motor (only with `outputs: ["efficiency_map"]`; with `shard`, the
    /// maps of the motors whose first result is in the shard's block).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub motor_maps: Option<Vec<MotorMapData>>,
    /// Which block of the motor × cycle pairs this answer holds (only when the request gave
    /// `shard`). Merged: `results` and `motor_maps` concatenated in shard order; `comparison`
    /// (omitted in a sharded answer: it needs every motor) recomputed from the merged results'
    /// `fe_km_per_kwh` and `energy_in_kwh` with paper eq. 11-13 and the request's normalised
    /// `desirability_weights` (in Rust: `bus_fuel_economy::merged_comparison`); `report`
    /// counters added.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shard: Option<ShardOut>,
    /// Settings used.
    pub echo: Echo,
    /// Work done and how the run stopped.
    pub report: SolverReport,
}

/// Result of one motor over one cycle (§6).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::CycleResult)]
pub struct CycleResult {
    /// Motor id.
    pub motor: String,
    /// Cycle name.
    pub cycle: String,
    /// Distance driven D \[km\] (achieved distance in `forward` mode).
    pub distance_km: f64,
    /// Cycle duration \[s\].
    pub duration_s: f64,
    /// Highest trace speed [km/h].
    pub max_speed_kmh: f64,
    /// Number of simulated intervals (after sub-stepping).
    pub n_intervals: u64,
    /// Energy drawn from the battery E_in (net; chemical side for `ecm_2rc`) \[kWh\].
    pub energy_in_kwh: f64,
    /// Σ of positive battery power × Δt \[kWh\].
    pub energy_traction_kwh: f64,
    /// Σ of negative battery power × Δt (≤ 0) \[kWh\].
    pub energy_regen_kwh: f64,
    /// Fuel economy FE = D / E_in [km/kWh] (paper eq. 1); null when E_in ≤ 0.
    pub fe_km_per_kwh: Option<f64>,
    /// Consumption E_in / D [kWh/km].
    pub consumption_kwh_per_km: f64,
    /// Intervals whose motoring torque demand exceeds the envelope T_max(ω) + 1e-9.
    pub n_over_envelope: u64,
    /// n_over_envelope / n_intervals.
    pub frac_over_envelope: f64,
    /// Intervals whose generating torque was limited to −T_max(ω) (`regen_limit`).
    pub n_regen_limited: u64,
    /// Intervals where the dq operating point could not be solved inside the envelope and the
    /// envelope point's loss was used (ipmsm only; normally 0).
    pub n_envelope_fallback: u64,
    /// Moving intervals whose motor loss was evaluated at the torque clamped to ±T_max(ω)
    /// (loss and efficiency maps and ipmsm, beyond the envelope in either direction; always 0 for
    /// the constant model, which is evaluated at the delivered torque).
    pub n_loss_clamped: u64,
    /// Largest motor torque demand T_M [N·m].
    pub max_motor_torque_demand_nm: f64,
    /// Largest motor speed over the (achieved) samples \[rpm\].
    pub max_motor_speed_rpm: f64,
    /// Energy dissipated in the friction brakes, at the wheel \[kWh\].
    pub friction_brake_kwh: f64,
    /// Cycle distance − achieved distance \[km\] (`forward` mode only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trace_miss_km: Option<f64>,
    /// State of charge at the end (`ecm_2rc` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery_soc_end: Option<f64>,
    /// Battery flags (`ecm_2rc` only): `battery_power_infeasible`, `soc_out_of_range`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery_flags: Option<Vec<String>>,
    /// Energy per loss mechanism (only with `outputs: ["loss_breakdown"]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub loss_breakdown: Option<LossBreakdown>,
    /// Operating-point histogram (only with `outputs: ["op_histogram"]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub op_histogram: Option<OpHistogram>,
    /// Per-interval traces (only with `outputs: ["traces"]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub traces: Option<Traces>,
    /// Human-readable warnings (envelope exceedance, trace miss, conventions used, ...).
    pub warnings: Vec<String>,
}

/// Energy per mechanism over the cycle \[kWh\]. Closure: energy_in = wheel + gear + friction brakes
/// + motor_charged + inverter + battery + aux (to rounding).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::LossBreakdown)]
pub struct LossBreakdown {
    /// Net energy at the wheels Σ F·v̄·Δt (road load plus net kinetic/potential change) \[kWh\].
    pub wheel_kwh: f64,
    /// Gear loss \[kWh\].
    pub gear_kwh: f64,
    /// Friction-brake energy at the wheel \[kWh\].
    pub friction_brake_kwh: f64,
    /// Motor loss charged by the power convention Σ(P_el − P_m)Δt \[kWh\].
    pub motor_charged_kwh: f64,
    /// Motor model loss at the evaluated operating points Σ P_loss Δt \[kWh\] (equals
    /// `motor_charged_kwh` for the `loss` convention).
    pub motor_model_kwh: f64,
    /// DC copper loss part of the model loss (ipmsm only) \[kWh\].
    pub motor_cu_dc_kwh: Option<f64>,
    /// Extra AC copper loss (k_AC − 1)·P_cu,DC (ipmsm only) \[kWh\].
    pub motor_cu_ac_extra_kwh: Option<f64>,
    /// Iron loss (ipmsm only) \[kWh\].
    pub motor_iron_kwh: Option<f64>,
    /// Mechanical loss (ipmsm only) \[kWh\].
    pub motor_mech_kwh: Option<f64>,
    /// Inverter loss \[kWh\].
    pub inverter_kwh: f64,
    /// Battery loss (P_in − P_dc) \[kWh\].
    pub battery_kwh: f64,
    /// Auxiliary load \[kWh\].
    pub aux_kwh: f64,
    /// Wheel traction demanded but dropped by `mode: clip` \[kWh\] (not part of the closure).
    pub clipped_traction_kwh: f64,
    /// Energy-weighted mean motor efficiency Σ|P_m|Δt / Σ(|P_m| + P_loss)Δt [-].
    pub mean_motor_efficiency: Option<f64>,
}

/// Time share of moving intervals per (speed, torque) bin, Fig. 15 style.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::OpHistogram)]
pub struct OpHistogram {
    /// Speed bin edges \[rpm\] (from 0).
    pub speed_edges_rpm: Vec<f64>,
    /// Torque bin edges [N·m] (multiples of the bin width).
    pub torque_edges_nm: Vec<f64>,
    /// share[speed bin][torque bin] of the moving time (sums to 1).
    pub share: Vec<Vec<f64>>,
    /// Bin with the largest share (absent if the bus never moves).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub modal_bin: Option<ModalBin>,
}

/// The histogram's modal bin.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::ModalBin)]
pub struct ModalBin {
    /// Speed range \[rpm\].
    pub rpm: [f64; 2],
    /// Torque range [N·m].
    pub nm: [f64; 2],
    /// Time share of the bin.
    pub share: f64,
}

/// Per-interval traces (arrays of equal length).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::Traces)]
pub struct Traces {
    /// Interval start time \[s\].
    pub t_s: Vec<f64>,
    /// Mean (achieved) speed v̄ [m/s].
    pub v_mps: Vec<f64>,
    /// Motor speed ω_m [rad/s].
    pub omega_rad_s: Vec<f64>,
    /// Motor torque demand T_M [N·m].
    pub torque_demand_nm: Vec<f64>,
    /// Motor torque delivered (after clip / regen limit) [N·m].
    pub torque_motor_nm: Vec<f64>,
    /// Motor shaft power P_m \[W\].
    pub p_mech_w: Vec<f64>,
    /// Motor model loss P_loss \[W\].
    pub p_loss_w: Vec<f64>,
    /// Battery internal power P_in \[W\].
    pub p_in_w: Vec<f64>,
}

/// Efficiency map of one motor (η on the grid; null outside the envelope, 0 at zero power).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::MotorMapData)]
pub struct MotorMapData {
    /// Motor id.
    pub motor: String,
    /// Speed axis \[rpm\].
    pub speed_rpm: Vec<f64>,
    /// Torque axis [N·m].
    pub torque_nm: Vec<f64>,
    /// Envelope T_max at `speed_rpm` [N·m].
    pub t_max_nm: Vec<f64>,
    /// η\[speed\]\[torque\] [-].
    pub efficiency: Vec<Vec<Option<f64>>>,
}

/// Comparison of the motors (paper eq. 11-13).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::Comparison)]
pub struct Comparison {
    /// The first motor, reference of `fe_change_pct`.
    pub reference_motor: String,
    /// Cycle order of the `d` arrays.
    pub cycles: Vec<String>,
    /// Normalised desirability weights w_i per cycle.
    pub weights: Vec<f64>,
    /// (FE_motor / FE_reference − 1)·100 per motor (except the reference) and cycle [%].
    pub fe_change_pct: BTreeMap<String, BTreeMap<String, Option<f64>>>,
    /// Desirability per motor.
    pub desirability: BTreeMap<String, Desirability>,
}

/// Desirability of one motor (eq. 12-13).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::Desirability)]
pub struct Desirability {
    /// d_i per cycle (in `comparison.cycles` order) [-].
    pub d: Vec<f64>,
    /// Overall D = Π d_i^{w_i} [-].
    pub overall: f64,
}

/// Settings used for the run.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::Echo)]
pub struct Echo {
    /// Envelope policy.
    pub mode: Mode,
    /// Power convention.
    pub power_convention: PowerConvention,
    /// Substeps per cycle interval.
    pub substeps: u32,
    /// ipmsm evaluation.
    pub motor_eval: MotorEval,
    /// Regeneration allowed.
    pub regen: bool,
    /// Regeneration limited by the envelope.
    pub regen_limit: bool,
    /// Version of the built-in cycle data.
    pub cycle_data_version: String,
}

// ---------------------------------------------------------------------------------------------
// Motor-map endpoint
// ---------------------------------------------------------------------------------------------

/// `POST /v1/bus-fuel-economy/motor-map`: envelope, loss and efficiency maps of one motor.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bus_fuel_economy::MotorMapRequest)]
#[serde(deny_unknown_fields)]
pub struct MotorMapRequest {
    /// The motor (any model of the main endpoint).
    pub motor: MotorSpec,
    /// Grid (default 250 rpm × 50 N·m); speeds 0..n_max, torques ±T_max(0) at multiples of the step.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub grid: GridSpec,
    /// Also return the ipmsm loss components and operating modes.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub include_components: bool,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 2000)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for MotorMapRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Maps of one motor; values outside the envelope are null.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::MotorMapResponse)]
pub struct MotorMapResponse {
    /// Motor id.
    pub motor: String,
    /// Speed axis \[rpm\].
    pub speed_rpm: Vec<f64>,
    /// Torque axis [N·m] (signed, contains 0).
    pub torque_nm: Vec<f64>,
    /// Envelope T_max at `speed_rpm` [N·m].
    pub t_max_nm: Vec<f64>,
    /// Total motor loss \[W\], loss_w\[speed\]\[torque\].
    pub loss_w: Vec<Vec<Option<f64>>>,
    /// Efficiency |P_m| / (|P_m| + P_loss) [-] (0 at zero power, spec §5.5).
    pub efficiency: Vec<Vec<Option<f64>>>,
    /// ipmsm loss components (only with `include_components`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub components: Option<LossComponentMaps>,
    /// Warnings (map conversions, extrapolations).
    pub warnings: Vec<String>,
    /// Work done.
    pub report: SolverReport,
}

/// ipmsm loss components on the grid \[W\] (null outside the envelope).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bus_fuel_economy::LossComponentMaps)]
pub struct LossComponentMaps {
    /// DC copper loss 1.5 R (i_d² + i_q²).
    pub cu_dc_w: Vec<Vec<Option<f64>>>,
    /// Extra AC copper loss (k_AC − 1) P_cu,DC.
    pub cu_ac_extra_w: Vec<Vec<Option<f64>>>,
    /// Iron loss.
    pub iron_w: Vec<Vec<Option<f64>>>,
    /// Mechanical loss.
    pub mech_w: Vec<Vec<Option<f64>>>,
    /// d-axis current [A peak].
    pub i_d_a: Vec<Vec<Option<f64>>>,
    /// q-axis current [A peak].
    pub i_q_a: Vec<Vec<Option<f64>>>,
    /// Operating mode: `mtpa`, `fw` or `envelope`.
    pub mode: Vec<Vec<Option<String>>>,
}

/// Curb mass \[kg\].
pub const CURB_MASS_KG: Range = Range::FINITE.gt(0.0).max(1e5);
/// Passengers [–].
pub const PASSENGERS: Range = Range::int(0, 500);
/// Mass per passenger \[kg\].
pub const MASS_PER_PASSENGER_KG: Range = Range::closed(0.0, 200.0);
/// Frontal area \[m²\].
pub const FRONTAL_AREA_M2: Range = Range::FINITE.gt(0.0).max(30.0);
/// Drag coefficient [–].
pub const DRAG_COEFF: Range = Range::FINITE.gt(0.0).max(3.0);
/// Rolling-resistance coefficient [–].
pub const ROLLING_COEFF: Range = Range::closed(0.0, 0.1);
/// Air density [kg/m³].
pub const AIR_DENSITY: Range = Range::FINITE.gt(0.0).max(2.0);
/// Gravity [m/s²].
pub const GRAVITY: Range = Range::FINITE.gt(9.0).max(10.5);
/// Wheel radius \[m\].
pub const WHEEL_RADIUS_M: Range = Range::FINITE.gt(0.1).max(2.0);
/// Final-drive gear ratio [–].
pub const GEAR_RATIO: Range = Range::closed(0.01, 50.0);
/// A constant efficiency (gear, inverter, battery, constant motor) [–]: at least 1 %.
pub const EFFICIENCY: Range = Range::closed(0.01, 1.0);
/// A fraction in [0, 1] (rotational inertia factor) [–].
pub const FRACTION: Range = Range::closed(0.0, 1.0);
/// Road grade (rise over run) [–].
pub const GRADE: Range = Range::closed(-0.3, 0.3);
/// Auxiliary power \[W\].
pub const AUX_POWER_W: Range = Range::closed(0.0, 1e5);
/// Battery nominal voltage \[V\].
pub const NOMINAL_VOLTAGE: Range = Range::FINITE.gt(0.0).max(5000.0);
/// Battery capacity \[kWh\].
pub const CAPACITY_KWH: Range = Range::FINITE.gt(0.0).max(1e4);
/// Initial state of charge [–]: (0, 1] (spec §2).
pub const SOC_INITIAL: Range = Range::FINITE.gt(0.0).max(1.0);
/// Series resistance R0 \[Ω\]: > 0 (spec §2).
pub const R0_OHM: Range = Range::FINITE.gt(0.0).max(100.0);
/// RC-branch resistance R1, R2 \[Ω\]: ≥ 0 (spec §2).
pub const RC_OHM: Range = Range::closed(0.0, 100.0);
/// RC-branch capacitance C1, C2 \[F\]: > 0 (spec §2).
pub const RC_F: Range = Range::FINITE.gt(0.0).max(1e9);
/// Smallest positive motor parameter accepted: far below any physical motor, above the subnormal
/// values whose products and quotients leave f64 (a fuzzer found an inductance of 8e-230 with
/// sizes of 5e-324 driving the map to non-finite numbers).
pub const MOTOR_FLOOR: f64 = 1e-12;
/// Torque [N·m] (peak, cap, envelope values): positive.
pub const TORQUE_NM: Range = Range::FINITE.min(MOTOR_FLOOR).max(1e6);
/// Power \[W\] (peak, cap): positive.
pub const POWER_W: Range = Range::FINITE.min(MOTOR_FLOOR).max(1e9);
/// Motor top speed \[rpm\].
pub const N_MAX_RPM: Range = Range::FINITE.min(MOTOR_FLOOR).max(1e5);
/// Pole pairs [–].
pub const POLE_PAIRS: Range = Range::int(1, 32);
/// Permanent-magnet flux linkage ψ_m \[Wb\].
pub const PSI_M_WB: Range = Range::FINITE.min(MOTOR_FLOOR).max(100.0);
/// Back-EMF peak phase voltage \[V\] and its speed \[rpm\].
pub const BACK_EMF: Range = Range::FINITE.min(MOTOR_FLOOR).max(1e5);
/// d- and q-axis inductance \[H\].
pub const INDUCTANCE_H: Range = Range::FINITE.min(MOTOR_FLOOR).max(1.0);
/// Phase resistance at 20 °C \[Ω\].
pub const R_PHASE_OHM: Range = Range::FINITE.min(MOTOR_FLOOR).max(100.0);
/// Winding temperature [°C] (spec §2).
pub const WINDING_TEMP_C: Range = Range::closed(-40.0, 250.0);
/// Current limit [A rms] and DC-link voltage \[V\].
pub const ELECTRIC_LIMIT: Range = Range::FINITE.min(MOTOR_FLOOR).max(1e5);
/// Voltage utilisation [–] (≤ 2/√3 with space-vector modulation).
pub const VOLTAGE_UTILIZATION: Range = Range::FINITE.min(MOTOR_FLOOR).max(1.155);
/// Stack scale [–].
pub const STACK_SCALE: Range = Range::FINITE.min(MOTOR_FLOOR).max(10.0);
/// Dowell conductor height \[m\].
pub const CONDUCTOR_HEIGHT_M: Range = Range::FINITE.min(MOTOR_FLOOR).max(0.1);
/// Dowell conductor layers [–].
pub const LAYERS: Range = Range::int(1, 100);
/// Dowell porosity [–].
pub const POROSITY: Range = Range::FINITE.min(MOTOR_FLOOR).max(1.0);
/// Stack length \[m\].
pub const STACK_LENGTH_M: Range = Range::FINITE.min(MOTOR_FLOOR).max(10.0);
/// End-winding length \[m\].
pub const END_LENGTH_M: Range = Range::closed(0.0, 10.0);
/// Iron and mechanical loss coefficients (k_h, k_e, c_fric, c_wind): ≥ 0 (spec §2).
pub const LOSS_COEFF: Range = Range::closed(0.0, 1e6);
/// AC resistance factor k_AC [–].
pub const K_AC: Range = Range::closed(1.0, 1000.0);
/// Loss-map grid speed step \[rpm\].
pub const SPEED_STEP_RPM: Range = Range::closed(1.0, 1e4);
/// Loss-map grid torque step [N·m].
pub const TORQUE_STEP_NM: Range = Range::closed(0.1, 1e4);
/// Operating-point histogram speed bin \[rpm\].
pub const SPEED_BIN_RPM: Range = Range::closed(1.0, 1e5);
/// Operating-point histogram torque bin [N·m].
pub const TORQUE_BIN_NM: Range = Range::closed(0.1, 1e5);
/// Sub-steps per cycle interval [–].
pub const SUBSTEPS: Range = Range::int(1, 32);
/// Desirability weight of a cycle [–] (normalised to sum 1; not all 0).
pub const DESIRABILITY_WEIGHT: Range = Range::closed(0.0, 1e6);
/// Open-circuit voltage table values \[V\].
pub const OCV_V: Range = Range::FINITE.gt(0.0).max(1e5);
/// A motor speed axis \[rpm\] (strictly increasing).
pub const SPEED_AXIS_RPM: Range = Range::closed(0.0, 1e5);
/// A motoring torque axis [N·m] (strictly increasing).
pub const TORQUE_AXIS_NM: Range = Range::closed(0.0, 1e6);
/// A signed torque axis of a loss map [N·m] (strictly increasing, containing 0).
pub const SIGNED_TORQUE_AXIS_NM: Range = Range::closed(-1e6, 1e6);
/// A frequency axis of a k_AC table \[Hz\] (strictly increasing).
pub const FREQ_HZ: Range = Range::closed(0.0, 1e7);
/// An efficiency-map value [–]: the floor keeps the converted loss |P|(1/η − 1) finite.
pub const MAP_EFFICIENCY: Range = Range::closed(1e-6, 1.0);
/// A loss-map value \[W\].
pub const LOSS_W: Range = Range::closed(0.0, 1e9);
/// Custom-cycle time \[s\] (about ±30 years: keeps Δt well resolved; strictly increasing, steps
/// of 1 ms to 60 s).
pub const TIME_S: Range = Range::closed(-1e9, 1e9);
/// Custom-cycle speed [m/s]: a service limit (720 km/h) that keeps v² and the road load finite.
pub const SPEED_MPS: Range = Range::closed(0.0, 200.0);
/// Custom-cycle speed [km/h] (the same limit as [`SPEED_MPS`]).
pub const SPEED_KMH: Range = Range::closed(0.0, 720.0);

/// Most motors per request (spec §3.5).
pub const MAX_MOTORS: usize = 8;
/// Most cycles per request (spec §3.4).
pub const MAX_CYCLES: usize = 16;
/// Most samples of one custom cycle (spec §3.4).
pub const MAX_CYCLE_SAMPLES: usize = 200_000;
/// Longest motor id / cycle name, in characters.
pub const MAX_NAME_LEN: usize = 64;
