//! Property tests of the 7-segment law (spec §5.5 items 1–6) plus renormalization invariance
//! and order independence of the grid evaluator. Random coefficients with some exact zeros,
//! random boundary conditions and intervals. `PROPTEST_CASES` scales the run.

// Reference expressions are written as in the spec.
#![allow(clippy::suboptimal_flops)]

use crate::support::cam_law_strategies::{coefficients, scaled_conditions};
use mechcalc::calc::cam_law::catalogue::{NamedLaw, TABLE3};
use mechcalc::calc::cam_law::law::{
    BoundaryConditions, Quantity, SevenSegmentLaw, accelerations_centroid, accelerations_cramer,
};
use proptest::prelude::*;

/// Boundary conditions with log-uniform Δt in [1e-2, 1e2], Δs of either sign (or 0) up to 1e2,
/// end rates up to a few times the natural scales Δs/Δt, Δs/Δt².
fn boundary_conditions() -> impl Strategy<Value = BoundaryConditions> {
    scaled_conditions(prop_oneof![1 => Just(0.0), 6 => -100.0f64..100.0], 3.0, 1.0)
}

/// Zero end rates (for the scaling property).
fn zero_rate_bc() -> impl Strategy<Value = BoundaryConditions> {
    (
        -100.0f64..100.0,
        -2.0f64..2.0,
        -100.0f64..100.0,
        prop_oneof![-100.0f64..-0.01, 0.01f64..100.0],
    )
        .prop_map(|(t_a, log_dt, s_a, ds)| {
            let dt = 10f64.powf(log_dt);
            BoundaryConditions {
                t_b: t_a + dt,
                s_a,
                s_b: s_a + ds,
                t_a,
                ..BoundaryConditions::UNIT_RISE
            }
        })
}

/// Natural scales of a law: (s, v, a) magnitudes used to state relative tolerances.
fn scales(law: &SevenSegmentLaw) -> (f64, f64, f64) {
    let bc = law.bc();
    let p = law.peaks();
    let dt = bc.t_b - bc.t_a;
    let a = p.a_max_abs.max(bc.a_a.abs()).max(bc.a_b.abs());
    let v = p.v_max_abs.max(a * dt);
    let s = bc.s_a.abs().max(bc.s_b.abs()).max(v * dt);
    (s, v, a)
}

/// Bounds of |ds/dx|, |dv/dx|, |da/dx|, |dj/dx| and the rounding of abscissae near the
/// interval (`4·eps·max(|t_a|, |t_b|)`): evaluating at a rounded abscissa moves each quantity by
/// up to (its slope) × (that rounding). With `t_a` far from 0 and a short Δt this term dominates
/// the spec's 1e-12·scale (which assumes `t_a = 0`), so every comparison at a computed
/// abscissa adds it.
struct Slopes {
    xtol: f64,
    ds: f64,
    dv: f64,
    da: f64,
    dj: f64,
}

fn slopes(law: &SevenSegmentLaw) -> Slopes {
    let bc = law.bc();
    let (_, sv, sa) = scales(law);
    let c_min = law
        .durations()
        .iter()
        .copied()
        .filter(|c| *c > 0.0)
        .fold(f64::INFINITY, f64::min);
    let jm = law.peaks().jerk_max_abs_finite.max(sa / c_min);
    Slopes {
        xtol: 4.0 * f64::EPSILON * bc.t_a.abs().max(bc.t_b.abs()),
        ds: sv,
        dv: sa,
        da: jm,
        dj: jm * std::f64::consts::FRAC_PI_2 / c_min,
    }
}

fn build(c: &[f64; 7], bc: &BoundaryConditions) -> SevenSegmentLaw {
    match SevenSegmentLaw::try_new(c, bc) {
        Ok(l) => l,
        Err(e) => panic!("generated law must be valid: {e}; c = {c:?}, bc = {bc:?}"),
    }
}

proptest! {
    /// §5.5 item 1: boundary conditions hold to 1e-12·scale; a(t_a) = a_a iff c0 > 0 (else A1),
    /// a(t_b) = a_b iff c6 > 0 (else A2).
    #[test]
    fn boundary_conditions_hold(c in coefficients(), bc in boundary_conditions()) {
        let law = build(&c, &bc);
        let (ss, sv, sa) = scales(&law);
        let start = law.eval(bc.t_a);
        let end = law.eval(bc.t_b);
        prop_assert!((start.s - bc.s_a).abs() <= 1e-12 * ss, "s(t_a) {} vs {}", start.s, bc.s_a);
        prop_assert!((end.s - bc.s_b).abs() <= 1e-12 * ss, "s(t_b) {} vs {} (scale {ss})", end.s, bc.s_b);
        prop_assert!((start.v - bc.v_a).abs() <= 1e-12 * sv, "v(t_a) {} vs {}", start.v, bc.v_a);
        prop_assert!((end.v - bc.v_b).abs() <= 1e-12 * sv, "v(t_b) {} vs {} (scale {sv})", end.v, bc.v_b);
        let want_a = if c[0] > 0.0 { bc.a_a } else { law.a1() };
        let want_b = if c[6] > 0.0 { bc.a_b } else { law.a2() };
        prop_assert!((start.a - want_a).abs() <= 1e-12 * sa, "a(t_a) {} vs {want_a}", start.a);
        prop_assert!((end.a - want_b).abs() <= 1e-12 * sa, "a(t_b) {} vs {want_b}", end.a);
        let k = law.knots();
        prop_assert!((k[7].s - bc.s_b).abs() <= 1e-12 * ss && (k[7].v - bc.v_b).abs() <= 1e-12 * sv);
        prop_assert_eq!(k[7].x.to_bits(), bc.t_b.to_bits());
    }

    /// §5.5 item 2: s and v continuous at every knot; v = ds/dx and a = dv/dx (central
    /// differences inside segments, away from knots).
    #[test]
    fn continuity_and_derivatives(c in coefficients(), bc in boundary_conditions(), frac in 0.2f64..0.8) {
        let law = build(&c, &bc);
        let (ss, sv, sa) = scales(&law);
        let dt = bc.t_b - bc.t_a;
        let eps = f64::EPSILON;
        let sl = slopes(&law);
        for knot in &law.knots()[1..7] {
            let h = 1e-9 * dt;
            let (l, r) = (law.eval(knot.x - h), law.eval(knot.x + h));
            let w = 2.0 * (h + sl.xtol);
            prop_assert!((l.s - r.s).abs() <= w * sv + 8.0 * eps * ss, "s jumps at {}", knot.x);
            prop_assert!((l.v - r.v).abs() <= w * sa + 8.0 * eps * sv, "v jumps at {}", knot.x);
            prop_assert!((law.eval(knot.x).s - knot.s).abs() <= 8.0 * eps * ss + sl.xtol * sl.ds);
        }
        let t = law.knot_times();
        for (k, &ck) in law.durations().iter().enumerate() {
            if ck <= 0.0 {
                continue;
            }
            let x = t[k] + frac * ck;
            let h = 1e-4 * ck;
            let (m, p, c0) = (law.eval(x - h), law.eval(x + h), law.eval(x));
            let ds = (p.s - m.s) / (2.0 * h);
            let dv = (p.v - m.v) / (2.0 * h);
            let dj = (p.a - m.a) / (2.0 * h);
            let jmax = law.peaks().jerk_max_abs_finite.max(sa / ck);
            let r = sl.xtol / h;
            prop_assert!((ds - c0.v).abs() <= 1e-6 * sv + 4.0 * eps * ss / h + r * sl.ds, "v != ds/dx in segment {k}: {ds} vs {}", c0.v);
            prop_assert!((dv - c0.a).abs() <= 1e-6 * sa + 4.0 * eps * sv / h + r * sl.dv, "a != dv/dx in segment {k}: {dv} vs {}", c0.a);
            prop_assert!((dj - c0.j).abs() <= 1e-6 * jmax + 4.0 * eps * sa / h + r * sl.da, "j != da/dx in segment {k}: {dj} vs {}", c0.j);
        }
    }

    /// §5.5 item 3: the Cramer and centroid forms of A1, A2 agree to 1e-12 relative.
    #[test]
    fn cramer_agrees_with_centroid(c in coefficients(), bc in boundary_conditions()) {
        let (c1, c2) = accelerations_cramer(&c, &bc).expect("non-singular");
        let (p1, p2) = accelerations_centroid(&c, &bc).expect("valid");
        let scale = p1.abs().max(p2.abs()).max(bc.a_a.abs()).max(bc.a_b.abs());
        prop_assert!((c1 - p1).abs() <= 1e-12 * scale, "A1 {c1} vs {p1}");
        prop_assert!((c2 - p2).abs() <= 1e-12 * scale, "A2 {c2} vs {p2}");
        let law = build(&c, &bc);
        prop_assert_eq!(law.a1().to_bits(), p1.to_bits());
    }

    /// §5.5 item 4: time reversal.
    #[test]
    fn time_reversal(c in coefficients(), bc in boundary_conditions(), xs in proptest::collection::vec(0.0f64..1.0, 16)) {
        let law = build(&c, &bc);
        let mut rc = c;
        rc.reverse();
        let rbc = BoundaryConditions { v_a: bc.v_b, v_b: bc.v_a, a_a: -bc.a_b, a_b: -bc.a_a, ..bc };
        let rev = build(&rc, &rbc);
        let (ss, sv, sa) = scales(&law);
        let sl = slopes(&law);
        // t_a + t_b − x is rounded twice.
        let dx = 2.0 * sl.xtol;
        for u in xs {
            let x = bc.t_a + u * (bc.t_b - bc.t_a);
            let f = law.eval(x);
            let r = rev.eval(bc.t_a + bc.t_b - x);
            prop_assert!((r.s - (bc.s_a + bc.s_b - f.s)).abs() <= 1e-12 * ss + dx * sl.ds, "s at {x}: {} vs {}", r.s, bc.s_a + bc.s_b - f.s);
            prop_assert!((r.v - f.v).abs() <= 1e-12 * sv + dx * sl.dv, "v at {x}: {} vs {}", r.v, f.v);
            prop_assert!((r.a + f.a).abs() <= 1e-12 * sa + dx * sl.da, "a at {x}: {} vs {}", r.a, -f.a);
        }
    }

    /// §5.5 item 5: scaling with zero end rates.
    #[test]
    fn scaling(c in coefficients(), bc in zero_rate_bc(), k in 0.01f64..100.0, u in 0.0f64..1.0) {
        let law = build(&c, &bc);
        let (ss, sv, sa) = scales(&law);
        let jm = law.peaks().jerk_max_abs_finite.max(sa / (bc.t_b - bc.t_a));
        let dt = bc.t_b - bc.t_a;
        let x = bc.t_a + u * dt;
        let f = law.eval(x);
        // Δs → kΔs.
        let ls = build(&c, &BoundaryConditions { s_b: bc.s_a + k * (bc.s_b - bc.s_a), ..bc });
        let g = ls.eval(x);
        prop_assert!(((g.s - bc.s_a) - k * (f.s - bc.s_a)).abs() <= 1e-12 * k * ss);
        prop_assert!((g.v - k * f.v).abs() <= 1e-12 * k * sv);
        prop_assert!((g.a - k * f.a).abs() <= 1e-12 * k * sa);
        prop_assert!((g.j - k * f.j).abs() <= 1e-11 * k * jm);
        // Δt → kΔt with the same ĉ.
        let lt = build(&c, &BoundaryConditions { t_b: bc.t_a + k * dt, ..bc });
        let h = lt.eval(bc.t_a + k * (x - bc.t_a));
        // Both laws evaluate at rounded abscissae: slopes of the original (scaled by k^-n) and
        // of the stretched law at their own rounding.
        let (so, sn) = (slopes(&law), slopes(&lt));
        let (k2, k3) = (k * k, k * k * k);
        prop_assert!((h.s - f.s).abs() <= 1e-12 * ss + so.xtol * so.ds + sn.xtol * sn.ds);
        prop_assert!((h.v - f.v / k).abs() <= 1e-12 * sv / k + so.xtol * so.dv / k + sn.xtol * sn.dv);
        prop_assert!((h.a - f.a / k2).abs() <= 1e-12 * sa / k2 + so.xtol * so.da / k2 + sn.xtol * sn.da, "a {} vs {}", h.a, f.a / k2);
        prop_assert!((h.j - f.j / k3).abs() <= 1e-11 * jm / k3 + so.xtol * so.dj / k3 + sn.xtol * sn.dj);
    }

    /// §5.5 item 6: the Table-3 vectors of L2, L4, L8 reproduce the closed forms of Appendix A.
    #[test]
    fn catalogue_closed_forms(u in 0.0f64..=1.0) {
        for (entry, named) in [(TABLE3[1], NamedLaw::ConstantAcceleration), (TABLE3[3], NamedLaw::SimpleHarmonic), (TABLE3[7], NamedLaw::Cycloidal)] {
            let law = build(&entry.coefficients, &BoundaryConditions::UNIT_RISE);
            let g = law.eval(u);
            let e = named.eval_normalized(u);
            let f = named.peak_factors();
            prop_assert!((g.s - e.s).abs() <= 1e-14, "{} s({u}): {} vs {}", entry.id, g.s, e.s);
            prop_assert!((g.v - e.v).abs() <= 1e-14 * f.cv, "{} v({u}): {} vs {}", entry.id, g.v, e.v);
            prop_assert!((g.a - e.a).abs() <= 1e-14 * f.ca.unwrap_or(1.0), "{} a({u}): {} vs {}", entry.id, g.a, e.a);
            prop_assert!((g.j - e.j).abs() <= 1e-14 * f.cj.unwrap_or(1.0), "{} j({u}): {} vs {}", entry.id, g.j, e.j);
        }
    }

    /// Renormalization invariance: λ·c builds the same law (to round-off).
    #[test]
    fn renormalization_invariance(c in coefficients(), bc in boundary_conditions(), lambda in 1e-3f64..1e3, u in 0.0f64..1.0) {
        let a = build(&c, &bc);
        let b = build(&c.map(|x| x * lambda), &bc);
        let (ss, sv, sa) = scales(&a);
        let x = bc.t_a + u * (bc.t_b - bc.t_a);
        let (fa, fb) = (a.eval(x), b.eval(x));
        prop_assert!((fa.s - fb.s).abs() <= 1e-12 * ss);
        prop_assert!((fa.v - fb.v).abs() <= 1e-12 * sv);
        prop_assert!((fa.a - fb.a).abs() <= 1e-12 * sa);
        for (p, q) in a.coefficients().iter().zip(b.coefficients()) {
            prop_assert!((p - q).abs() <= 4.0 * f64::EPSILON);
        }
    }

    /// The grid evaluator equals point evaluation for sorted and unsorted abscissae, including
    /// points slightly outside [t_a, t_b] (clamped to the end values).
    #[test]
    fn grid_matches_pointwise(c in coefficients(), bc in boundary_conditions(), us in proptest::collection::vec(-0.01f64..1.01, 1..64)) {
        let law = build(&c, &bc);
        let dt = bc.t_b - bc.t_a;
        let unsorted: Vec<f64> = us.iter().map(|u| bc.t_a + u * dt).collect();
        let mut sorted = unsorted.clone();
        sorted.sort_by(f64::total_cmp);
        let mut out = vec![0.0; unsorted.len()];
        for xs in [&unsorted, &sorted] {
            for q in Quantity::ALL {
                law.eval_quantity_into(xs, q, &mut out);
                for (x, y) in xs.iter().zip(&out) {
                    prop_assert_eq!(y.to_bits(), law.eval(*x).get(q).to_bits(), "{:?} at {}", q, x);
                }
            }
        }
    }
}
