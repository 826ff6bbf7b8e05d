//! The spec's demo IPMSM (bus_fuel_economy.md V5) as a model object, and an efficiency map
//! tabulated from it. Shared by tests/it/{paper,http}_bus_fuel_economy.rs, benches/bus_fuel_economy.rs
//! and tests/slow/props_bus_fuel_economy.rs (each includes this file with `#[path]`), so they check and
//! time the same motor.

use mechcalc::calc::bus_fuel_economy::ac_factor::{AcFactor, Dowell};
use mechcalc::calc::bus_fuel_economy::ipmsm::{
    Ipmsm, IpmsmParams, psi_from_back_emf, rpm_to_rad_s,
};
use serde_json::{Value, json};

/// The demo IPMSM (V5) as a request's motor object: `id`, and the Dowell AC factor's conductor
/// height `h` (m).
pub fn demo_ipmsm_json(id: &str, h: f64) -> Value {
    json!({"id": id, "model": "ipmsm", "pole_pairs": 4, "back_emf": {"v_peak_phase": 83.3, "at_rpm": 1000},
           "ld_h": 0.00035, "lq_h": 0.00055, "r_phase_20c_ohm": 0.006, "winding_temp_c": 100, "i_max_arms": 500,
           "v_dc": 360, "n_max_rpm": 5200, "t_cap_nm": 800, "p_cap_w": 130000,
           "ac_factor": {"model": "dowell", "conductor_height_m": h, "layers": 6, "porosity": 0.9,
                         "stack_length_m": 0.083, "end_length_m": 0.05},
           "iron": {"k_h": 3.0, "k_e": 0.03}})
}

/// The demo IPMSM (V5); `caps = false` drops the 800 N·m / 130 kW caps (raw electrical envelope).
pub fn demo_ipmsm(caps: bool) -> Ipmsm {
    Ipmsm::new(&demo_params(caps))
}

/// Parameters of [`demo_ipmsm`].
pub fn demo_params(caps: bool) -> IpmsmParams {
    IpmsmParams {
        pole_pairs: 4.0,
        psi_m_wb: psi_from_back_emf(83.3, 1000.0, 4.0),
        ld_h: 0.00035,
        lq_h: 0.00055,
        r_20_ohm: 0.006,
        winding_temp_c: 100.0,
        i_max_arms: 500.0,
        v_dc: 360.0,
        voltage_utilization: 1.0,
        n_max_rpm: 5200.0,
        t_cap_nm: if caps { 800.0 } else { f64::INFINITY },
        p_cap_w: if caps { 130_000.0 } else { f64::INFINITY },
        ac: AcFactor::Dowell(Dowell {
            conductor_height_m: 0.0035,
            layers: 6.0,
            porosity: 0.9,
            stack_length_m: 0.083,
            end_length_m: 0.05,
        }),
        k_h: 3.0,
        k_e: 0.03,
        c_fric: 0.0,
        c_wind: 0.0,
        stack_scale: 1.0,
    }
}

/// The capped demo motor as an `efficiency_map` motor on a grid [rpm] × [N·m ≥ 0]: η at the
/// torque clamped to the envelope (η at n = 0 or T = 0 is irrelevant, the conversion replaces it).
pub fn demo_efficiency_map(speed_step: f64, torque_step: f64) -> Value {
    let m = demo_ipmsm(true);
    let speeds: Vec<f64> = (0..)
        .map(|k| f64::from(k) * speed_step)
        .take_while(|&n| n < 5200.0 - 1e-9)
        .chain([5200.0])
        .collect();
    let torques: Vec<f64> = (0..)
        .map(|k| f64::from(k) * torque_step)
        .take_while(|&t| t <= 800.0 + 1e-9)
        .collect();
    let eff: Vec<Vec<f64>> = speeds
        .iter()
        .map(|&n| {
            let w = rpm_to_rad_s(n);
            let tm = m.t_max(w);
            torques
                .iter()
                .map(|&t| {
                    if n <= 0.0 || t <= 0.0 {
                        return 0.5;
                    }
                    let tc = t.min(tm);
                    let p = tc * w;
                    p / (p + m.evaluate(w, tc, tm).0.total)
                })
                .collect()
        })
        .collect();
    json!({"id": "emap", "model": "efficiency_map", "speed_rpm": speeds, "torque_nm": torques, "efficiency": eff})
}
