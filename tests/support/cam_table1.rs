//! The spec's Table-1 cam-law case (cam_law_fit.md §5.2/§8: non-zero end rates, all seven
//! segments non-empty) and Phase II of the paper's real cam, shared by the cam-law tests and
//! benches (each includes this file with `#[path]`) so they evaluate, fit and time the same law.

use mechcalc::calc::cam_law::law::BoundaryConditions;

/// Table-1 boundary conditions on [0, 1] with unit rise.
pub const TABLE1_BC: BoundaryConditions = BoundaryConditions {
    t_a: 0.0,
    t_b: 1.0,
    s_a: 0.0,
    s_b: 1.0,
    v_a: 0.2,
    v_b: 0.5,
    a_a: 1.4,
    a_b: 1.2,
};

/// Table-1 coefficient vector before normalisation (ĉ = c / 31).
pub const TABLE1_C: [f64; 7] = [2.0, 4.0, 6.0, 3.0, 8.0, 7.0, 1.0];

/// Table-1 knot displacements s(t_k), k = 0..7 (§5.2, 10 decimals).
#[allow(
    dead_code,
    reason = "the paper tests check the knots; the benches do not"
)]
pub const TABLE1_KNOT_S: [f64; 8] = [
    0.0,
    0.0183293714,
    0.1029953061,
    0.3409300267,
    0.4772699257,
    0.8062166995,
    0.9836654137,
    1.0,
];

/// Table-1 knot velocities v(t_k), k = 0..7 (§5.2, 10 decimals).
#[allow(
    dead_code,
    reason = "the paper tests check the knots; the benches do not"
)]
pub const TABLE1_KNOT_V: [f64; 8] = [
    0.2,
    0.3974939772,
    0.9148280105,
    1.4088456222,
    1.4088456222,
    1.0395991318,
    0.5320894799,
    0.5,
];

/// Phase II of the paper's real cam (cam_law.md §5.2, paper Tables 8/10): the coefficients as
/// printed (they sum to 1.05; the law renormalises them).
#[allow(dead_code, reason = "the paper tests use Phase II; the benches do not")]
pub const PHASE2_C: [f64; 7] = [0.3917, 0.0500, 0.1195, 0.0235, 0.1199, 0.1389, 0.2065];

/// Phase II boundary conditions: a fall from 20.38 to −4.27 over 210°–300°.
#[allow(dead_code, reason = "the paper tests use Phase II; the benches do not")]
pub const PHASE2_BC: BoundaryConditions = BoundaryConditions {
    t_a: 210.0,
    t_b: 300.0,
    s_a: 20.38,
    s_b: -4.27,
    v_a: -0.0028,
    v_b: 0.0183,
    a_a: 0.0,
    a_b: 0.006,
};
