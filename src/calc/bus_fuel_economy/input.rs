//! Validation of the wire request into SI domain inputs (spec §3, §3.7), collecting every issue.

use super::ac_factor::{AcFactor, Dowell};
use super::battery::{Battery, Ecm};
use super::cycles::{self, Cycle};
use super::ipmsm::{Ipmsm, IpmsmParams, psi_from_back_emf, rpm_to_rad_s};
use super::maps::{Envelope, Grid2, efficiency_to_loss};
use super::motor::{MotorInput, MotorKind};
use super::sim::{Mode, PowerConvention, Vehicle};
use super::wire as w;
use super::wire::{
    AcFactorSpec, BatteryModel, BatterySpec, BusFuelEconomyRequest, CycleSpec, EfficiencyMapMotor,
    EnvelopeTable, GridSpec, IpmsmMotor, LossMapMotor, MotorSpec, OptionsSpec, OutputKind,
    VehicleSpec,
};
use crate::calc::{CalcFailure, ProblemClass, Range, Validator};

/// Most motors per request (spec §3.5).
pub const MAX_MOTORS: usize = 8;
/// Most cycles per request (spec §3.4).
pub const MAX_CYCLES: usize = 16;
/// Most samples of one custom cycle (spec §3.4).
pub const MAX_CYCLE_SAMPLES: usize = 200_000;
/// Most intervals over all cycles after sub-stepping (spec §3.7, §8 item 10).
pub const MAX_TOTAL_INTERVALS: usize = 1_000_000;
/// Largest custom-cycle time step \[s\] (spec §3.4).
pub const MAX_TIME_STEP_S: f64 = 60.0;
/// Smallest custom-cycle time step \[s\] (1 kHz sampling): a service limit that bounds the
/// acceleration (≤ 2·10⁵ m/s²) and so keeps every force, torque and power finite.
pub const MIN_TIME_STEP_S: f64 = 1e-3;
/// Smallest efficiency of the gear, inverter, battery and a constant motor [-]: a service limit
/// (the spec allows (0, 1]) that keeps P/η finite; real drivetrains are far above it.
pub const MIN_EFFICIENCY: f64 = w::EFFICIENCY.lo;
/// Smallest value of an efficiency map [-]: keeps the converted loss |P|(1/η − 1) finite.
pub const MIN_MAP_EFFICIENCY: f64 = w::MAP_EFFICIENCY.lo;
/// Smallest gear ratio [-]: a service limit (spec (0, 50]) that keeps T_w/(η_T i_g) finite.
pub const MIN_GEAR_RATIO: f64 = w::GEAR_RATIO.lo;
/// Largest trace speed [m/s] (720 km/h): a service limit that keeps v² and the road load finite.
pub const MAX_SPEED_MPS: f64 = w::SPEED_MPS.hi;
/// Largest |time| of a custom trace \[s\] (about 30 years): keeps Δt well resolved.
pub const MAX_TIME_S: f64 = w::TIME_S.hi;
/// Relative slack of the cycle-speed vs n_max check (rounding of the rpm conversion).
const SPEED_CHECK_SLACK: f64 = 1e-12;
/// Longest id / cycle name.
const MAX_NAME_LEN: usize = 64;

/// Default envelope of constant / map motors (spec §3.5).
const DEFAULT_T_PEAK: f64 = 800.0;
const DEFAULT_P_PEAK: f64 = 130_000.0;
const DEFAULT_N_MAX: f64 = 5200.0;

/// How an `ipmsm` motor's loss is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotorEval {
    /// Solve the dq operating point at every interval.
    Direct,
    /// Interpolate a loss map precomputed on the options' grid.
    LossMap,
}

impl From<w::Mode> for Mode {
    fn from(m: w::Mode) -> Self {
        match m {
            w::Mode::Backward => Self::Backward,
            w::Mode::Clip => Self::Clip,
            w::Mode::Forward => Self::Forward,
        }
    }
}

impl From<w::PowerConvention> for PowerConvention {
    fn from(c: w::PowerConvention) -> Self {
        match c {
            w::PowerConvention::Paper => Self::Paper,
            w::PowerConvention::Loss => Self::Loss,
        }
    }
}

impl From<w::MotorEval> for MotorEval {
    fn from(e: w::MotorEval) -> Self {
        match e {
            w::MotorEval::Direct => Self::Direct,
            w::MotorEval::LossMap => Self::LossMap,
        }
    }
}

/// Validated options.
#[derive(Debug, Clone)]
pub struct Options {
    /// Envelope policy.
    pub mode: Mode,
    /// Power convention.
    pub convention: PowerConvention,
    /// Substeps k.
    pub substeps: usize,
    /// Regeneration allowed.
    pub regen: bool,
    /// Regeneration limited by the envelope.
    pub regen_limit: bool,
    /// ipmsm evaluation.
    pub motor_eval: MotorEval,
    /// Map grid: speed step \[rpm\], torque step [N·m].
    pub grid: (f64, f64),
    /// Loss breakdown requested.
    pub breakdown: bool,
    /// Histogram requested.
    pub histogram: bool,
    /// Traces requested.
    pub traces: bool,
    /// Efficiency maps requested.
    pub efficiency_map: bool,
    /// Histogram bins: speed \[rpm\], torque [N·m].
    pub hist_bins: (f64, f64),
    /// Normalised desirability weights per cycle.
    pub weights: Vec<f64>,
}

/// A validated request in SI units.
#[derive(Debug, Clone)]
pub struct BusFuelEconomyInput {
    /// Vehicle.
    pub vehicle: Vehicle,
    /// Constant road slope of the vehicle.
    pub grade: f64,
    /// η_Inv.
    pub inverter_eff: f64,
    /// Battery.
    pub battery: Battery,
    /// Cycles.
    pub cycles: Vec<Cycle>,
    /// Motors.
    pub motors: Vec<MotorInput>,
    /// Options.
    pub options: Options,
    /// The block of motor × cycle pairs to simulate (all when `None`).
    pub shard: Option<crate::calc::common::Shard>,
}

/// Strictly increasing, finite, ≥ `min_len` points, each in `range` (the first checked against
/// its lower end, then the order, then every point).
fn axis(v: &mut Validator, ptr: &str, xs: &[f64], min_len: usize, range: Range) -> bool {
    if xs.len() < min_len {
        v.push(
            ptr,
            format!("needs at least {min_len} points, got {}", xs.len()),
        );
        return false;
    }
    if !v.all_finite(ptr, xs) {
        return false;
    }
    if xs[0] < range.lo {
        v.push(
            format!("{ptr}/0"),
            format!("must be ≥ {}, got {}", range.lo, xs[0]),
        );
        return false;
    }
    if let Some(i) = (1..xs.len()).find(|&i| xs[i] <= xs[i - 1]) {
        v.push(
            format!("{ptr}/{i}"),
            format!(
                "axis must be strictly increasing: {} after {}",
                xs[i],
                xs[i - 1]
            ),
        );
        return false;
    }
    v.all_in(ptr, "", xs, range)
}

/// A table `[rows][cols]` of values in `range`.
fn table(
    v: &mut Validator,
    ptr: &str,
    t: &[Vec<f64>],
    (rows, cols): (usize, usize),
    range: Range,
) -> bool {
    if t.len() != rows {
        v.push(
            ptr,
            format!("must have {rows} rows (one per speed), got {}", t.len()),
        );
        return false;
    }
    for (i, row) in t.iter().enumerate() {
        let p = format!("{ptr}/{i}");
        if row.len() != cols {
            v.push(
                p,
                format!(
                    "must have {cols} values (one per torque), got {}",
                    row.len()
                ),
            );
            return false;
        }
        if !v.all_in(&p, "", row, range) {
            return false;
        }
    }
    true
}

fn name_ok(v: &mut Validator, ptr: &str, name: &str, what: &str) {
    let n = name.chars().count();
    if n == 0 || n > MAX_NAME_LEN {
        v.push(
            ptr,
            format!("{what} must have 1..{MAX_NAME_LEN} characters, got {n}"),
        );
    }
}

fn vehicle(v: &mut Validator, s: &VehicleSpec) -> Vehicle {
    let fields = [
        ("curb_mass_kg", s.curb_mass_kg, w::CURB_MASS_KG),
        ("passengers", f64::from(s.passengers), w::PASSENGERS),
        (
            "mass_per_passenger_kg",
            s.mass_per_passenger_kg,
            w::MASS_PER_PASSENGER_KG,
        ),
        ("frontal_area_m2", s.frontal_area_m2, w::FRONTAL_AREA_M2),
        ("drag_coeff", s.drag_coeff, w::DRAG_COEFF),
        ("rolling_coeff", s.rolling_coeff, w::ROLLING_COEFF),
        ("air_density", s.air_density, w::AIR_DENSITY),
        ("gravity", s.gravity, w::GRAVITY),
        ("wheel_radius_m", s.wheel_radius_m, w::WHEEL_RADIUS_M),
        ("gear_ratio", s.gear_ratio, w::GEAR_RATIO),
        ("gear_efficiency", s.gear_efficiency, w::EFFICIENCY),
        (
            "rotational_inertia_factor",
            s.rotational_inertia_factor,
            w::FRACTION,
        ),
        ("grade", s.grade, w::GRADE),
        ("aux_power_w", s.aux_power_w, w::AUX_POWER_W),
    ];
    for (name, x, range) in fields {
        v.range(&format!("/vehicle/{name}"), "", x, range);
    }
    let mass = f64::from(s.passengers).mul_add(s.mass_per_passenger_kg, s.curb_mass_kg);
    Vehicle {
        mass,
        mass_eff: mass * (1.0 + s.rotational_inertia_factor),
        gravity: s.gravity,
        rolling: s.rolling_coeff,
        aero: 0.5 * s.air_density * s.drag_coeff * s.frontal_area_m2,
        wheel_radius: s.wheel_radius_m,
        gear_ratio: s.gear_ratio,
        gear_eff: s.gear_efficiency,
        aux_w: s.aux_power_w,
    }
}

fn battery(v: &mut Validator, b: &BatterySpec) -> Battery {
    let ecm_fields: [(&str, bool); 10] = [
        ("nominal_voltage", b.nominal_voltage.is_some()),
        ("capacity_kwh", b.capacity_kwh.is_some()),
        ("soc_initial", b.soc_initial.is_some()),
        ("ocv_soc", b.ocv_soc.is_some()),
        ("ocv_v", b.ocv_v.is_some()),
        ("r0_ohm", b.r0_ohm.is_some()),
        ("r1_ohm", b.r1_ohm.is_some()),
        ("c1_f", b.c1_f.is_some()),
        ("r2_ohm", b.r2_ohm.is_some()),
        ("c2_f", b.c2_f.is_some()),
    ];
    match b.model {
        BatteryModel::Constant => {
            for (name, present) in ecm_fields {
                if present {
                    v.push(
                        format!("/battery/{name}"),
                        "is an ecm_2rc field; not allowed with model \"constant\"".to_owned(),
                    );
                }
            }
            let eta = b.efficiency.unwrap_or(1.0);
            v.range("/battery/efficiency", "", eta, w::EFFICIENCY);
            Battery::Constant { eta }
        }
        BatteryModel::Ecm2rc => {
            if b.efficiency.is_some() {
                v.push(
                    "/battery/efficiency",
                    "is a constant-model field; not allowed with model \"ecm_2rc\"".to_owned(),
                );
            }
            // Required field in its range; NaN placeholder when missing.
            let mut need = |name: &str, x: Option<f64>, range: Range| -> f64 {
                let ptr = format!("/battery/{name}");
                match x {
                    None => {
                        v.push(ptr, "is required for model \"ecm_2rc\"".to_owned());
                        f64::NAN
                    }
                    Some(x) => {
                        v.range(&ptr, "", x, range);
                        x
                    }
                }
            };
            let soc0 = need("soc_initial", b.soc_initial, w::SOC_INITIAL);
            let r0 = need("r0_ohm", b.r0_ohm, w::R0_OHM);
            let r1 = need("r1_ohm", b.r1_ohm, w::RC_OHM);
            let c1 = need("c1_f", b.c1_f, w::RC_F);
            let r2 = need("r2_ohm", b.r2_ohm, w::RC_OHM);
            let c2 = need("c2_f", b.c2_f, w::RC_F);
            let vn = b.nominal_voltage.unwrap_or(360.0);
            let cap = b.capacity_kwh.unwrap_or(256.0);
            v.range("/battery/nominal_voltage", "", vn, w::NOMINAL_VOLTAGE);
            v.range("/battery/capacity_kwh", "", cap, w::CAPACITY_KWH);
            let (soc_t, ocv_t) = match (&b.ocv_soc, &b.ocv_v) {
                (Some(s), Some(o)) => {
                    let ok_s = axis(v, "/battery/ocv_soc", s, 2, w::FRACTION);
                    if ok_s && s.last().is_some_and(|&x| x > 1.0) {
                        v.push(
                            "/battery/ocv_soc",
                            "SOC points must lie in [0, 1]".to_owned(),
                        );
                    }
                    if o.len() != s.len() {
                        v.push(
                            "/battery/ocv_v",
                            format!("must have {} values like ocv_soc, got {}", s.len(), o.len()),
                        );
                    } else {
                        v.all_in("/battery/ocv_v", "", o, w::OCV_V);
                    }
                    (s.clone(), o.clone())
                }
                _ => {
                    if b.ocv_soc.is_none() {
                        v.push(
                            "/battery/ocv_soc",
                            "is required for model \"ecm_2rc\"".to_owned(),
                        );
                    }
                    if b.ocv_v.is_none() {
                        v.push(
                            "/battery/ocv_v",
                            "is required for model \"ecm_2rc\"".to_owned(),
                        );
                    }
                    (Vec::new(), Vec::new())
                }
            };
            Battery::Ecm(Ecm {
                ocv_soc: soc_t,
                ocv_v: ocv_t,
                r0,
                r1,
                c1,
                r2,
                c2,
                soc0,
                q_coulomb: cap * 3.6e6 / vn,
            })
        }
    }
}

fn cycle(v: &mut Validator, j: usize, c: &CycleSpec) -> Option<Cycle> {
    let base = format!("/cycles/{j}");
    match c {
        CycleSpec::Builtin(name) => {
            let cy = cycles::builtin(name);
            if cy.is_none() {
                v.push(
                    &base,
                    format!("unknown built-in cycle '{name}' (known: manhattan, hwfet, hdudds)"),
                );
            }
            cy
        }
        CycleSpec::Custom(cc) => {
            name_ok(v, &format!("{base}/name"), &cc.name, "cycle name");
            let n = cc.time_s.len();
            let mut ok = true;
            if !(2..=MAX_CYCLE_SAMPLES).contains(&n) {
                v.push(
                    format!("{base}/time_s"),
                    format!("must have 2..{MAX_CYCLE_SAMPLES} samples, got {n}"),
                );
                ok = false;
            }
            let (speeds, sp_ptr, factor) = match (&cc.speed_kmh, &cc.speed_mps) {
                (Some(s), None) => (s, format!("{base}/speed_kmh"), 1.0 / 3.6),
                (None, Some(s)) => (s, format!("{base}/speed_mps"), 1.0),
                (Some(_), Some(_)) => {
                    v.push(
                        &base,
                        "give exactly one of speed_kmh and speed_mps, not both".to_owned(),
                    );
                    return None;
                }
                (None, None) => {
                    v.push(&base, "needs speed_kmh or speed_mps".to_owned());
                    return None;
                }
            };
            if speeds.len() != n {
                v.push(
                    &sp_ptr,
                    format!("must have {n} samples like time_s, got {}", speeds.len()),
                );
                ok = false;
            }
            let tp = format!("{base}/time_s");
            ok &= v.all_finite(&tp, &cc.time_s);
            ok &= v.all_finite(&sp_ptr, speeds);
            if !ok {
                return None;
            }
            if let Some(i) = cc.time_s.iter().position(|&t| !w::TIME_S.contains(t)) {
                v.push(
                    format!("{tp}/{i}"),
                    format!("|time| must be ≤ {MAX_TIME_S} s, got {}", cc.time_s[i]),
                );
                ok = false;
            }
            if let Some(i) = (1..n).find(|&i| cc.time_s[i] <= cc.time_s[i - 1]) {
                v.push(
                    format!("{tp}/{i}"),
                    format!(
                        "time must be strictly increasing: {} after {}",
                        cc.time_s[i],
                        cc.time_s[i - 1]
                    ),
                );
                ok = false;
            } else if let Some(i) = (1..n).find(|&i| {
                let dt = cc.time_s[i] - cc.time_s[i - 1];
                // 1e-6 relative slack: 10.001 − 10.0 is 0.000999999… in binary.
                !(MIN_TIME_STEP_S * (1.0 - 1e-6)..=MAX_TIME_STEP_S).contains(&dt)
            }) {
                v.push(
                    format!("{tp}/{i}"),
                    format!(
                        "time step must be in [{MIN_TIME_STEP_S}, {MAX_TIME_STEP_S}] s, got {} s",
                        cc.time_s[i] - cc.time_s[i - 1]
                    ),
                );
                ok = false;
            }
            let mps: Vec<f64> = speeds.iter().map(|s| s * factor).collect();
            if let Some(i) = mps.iter().position(|&s| !w::SPEED_MPS.contains(s)) {
                v.push(
                    format!("{sp_ptr}/{i}"),
                    format!(
                        "speed must be in [0, {MAX_SPEED_MPS}] m/s, got {} m/s",
                        mps[i]
                    ),
                );
                ok = false;
            }
            if let Some(g) = &cc.grade {
                let gp = format!("{base}/grade");
                if g.len() != n {
                    v.push(
                        &gp,
                        format!("must have {n} samples like time_s, got {}", g.len()),
                    );
                    ok = false;
                } else if !v.all_finite(&gp, g) {
                    ok = false;
                } else if let Some(i) = g.iter().position(|&x| !w::GRADE.contains(x)) {
                    v.push(
                        format!("{gp}/{i}"),
                        format!("grade must be in [-0.3, 0.3], got {}", g[i]),
                    );
                    ok = false;
                }
            }
            ok.then(|| Cycle {
                name: cc.name.clone(),
                time_s: cc.time_s.clone(),
                speed_mps: mps,
                grade: cc.grade.clone(),
            })
        }
    }
}

/// Envelope fields shared by constant and map motors.
fn envelope(
    v: &mut Validator,
    base: &str,
    t_peak: Option<f64>,
    p_peak: Option<f64>,
    n_max: Option<f64>,
    table: Option<&EnvelopeTable>,
) -> (Envelope, f64) {
    let n_max = n_max.unwrap_or(DEFAULT_N_MAX);
    v.range(&format!("{base}/n_max_rpm"), "", n_max, w::N_MAX_RPM);
    let env = match table {
        Some(t) => {
            if t_peak.is_some() || p_peak.is_some() {
                v.push(
                    format!("{base}/envelope"),
                    "give either envelope or t_peak_nm/p_peak_w, not both".to_owned(),
                );
            }
            let p = format!("{base}/envelope");
            let ok = axis(
                v,
                &format!("{p}/speed_rpm"),
                &t.speed_rpm,
                2,
                w::SPEED_AXIS_RPM,
            );
            if t.t_max_nm.len() != t.speed_rpm.len() {
                v.push(
                    format!("{p}/t_max_nm"),
                    format!(
                        "must have {} values like speed_rpm, got {}",
                        t.speed_rpm.len(),
                        t.t_max_nm.len()
                    ),
                );
            } else {
                v.all_in(&format!("{p}/t_max_nm"), "", &t.t_max_nm, w::TORQUE_NM);
            }
            let _ = ok;
            Envelope::Table {
                speed: t.speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect(),
                t_max: t.t_max_nm.clone(),
            }
        }
        None => {
            let tp = t_peak.unwrap_or(DEFAULT_T_PEAK);
            let pp = p_peak.unwrap_or(DEFAULT_P_PEAK);
            v.range(&format!("{base}/t_peak_nm"), "", tp, w::TORQUE_NM);
            v.range(&format!("{base}/p_peak_w"), "", pp, w::POWER_W);
            Envelope::TorquePower {
                t_peak: tp,
                p_peak: pp,
            }
        }
    };
    (env, rpm_to_rad_s(n_max))
}

/// ψ_m of an IPMSM (`p` = `{base}/`), given directly or from the back-EMF at `pp` pole pairs
/// (NaN when neither or both are given).
fn psi_m(v: &mut Validator, base: &str, p: &str, m: &IpmsmMotor, pp: f64) -> f64 {
    match (m.psi_m_wb, &m.back_emf) {
        (Some(psi), None) => {
            v.range(&format!("{p}psi_m_wb"), "", psi, w::PSI_M_WB);
            psi
        }
        (None, Some(b)) => {
            let a = v.range(
                &format!("{p}back_emf/v_peak_phase"),
                "",
                b.v_peak_phase,
                w::BACK_EMF,
            );
            let c = v.range(&format!("{p}back_emf/at_rpm"), "", b.at_rpm, w::BACK_EMF);
            let psi = psi_from_back_emf(b.v_peak_phase, b.at_rpm, pp);
            if a && c && !w::PSI_M_WB.contains(psi) {
                v.push(
                    format!("{p}back_emf"),
                    format!("implies ψ_m = {psi} Wb, outside {}", w::PSI_M_WB),
                );
            }
            psi
        }
        (Some(_), Some(_)) => {
            v.push(
                base,
                "give exactly one of psi_m_wb and back_emf, not both".to_owned(),
            );
            f64::NAN
        }
        (None, None) => {
            v.push(base, "needs psi_m_wb or back_emf".to_owned());
            f64::NAN
        }
    }
}

/// The AC resistance factor of an IPMSM (`p` = `{base}/`).
fn ac_factor(v: &mut Validator, p: &str, spec: Option<&AcFactorSpec>) -> AcFactor {
    let ap = format!("{p}ac_factor");
    match spec {
        None | Some(AcFactorSpec::NoAc(_)) => AcFactor::None,
        Some(AcFactorSpec::Table(t)) => {
            axis(v, &format!("{ap}/freq_hz"), &t.freq_hz, 1, w::FREQ_HZ);
            if t.k_ac.len() != t.freq_hz.len() {
                v.push(
                    format!("{ap}/k_ac"),
                    format!(
                        "must have {} values like freq_hz, got {}",
                        t.freq_hz.len(),
                        t.k_ac.len()
                    ),
                );
            } else {
                v.all_in(&format!("{ap}/k_ac"), "k_AC", &t.k_ac, w::K_AC);
            }
            AcFactor::Table {
                freq_hz: t.freq_hz.clone(),
                k_ac: t.k_ac.clone(),
            }
        }
        Some(AcFactorSpec::Dowell(d)) => {
            let fields = [
                (
                    "conductor_height_m",
                    d.conductor_height_m,
                    w::CONDUCTOR_HEIGHT_M,
                ),
                ("layers", f64::from(d.layers), w::LAYERS),
                ("porosity", d.porosity, w::POROSITY),
                ("stack_length_m", d.stack_length_m, w::STACK_LENGTH_M),
                ("end_length_m", d.end_length_m, w::END_LENGTH_M),
            ];
            for (name, x, range) in fields {
                v.range(&format!("{ap}/{name}"), "", x, range);
            }
            AcFactor::Dowell(Dowell {
                conductor_height_m: d.conductor_height_m,
                layers: f64::from(d.layers),
                porosity: d.porosity,
                stack_length_m: d.stack_length_m,
                end_length_m: d.end_length_m,
            })
        }
    }
}

/// The scalar fields of an IPMSM after ψ_m (`p` = `{base}/`): dq inductances, winding, current
/// and voltage limits, speed limit; returns the winding temperature and voltage utilization
/// with their defaults applied.
fn ipmsm_ratings(v: &mut Validator, p: &str, m: &IpmsmMotor) -> (f64, f64) {
    let ld_ok = v.range(&format!("{p}ld_h"), "", m.ld_h, w::INDUCTANCE_H);
    let lq_ok = v.range(&format!("{p}lq_h"), "", m.lq_h, w::INDUCTANCE_H);
    if ld_ok && lq_ok && m.lq_h < m.ld_h {
        v.push(
            format!("{p}lq_h"),
            format!("must be ≥ ld_h ({}) for an IPMSM with reluctance torque (MTPA assumes L_q ≥ L_d), got {}", m.ld_h, m.lq_h),
        );
    }
    let temp = m.winding_temp_c.unwrap_or(100.0);
    let util = m.voltage_utilization.unwrap_or(1.0);
    let fields = [
        ("r_phase_20c_ohm", m.r_phase_20c_ohm, w::R_PHASE_OHM),
        ("winding_temp_c", temp, w::WINDING_TEMP_C),
        ("i_max_arms", m.i_max_arms, w::ELECTRIC_LIMIT),
        ("v_dc", m.v_dc, w::ELECTRIC_LIMIT),
        ("voltage_utilization", util, w::VOLTAGE_UTILIZATION),
        ("n_max_rpm", m.n_max_rpm, w::N_MAX_RPM),
    ];
    for (name, x, range) in fields {
        v.range(&format!("{p}{name}"), "", x, range);
    }
    (temp, util)
}

/// An optional field of an IPMSM checked against `range` when given; `default` when absent.
fn optional(v: &mut Validator, ptr: &str, x: Option<f64>, range: Range, default: f64) -> f64 {
    if let Some(x) = x {
        v.range(ptr, "", x, range);
    }
    x.unwrap_or(default)
}

fn ipmsm(v: &mut Validator, base: &str, m: &IpmsmMotor) -> Ipmsm {
    let p = format!("{base}/");
    v.uint(
        &format!("{p}pole_pairs"),
        "",
        u64::from(m.pole_pairs),
        w::POLE_PAIRS,
    );
    let pp = f64::from(m.pole_pairs).clamp(w::POLE_PAIRS.lo, w::POLE_PAIRS.hi);
    let psi = psi_m(v, base, &p, m, pp);
    let (temp, util) = ipmsm_ratings(v, &p, m);
    let t_cap = optional(
        v,
        &format!("{p}t_cap_nm"),
        m.t_cap_nm,
        w::TORQUE_NM,
        f64::INFINITY,
    );
    let p_cap = optional(
        v,
        &format!("{p}p_cap_w"),
        m.p_cap_w,
        w::POWER_W,
        f64::INFINITY,
    );
    let ac = ac_factor(v, &p, m.ac_factor.as_ref());
    let iron = m.iron.clone().unwrap_or_default();
    let mech = m.mech.clone().unwrap_or_default();
    for (name, x) in [
        ("iron/k_h", iron.k_h),
        ("iron/k_e", iron.k_e),
        ("mech/c_fric_nm", mech.c_fric_nm),
        ("mech/c_wind", mech.c_wind),
    ] {
        v.range(&format!("{p}{name}"), "", x, w::LOSS_COEFF);
    }
    let scale = optional(
        v,
        &format!("{p}stack_scale"),
        m.stack_scale,
        w::STACK_SCALE,
        1.0,
    );
    if m.stack_scale.is_some() && !matches!(ac, AcFactor::Dowell(_)) {
        v.push(
            format!("{p}stack_scale"),
            "needs ac_factor model \"dowell\" (its stack/end lengths split the resistance)"
                .to_owned(),
        );
    }
    Ipmsm::new(&IpmsmParams {
        pole_pairs: pp,
        psi_m_wb: psi,
        ld_h: m.ld_h,
        lq_h: m.lq_h,
        r_20_ohm: m.r_phase_20c_ohm,
        winding_temp_c: temp,
        i_max_arms: m.i_max_arms,
        v_dc: m.v_dc,
        voltage_utilization: util,
        n_max_rpm: m.n_max_rpm,
        t_cap_nm: t_cap,
        p_cap_w: p_cap,
        ac,
        k_h: iron.k_h,
        k_e: iron.k_e,
        c_fric: mech.c_fric_nm,
        c_wind: mech.c_wind,
        stack_scale: scale,
    })
}

/// Warn when the envelope reaches beyond a map's torque axis (lookups are held at the edge).
fn map_axis_warning(loss: &Grid2, env: &Envelope, warnings: &mut Vec<String>) {
    let (lo, hi) = loss.torque_range();
    let peak = env.peak();
    if peak > hi || -peak < lo {
        warnings.push(format!(
            "envelope torque ±{peak:.1} N·m exceeds the map torque axis [{lo:.1}, {hi:.1}] N·m: losses are held at the axis edge (no extrapolation)"
        ));
    }
}

/// The speed and torque axes of a map motor (`base` = `/motors/{i}`), at least 2 points each:
/// whether each is valid.
fn map_axes(
    v: &mut Validator,
    base: &str,
    (speed_rpm, torque_nm): (&[f64], &[f64]),
    torque_range: Range,
) -> (bool, bool) {
    let ok_s = axis(
        v,
        &format!("{base}/speed_rpm"),
        speed_rpm,
        2,
        w::SPEED_AXIS_RPM,
    );
    let ok_t = axis(v, &format!("{base}/torque_nm"), torque_nm, 2, torque_range);
    (ok_s, ok_t)
}

/// The loss grid of an efficiency-map motor (`base` = `/motors/{i}`); empty when invalid.
fn efficiency_map(
    v: &mut Validator,
    base: &str,
    m: &EfficiencyMapMotor,
    env: &Envelope,
    warnings: &mut Vec<String>,
) -> Grid2 {
    let (ok_s, ok_t) = map_axes(v, base, (&m.speed_rpm, &m.torque_nm), w::TORQUE_AXIS_NM);
    let shape = (m.speed_rpm.len(), m.torque_nm.len());
    let mut ok = ok_s && ok_t;
    if ok {
        ok &= table(
            v,
            &format!("{base}/efficiency"),
            &m.efficiency,
            shape,
            w::MAP_EFFICIENCY,
        );
        if let Some(g) = &m.efficiency_gen {
            ok &= table(
                v,
                &format!("{base}/efficiency_gen"),
                g,
                shape,
                w::MAP_EFFICIENCY,
            );
        }
    }
    if !ok {
        return Grid2 {
            speed: vec![],
            torque: vec![],
            values: vec![],
        };
    }
    let speed: Vec<f64> = m.speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect();
    let conv = efficiency_to_loss(
        &speed,
        &m.torque_nm,
        &m.efficiency,
        m.efficiency_gen.as_deref(),
    );
    warnings.extend(conv.warnings);
    map_axis_warning(&conv.loss, env, warnings);
    conv.loss
}

/// The loss grid of a loss-map motor (`base` = `/motors/{i}`); without values when invalid.
fn loss_map(
    v: &mut Validator,
    base: &str,
    m: &LossMapMotor,
    env: &Envelope,
    warnings: &mut Vec<String>,
) -> Grid2 {
    let (ok_s, ok_t) = map_axes(
        v,
        base,
        (&m.speed_rpm, &m.torque_nm),
        w::SIGNED_TORQUE_AXIS_NM,
    );
    if ok_t && !m.torque_nm.iter().any(|&t| t.abs() <= 0.0) {
        v.push(
            format!("{base}/torque_nm"),
            "signed torque axis must contain 0".to_owned(),
        );
    }
    let (ns, nt) = (m.speed_rpm.len(), m.torque_nm.len());
    let ok = ok_s && ok_t && table(v, &format!("{base}/loss_w"), &m.loss_w, (ns, nt), w::LOSS_W);
    let loss = Grid2 {
        speed: m.speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect(),
        torque: m.torque_nm.clone(),
        values: if ok {
            m.loss_w.iter().flatten().copied().collect()
        } else {
            vec![]
        },
    };
    if ok {
        map_axis_warning(&loss, env, warnings);
    }
    loss
}

/// The admissible speed of a motor in rpm as given (axes of maps are built from it without a
/// round trip): `n_max_rpm` (default [`DEFAULT_N_MAX`]), for maps at most their last speed.
fn n_max_rpm(spec: &MotorSpec) -> f64 {
    let map = |n_max: Option<f64>, speed_rpm: &[f64]| {
        n_max
            .unwrap_or(DEFAULT_N_MAX)
            .min(speed_rpm.last().copied().unwrap_or(0.0))
    };
    match spec {
        MotorSpec::Constant(m) => m.n_max_rpm.unwrap_or(DEFAULT_N_MAX),
        MotorSpec::EfficiencyMap(m) => map(m.n_max_rpm, &m.speed_rpm),
        MotorSpec::LossMap(m) => map(m.n_max_rpm, &m.speed_rpm),
        MotorSpec::Ipmsm(m) => m.n_max_rpm,
    }
}

/// The envelope of a tabulated motor (constant efficiency, efficiency map or loss map: the same
/// four envelope fields) under the pointer `base`.
macro_rules! table_envelope {
    ($v:expr, $base:expr, $m:expr) => {
        envelope(
            $v,
            $base,
            $m.t_peak_nm,
            $m.p_peak_w,
            $m.n_max_rpm,
            $m.envelope.as_ref(),
        )
        .0
    };
}

fn motor(v: &mut Validator, i: usize, spec: &MotorSpec) -> MotorInput {
    let base = format!("/motors/{i}");
    name_ok(v, &format!("{base}/id"), spec.id(), "motor id");
    let mut warnings = Vec::new();
    let kind = match spec {
        MotorSpec::Constant(m) => {
            v.range(
                &format!("{base}/efficiency"),
                "",
                m.efficiency,
                w::EFFICIENCY,
            );
            MotorKind::Constant {
                eta: m.efficiency,
                envelope: table_envelope!(v, &base, m),
            }
        }
        MotorSpec::EfficiencyMap(m) => {
            let envelope = table_envelope!(v, &base, m);
            let loss = efficiency_map(v, &base, m, &envelope, &mut warnings);
            MotorKind::Map { loss, envelope }
        }
        MotorSpec::LossMap(m) => {
            let envelope = table_envelope!(v, &base, m);
            let loss = loss_map(v, &base, m, &envelope, &mut warnings);
            MotorKind::Map { loss, envelope }
        }
        MotorSpec::Ipmsm(m) => MotorKind::Ipmsm(Box::new(ipmsm(v, &base, m))),
    };
    let n_max_rpm = n_max_rpm(spec);
    MotorInput {
        id: spec.id().to_owned(),
        kind,
        omega_max: rpm_to_rad_s(n_max_rpm),
        n_max_rpm,
        warnings,
    }
}

fn grid(v: &mut Validator, ptr: &str, g: &GridSpec) -> (f64, f64) {
    v.range(
        &format!("{ptr}/speed_step_rpm"),
        "",
        g.speed_step_rpm,
        w::SPEED_STEP_RPM,
    );
    v.range(
        &format!("{ptr}/torque_step_nm"),
        "",
        g.torque_step_nm,
        w::TORQUE_STEP_NM,
    );
    (g.speed_step_rpm, g.torque_step_nm)
}

/// Validate a motor on its own (motor-map endpoint).
///
/// # Errors
/// Every offending field, as one [`CalcFailure`].
pub fn validate_motor(
    spec: &MotorSpec,
    g: &GridSpec,
    time_limit_ms: Option<u64>,
) -> Result<(MotorInput, (f64, f64)), CalcFailure> {
    let mut v = Validator::new();
    let _ = crate::calc::common::time_limit(&mut v, time_limit_ms);
    let m = motor(&mut v, 0, spec);
    let gr = grid(&mut v, "/grid", g);
    v.finish().map_err(|mut e| {
        for issue in &mut e.errors {
            issue.pointer = issue.pointer.replacen("/motors/0", "/motor", 1);
        }
        e.detail = e.detail.replacen("/motors/0", "/motor", 1);
        e
    })?;
    Ok((m, gr))
}

/// The cycles (at most [`MAX_CYCLES`] checked), each valid one with its index; zero distance and
/// duplicate names are reported.
fn cycles(v: &mut Validator, specs: &[CycleSpec]) -> Vec<(usize, Cycle)> {
    if specs.is_empty() || specs.len() > MAX_CYCLES {
        v.push(
            "/cycles",
            format!("must have 1..{MAX_CYCLES} entries, got {}", specs.len()),
        );
    }
    let mut cycles_ok: Vec<(usize, Cycle)> = Vec::new();
    for (j, c) in specs.iter().enumerate().take(MAX_CYCLES) {
        if let Some(cy) = cycle(v, j, c) {
            if cy.distance_m() <= 0.0 {
                v.push(
                    format!("/cycles/{j}"),
                    format!(
                        "cycle '{}' has zero distance (fuel economy undefined)",
                        cy.name
                    ),
                );
            } else if let Some((k, _)) = cycles_ok.iter().find(|(_, o)| o.name == cy.name) {
                v.push(
                    format!("/cycles/{j}"),
                    format!("duplicate cycle name '{}' (also /cycles/{k})", cy.name),
                );
            }
            cycles_ok.push((j, cy));
        }
    }
    cycles_ok
}

/// The motors (at most [`MAX_MOTORS`] checked), with duplicate ids reported.
fn motors(v: &mut Validator, specs: &[MotorSpec]) -> Vec<MotorInput> {
    if specs.is_empty() || specs.len() > MAX_MOTORS {
        v.push(
            "/motors",
            format!("must have 1..{MAX_MOTORS} entries, got {}", specs.len()),
        );
    }
    let mut motors = Vec::new();
    for (i, m) in specs.iter().enumerate().take(MAX_MOTORS) {
        if let Some(k) = specs[..i].iter().position(|o| o.id() == m.id()) {
            v.push(
                format!("/motors/{i}/id"),
                format!("duplicate motor id '{}' (also /motors/{k})", m.id()),
            );
        }
        motors.push(motor(v, i, m));
    }
    motors
}

/// The desirability weights of `n_cycles` cycles, normalised (equal weights when absent or
/// invalid).
fn desirability(v: &mut Validator, weights: Option<&[f64]>, n_cycles: usize) -> Vec<f64> {
    let n_cyc = n_cycles.max(1);
    let equal = vec![1.0 / n_cyc as f64; n_cyc];
    let Some(w) = weights else {
        return equal;
    };
    let p = "/options/desirability_weights";
    if w.len() != n_cycles {
        v.push(
            p,
            format!(
                "must have one weight per cycle ({n_cycles}), got {}",
                w.len()
            ),
        );
        return equal;
    }
    if !v.all_in(p, "", w, w::DESIRABILITY_WEIGHT) {
        return equal;
    }
    let s: f64 = w.iter().sum();
    if s > 0.0 {
        w.iter().map(|x| x / s).collect()
    } else {
        v.push(p, "weights must not all be 0".to_owned());
        equal
    }
}

/// The options: substeps, loss-map grid, histogram bins and desirability weights; returns the
/// grid and the normalised weights.
fn options(v: &mut Validator, o: &OptionsSpec, n_cycles: usize) -> ((f64, f64), Vec<f64>) {
    v.uint("/options/substeps", "", u64::from(o.substeps), w::SUBSTEPS);
    let gr = grid(v, "/options/loss_map_grid", &o.loss_map_grid);
    v.range(
        "/options/op_histogram/speed_bin_rpm",
        "",
        o.op_histogram.speed_bin_rpm,
        w::SPEED_BIN_RPM,
    );
    v.range(
        "/options/op_histogram/torque_bin_nm",
        "",
        o.op_histogram.torque_bin_nm,
        w::TORQUE_BIN_NM,
    );
    let weights = desirability(v, o.desirability_weights.as_deref(), n_cycles);
    (gr, weights)
}

/// Every cycle's top speed within every motor's speed limit (spec §3.7, §8 item 4).
fn speed_limits(
    v: &mut Validator,
    veh: &Vehicle,
    (motors, specs): (&[MotorInput], &[MotorSpec]),
    cycles: &[(usize, Cycle)],
) {
    for (i, m) in motors.iter().enumerate() {
        for (j, c) in cycles {
            let w_need = veh.motor_speed(c.max_speed_mps());
            if w_need.is_finite() && w_need > m.omega_max * (1.0 + SPEED_CHECK_SLACK) {
                let field = match specs.get(i) {
                    Some(MotorSpec::EfficiencyMap(_) | MotorSpec::LossMap(_)) => {
                        "n_max_rpm (or the map's last speed_rpm)"
                    }
                    _ => "n_max_rpm",
                };
                v.push(
                    format!("/motors/{i}/n_max_rpm"),
                    format!(
                        "cycle '{}' (/cycles/{j}) needs {:.1} rpm at its top speed {:.3} km/h, above the motor's {field} {:.1} rpm",
                        c.name,
                        super::ipmsm::rad_s_to_rpm(w_need),
                        c.max_speed_mps() * 3.6,
                        super::ipmsm::rad_s_to_rpm(m.omega_max)
                    ),
                );
            }
        }
    }
}

impl TryFrom<&BusFuelEconomyRequest> for BusFuelEconomyInput {
    type Error = CalcFailure;

    fn try_from(req: &BusFuelEconomyRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let _ = crate::calc::common::time_limit(&mut v, req.time_limit_ms);
        let shard = crate::calc::common::shard(&mut v, req.shard);
        let veh = vehicle(&mut v, &req.vehicle);
        v.range(
            "/inverter/efficiency",
            "",
            req.inverter.efficiency,
            w::EFFICIENCY,
        );
        let bat = battery(&mut v, &req.battery);
        let cycles_ok = cycles(&mut v, &req.cycles);
        let motors = motors(&mut v, &req.motors);
        let (gr, weights) = options(&mut v, &req.options, req.cycles.len());
        speed_limits(&mut v, &veh, (&motors, &req.motors), &cycles_ok);
        v.finish()?;

        let o = &req.options;
        let substeps = usize::try_from(o.substeps).unwrap_or(1);
        let total: usize = cycles_ok.iter().map(|(_, c)| c.intervals(substeps)).sum();
        if total > MAX_TOTAL_INTERVALS {
            return Err(CalcFailure::field(
                ProblemClass::TooLarge,
                "TOO_MANY_SAMPLES",
                "/options/substeps",
                format!(
                    "{total} intervals after sub-stepping exceed the limit {MAX_TOTAL_INTERVALS}"
                ),
            ));
        }
        let has = |k: OutputKind| o.outputs.contains(&k);
        Ok(Self {
            vehicle: veh,
            grade: req.vehicle.grade,
            inverter_eff: req.inverter.efficiency,
            battery: bat,
            cycles: cycles_ok.into_iter().map(|(_, c)| c).collect(),
            motors,
            options: Options {
                mode: o.mode.into(),
                convention: o.power_convention.into(),
                substeps,
                regen: o.regen,
                regen_limit: o.regen_limit,
                motor_eval: o.motor_eval.map_or(MotorEval::LossMap, MotorEval::from),
                grid: gr,
                breakdown: has(OutputKind::LossBreakdown),
                histogram: has(OutputKind::OpHistogram),
                traces: has(OutputKind::Traces),
                efficiency_map: has(OutputKind::EfficiencyMap),
                hist_bins: (o.op_histogram.speed_bin_rpm, o.op_histogram.torque_bin_nm),
                weights,
            },
            shard,
        })
    }
}
