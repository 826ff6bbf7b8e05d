//! Comparison of motors: relative FE change and the desirability of paper eq. 11-13 (spec §5.7),
//! plus the paper's constants kept for reference (spec V8).

/// Individual desirability d = (f − f_max)/(f_min − f_max) clipped to [0, 1]; 1 when
/// f_max = f_min (all designs equal) (paper eq. 12).
#[must_use]
pub fn desirability(f: f64, f_min: f64, f_max: f64) -> f64 {
    let span = f_min - f_max;
    if span.abs() <= 0.0 {
        return 1.0;
    }
    // `+ 0.0` turns a −0 (f = f_max) into +0.
    ((f - f_max) / span).clamp(0.0, 1.0) + 0.0
}

/// Overall desirability D = Π d_i^{w_i} with weights normalised to sum 1 (paper eq. 13); 0 when
/// any d_i with positive weight is 0 (computed as exp(Σ w_i ln d_i) only when all d_i > 0).
#[must_use]
pub fn overall_desirability(d: &[f64], w: &[f64]) -> f64 {
    let sw: f64 = w.iter().sum();
    if d.is_empty() || d.len() != w.len() || sw <= 0.0 {
        return 0.0;
    }
    let mut acc = 0.0;
    for (&di, &wi) in d.iter().zip(w) {
        if wi <= 0.0 {
            continue;
        }
        if di <= 0.0 {
            return 0.0;
        }
        acc += wi / sw * di.ln();
    }
    acc.exp()
}

/// Paper constants (spec §5.7 and V8).
pub mod paper {
    use std::f64::consts::PI;

    /// Rated torque of the initial motor [N·m] (Table 1).
    pub const RATED_TORQUE_NM: f64 = 800.0;
    /// Maximum power \[W\] (Table 1).
    pub const MAX_POWER_W: f64 = 130_000.0;
    /// Maximum speed \[rpm\] (Table 1).
    pub const MAX_SPEED_RPM: f64 = 5200.0;
    /// Torque at maximum speed as printed in the paper [N·m] (exact 130 kW / 5200 rpm = 238.73).
    pub const TORQUE_AT_MAX_SPEED_NM: f64 = 238.9;
    /// Constraint margin of g1/g2 (5 %).
    pub const CONSTRAINT_MARGIN: f64 = 1.05;

    /// Constraint g1: torque at base speed ≥ 1.05·800 = 840 N·m.
    #[must_use]
    pub fn g1_torque_nm() -> f64 {
        CONSTRAINT_MARGIN * RATED_TORQUE_NM
    }

    /// Constraint g2: torque at maximum speed ≥ 1.05·238.9 = 250.845 N·m.
    #[must_use]
    pub fn g2_torque_nm() -> f64 {
        CONSTRAINT_MARGIN * TORQUE_AT_MAX_SPEED_NM
    }

    /// Torque of a power at a speed, P/ω [N·m].
    #[must_use]
    pub fn torque_at_power(p_w: f64, rpm: f64) -> f64 {
        p_w / (rpm * PI / 30.0)
    }

    /// Initial sample count of the Kriging design, n_s = (n_d + 1)(n_d + 2)/2 (eq. 15).
    #[must_use]
    pub fn initial_samples(n_d: u64) -> u64 {
        (n_d + 1) * (n_d + 2) / 2
    }

    /// Vehicle speed [km/h] at a motor speed \[rpm\] through gear ratio i_g and wheel radius r \[m\].
    #[must_use]
    pub fn vehicle_speed_kmh(rpm: f64, gear_ratio: f64, wheel_radius_m: f64) -> f64 {
        rpm * PI / 30.0 / gear_ratio * wheel_radius_m * 3.6
    }

    /// Relative error of a measured vs simulated back-EMF, (measured − simulated)/measured.
    #[must_use]
    pub fn back_emf_error(measured: f64, simulated: f64) -> f64 {
        (measured - simulated) / measured
    }
}
