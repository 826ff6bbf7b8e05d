//! Property tests of the fit (spec §5.5 items 7–8, and the fit's invariants): objectives on
//! noise-free data, DTW monotone in the band radius, DTW_0 = Σ|d|, renormalization invariance,
//! final ≤ initial, reproducibility per seed, identification round trips for random laws with
//! end rates, and the numpy-equivalent derivative. `PROPTEST_CASES` scales the run.

// Reference expressions are written as in the spec.
#![allow(clippy::suboptimal_flops)]

use crate::support::cam_law_strategies::{coefficients, scaled_conditions};
use mechcalc::calc::cam_law::law::{BoundaryConditions, Quantity, SevenSegmentLaw};
use mechcalc::calc::cam_law_fit::compute::LawModel;
use mechcalc::calc::cam_law_fit::objective::{Ctx, CurveModel, Dtw, Metric, euclidean};
use mechcalc::calc::cam_law_fit::{self, FitCamLawRequest};
use mechcalc::numerics::Budget;
use mechcalc::numerics::grid;
use proptest::prelude::*;
use serde_json::json;

/// Boundary conditions: log-uniform Δt in [1e-2, 1e2], Δs of either sign up to 1e2, end rates up
/// to a few times the natural scales.
fn boundary_conditions() -> impl Strategy<Value = BoundaryConditions> {
    scaled_conditions(prop_oneof![-100.0f64..-0.01, 0.01f64..100.0], 2.0, 0.0)
}

/// `cases` by default; `PROPTEST_CASES` overrides it for bigger runs.
fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(cases);
    ProptestConfig::with_cases(cases)
}

fn quantity() -> impl Strategy<Value = Quantity> {
    prop_oneof![Just(Quantity::S), Just(Quantity::V), Just(Quantity::A)]
}

fn samples(c: &[f64; 7], bc: &BoundaryConditions, q: Quantity, n: usize) -> (Vec<f64>, Vec<f64>) {
    let xs = grid::linspace(bc.t_a, bc.t_b, n);
    let law = SevenSegmentLaw::try_new(c, bc).expect("law");
    let mut y = vec![0.0; n];
    law.eval_quantity_into(&xs, q, &mut y);
    (xs, y)
}

fn name(q: Quantity) -> &'static str {
    match q {
        Quantity::S => "displacement",
        Quantity::V => "velocity",
        Quantity::A | Quantity::J => "acceleration",
    }
}

fn fit_request(xs: &[f64], y: &[f64], q: Quantity, bc: &BoundaryConditions) -> serde_json::Value {
    json!({
        "abscissa": {"values": xs},
        "channels": {name(q): y},
        "fit_on": name(q),
        "constraints": {"t_a": bc.t_a, "t_b": bc.t_b, "s_a": bc.s_a, "s_b": bc.s_b,
                        "v_a": bc.v_a, "v_b": bc.v_b, "a_a": bc.a_a, "a_b": bc.a_b},
        "outputs": {"error_table": false, "classify": false}
    })
}

fn run(v: serde_json::Value) -> cam_law_fit::FitCamLawResponse {
    let req: FitCamLawRequest = serde_json::from_value(v).expect("request");
    cam_law_fit::run(req, &Budget::unlimited()).expect("fit")
}

proptest! {
    #![proptest_config(config(32))]

    /// §5.5 item 7: EN(true c) = 0 and DTW(true c) = 0 on noise-free data.
    #[test]
    fn objective_is_zero_at_the_generating_law(c in coefficients(), bc in boundary_conditions(), q in quantity()) {
        let (xs, y) = samples(&c, &bc, q, 60);
        let model = LawModel { xs: &xs, bc, quantity: q };
        let mut ctx = Ctx::new(&model, &y, Metric::Euclidean, Budget::unlimited(), false);
        prop_assert!(ctx.value(&c).expect("budget").abs() <= 0.0);
        let mut ctx = Ctx::new(&model, &y, Metric::Dtw { window: 1 }, Budget::unlimited(), false);
        prop_assert!(ctx.value(&c).expect("budget").abs() <= 0.0);
    }

    /// §5.5 item 7: DTW_w ≤ DTW_{w−1}, DTW_0 = Σ|d|, DTW ≥ 0; and DTW_0 ≥ EN (L1 ≥ L2 norm).
    #[test]
    fn dtw_is_monotone_in_the_band(a in proptest::collection::vec(-10.0f64..10.0, 2..80), seed in 0u64..1000) {
        let b: Vec<f64> = a.iter().enumerate().map(|(i, v)| {
            #[allow(clippy::cast_precision_loss)]
            let t = (i as f64).mul_add(0.7, seed as f64);
            v + t.sin()
        }).collect();
        let mut d = Dtw::new();
        let l1: f64 = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).sum();
        let d0 = d.distance(&a, &b, 0);
        prop_assert!((d0 - l1).abs() <= 1e-12 * l1.max(1.0));
        prop_assert!(d0 + 1e-12 >= euclidean(&a, &b));
        let mut prev = d0;
        for w in 1..6 {
            let dw = d.distance(&a, &b, w);
            prop_assert!(dw >= 0.0 && dw <= prev + 1e-12 * prev.max(1.0), "w = {w}: {dw} > {prev}");
            prev = dw;
        }
    }

    /// §5.5 item 8: multiplying all genes by λ > 0 leaves the objective unchanged.
    #[test]
    fn objective_is_invariant_to_gene_scale(c in coefficients(), g in coefficients(), bc in boundary_conditions(),
                                            q in quantity(), log_lambda in -6.0f64..6.0) {
        let (xs, y) = samples(&c, &bc, q, 50);
        let model = LawModel { xs: &xs, bc, quantity: q };
        let lambda = 10f64.powf(log_lambda);
        let scaled = g.map(|v| v * lambda);
        for metric in [Metric::Euclidean, Metric::Dtw { window: 2 }] {
            let mut ctx = Ctx::new(&model, &y, metric, Budget::unlimited(), false);
            let f1 = ctx.value(&g).expect("budget");
            let f2 = ctx.value(&scaled).expect("budget");
            let scale = y.iter().map(|v| v.abs()).fold(1e-300, f64::max);
            prop_assert!((f1 - f2).abs() <= 1e-9 * (f1.abs() + scale), "{f1} vs {f2}");
        }
        // A degenerate candidate (empty pulse) is +∞, never NaN.
        let mut bad = g;
        bad[0] = 0.0; bad[1] = 0.0; bad[2] = 0.0;
        let mut out = vec![0.0; xs.len()];
        prop_assert!(!model.curve(&bad, &mut out));
        let mut ctx = Ctx::new(&model, &y, Metric::Euclidean, Budget::unlimited(), false);
        prop_assert!(ctx.value(&bad).expect("budget").is_infinite());
    }

    /// numpy-equivalent `gradient` is exact on quadratics for any strictly increasing grid.
    #[test]
    fn gradient_is_exact_on_quadratics(steps in proptest::collection::vec(0.01f64..1.0, 8..40),
                                        a in -5.0f64..5.0, b in -5.0f64..5.0) {
        let mut xs = vec![0.0];
        for h in steps { xs.push(xs[xs.len() - 1] + h); }
        let y: Vec<f64> = xs.iter().map(|x| a * x * x + b * x).collect();
        for (d, x) in grid::gradient(&y, &xs).iter().zip(&xs) {
            let exact = 2.0f64.mul_add(a * x, b);
            prop_assert!((d - exact).abs() <= 1e-9 * (1.0 + exact.abs()), "{d} vs {exact}");
        }
    }
}

proptest! {
    #![proptest_config(config(16))]

    /// Identification round trip: a random law with all segments of at least 3 % (clearly above
    /// the sample spacing) and random end rates is recovered from its acceleration or velocity
    /// samples; final ≤ initial.
    #[test]
    fn auto_recovers_random_laws_with_end_rates(c in proptest::array::uniform7(0.03f64..1.0),
                                                bc in boundary_conditions(),
                                                q in prop_oneof![Just(Quantity::A), Just(Quantity::V)]) {
        let sum: f64 = c.iter().sum();
        let truth = c.map(|v| v / sum);
        // Identifiability: when end rates nearly cancel a pulse (|A| ≪ |Δs|/Δt²), its segment
        // lengths barely change the curve (the problem is flat, not the optimizer wrong).
        let law = SevenSegmentLaw::try_new(&truth, &bc).expect("law");
        let dt = bc.t_b - bc.t_a;
        let natural = (bc.s_b - bc.s_a).abs() / (dt * dt);
        prop_assume!(law.a1().abs() >= 0.5 * natural && law.a2().abs() >= 0.5 * natural);
        let (xs, y) = samples(&truth, &bc, q, 200);
        let r = run(fit_request(&xs, &y, q, &bc));
        let err = r.coefficients.iter().zip(&truth).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        prop_assert!(r.objective.final_value <= r.objective.initial);
        prop_assert!(err <= 1e-7, "err {err:.3e}, f {:.3e}, c {:?} vs {:?}", r.objective.final_value, r.coefficients, truth);
    }

    /// Every stochastic method is reproducible per seed, and final ≤ initial (elitism).
    #[test]
    fn stochastic_methods_are_reproducible(c in coefficients(), seed in 0u64..1_000_000,
                                           method in prop_oneof![Just("ga"), Just("de"), Just("cmaes")],
                                           metric in prop_oneof![Just("euclidean"), Just("dtw")]) {
        let bc = BoundaryConditions::UNIT_RISE;
        let (xs, y) = samples(&c, &bc, Quantity::A, 40);
        let mut v = fit_request(&xs, &y, Quantity::A, &bc);
        v["objective"] = json!({"metric": metric});
        v["optimizer"] = json!({"method": method, "seed": seed, "max_evaluations": 1500,
                                "ga": {"population": 20, "generations": 30}});
        let a = run(v.clone());
        let b = run(v);
        prop_assert_eq!(a.coefficients.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        b.coefficients.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        prop_assert_eq!(a.optimizer_report.evaluations, b.optimizer_report.evaluations);
        prop_assert!(a.objective.final_value <= a.objective.initial);
        prop_assert!(a.optimizer_report.evaluations <= 1500);
    }

    /// Scaling the rise by k (zero end rates) scales the data and leaves the identified
    /// coefficients unchanged (spec §5.5 item 5 seen through the fit).
    #[test]
    fn fit_is_invariant_to_the_rise_scale(c in proptest::array::uniform7(0.05f64..1.0), log_k in -3.0f64..3.0) {
        let bc = BoundaryConditions::UNIT_RISE;
        let k = 10f64.powf(log_k);
        let (xs, y) = samples(&c, &bc, Quantity::A, 120);
        let bck = BoundaryConditions { s_b: k, ..bc };
        let yk: Vec<f64> = y.iter().map(|v| v * k).collect();
        let r1 = run(fit_request(&xs, &y, Quantity::A, &bc));
        let r2 = run(fit_request(&xs, &yk, Quantity::A, &bck));
        let d = r1.coefficients.iter().zip(&r2.coefficients).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        prop_assert!(d <= 1e-8, "{d:.3e}");
    }
}
