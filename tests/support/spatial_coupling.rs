//! Helpers of the spatial-coupling tests (`tests/it/paper_spatial_coupling.rs`,
//! `tests/slow/props_spatial_coupling.rs`, `tests/slow/stress_spatial_coupling.rs`): requests
//! through the public `run`, the independent loop-closure check (spec §4's seven equations with
//! shaft frames built here from the returned angles) and rates against central differences.

#![allow(
    clippy::suboptimal_flops,
    reason = "test arithmetic follows the spec's formulas; mul_add gains nothing here"
)]

use mechcalc::calc::spatial_coupling::{SpatialCouplingRequest, run};
use mechcalc::numerics::Budget;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// The answer to `body` through `run` (panics on a refused request).
pub fn answer(body: Value) -> Value {
    let req: SpatialCouplingRequest = serde_json::from_value(body).expect("valid request JSON");
    serde_json::to_value(run(req, &Budget::unlimited()).expect("request succeeds"))
        .expect("serializes")
}

pub fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

pub fn v3(v: &Value) -> [f64; 3] {
    [num(&v[0]), num(&v[1]), num(&v[2])]
}

/// Difference of two angles in degrees, modulo 360, in (−180, 180].
pub fn dang(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 { d - 360.0 } else { d }
}

pub fn close(got: f64, want: f64, tol: f64, what: &str) {
    let e = (got - want).abs();
    assert!(
        e <= tol * want.abs().max(1.0),
        "{what}: got {got:.17e}, want {want:.17e}, |Δ| = {e:e} > {tol:e}"
    );
}

pub fn close_angle(got: f64, want: f64, tol: f64, what: &str) {
    let e = dang(got, want).abs();
    assert!(
        e <= tol,
        "{what}: got {got:.15}, want {want:.15}, |Δ| = {e:e} deg"
    );
}

/// The refusal of `body` through `run`.
pub fn refusal(body: Value) -> mechcalc::calc::CalcFailure {
    let req: SpatialCouplingRequest = serde_json::from_value(body).expect("valid request JSON");
    match run(req, &Budget::unlimited()) {
        Ok(_) => panic!("request unexpectedly succeeded"),
        Err(e) => e,
    }
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Shaft frames from the returned angles, built here from T01 = X(π/2 − α, a)·Z(θ1),
/// T02 = X(α − π/2, −a)·Z(θ2) (spec §3.1).
pub fn shaft_frames(alpha_deg: f64, t1_deg: f64, t2_deg: f64) -> [[[f64; 3]; 3]; 2] {
    let (s1, c1) = t1_deg.to_radians().sin_cos();
    let (s2, c2) = t2_deg.to_radians().sin_cos();
    // Rotation about x by φ maps (x, y, z) to (x, y cos φ − z sin φ, y sin φ + z cos φ).
    let rx = |phi: f64, v: [f64; 3]| {
        let (s, c) = phi.sin_cos();
        [v[0], v[1] * c - v[2] * s, v[1] * s + v[2] * c]
    };
    let p1 = std::f64::consts::FRAC_PI_2 - alpha_deg.to_radians();
    let p2 = -p1;
    let f1 = [
        rx(p1, [c1, s1, 0.0]),
        rx(p1, [-s1, c1, 0.0]),
        rx(p1, [0.0, 0.0, 1.0]),
    ];
    let f2 = [
        rx(p2, [c2, s2, 0.0]),
        rx(p2, [-s2, c2, 0.0]),
        rx(p2, [0.0, 0.0, 1.0]),
    ];
    [f1, f2]
}

/// The seven closure residuals of spec §4 (R3 from the returned i3, j3; p = returned rB), plus the
/// returned relative coordinates and θ31, θ32 recomputed from them; largest, relative to
/// max(a, |rB|).
pub fn closure_residual(alpha: f64, beta: f64, a: f64, p: &Value) -> f64 {
    let t1 = num(&p["theta1_deg"]);
    let t2 = num(&p["theta2_deg"]);
    let [[i1, j1, k1], [i2, j2, k2]] = shaft_frames(alpha, t1, t2);
    let rb = v3(&p["contact"]["rB_m"]);
    let i3 = v3(&p["frames"]["i3"]);
    let j3 = v3(&p["frames"]["j3"]);
    let k3 = v3(&p["frames"]["k3"]);
    let (a1, a2) = ([a, 0.0, 0.0], [-a, 0.0, 0.0]);
    let (sb, cb) = beta.to_radians().sin_cos();
    let n0 = [0.0, -cb, sb];
    let l = a.max(dot(rb, rb).sqrt());
    let mut r: Vec<f64> = vec![
        dot(i3, i1),
        dot(i3, k1),
        dot(sub(rb, a1), j1) / l,
        dot(j3, i2),
        dot(j3, k2),
        dot(sub(rb, a2), j2) / l,
        dot(n0, rb) / l,
        // Body 3 is a rigid frame: orthonormal, right-handed.
        dot(i3, j3),
        dot(i3, i3) - 1.0,
        dot(j3, j3) - 1.0,
        dot(sub(cross(i3, j3), k3), sub(cross(i3, j3), k3)).sqrt(),
    ];
    let r1 = &p["relative_1"];
    let r2 = &p["relative_2"];
    r.push((num(&r1["x1B_m"]) - dot(sub(rb, a1), i1)) / l);
    r.push((num(&r1["z1B_m"]) - dot(sub(rb, a1), k1)) / l);
    r.push((num(&r2["x2B_m"]) - dot(sub(rb, a2), i2)) / l);
    r.push((num(&r2["z2B_m"]) - dot(sub(rb, a2), k2)) / l);
    r.push(
        dang(
            num(&r1["theta31_deg"]),
            dot(k3, i1).atan2(dot(k3, k1)).to_degrees(),
        )
        .to_radians(),
    );
    r.push(
        dang(
            num(&r2["theta32_deg"]),
            dot(k3, i2).atan2(dot(k3, k2)).to_degrees(),
        )
        .to_radians(),
    );
    r.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Random configurations in the valid domain (valid support plane, min|D|/max|D| ≥ 1e-3).
pub fn random_config(rng: &mut ChaCha8Rng) -> (f64, f64, f64, i64, f64) {
    loop {
        let alpha: f64 = rng.random_range(-89.0..89.0);
        let beta: f64 = rng.random_range(-89.9..90.0);
        let (c2a, cm, cp) = (
            (2.0 * alpha).to_radians().cos(),
            (alpha - beta).to_radians().cos(),
            (alpha + beta).to_radians().cos(),
        );
        let (d0, d90) = (cm * c2a, cp);
        if c2a.abs() < 0.05
            || d0 * d90 <= 0.0
            || d0.abs().min(d90.abs()) < 1e-3 * d0.abs().max(d90.abs())
        {
            continue;
        }
        let a = 10f64.powf(rng.random_range(-3.0..3.0));
        let sigma = if rng.random_bool(0.5) { 1 } else { -1 };
        return (alpha, beta, a, sigma, rng.random_range(-720.0..720.0));
    }
}

/// The reference of [`fd_error`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Differences {
    /// Central differences at h = 1e-5 rad (spec §6).
    Central,
    /// Richardson extrapolation of the central differences at h and h/2 (truncation O(h⁴)
    /// instead of O(h²)): for random configurations, whose truncation error h²/6·f''' grows
    /// like 1/min|D|³ and passes 1e-6 near the sampled min|D|/max|D| = 1e-3.
    Extrapolated,
}

/// Largest |analytic − finite difference| over every rate of one configuration, relative to
/// the rate's scale, with h = 1e-5 rad. The returned positions at θ1 ± h (and θ1 ± h/2) are
/// further requests.
pub fn fd_error(
    (alpha, beta, a, sigma): (f64, f64, f64, i64),
    t: f64,
    omega1: f64,
    differences: Differences,
) -> f64 {
    let h_rad: f64 = 1e-5;
    let h = h_rad.to_degrees();
    let body = |th: f64| {
        answer(json!({
            "alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma, "omega1_rad_s": omega1,
            "theta1_deg": [th], "body3_points_m": [[0.3 * a, -0.2 * a, 0.5 * a]],
            "outputs": {"contact": true, "relative_1": true, "relative_2": true}
        }))["points"][0]
            .clone()
    };
    let c = body(t);
    // (answer at θ1 + s, at θ1 − s, input time between them at ω1) for s = h and, when
    // extrapolating, s = h/2.
    let fractions: &[f64] = match differences {
        Differences::Central => &[1.0],
        Differences::Extrapolated => &[1.0, 0.5],
    };
    let steps: Vec<(Value, Value, f64)> = fractions
        .iter()
        .map(|f| (body(t + f * h), body(t - f * h), 2.0 * f * h_rad / omega1))
        .collect();
    let combine = |d: &dyn Fn(&Value, &Value) -> f64| match steps.as_slice() {
        [(p, m, dt), (p2, m2, dt2)] => (4.0 * d(p2, m2) / dt2 - d(p, m) / dt) / 3.0,
        [(p, m, dt), ..] => d(p, m) / dt,
        [] => f64::NAN,
    };
    let fd = |f: &dyn Fn(&Value) -> f64| combine(&|p, m| f(p) - f(m));
    let fd_angle = |f: &dyn Fn(&Value) -> f64| combine(&|p, m| dang(f(p), f(m)).to_radians());
    let mut worst: f64 = 0.0;
    let mut cmp = |analytic: f64, numeric: f64, scale: f64| {
        worst = worst.max((analytic - numeric).abs() / scale);
    };
    let w = omega1.abs();
    cmp(
        num(&c["omega2_rad_s"]),
        fd_angle(&|v| num(&v["theta2_deg"])),
        w,
    );
    cmp(
        num(&c["epsilon2_rad_s2"]),
        fd(&|v| num(&v["omega2_rad_s"])),
        w * w,
    );
    for k in 0..3 {
        cmp(
            num(&c["contact"]["vB_m_s"][k]),
            fd(&|v| num(&v["contact"]["rB_m"][k])),
            a * w,
        );
        cmp(
            num(&c["body3_points"][0]["v0_m_s"][k]),
            fd(&|v| num(&v["body3_points"][0]["r0_m"][k])),
            a * w,
        );
        cmp(
            num(&c["body3_points"][0]["v1_m_s"][k]),
            fd(&|v| num(&v["body3_points"][0]["r1_m"][k])),
            a * w,
        );
        cmp(
            num(&c["body3_points"][0]["v2_m_s"][k]),
            fd(&|v| num(&v["body3_points"][0]["r2_m"][k])),
            a * w,
        );
    }
    for (g, x, z, vx, vz, th, om) in [
        (
            "relative_1",
            "x1B_m",
            "z1B_m",
            "vx1B_m_s",
            "vz1B_m_s",
            "theta31_deg",
            "omega31_rad_s",
        ),
        (
            "relative_2",
            "x2B_m",
            "z2B_m",
            "vx2B_m_s",
            "vz2B_m_s",
            "theta32_deg",
            "omega32_rad_s",
        ),
    ] {
        cmp(num(&c[g][vx]), fd(&|v| num(&v[g][x])), a * w);
        cmp(num(&c[g][vz]), fd(&|v| num(&v[g][z])), a * w);
        cmp(num(&c[g][om]), fd_angle(&|v| num(&v[g][th])), w);
    }
    worst
}
