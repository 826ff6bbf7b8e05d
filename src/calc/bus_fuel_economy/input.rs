//! The rules between fields of the wire requests (spec §3, §3.7), turning them into SI domain
//! inputs. Every per-field rule (counts, name lengths, ranges of every number and table value,
//! exactly one of `speed_kmh`/`speed_mps` and of `psi_m_wb`/`back_emf`) is declared on the wire
//! types and checked at the door; what is left here is what JSON Schema cannot state, each rule
//! with its own code ([`CROSS_FIELD_RULES`], [`MOTOR_MAP_RULES`]).

use super::ac_factor::{AcFactor, Dowell};
use super::battery::{Battery, Ecm};
use super::cycles::{self, Cycle};
use super::error::{
    DEADLINE_RULE, HISTOGRAM_TOO_LARGE_RULE, MAP_TOO_LARGE_RULE, SPEED_UNREACHABLE_RULE,
};
use super::ipmsm::{Ipmsm, IpmsmParams, psi_from_back_emf, rpm_to_rad_s};
use super::maps::{Envelope, Grid2, efficiency_to_loss};
use super::motor::{MotorInput, MotorKind};
use super::sim::Vehicle;
use super::wire as w;
use super::wire::{
    AcFactorSpec, BatteryModel, BatterySpec, BusFuelEconomyRequest, CycleSpec, EfficiencyMapMotor,
    EnvelopeTable, GridSpec, IpmsmMotor, LossMapMotor, MotorMapRequest, MotorSpec, VehicleSpec,
};
pub use super::wire::{MAX_CYCLE_SAMPLES, MAX_CYCLES, MAX_MOTORS};
use crate::calc::common::{RESPONSE_TOO_LARGE_RULE, SHARD_INDEX_BELOW_COUNT};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, CrossRule, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/bus-fuel-economy` and the failures of its computation,
    /// as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid BATTERY_MODEL_FIELDS ["/battery/model", "/battery/*"]
        "A battery gives only the fields of its model: efficiency for constant; nominal_voltage, \
         capacity_kwh, soc_initial, ocv_soc, ocv_v, r0_ohm, r1_ohm, c1_f, r2_ohm, c2_f for ecm_2rc.";
    invalid BATTERY_ECM_REQUIRED ["/battery/model", "/battery/*"]
        "With model ecm_2rc, soc_initial, ocv_soc, ocv_v, r0_ohm, r1_ohm, c1_f, r2_ohm and c2_f are given.";
    invalid AXIS_ORDER ["/battery/ocv_soc", "/cycles/*/time_s", "/motors/*/speed_rpm",
        "/motors/*/torque_nm", "/motors/*/envelope/speed_rpm", "/motors/*/ac_factor/freq_hz"]
        "Every axis (OCV SOC points, cycle times, map and envelope speeds and torques, k_AC \
         frequencies) is strictly increasing.";
    invalid LENGTH_MISMATCH ["/battery/ocv_v", "/cycles/*/speed_kmh", "/cycles/*/speed_mps",
        "/cycles/*/grade", "/motors/*/envelope/t_max_nm", "/motors/*/ac_factor/k_ac",
        "/motors/*/efficiency", "/motors/*/efficiency_gen", "/motors/*/loss_w",
        "/options/desirability_weights"]
        "Paired lists have the length of their axis (ocv_v ~ ocv_soc, speeds and grade ~ time_s, \
         t_max_nm ~ speed_rpm, k_ac ~ freq_hz), map tables are speed_rpm × torque_nm, and \
         desirability_weights hold one weight per cycle.";
    invalid TIME_STEP ["/cycles/*/time_s"]
        "Each time step of a custom cycle lies in [0.001, 60] s.";
    invalid UNKNOWN_CYCLE ["/cycles/*"] "A built-in cycle is one of manhattan, hwfet, hdudds.";
    invalid ZERO_DISTANCE ["/cycles/*"]
        "Every cycle drives a positive distance (fuel economy is undefined otherwise).";
    invalid DUPLICATE_NAME ["/cycles/*", "/motors/*/id"]
        "Cycle names are unique among the cycles, motor ids among the motors.";
    invalid ENVELOPE_CONFLICT ["/motors/*/envelope", "/motors/*/t_peak_nm", "/motors/*/p_peak_w"]
        "A motor gives either envelope or t_peak_nm/p_peak_w, not both.";
    invalid BACK_EMF_PSI ["/motors/*/back_emf", "/motors/*/pole_pairs"]
        "ψ_m = v_peak_phase / (pole_pairs·2π·at_rpm/60) lies in (0, 100] Wb.";
    invalid LQ_BELOW_LD ["/motors/*/lq_h", "/motors/*/ld_h"]
        "An ipmsm has lq_h ≥ ld_h (reluctance torque; MTPA assumes L_q ≥ L_d).";
    invalid STACK_SCALE_DOWELL("STACK_SCALE_NEEDS_DOWELL") ["/motors/*/stack_scale",
        "/motors/*/ac_factor"]
        "stack_scale is given only with ac_factor model dowell (its stack/end lengths split the resistance).";
    invalid LOSS_AXIS_ZERO ["/motors/*/torque_nm"]
        "A loss_map motor's signed torque axis contains 0.";
    invalid DESIRABILITY_ZERO ["/options/desirability_weights"]
        "The desirability weights are not all 0.";
    invalid CYCLE_ABOVE_MOTOR_SPEED ["/motors/*/n_max_rpm", "/cycles", "/vehicle"]
        "The motor speed at every cycle's top speed (through wheel radius and gear ratio) is within \
         each motor's n_max_rpm (for maps, also their last speed_rpm).";
    too_large TOO_MANY_SAMPLES ["/options/substeps", "/cycles"]
        "The intervals of all cycles after sub-stepping number at most 1 000 000.";
    listed SHARD_INDEX_BELOW_COUNT;
    listed DEADLINE_RULE;
    listed SPEED_UNREACHABLE_RULE;
    listed HISTOGRAM_TOO_LARGE_RULE;
    listed MAP_TOO_LARGE_RULE;
    listed RESPONSE_TOO_LARGE_RULE;
}

/// The rules between fields of `POST /v1/bus-fuel-economy/motor-map` and the failures of its
/// computation, as the document lists them (the motor's rules apply to `/motor/...` here).
pub const MOTOR_MAP_RULES: &[CrossRule] = &[
    AXIS_ORDER,
    LENGTH_MISMATCH,
    ENVELOPE_CONFLICT,
    BACK_EMF_PSI,
    LQ_BELOW_LD,
    STACK_SCALE_DOWELL,
    LOSS_AXIS_ZERO,
    DEADLINE_RULE,
    MAP_TOO_LARGE_RULE,
    RESPONSE_TOO_LARGE_RULE,
];

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

/// Default envelope of constant / map motors (spec §3.5).
const DEFAULT_T_PEAK: f64 = 800.0;
const DEFAULT_P_PEAK: f64 = 130_000.0;
const DEFAULT_N_MAX: f64 = 5200.0;

/// How an `ipmsm` motor's loss is evaluated: the request's `motor_eval`.
pub use super::wire::MotorEval;

/// The request's options (their ranges are checked at the door).
pub use super::wire::{OptionsSpec as Options, OutputKind};

impl Options {
    /// Substeps k (in [1, 32] at the door).
    #[must_use]
    pub fn k(&self) -> usize {
        usize::try_from(self.substeps).unwrap_or(1)
    }

    /// Whether the output `kind` was requested.
    #[must_use]
    pub fn has(&self, kind: OutputKind) -> bool {
        self.outputs.contains(&kind)
    }

    /// How an ipmsm's loss is evaluated (default: a precomputed loss map).
    #[must_use]
    pub fn eval(&self) -> MotorEval {
        self.motor_eval.unwrap_or(MotorEval::LossMap)
    }

    /// Histogram bins: speed \[rpm\], torque [N·m].
    #[must_use]
    pub const fn hist_bins(&self) -> (f64, f64) {
        (
            self.op_histogram.speed_bin_rpm,
            self.op_histogram.torque_bin_nm,
        )
    }
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
    /// Normalised desirability weights per cycle.
    pub weights: Vec<f64>,
    /// The block of motor × cycle pairs to simulate (all when `None`).
    pub shard: Option<crate::calc::common::Shard>,
}

/// An axis strictly increases (its count and range are checked at the door).
fn axis(v: &mut Validator, ptr: &str, xs: &[f64]) -> bool {
    let Some(i) = (1..xs.len()).find(|&i| xs[i] <= xs[i - 1]) else {
        return true;
    };
    rule!(v, AXIS_ORDER, format!("{ptr}/{i}");
        "axis must be strictly increasing: {} after {}", xs[i], xs[i - 1]);
    false
}

/// A list `ys` at `ptr` has the length of its axis `xs` (named `axis`).
fn same_length(v: &mut Validator, ptr: &str, ys: &[f64], n: usize, axis: &str) -> bool {
    ensure_rule!(v, ys.len() == n, LENGTH_MISMATCH, ptr;
        "must have {n} values like {axis}, got {}", ys.len())
}

/// An axis `{base}/{x}` (strictly increasing) and the list `{base}/{y}` paired with it.
fn paired(v: &mut Validator, base: &str, (x, xs): (&str, &[f64]), (y, ys): (&str, &[f64])) {
    axis(v, &format!("{base}/{x}"), xs);
    same_length(v, &format!("{base}/{y}"), ys, xs.len(), x);
}

/// A table `[rows][cols]` (its values are checked at the door).
fn table(v: &mut Validator, ptr: &str, t: &[Vec<f64>], (rows, cols): (usize, usize)) -> bool {
    if t.len() != rows {
        rule!(v, LENGTH_MISMATCH, ptr; "must have {rows} rows (one per speed), got {}", t.len());
        return false;
    }
    for (i, row) in t.iter().enumerate() {
        if row.len() != cols {
            rule!(v, LENGTH_MISMATCH, format!("{ptr}/{i}");
                "must have {cols} values (one per torque), got {}", row.len());
            return false;
        }
    }
    true
}

/// The vehicle (every field's range is checked at the door).
fn vehicle(s: &VehicleSpec) -> Vehicle {
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
                    rule!(v, BATTERY_MODEL_FIELDS, format!("/battery/{name}");
                        "is an ecm_2rc field; not allowed with model \"constant\"");
                }
            }
            Battery::Constant {
                eta: b.efficiency.unwrap_or(1.0),
            }
        }
        BatteryModel::Ecm2rc => {
            if b.efficiency.is_some() {
                rule!(v, BATTERY_MODEL_FIELDS, "/battery/efficiency";
                    "is a constant-model field; not allowed with model \"ecm_2rc\"");
            }
            // A required field (its range is checked at the door); NaN placeholder when missing.
            let mut need = |name: &str, x: Option<f64>| -> f64 {
                x.unwrap_or_else(|| {
                    rule!(v, BATTERY_ECM_REQUIRED, format!("/battery/{name}");
                        "is required for model \"ecm_2rc\"");
                    f64::NAN
                })
            };
            let soc0 = need("soc_initial", b.soc_initial);
            let r0 = need("r0_ohm", b.r0_ohm);
            let r1 = need("r1_ohm", b.r1_ohm);
            let c1 = need("c1_f", b.c1_f);
            let r2 = need("r2_ohm", b.r2_ohm);
            let c2 = need("c2_f", b.c2_f);
            let vn = b.nominal_voltage.unwrap_or(360.0);
            let cap = b.capacity_kwh.unwrap_or(256.0);
            let (soc_t, ocv_t) = match (&b.ocv_soc, &b.ocv_v) {
                (Some(s), Some(o)) => {
                    paired(v, "/battery", ("ocv_soc", s), ("ocv_v", o));
                    (s.clone(), o.clone())
                }
                _ => {
                    for (name, given) in [
                        ("ocv_soc", b.ocv_soc.is_some()),
                        ("ocv_v", b.ocv_v.is_some()),
                    ] {
                        if !given {
                            rule!(v, BATTERY_ECM_REQUIRED, format!("/battery/{name}");
                                "is required for model \"ecm_2rc\"");
                        }
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
                rule!(v, UNKNOWN_CYCLE, &base;
                    "unknown built-in cycle '{name}' (known: manhattan, hwfet, hdudds)");
            }
            cy
        }
        CycleSpec::Custom(cc) => {
            // Sample count, ranges and exactly one of the speed lists: checked at the door.
            let n = cc.time_s.len();
            let (speeds, sp_ptr, factor) = match (&cc.speed_kmh, &cc.speed_mps) {
                (Some(s), None) => (s, format!("{base}/speed_kmh"), 1.0 / 3.6),
                (None, Some(s)) => (s, format!("{base}/speed_mps"), 1.0),
                _ => return None,
            };
            let mut ok = same_length(v, &sp_ptr, speeds, n, "time_s");
            let tp = format!("{base}/time_s");
            if axis(v, &tp, &cc.time_s) {
                if let Some(i) = (1..n).find(|&i| {
                    let dt = cc.time_s[i] - cc.time_s[i - 1];
                    // 1e-6 relative slack: 10.001 − 10.0 is 0.000999999… in binary.
                    !(MIN_TIME_STEP_S * (1.0 - 1e-6)..=MAX_TIME_STEP_S).contains(&dt)
                }) {
                    rule!(v, TIME_STEP, format!("{tp}/{i}");
                        "time step must be in [{MIN_TIME_STEP_S}, {MAX_TIME_STEP_S}] s, got {} s",
                        cc.time_s[i] - cc.time_s[i - 1]);
                    ok = false;
                }
            } else {
                ok = false;
            }
            // km/h in [0, 720] is m/s in [0, 200] (the door): the conversion stays in range.
            let mps: Vec<f64> = speeds.iter().map(|s| s * factor).collect();
            if let Some(g) = &cc.grade {
                ok &= same_length(v, &format!("{base}/grade"), g, n, "time_s");
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

/// Envelope fields shared by constant and map motors (ranges checked at the door).
fn envelope(
    v: &mut Validator,
    base: &str,
    t_peak: Option<f64>,
    p_peak: Option<f64>,
    n_max: Option<f64>,
    table: Option<&EnvelopeTable>,
) -> (Envelope, f64) {
    let n_max = n_max.unwrap_or(DEFAULT_N_MAX);
    let env = match table {
        Some(t) => {
            let p = format!("{base}/envelope");
            ensure_rule!(v, t_peak.is_none() && p_peak.is_none(), ENVELOPE_CONFLICT, &p;
                "give either envelope or t_peak_nm/p_peak_w, not both");
            paired(
                v,
                &p,
                ("speed_rpm", &t.speed_rpm),
                ("t_max_nm", &t.t_max_nm),
            );
            Envelope::Table {
                speed: t.speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect(),
                t_max: t.t_max_nm.clone(),
            }
        }
        None => Envelope::TorquePower {
            t_peak: t_peak.unwrap_or(DEFAULT_T_PEAK),
            p_peak: p_peak.unwrap_or(DEFAULT_P_PEAK),
        },
    };
    (env, rpm_to_rad_s(n_max))
}

/// ψ_m of an IPMSM (`p` = `{base}/`), given directly or from the back-EMF at `pp` pole pairs
/// (exactly one of them: checked at the door; NaN past a skipped door).
fn psi_m(v: &mut Validator, p: &str, m: &IpmsmMotor, pp: f64) -> f64 {
    match (m.psi_m_wb, &m.back_emf) {
        (Some(psi), None) => psi,
        (None, Some(b)) => {
            let psi = psi_from_back_emf(b.v_peak_phase, b.at_rpm, pp);
            ensure_rule!(v, w::PSI_M_WB.contains(psi), BACK_EMF_PSI, format!("{p}back_emf");
                "implies ψ_m = {psi} Wb, outside {}", w::PSI_M_WB);
            psi
        }
        _ => f64::NAN,
    }
}

/// The AC resistance factor of an IPMSM (`p` = `{base}/`).
fn ac_factor(v: &mut Validator, p: &str, spec: Option<&AcFactorSpec>) -> AcFactor {
    let ap = format!("{p}ac_factor");
    match spec {
        None | Some(AcFactorSpec::NoAc(_)) => AcFactor::None,
        Some(AcFactorSpec::Table(t)) => {
            paired(v, &ap, ("freq_hz", &t.freq_hz), ("k_ac", &t.k_ac));
            AcFactor::Table {
                freq_hz: t.freq_hz.clone(),
                k_ac: t.k_ac.clone(),
            }
        }
        Some(AcFactorSpec::Dowell(d)) => AcFactor::Dowell(Dowell {
            conductor_height_m: d.conductor_height_m,
            layers: f64::from(d.layers),
            porosity: d.porosity,
            stack_length_m: d.stack_length_m,
            end_length_m: d.end_length_m,
        }),
    }
}

fn ipmsm(v: &mut Validator, base: &str, m: &IpmsmMotor) -> Ipmsm {
    let p = format!("{base}/");
    let pp = f64::from(m.pole_pairs);
    let psi = psi_m(v, &p, m, pp);
    ensure_rule!(v, m.lq_h >= m.ld_h, LQ_BELOW_LD, format!("{p}lq_h");
        "must be ≥ ld_h ({}) for an IPMSM with reluctance torque (MTPA assumes L_q ≥ L_d), got {}",
        m.ld_h, m.lq_h);
    let ac = ac_factor(v, &p, m.ac_factor.as_ref());
    let iron = m.iron.clone().unwrap_or_default();
    let mech = m.mech.clone().unwrap_or_default();
    ensure_rule!(v, m.stack_scale.is_none() || matches!(ac, AcFactor::Dowell(_)),
        STACK_SCALE_DOWELL, format!("{p}stack_scale");
        "needs ac_factor model \"dowell\" (its stack/end lengths split the resistance)");
    Ipmsm::new(&IpmsmParams {
        pole_pairs: pp,
        psi_m_wb: psi,
        ld_h: m.ld_h,
        lq_h: m.lq_h,
        r_20_ohm: m.r_phase_20c_ohm,
        winding_temp_c: m.winding_temp_c.unwrap_or(100.0),
        i_max_arms: m.i_max_arms,
        v_dc: m.v_dc,
        voltage_utilization: m.voltage_utilization.unwrap_or(1.0),
        n_max_rpm: m.n_max_rpm,
        t_cap_nm: m.t_cap_nm.unwrap_or(f64::INFINITY),
        p_cap_w: m.p_cap_w.unwrap_or(f64::INFINITY),
        ac,
        k_h: iron.k_h,
        k_e: iron.k_e,
        c_fric: mech.c_fric_nm,
        c_wind: mech.c_wind,
        stack_scale: m.stack_scale.unwrap_or(1.0),
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

/// The speed and torque axes of a map motor (`base` = `/motors/{i}`; counts and ranges checked
/// at the door): whether each increases strictly.
fn map_axes(
    v: &mut Validator,
    base: &str,
    (speed_rpm, torque_nm): (&[f64], &[f64]),
) -> (bool, bool) {
    let ok_s = axis(v, &format!("{base}/speed_rpm"), speed_rpm);
    let ok_t = axis(v, &format!("{base}/torque_nm"), torque_nm);
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
    let (ok_s, ok_t) = map_axes(v, base, (&m.speed_rpm, &m.torque_nm));
    let shape = (m.speed_rpm.len(), m.torque_nm.len());
    let mut ok = ok_s && ok_t;
    if ok {
        ok &= table(v, &format!("{base}/efficiency"), &m.efficiency, shape);
        if let Some(g) = &m.efficiency_gen {
            ok &= table(v, &format!("{base}/efficiency_gen"), g, shape);
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
    let (ok_s, ok_t) = map_axes(v, base, (&m.speed_rpm, &m.torque_nm));
    if ok_t && !m.torque_nm.iter().any(|&t| t.abs() <= 0.0) {
        rule!(v, LOSS_AXIS_ZERO, format!("{base}/torque_nm"); "signed torque axis must contain 0");
    }
    let (ns, nt) = (m.speed_rpm.len(), m.torque_nm.len());
    let ok = ok_s && ok_t && table(v, &format!("{base}/loss_w"), &m.loss_w, (ns, nt));
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
    let mut warnings = Vec::new();
    let kind = match spec {
        MotorSpec::Constant(m) => MotorKind::Constant {
            eta: m.efficiency,
            envelope: table_envelope!(v, &base, m),
        },
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

impl GridSpec {
    /// The map grid: speed step \[rpm\], torque step [N·m] (ranges checked at the door).
    #[must_use]
    pub const fn steps(&self) -> (f64, f64) {
        (self.speed_step_rpm, self.torque_step_nm)
    }
}

/// A validated motor-map request: the motor, the grid and whether to return the components.
#[derive(Debug, Clone)]
pub struct MotorMapInput {
    /// The motor.
    pub motor: MotorInput,
    /// Speed step \[rpm\], torque step [N·m].
    pub grid: (f64, f64),
    /// Also return the ipmsm loss components and operating modes.
    pub include_components: bool,
}

impl TryFrom<MotorMapRequest> for MotorMapInput {
    type Error = CalcFailure;

    /// The motor's rules between fields (pointers under `/motor`).
    fn try_from(req: MotorMapRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let m = motor(&mut v, 0, &req.motor);
        v.finish().map_err(|mut e| {
            for issue in &mut e.errors {
                issue.pointer = issue.pointer.replacen("/motors/0", "/motor", 1);
            }
            e.detail = e.detail.replacen("/motors/0", "/motor", 1);
            e
        })?;
        Ok(Self {
            motor: m,
            grid: req.grid.steps(),
            include_components: req.include_components,
        })
    }
}

/// The cycles (their count is checked at the door), each valid one with its index; zero distance
/// and duplicate names are reported.
fn cycles(v: &mut Validator, specs: &[CycleSpec]) -> Vec<(usize, Cycle)> {
    let mut cycles_ok: Vec<(usize, Cycle)> = Vec::new();
    for (j, c) in specs.iter().enumerate().take(MAX_CYCLES) {
        if let Some(cy) = cycle(v, j, c) {
            if cy.distance_m() <= 0.0 {
                rule!(v, ZERO_DISTANCE, format!("/cycles/{j}");
                    "cycle '{}' has zero distance (fuel economy undefined)", cy.name);
            } else if let Some((k, _)) = cycles_ok.iter().find(|(_, o)| o.name == cy.name) {
                rule!(v, DUPLICATE_NAME, format!("/cycles/{j}");
                    "duplicate cycle name '{}' (also /cycles/{k})", cy.name);
            }
            cycles_ok.push((j, cy));
        }
    }
    cycles_ok
}

/// The motors (their count is checked at the door), with duplicate ids reported.
fn motors(v: &mut Validator, specs: &[MotorSpec]) -> Vec<MotorInput> {
    let mut motors = Vec::new();
    for (i, m) in specs.iter().enumerate().take(MAX_MOTORS) {
        if let Some(k) = specs[..i].iter().position(|o| o.id() == m.id()) {
            rule!(v, DUPLICATE_NAME, format!("/motors/{i}/id");
                "duplicate motor id '{}' (also /motors/{k})", m.id());
        }
        motors.push(motor(v, i, m));
    }
    motors
}

/// The desirability weights of `n_cycles` cycles, normalised (equal weights when absent or
/// invalid; their range is checked at the door).
fn desirability(v: &mut Validator, weights: Option<&[f64]>, n_cycles: usize) -> Vec<f64> {
    let n_cyc = n_cycles.max(1);
    let equal = vec![1.0 / n_cyc as f64; n_cyc];
    let Some(w) = weights else {
        return equal;
    };
    let p = "/options/desirability_weights";
    if !ensure_rule!(v, w.len() == n_cycles, LENGTH_MISMATCH, p;
        "must have one weight per cycle ({n_cycles}), got {}", w.len())
    {
        return equal;
    }
    let s: f64 = w.iter().sum();
    if s > 0.0 {
        w.iter().map(|x| x / s).collect()
    } else {
        rule!(v, DESIRABILITY_ZERO, p; "weights must not all be 0");
        equal
    }
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
                rule!(v, CYCLE_ABOVE_MOTOR_SPEED, format!("/motors/{i}/n_max_rpm");
                    "cycle '{}' (/cycles/{j}) needs {:.1} rpm at its top speed {:.3} km/h, above the motor's {field} {:.1} rpm",
                    c.name, super::ipmsm::rad_s_to_rpm(w_need), c.max_speed_mps() * 3.6,
                    super::ipmsm::rad_s_to_rpm(m.omega_max));
            }
        }
    }
}

impl TryFrom<&BusFuelEconomyRequest> for BusFuelEconomyInput {
    type Error = CalcFailure;

    fn try_from(req: &BusFuelEconomyRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let shard = crate::calc::common::shard_rule(&mut v, req.shard);
        let veh = vehicle(&req.vehicle);
        let bat = battery(&mut v, &req.battery);
        let cycles_ok = cycles(&mut v, &req.cycles);
        let motors = motors(&mut v, &req.motors);
        let weights = desirability(
            &mut v,
            req.options.desirability_weights.as_deref(),
            req.cycles.len(),
        );
        speed_limits(&mut v, &veh, (&motors, &req.motors), &cycles_ok);
        v.finish()?;
        // `finish` succeeded: every cycle converted (exactly one speed list: the door).
        if cycles_ok.len() != req.cycles.len() {
            return Err(crate::calc::rules::door_skipped("/cycles"));
        }

        let o = &req.options;
        let total: usize = cycles_ok.iter().map(|(_, c)| c.intervals(o.k())).sum();
        if total > MAX_TOTAL_INTERVALS {
            return Err(TOO_MANY_SAMPLES.fail(
                "/options/substeps",
                format!(
                    "{total} intervals after sub-stepping exceed the limit {MAX_TOTAL_INTERVALS}"
                ),
            ));
        }
        Ok(Self {
            vehicle: veh,
            grade: req.vehicle.grade,
            inverter_eff: req.inverter.efficiency,
            battery: bat,
            cycles: cycles_ok.into_iter().map(|(_, c)| c).collect(),
            motors,
            options: o.clone(),
            weights,
            shard,
        })
    }
}

impl TryFrom<BusFuelEconomyRequest> for BusFuelEconomyInput {
    type Error = CalcFailure;

    fn try_from(req: BusFuelEconomyRequest) -> Result<Self, CalcFailure> {
        Self::try_from(&req)
    }
}
