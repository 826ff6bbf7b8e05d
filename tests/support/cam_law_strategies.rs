//! Proptest strategies shared by the cam-law property files (`props_cam_law`, `props_cam_law_fit`).

use mechcalc::calc::cam_law::law::BoundaryConditions;
use proptest::prelude::*;

/// Seven coefficients, each exactly 0 with probability ~1/3, else in [0.02, 1]; both pulses
/// non-empty (an empty pulse is repaired by giving its middle segment a length).
pub fn coefficients() -> impl Strategy<Value = [f64; 7]> {
    proptest::array::uniform7(prop_oneof![1 => Just(0.0), 2 => 0.02f64..1.0]).prop_map(|mut c| {
        if c[0] + c[1] + c[2] <= 0.0 {
            c[1] = 0.3;
        }
        if c[4] + c[5] + c[6] <= 0.0 {
            c[5] = 0.3;
        }
        c
    })
}

/// Boundary conditions from t_a ∈ [−100, 100), log-uniform Δt ∈ [1e-2, 1e2], s_a ∈ [−100, 100),
/// Δs from `ds`, and end rates r·scale/Δt (velocities) and r·scale/Δt² (accelerations) with each
/// r ∈ [−`rate`, `rate`) and scale = max(|Δs|, `scale_floor`).
pub fn scaled_conditions(
    ds: impl Strategy<Value = f64>,
    rate: f64,
    scale_floor: f64,
) -> impl Strategy<Value = BoundaryConditions> {
    (
        -100.0f64..100.0,
        -2.0f64..2.0,
        -100.0f64..100.0,
        ds,
        proptest::array::uniform4(-rate..rate),
    )
        .prop_map(move |(t_a, log_dt, s_a, ds, r)| {
            let dt = 10f64.powf(log_dt);
            let scale = ds.abs().max(scale_floor);
            BoundaryConditions {
                t_a,
                t_b: t_a + dt,
                s_a,
                s_b: s_a + ds,
                v_a: r[0] * scale / dt,
                v_b: r[1] * scale / dt,
                a_a: r[2] * scale / dt / dt,
                a_b: r[3] * scale / dt / dt,
            }
        })
}
