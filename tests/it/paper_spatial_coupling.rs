//! Validation cases of the spatial-coupling spec (`shared/specs/spatial_coupling.md` §6), driven
//! through the public entry point `run`, and the independent checks of the issue: loop closure of
//! the returned configuration (the 7 equations of spec §4, evaluated here from the returned angles
//! and point with frames built in this file) and the returned rates against central differences
//! of the returned positions.
//!
//! Tolerances. The spec's golden table prints 8 decimals (angles 6): checked at half a unit of the
//! last printed digit (5e-9, angles 5e-7 deg) — the spec's own "1e-9 (angles 1e-7)" is tighter
//! than its printed digits allow (e.g. i12 = −1.15470054 is 1.6e-9 from −1.1547005383792515), so
//! the full-precision reference below (an independent vector implementation of §3.1–3.4 with
//! frames, dot products and the four-quadrant angles of the spec, not the reduced forms of the
//! module) is checked at 1e-12, the closed-form tolerance of the issue.

#![allow(
    clippy::suboptimal_flops,
    reason = "test arithmetic follows the spec's formulas; mul_add gains nothing here"
)]
#![allow(
    clippy::approx_constant,
    reason = "the tables are the spec's printed values and an independent reference, not constants"
)]
#![allow(
    clippy::needless_range_loop,
    reason = "vector components compared index by index against their reference"
)]

use crate::support::spatial_coupling::{
    Differences, answer, close, close_angle, closure_residual, dang, fd_error, num, random_config,
    v3,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// Half a unit of the 8th decimal (the golden table's lengths, ratios, rates).
const PRINTED_8: f64 = 5e-9;
/// Half a unit of the 6th decimal (the golden table's angles in degrees).
const PRINTED_6: f64 = 5e-7;
/// Closed forms against the independent reference.
const EXACT: f64 = 1e-12;

/// Everything of one point (all groups on).
fn point(alpha: f64, beta: f64, a: f64, sigma: i64, theta1: f64) -> Value {
    let b = answer(json!({
        "alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma, "theta1_deg": [theta1],
        "outputs": {"contact": true, "relative_1": true, "relative_2": true, "frames": true, "check": true}
    }));
    b["points"][0].clone()
}

/// Golden points as printed in spec §6 (a = 1 unless said, σ = +1; rates per unit ω1).
struct Golden {
    case: (f64, f64, f64, i64, f64),
    theta2: f64,
    i12: f64,
    rb: [f64; 3],
    x1z1: [f64; 2],
    x2z2: [f64; 2],
    th31: f64,
    w31: f64,
    th32: f64,
    w32: f64,
    vb: f64,
}

#[rustfmt::skip]
const GOLDEN: &[Golden] = &[
    Golden { case: (15.0, 15.0, 1.0, 1, 0.0), theta2: 90.0, i12: -1.154_700_54, rb: [-1.0, 0.0, 0.0], x1z1: [-2.0, 0.0], x2z2: [0.0, 0.0], th31: 0.0, w31: -0.577_350_27, th32: 210.0, w32: 0.0, vb: 2.0 },
    Golden { case: (15.0, 15.0, 1.0, 1, 30.0), theta2: 56.309_932, i12: -1.065_877_42, rb: [-0.5, -0.224_143_87, -0.836_516_30], x1z1: [-1.732_050_81, 0.0], x2z2: [0.901_387_82, -0.433_012_70], th31: 343.897_886, w31: -0.461_538_46, th32: 205.658_906, w32: -0.277_350_10, vb: 2.0 },
    Golden { case: (15.0, 15.0, 1.0, 1, 90.0), theta2: 0.0, i12: -0.866_025_40, rb: [1.0, 0.0, 0.0], x1z1: [0.0, 0.0], x2z2: [2.0, 0.0], th31: 330.0, w31: 0.0, th32: 180.0, w32: -0.5, vb: 2.0 },
    Golden { case: (15.0, 15.0, 1.0, 1, 135.0), theta2: 319.106_605, i12: -0.989_743_32, rb: [0.0, 0.258_819_05, 0.965_925_83], x1z1: [1.414_213_56, 0.0], x2z2: [1.322_875_66, 0.5], th31: 337.792_346, w31: 0.349_927_11, th32: 159.295_189, w32: -0.377_964_47, vb: 2.0 },
    Golden { case: (15.0, 15.0, 1.0, 1, 200.0), theta2: 247.204_123, i12: -1.111_365_52, rb: [-0.766_044_44, -0.166_365_68, -0.620_885_15], x1z1: [1.879_385_24, 0.0], x2z2: [-0.603_835_36, -0.321_393_80], th31: 11.170_229, w31: 0.522_170_99, th32: 151.975_679, w32: 0.193_724_63, vb: 2.0 },
    Golden { case: (15.0, 5.0, 1.0, 1, 30.0), theta2: 56.309_932, i12: -1.065_877_42, rb: [-0.462_771_57, -0.074_741_26, -0.854_296_55], x1z1: [-1.689_063_13, -0.148_913_70], x2z2: [0.968_502_32, -0.293_302_73], th31: 343.897_886, w31: -0.461_538_46, th32: 205.658_906, w32: -0.277_350_10, vb: 2.033_114_83 },
    Golden { case: (15.0, 5.0, 1.0, 1, 90.0), theta2: 0.0, i12: -0.866_025_40, rb: [1.0, 0.0, 0.0], x1z1: [0.0, 0.0], x2z2: [2.0, 0.0], th31: 330.0, w31: 0.0, th32: 180.0, w32: -0.5, vb: 1.843_209_97 },
    Golden { case: (30.0, 30.0, 0.05, 1, 120.0), theta2: 343.897_886, i12: -0.615_384_62, rb: [0.025, 0.021_650_64, 0.0375], x1z1: [0.05, 0.0], x2z2: [0.078_062_47, 0.0375], th31: 303.690_068, w31: 0.266_469_36, th32: 154.341_094, w32: -0.832_050_29, vb: 0.1 },
];

#[test]
fn golden_points_of_spec_section_6_at_printed_digits() {
    for g in GOLDEN {
        let (alpha, beta, a, sigma, t) = g.case;
        let p = point(alpha, beta, a, sigma, t);
        let w = format!("α={alpha} β={beta} a={a} θ1={t}");
        close_angle(
            num(&p["theta2_deg"]),
            g.theta2,
            PRINTED_6,
            &format!("{w} θ2"),
        );
        close(num(&p["i12"]), g.i12, PRINTED_8, &format!("{w} i12"));
        let rb = v3(&p["contact"]["rB_m"]);
        for k in 0..3 {
            close(rb[k], g.rb[k], PRINTED_8, &format!("{w} rB[{k}]"));
        }
        close(
            num(&p["relative_1"]["x1B_m"]),
            g.x1z1[0],
            PRINTED_8,
            &format!("{w} x1B"),
        );
        close(
            num(&p["relative_1"]["z1B_m"]),
            g.x1z1[1],
            PRINTED_8,
            &format!("{w} z1B"),
        );
        close(
            num(&p["relative_2"]["x2B_m"]),
            g.x2z2[0],
            PRINTED_8,
            &format!("{w} x2B"),
        );
        close(
            num(&p["relative_2"]["z2B_m"]),
            g.x2z2[1],
            PRINTED_8,
            &format!("{w} z2B"),
        );
        close_angle(
            num(&p["relative_1"]["theta31_deg"]),
            g.th31,
            PRINTED_6,
            &format!("{w} θ31"),
        );
        close(
            num(&p["relative_1"]["omega31_rad_s"]),
            g.w31,
            PRINTED_8,
            &format!("{w} ω31"),
        );
        close_angle(
            num(&p["relative_2"]["theta32_deg"]),
            g.th32,
            PRINTED_6,
            &format!("{w} θ32"),
        );
        close(
            num(&p["relative_2"]["omega32_rad_s"]),
            g.w32,
            PRINTED_8,
            &format!("{w} ω32"),
        );
        close(
            num(&p["contact"]["vB_mag"]),
            g.vb,
            PRINTED_8,
            &format!("{w} |vB|"),
        );
        // Single points report angles in [0°, 360°).
        for ang in [
            &p["theta2_deg"],
            &p["relative_1"]["theta31_deg"],
            &p["relative_2"]["theta32_deg"],
        ] {
            assert!(
                (0.0..360.0).contains(&num(ang)),
                "{w}: {ang} outside [0, 360)"
            );
        }
    }
}

/// The golden point θ1 = 0 writes θ31 as 0, never −0 or 360 (degree trig is exact there).
#[test]
fn theta31_at_zero_is_plain_zero() {
    let p = point(15.0, 15.0, 1.0, 1, 0.0);
    let t = num(&p["relative_1"]["theta31_deg"]);
    assert_eq!(t.to_bits(), 0f64.to_bits(), "θ31(0) = {t}");
    // Exact: the trig of 0° and 90° is exact in degrees.
    assert_eq!(num(&p["theta2_deg"]).to_bits(), 90f64.to_bits(), "θ2(0)");
    assert_eq!(
        num(&p["relative_2"]["theta32_deg"]).to_bits(),
        210f64.to_bits(),
        "θ32(0)"
    );
}

/// Full-precision reference (independent implementation, see the file docs).
struct Ref {
    alpha: f64,
    beta: f64,
    a: f64,
    sigma: i64,
    theta1: f64,
    theta2: f64,
    i12: f64,
    di12: f64,
    rb: [f64; 3],
    vb: [f64; 3],
    x1: f64,
    z1: f64,
    vx1: f64,
    vz1: f64,
    x2: f64,
    z2: f64,
    vx2: f64,
    vz2: f64,
    th31: f64,
    w31: f64,
    th32: f64,
    w32: f64,
}

#[rustfmt::skip]
const REFERENCE: &[Ref] = &[
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: 1, theta1: 0.0, theta2: 90.0, i12: -1.1547005383792515, di12: 0.0, rb: [-1.0, -0.0, -0.0], vb: [0.0, -0.5176380902050415, -1.9318516525781364], x1: -2.0, z1: 0.0, vx1: 0.0, vz1: 5.551115123125783e-17, x2: 0.0, z2: 0.0, vx2: 1.7320508075688772, vz2: -0.9999999999999998, th31: 0.0, w31: -0.5773502691896256, th32: 210.0, w32: -0.0 },
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: 1, theta1: 30.0, theta2: 56.30993247402022, i12: -1.0658774200423862, di12: 0.28402366863905315, rb: [-0.5000000000000002, -0.22414386804201333, -0.8365163037378079], vb: [1.7320508075688772, -0.2588190451025208, -0.9659258262890685], x1: -1.7320508075688774, z1: -2.7755575615628914e-17, vx1: 0.9999999999999998, vz1: 0.0, x2: 0.9013878188659973, z2: -0.4330127018922193, vx2: 1.6813456149534152, vz2: -0.5000000000000001, th31: 343.897886248014, w31: -0.46153846153846156, th32: 205.65890627325527, w32: -0.2773500981126145 },
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: 1, theta1: 90.0, theta2: 3.0383242517508457e-15, i12: -0.8660254037844387, di12: 2.6514380968122667e-17, rb: [1.0, -3.169619151431765e-17, -1.1829179713786698e-16], vb: [2.4492935982947064e-16, 0.5176380902050415, 1.9318516525781364], x1: -1.2246467991473532e-16, z1: 0.0, vx1: 2.0, vz1: -5.551115123125783e-17, x2: 2.0, z2: -6.123233995736766e-17, vx2: 1.5308084989341913e-16, vz2: 0.9999999999999998, th31: 330.0, w31: -2.651438096812267e-17, th32: 180.0, w32: -0.49999999999999994 },
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: 1, theta1: 135.0, theta2: 319.1066053508691, i12: -0.989743318610787, di12: -0.2827838053173676, rb: [1.922962686383564e-16, 0.2588190451025208, 0.9659258262890684], vb: [-2.0000000000000004, 9.508857454295294e-17, 3.54875391413601e-16], x1: 1.414213562373095, z1: -5.551115123125783e-17, vx1: 1.4142135623730954, vz1: 1.232595164407831e-32, x2: 1.3228756555322954, z2: 0.5, vx2: -1.511857892036909, vz2: 1.8369701987210297e-16, th31: 337.7923457014035, w31: 0.3499271061118825, th32: 159.29518894536457, w32: -0.37796447300922714 },
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: 1, theta1: 200.0, theta2: 247.20412274114153, i12: -1.1113655153714046, di12: 0.22918738402782224, rb: [-0.7660444431189782, -0.16636567534280186, -0.6208851530148455], vb: [1.2855752193730783, -0.39653378254829236, -1.4798842233876965], x1: 1.879385241571817, z1: -2.7755575615628914e-17, vx1: -0.684040286651337, vz1: -1.1102230246251565e-16, x2: -0.6038353550185763, z2: -0.3213938048432695, vx2: -1.721285897689862, vz2: -0.7660444431189781, th31: 11.170229433078788, w31: 0.5221709868952185, th32: 151.97567932639532, w32: 0.19372462620528774 },
    Ref { alpha: 15.0, beta: 5.0, a: 1.0, sigma: 1, theta1: 30.0, theta2: 56.30993247402022, i12: -1.0658774200423862, di12: 0.28402366863905315, rb: [-0.46277157486728954, -0.07474126333742442, -0.85429654912122], vb: [1.8148254452139645, -0.079877869612333, -0.9130082275021171], x1: -1.689063125025125, z1: -0.1489137005308423, vx1: 1.1203988687414037, vz1: -0.15914782040533976, x2: 0.9685023167263773, z2: -0.2933027336250234, vx2: 1.7232659733817788, vz2: -0.31346001482034613, th31: 343.897886248014, w31: -0.46153846153846156, th32: 205.65890627325527, w32: -0.2773500981126145 },
    Ref { alpha: 15.0, beta: 5.0, a: 1.0, sigma: 1, theta1: 90.0, theta2: 3.0383242517508457e-15, i12: -0.8660254037844387, di12: 2.6514380968122667e-17, rb: [1.0, -9.836750936017385e-18, -1.1243457768791532e-16], vb: [2.222988016816668e-16, 0.16064633399386852, 1.8361959997967847], x1: -1.111494008408334e-16, z1: -1.959863825781907e-17, vx1: 1.8152074690959048, vz1: 0.3200700523851351, x2: 2.0, z2: -3.860178180956379e-17, vx2: 1.304502917456153e-16, vz2: 0.6304149381918093, th31: 330.0, w31: -2.651438096812267e-17, th32: 180.0, w32: -0.49999999999999994 },
    Ref { alpha: 30.0, beta: 30.0, a: 0.05, sigma: 1, theta1: 120.0, theta2: 343.897886248014, i12: -0.6153846153846154, di12: -0.49194342463494706, rb: [0.025000000000000015, 0.02165063509461096, 0.0375], vb: [-0.08660254037844385, 0.02500000000000002, 0.04330127018922198], x1: 0.04999999999999999, z1: 0.0, vx1: 0.08660254037844389, vz1: 3.469446951953614e-18, x2: 0.07806247497997998, z2: 0.03749999999999999, vx2: -0.07627127698096897, vz2: 0.043301270189221974, th31: 303.69006752597977, w31: 0.26646935501059643, th32: 154.34109372674476, w32: -0.8320502943378436 },
    // σ = −1: ω32 = −σ·sin2α·s1/ρ, the rate of θ32 (spec §3.4 drops σ; see other_assembly_mode).
    Ref { alpha: 15.0, beta: 15.0, a: 1.0, sigma: -1, theta1: 30.0, theta2: 236.30993247402023, i12: -1.0658774200423862, di12: 0.28402366863905315, rb: [-0.5000000000000002, -0.22414386804201333, -0.8365163037378079], vb: [1.7320508075688772, -0.2588190451025208, -0.9659258262890685], x1: -1.7320508075688774, z1: -2.7755575615628914e-17, vx1: 0.9999999999999998, vz1: 0.0, x2: -0.9013878188659973, z2: -0.4330127018922193, vx2: -1.6813456149534152, vz2: -0.5000000000000001, th31: 163.897886248014, w31: -0.46153846153846156, th32: 334.3410937267447, w32: 0.2773500981126145 },
];

#[test]
fn closed_forms_match_the_independent_reference_to_1e_12() {
    let mut worst: f64 = 0.0;
    for r in REFERENCE {
        let p = point(r.alpha, r.beta, r.a, r.sigma, r.theta1);
        let w = format!("α={} β={} σ={} θ1={}", r.alpha, r.beta, r.sigma, r.theta1);
        // Lengths relative to a, rates per unit ω1 = 1.
        let s = r.a;
        let mut chk = |got: f64, want: f64, scale: f64, what: &str| {
            let e = (got - want).abs() / scale;
            worst = worst.max(e);
            assert!(
                e <= EXACT,
                "{w} {what}: got {got:.17e}, want {want:.17e}, rel {e:e}"
            );
        };
        chk(dang(num(&p["theta2_deg"]), r.theta2), 0.0, 360.0, "θ2");
        chk(num(&p["i12"]), r.i12, 1.0, "i12");
        chk(num(&p["di12_dtheta1"]), r.di12, 1.0, "di12");
        chk(num(&p["omega2_rad_s"]), r.i12, 1.0, "ω2");
        let rb = v3(&p["contact"]["rB_m"]);
        let vb = v3(&p["contact"]["vB_m_s"]);
        for k in 0..3 {
            chk(rb[k], r.rb[k], s, "rB");
            chk(vb[k], r.vb[k], s, "vB");
        }
        let r1 = &p["relative_1"];
        let r2 = &p["relative_2"];
        chk(num(&r1["x1B_m"]), r.x1, s, "x1B");
        chk(num(&r1["z1B_m"]), r.z1, s, "z1B");
        chk(num(&r1["vx1B_m_s"]), r.vx1, s, "vx1B");
        chk(num(&r1["vz1B_m_s"]), r.vz1, s, "vz1B");
        chk(num(&r2["x2B_m"]), r.x2, s, "x2B");
        chk(num(&r2["z2B_m"]), r.z2, s, "z2B");
        chk(num(&r2["vx2B_m_s"]), r.vx2, s, "vx2B");
        chk(num(&r2["vz2B_m_s"]), r.vz2, s, "vz2B");
        chk(dang(num(&r1["theta31_deg"]), r.th31), 0.0, 360.0, "θ31");
        chk(num(&r1["omega31_rad_s"]), r.w31, 1.0, "ω31");
        chk(dang(num(&r2["theta32_deg"]), r.th32), 0.0, 360.0, "θ32");
        chk(num(&r2["omega32_rad_s"]), r.w32, 1.0, "ω32");
    }
    eprintln!("worst deviation from the independent reference: {worst:e}");
}

/// Spec §6: σ = −1 flips x2B, shifts θ2, θ31, θ32 by 180°, leaves rB, i12, ω31, ω32; di12/dθ1.
#[test]
fn other_assembly_mode_and_di12() {
    let p = point(15.0, 15.0, 1.0, -1, 30.0);
    close_angle(num(&p["theta2_deg"]), 236.309_932, PRINTED_6, "θ2 σ=−1");
    close(
        num(&p["relative_2"]["x2B_m"]),
        -0.901_387_82,
        PRINTED_8,
        "x2B σ=−1",
    );
    close_angle(
        num(&p["relative_1"]["theta31_deg"]),
        163.897_886,
        PRINTED_6,
        "θ31 σ=−1",
    );
    close_angle(
        num(&p["relative_2"]["theta32_deg"]),
        334.341_094,
        PRINTED_6,
        "θ32 σ=−1",
    );
    let q = point(15.0, 15.0, 1.0, 1, 30.0);
    for k in ["i12", "di12_dtheta1"] {
        close(num(&p[k]), num(&q[k]), EXACT, k);
    }
    for k in 0..3 {
        close(
            num(&p["contact"]["rB_m"][k]),
            num(&q["contact"]["rB_m"][k]),
            EXACT,
            "rB",
        );
    }
    close(
        num(&p["relative_1"]["omega31_rad_s"]),
        num(&q["relative_1"]["omega31_rad_s"]),
        EXACT,
        "ω31",
    );
    // Spec §3.4/§6 say ω32 is unchanged by σ; the rate of the returned θ32 (which the golden
    // table confirms: 334.341094 for σ = −1) is −σ·sin2α·s1/ρ, and the vector ω32·j2 — the
    // physical relative rotation, the same in both modes since j2 flips with σ — is unchanged.
    // The deciding properties: ω32 = dθ32/dt (tested against central differences) and
    // ω1 k1 + ω31 j1 = ω2 k2 + ω32 j2 (tests/slow/props_spatial_coupling.rs).
    close(
        num(&p["relative_2"]["omega32_rad_s"]),
        -num(&q["relative_2"]["omega32_rad_s"]),
        EXACT,
        "ω32 flips with σ",
    );
    let fd = crate::support::spatial_coupling::fd_error(
        (15.0, 15.0, 1.0, -1),
        30.0,
        1.0,
        Differences::Central,
    );
    assert!(fd < 1e-8, "σ = −1 rates vs central differences: {fd:e}");
    close(
        num(&q["di12_dtheta1"]),
        0.284_023_67,
        PRINTED_8,
        "di12 at 30°",
    );
    close(
        num(&point(15.0, 15.0, 1.0, 1, 60.0)["di12_dtheta1"]),
        0.213_333_33,
        PRINTED_8,
        "di12 at 60°",
    );
}

/// A 3600-point sweep of the paper-like case (α = β = 15°, a = 1): the statements of spec §6.
fn paper_sweep(alpha: f64) -> Value {
    answer(json!({
        "alpha_deg": alpha, "sweep": {"start_deg": 0, "end_deg": 360, "n_points": 3601},
        "outputs": {"contact": true, "relative_1": true, "relative_2": true, "series": true}
    }))
}

#[test]
#[expect(
    clippy::too_many_lines,
    reason = "the paper's statements over one 3601-point revolution checked in sequence on the one computed answer (ratios, signs, oscillation, sign changes, lemniscate boxes)"
)]
fn paper_statements_over_a_revolution() {
    let b = paper_sweep(15.0);
    let s = &b["summary"];
    let c2a = 30f64.to_radians().cos();
    close(
        num(&s["ratio_range_abs"][0]),
        c2a,
        EXACT,
        "|i12| min = cos 2α",
    );
    close(
        num(&s["ratio_range_abs"][1]),
        1.0 / c2a,
        EXACT,
        "|i12| max = 1/cos 2α",
    );
    assert!(num(&s["i12_max"]) < 0.0, "i12 < 0");
    close(
        num(&s["fluctuation"]),
        30f64.to_radians().sin() * 30f64.to_radians().tan(),
        EXACT,
        "δ",
    );
    assert!(!s["homokinetic"].as_bool().expect("bool"));
    for k in 0..2 {
        close(num(&s["rB_radius_range_m"][k]), 1.0, EXACT, "|rB| ≡ a");
        close(num(&s["vB_range_m_s"][k]), 2.0, EXACT, "|vB| ≡ 2aω1");
    }
    close(
        num(&s["lemniscate_box_m"]["x"][1]) - num(&s["lemniscate_box_m"]["x"][0]),
        4.0,
        EXACT,
        "box 4a",
    );
    close(
        num(&s["lemniscate_box_m"]["z"][1]) - num(&s["lemniscate_box_m"]["z"][0]),
        1.0,
        EXACT,
        "box 1a",
    );
    close(
        num(&s["theta31_amplitude_deg"]),
        30.0,
        1e-10,
        "θ31 amplitude 2α",
    );
    close(
        num(&s["theta32_amplitude_deg"]),
        30.0,
        1e-10,
        "θ32 amplitude 2α",
    );
    close(
        num(&s["omega31_max_abs"]),
        30f64.to_radians().tan(),
        EXACT,
        "max|ω31| = tan 2α",
    );
    close(num(&s["omega32_max_abs"]), 0.5, EXACT, "max|ω32| = sin 2α");
    close(
        num(&s["D_min_over_max"]),
        1.0,
        EXACT,
        "D constant for β = α",
    );
    let series = b["series"].as_array().expect("series");
    assert_eq!(series.len(), 3601);
    let (mut x1_lo, mut x1_hi, mut z1_max) = (f64::INFINITY, f64::NEG_INFINITY, 0f64);
    let (mut th31_lo, mut th31_hi, mut th32_lo, mut th32_hi) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let (mut w31_signs, mut w32_signs) = (Vec::new(), Vec::new());
    for p in series {
        let r1 = &p["relative_1"];
        let r2 = &p["relative_2"];
        let x1 = num(&r1["x1B_m"]);
        x1_lo = x1_lo.min(x1);
        x1_hi = x1_hi.max(x1);
        z1_max = z1_max.max(num(&r1["z1B_m"]).abs());
        let (t31, t32) = (num(&r1["theta31_deg"]), num(&r2["theta32_deg"]));
        th31_lo = th31_lo.min(t31);
        th31_hi = th31_hi.max(t31);
        th32_lo = th32_lo.min(t32);
        th32_hi = th32_hi.max(t32);
        let (w31, w32) = (num(&r1["omega31_rad_s"]), num(&r2["omega32_rad_s"]));
        // Signs of the nonzero values (the rates are exactly 0 at multiples of 90°).
        if w31 != 0.0 {
            w31_signs.push(w31 > 0.0);
        }
        if w32 != 0.0 {
            w32_signs.push(w32 > 0.0);
        }
    }
    assert!(z1_max <= 1e-15, "z1B ≡ 0: {z1_max:e}");
    close(x1_lo, -2.0, EXACT, "x1B min −2a");
    close(x1_hi, 2.0, EXACT, "x1B max 2a");
    // The sweep starts at θ31 = 0 (first value in [0°, 360°)), oscillating ±30° about it.
    close(th31_lo, -30.0, 1e-10, "θ31 min");
    close(th31_hi, 30.0, 1e-10, "θ31 max");
    close(th32_lo, 150.0, 1e-10, "θ32 min");
    close(th32_hi, 210.0, 1e-10, "θ32 max");
    // Sign changes per (periodic) revolution: twice each (body 3 oscillates about both shafts).
    let cyclic = |v: &[bool]| {
        (0..v.len())
            .filter(|&i| v[i] != v[(i + 1) % v.len()])
            .count()
    };
    assert_eq!(
        cyclic(&w31_signs),
        2,
        "ω31 changes sign twice per revolution"
    );
    assert_eq!(
        cyclic(&w32_signs),
        2,
        "ω32 changes sign twice per revolution"
    );
    // Lemniscate boxes of spec §6 for other α: 4a × 2a sin 2α.
    for (alpha, h) in [(10.0, 0.684), (20.0, 1.286), (30.0, 1.732)] {
        let s = &paper_sweep(alpha)["summary"];
        let hz = num(&s["lemniscate_box_m"]["z"][1]) - num(&s["lemniscate_box_m"]["z"][0]);
        assert!((hz - h).abs() < 5e-4, "α = {alpha}: box height {hz} vs {h}");
        close(
            hz,
            2.0 * (2.0 * alpha).to_radians().sin(),
            EXACT,
            "box height 2a sin 2α",
        );
    }
}

/// Erratum 1: the single-argument Eq. (21) θ2 = atan(cos2α / tan θ1) agrees with the returned θ2
/// on (0°, 180°) and is off by exactly 180° on (180°, 360°); the returned two-argument θ2 only
/// wraps by 360° at θ1 = 90° (single points) and is continuous along a sweep.
#[test]
fn eq21_jumps_by_pi_the_two_argument_form_does_not() {
    let c2a = 30f64.to_radians().cos();
    for i in 1..360 {
        let t = f64::from(i) + 0.5;
        let p = answer(json!({"alpha_deg": 15, "theta1_deg": [t]}));
        let th2 = num(&p["points"][0]["theta2_deg"]);
        let eq21 = (c2a / t.to_radians().tan()).atan().to_degrees();
        let want = if t < 180.0 { 0.0 } else { 180.0 };
        assert!(
            (dang(th2, eq21).abs() - want).abs() < 1e-9,
            "θ1 = {t}: θ2 {th2}, Eq. (21) {eq21}"
        );
    }
    let s = paper_sweep(15.0);
    let th: Vec<f64> = s["series"]
        .as_array()
        .expect("series")
        .iter()
        .map(|p| num(&p["theta2_deg"]))
        .collect();
    assert!(
        th.windows(2).all(|w| (w[1] - w[0]).abs() < 0.2),
        "continuous along the sweep"
    );
    close(th[0], 90.0, EXACT, "θ2(0)");
    close(
        th[th.len() - 1],
        -270.0,
        EXACT,
        "θ2(360) = θ2(0) − 360 (one output turn, −z2 sense)",
    );
}

// ---------------------------------------------------------------------------------------------
// Independent check 1: loop closure of the returned configuration (spec §4's seven equations)
// ---------------------------------------------------------------------------------------------

#[test]
fn loop_closure_of_the_returned_configuration() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let mut worst: f64 = 0.0;
    let mut worst_check: f64 = 0.0;
    for _ in 0..2000 {
        let (alpha, beta, a, sigma, t) = random_config(&mut rng);
        let p = point(alpha, beta, a, sigma, t);
        let r = closure_residual(alpha, beta, a, &p);
        assert!(
            r < 1e-12,
            "α={alpha} β={beta} a={a} σ={sigma} θ1={t}: closure residual {r:e}"
        );
        worst = worst.max(r);
        worst_check = worst_check.max(num(&p["check"]["max_residual"]));
    }
    assert!(
        worst_check < 1e-12,
        "the module's own check: {worst_check:e}"
    );
    eprintln!(
        "closure residual over 2000 random configurations: {worst:e} (module check {worst_check:e})"
    );
}

// ---------------------------------------------------------------------------------------------
// Independent check 2: rates against central differences of the returned positions
// ---------------------------------------------------------------------------------------------

#[test]
fn rates_match_central_differences_of_positions() {
    let mut rng = ChaCha8Rng::seed_from_u64(1414);
    let mut worst: f64 = 0.0;
    for i in 0..200 {
        let (alpha, beta, a, sigma, t) = random_config(&mut rng);
        let omega1 = if i % 2 == 0 {
            1.0
        } else {
            rng.random_range(-50.0..50.0)
        };
        let e = fd_error(
            (alpha, beta, a, sigma),
            t,
            omega1,
            Differences::Extrapolated,
        );
        // The plain difference's truncation h²/6·f''' grows with 1/|cos 2α|³ and 1/min|D|³ and
        // passes 1e-6 near the sampled min|D|/max|D| = 1e-3: compare with the Richardson
        // extrapolation of h and h/2 (O(h⁴)), whose own error is far below the bound.
        assert!(
            e < 1e-6,
            "α={alpha} β={beta} a={a} σ={sigma} θ1={t} ω1={omega1}: FD error {e:e}"
        );
        worst = worst.max(e);
    }
    eprintln!("worst rate vs extrapolated central differences (h = 1e-5 rad, h/2): {worst:e}");
    // The spec's bound (< 1e-8) on its own validation cases.
    for r in REFERENCE {
        let e = fd_error(
            (r.alpha, r.beta, r.a, r.sigma),
            r.theta1 + 7.0,
            1.0,
            Differences::Central,
        );
        assert!(
            e < 1e-8,
            "α={} β={} θ1={}: FD error {e:e}",
            r.alpha,
            r.beta,
            r.theta1 + 7.0
        );
    }
}

/// The answer to `body` with the job allowed `threads` threads, serialized (the elapsed time
/// zeroed).
fn answer_on(body: &Value, threads: usize) -> String {
    use mechcalc::calc::spatial_coupling::{SpatialCouplingRequest, run};
    use mechcalc::numerics::Budget;
    let req: SpatialCouplingRequest = serde_json::from_value(body.clone()).expect("valid request");
    let mut v = serde_json::to_value(
        run(req, &Budget::unlimited().with_threads(threads)).expect("request succeeds"),
    )
    .expect("serializes");
    v["report"]["elapsed_ms"] = json!(0);
    serde_json::to_string(&v).expect("serializes")
}

/// Large sweeps are split over the job's threads in chunks; the answer (series and summary,
/// reduced in chunk order) is byte for byte the same for any number of threads.
#[test]
fn sweep_answers_do_not_depend_on_thread_count() {
    let bodies = [
        json!({"alpha_deg": 15, "beta_deg": 5, "sweep": {"start_deg": -30, "end_deg": 750, "n_points": 100_001},
               "outputs": {"summary": true}}),
        json!({"alpha_deg": 30, "beta_deg": 10, "branch": -1, "a_m": 0.07, "omega1_rad_s": 3,
               "sweep": {"start_deg": 0, "end_deg": 360, "n_points": 20_001},
               "body3_points_m": [[0.01, 0.02, 0.03]],
               "outputs": {"contact": true, "relative_1": true, "relative_2": true, "frames": true,
                           "check": true, "summary": true, "series": true, "decimate": 7}}),
        json!({"alpha_deg": 15, "beta_deg": 15, "sweep": {"start_deg": 0, "end_deg": 360, "n_points": 30_001},
               "outputs": {"contact": true, "summary": false, "series": true, "decimate": 1000}}),
    ];
    for body in &bodies {
        let one = answer_on(body, 1);
        for threads in [2, 3] {
            assert!(answer_on(body, threads) == one, "{threads} threads: {body}");
        }
    }
}
