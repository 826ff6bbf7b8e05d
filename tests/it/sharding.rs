//! `shard: {index, count}` on the sweeps: for count ∈ {1, 2, 3, 7} and one more than the items
//! the shards' answers, merged by `mechcalc::merge` (the rule documented on each answer's
//! `shard`: concatenate the per-item arrays in shard order, add the counters, recompute the
//! named reductions) and given in reverse order, equal the unsharded answer exactly — every
//! number compared as JSON text, i.e. bit for bit, timings aside ([`comparable`]). Bad shards
//! are 422 with the field's pointer.

use crate::common;

use mechcalc::calc::bus_fuel_economy::{self, BusFuelEconomyRequest, BusFuelEconomyResponse};
use mechcalc::calc::continuum_workspace::wire::{WorkspaceResponse, WorkspaceShardResponse};
use mechcalc::calc::continuum_workspace::{
    self, ContinuumWorkspaceRequest, ContinuumWorkspaceResponse,
};
use mechcalc::calc::irefc::stress::wire::StressSweepResponse;
use mechcalc::calc::irefc::{IrefcStressRequest, IrefcStressResponse, run_stress};
use mechcalc::calc::machining_size::{self, TrainRequest, TrainResponse};
use mechcalc::merge::{ShardFile, Sweep, merge};
use mechcalc::numerics::Budget;
use serde::Serialize;
use serde_json::{Value, json};

const COUNTS: [u32; 4] = [1, 2, 3, 7];

/// JSON text of a value: equal text means equal numbers to the last bit (shortest round-trip
/// formatting).
fn text<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("serializable")
}

pub(crate) fn with_shard(body: &Value, index: u32, count: u32) -> Value {
    let mut b = body.clone();
    b["shard"] = json!({"index": index, "count": count});
    b
}

/// Members that describe a run rather than the request, and differ between two runs of one
/// request: wall-clock times everywhere.
const TIMINGS: [&str; 3] = ["elapsed_ms", "compute_ms", "timing_ms"];

/// The JSON text of an answer of `sweep` without what a merged answer cannot reproduce (the
/// module docs of `mechcalc::merge`): timings; the IREFC sweep's `meta.threads` (each shard
/// uses at most as many threads as it has combinations); the continuum workspace's report
/// counters (every shard repeats the assembly-mode search).
pub(crate) fn comparable(answer: &Value, sweep: Sweep) -> String {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                for k in TIMINGS {
                    m.shift_remove(k);
                }
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = answer.clone();
    strip(&mut v);
    let drop: &[(&str, &str)] = match sweep {
        Sweep::IrefcStress => &[("/meta", "threads")],
        Sweep::ContinuumWorkspace => &[("/report", "iterations"), ("/report", "evaluations")],
        _ => &[],
    };
    for (parent, key) in drop {
        let o = v.pointer_mut(parent).and_then(Value::as_object_mut);
        assert!(
            o.and_then(|o| o.shift_remove(*key)).is_some(),
            "{parent}/{key} is in every answer"
        );
    }
    v.to_string()
}

/// The shards' answers as the merge reads them, in reverse order (any order merges).
fn files<T: Serialize>(parts: &[T]) -> Vec<ShardFile> {
    parts
        .iter()
        .enumerate()
        .rev()
        .map(|(i, p)| ShardFile {
            name: format!("shard {i}"),
            answer: serde_json::to_value(p).expect("serializable"),
        })
        .collect()
}

/// Asserts that the library's merge of `parts` equals `whole`, timings aside.
fn assert_merges<T: Serialize, W: Serialize>(
    sweep: Sweep,
    parts: &[T],
    whole: &W,
    request: Option<&Value>,
    count: u32,
) {
    let merged = merge(sweep, files(parts), request)
        .unwrap_or_else(|e| panic!("{sweep:?}, count {count}: {e}"));
    let whole = serde_json::to_value(whole).expect("serializable");
    assert_eq!(
        comparable(&merged, sweep),
        comparable(&whole, sweep),
        "{sweep:?}, count {count}: the merged answer"
    );
}

// ---------------------------------------------------------------------------------------------
// IREFC design sweep
// ---------------------------------------------------------------------------------------------

/// 7 × Z2, 6 × χ: 42 combinations, some of them infeasible (undercut at small χ and large Z2).
pub(crate) fn irefc_body() -> Value {
    json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 2, "torque_Nm": 119.366207, "step_deg": 2,
           "refine": true, "sweep": {"Z2": {"from": 10, "to": 16}, "chi": {"from": 1.05, "to": 1.55, "step": 0.1}}})
}

fn irefc(body: &Value) -> StressSweepResponse {
    let req: IrefcStressRequest = serde_json::from_value(body.clone()).expect("valid request");
    match run_stress(req, &Budget::unlimited()).expect("sweep runs") {
        IrefcStressResponse::Sweep(r) => r,
        IrefcStressResponse::Single(_) => panic!("a sweep request answered as single"),
    }
}

#[test]
fn irefc_sweep_shards_merge_into_the_whole_sweep() {
    let body = irefc_body();
    let whole = irefc(&body);
    let n = whole.records.len();
    assert_eq!(n, 42);
    assert!(
        whole.n_valid > 0 && whole.n_invalid > 0,
        "the sweep mixes valid and invalid"
    );
    assert!(whole.shard.is_none(), "no shard statement without a shard");
    for count in COUNTS.into_iter().chain([n as u32 + 1]) {
        let parts: Vec<StressSweepResponse> = (0..count)
            .map(|i| irefc(&with_shard(&body, i, count)))
            .collect();
        let mut next = 0u64;
        for (i, p) in parts.iter().enumerate() {
            let s = *p
                .shard
                .as_deref()
                .expect("a sharded answer says which shard it is");
            assert_eq!((s.index, s.count, s.total), (i as u32, count, n as u64));
            assert_eq!(s.start, next, "blocks are contiguous in index order");
            assert_eq!(s.end - s.start, p.records.len() as u64);
            assert_eq!(p.meta.n_combinations, p.records.len() as u64);
            next = s.end;
        }
        assert_eq!(next, n as u64, "count {count}: the blocks cover the sweep");
        // The picks come from different shards for most counts: the merge compares them.
        assert_merges(Sweep::IrefcStress, &parts, &whole, None, count);
    }
}

// ---------------------------------------------------------------------------------------------
// Bus: motors × cycles
// ---------------------------------------------------------------------------------------------

pub(crate) fn bus_body() -> Value {
    let motor = |id: &str, eff: f64| {
        json!({"id": id, "model": "constant", "efficiency": eff, "t_peak_nm": 800,
               "p_peak_w": 130000, "n_max_rpm": 5200})
    };
    json!({"cycles": ["manhattan", "hwfet", "hdudds"],
           "motors": [motor("a", 0.93), motor("b", 0.9), motor("c", 0.95)],
           "options": {"outputs": ["loss_breakdown", "efficiency_map"],
                       "desirability_weights": [1, 2, 1]}})
}

fn bus(body: &Value) -> BusFuelEconomyResponse {
    let req: BusFuelEconomyRequest = serde_json::from_value(body.clone()).expect("valid request");
    bus_fuel_economy::run(req, &Budget::unlimited()).expect("runs")
}

#[test]
fn bus_comparison_shards_merge_into_the_whole_comparison() {
    let body = bus_body();
    let whole = bus(&body);
    assert_eq!(whole.results.len(), 9);
    assert!(whole.comparison.is_some(), "3 motors are compared");
    for count in COUNTS.into_iter().chain([10]) {
        let parts: Vec<BusFuelEconomyResponse> = (0..count)
            .map(|i| bus(&with_shard(&body, i, count)))
            .collect();
        let mut next = 0u64;
        for (i, p) in parts.iter().enumerate() {
            let s = p.shard.expect("a sharded answer says which shard it is");
            assert_eq!(
                (s.index, s.count, s.total, s.start),
                (i as u32, count, 9, next)
            );
            assert_eq!(s.end - s.start, p.results.len() as u64);
            assert!(p.comparison.is_none(), "a shard cannot compare all motors");
            next = s.end;
        }
        assert_merges(Sweep::BusFuelEconomy, &parts, &whole, Some(&body), count);
    }
    // The comparison needs the request's desirability weights.
    let parts: Vec<BusFuelEconomyResponse> =
        (0..2).map(|i| bus(&with_shard(&body, i, 2))).collect();
    let e = merge(Sweep::BusFuelEconomy, files(&parts), None).expect_err("needs the request");
    assert!(e.to_string().contains("--request"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Machining size: k-fold cross-validation folds
// ---------------------------------------------------------------------------------------------

pub(crate) fn train_body() -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("api/machining_size/train_synthetic.json");
    let mut b: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json");
    b["params"]["n_estimators"] = json!(25);
    b["validation"]["k_fold"] = json!(7);
    b["outputs"] = json!(["importance"]);
    b
}

fn train(body: &Value) -> TrainResponse {
    let req: TrainRequest = serde_json::from_value(body.clone()).expect("valid request");
    machining_size::run_train(req, &Budget::unlimited()).expect("trains")
}

#[test]
fn machining_cv_fold_shards_merge_into_the_whole_cross_validation() {
    let body = train_body();
    let whole = train(&body);
    let cv = whole.metrics.cv.as_ref().expect("7-fold CV finished");
    assert_eq!((cv.k, cv.folds.len()), (7, 7));
    for count in COUNTS.into_iter().chain([8]) {
        let parts: Vec<TrainResponse> = (0..count)
            .map(|i| train(&with_shard(&body, i, count)))
            .collect();
        let mut next = 0u64;
        for (i, p) in parts.iter().enumerate() {
            assert_eq!(
                text(&p.model),
                text(&whole.model),
                "every shard trains the same model"
            );
            let c = p.metrics.cv.as_ref().expect("the shard's folds finished");
            let s = c.shard.expect("a sharded answer says which shard it is");
            assert_eq!(
                (s.index, s.count, s.total, s.start),
                (i as u32, count, 7, next)
            );
            assert_eq!(c.k, 7);
            assert_eq!(s.end - s.start, c.folds.len() as u64);
            next = s.end;
        }
        assert_eq!(next, 7);
        // The means and sds over the folds, and the trees built in all, are recomputed.
        assert_merges(Sweep::MachiningTrain, &parts, &whole, None, count);
    }
}

// ---------------------------------------------------------------------------------------------
// Continuum workspace: the waves of a sweep
// ---------------------------------------------------------------------------------------------

const CONTINUUM: &str = "/v1/continuum-workspace";

/// Design 1, one wave per stable assembly mode at (-0.22, 0.2425) (a node of the 5 x 5 grid):
/// the N_grid 4 search finds three stable modes there (tests/it/http_continuum_workspace.rs).
pub(crate) fn continuum_body() -> Value {
    json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "assembly_modes": {"n_grid": 4},
           "workspace": {"grid": [5, 5], "ranges_m": [[-0.26, -0.18], [0.2025, 0.2825]],
                         "seed": {"kind": "all_stable_modes", "inputs_m": [-0.22, 0.2425]},
                         "stability_segments": 10, "return_nodes": true}})
}

fn continuum(body: &Value) -> ContinuumWorkspaceResponse {
    let req: ContinuumWorkspaceRequest =
        serde_json::from_value(body.clone()).expect("valid request");
    continuum_workspace::run(req, &Budget::unlimited()).expect("sweep runs")
}

fn continuum_whole(body: &Value) -> WorkspaceResponse {
    match continuum(body) {
        ContinuumWorkspaceResponse::Workspace(r) => *r,
        _ => panic!("an unsharded sweep answered in another shape"),
    }
}

fn continuum_shard(body: &Value) -> WorkspaceShardResponse {
    match continuum(body) {
        ContinuumWorkspaceResponse::WorkspaceShard(r) => *r,
        _ => panic!("a sharded sweep answered in another shape"),
    }
}

#[test]
fn continuum_wave_shards_merge_into_the_whole_sweep() {
    let body = continuum_body();
    let whole = continuum_whole(&body);
    let n = 1 + whole.other_waves.as_ref().map_or(0, Vec::len);
    assert!(n >= 2, "the sweep has one wave per stable mode, got {n}");
    assert!(
        whole.wave.metrics.n_accepted > 1,
        "the first wave spreads beyond its seed"
    );
    assert!(
        !text(&whole).contains("\"shard\""),
        "no shard statement without a shard"
    );
    for count in [1, 2, 3, n as u32 + 1, 7] {
        let parts: Vec<WorkspaceShardResponse> = (0..count)
            .map(|i| continuum_shard(&with_shard(&body, i, count)))
            .collect();
        let mut next = 0u64;
        for (i, p) in parts.iter().enumerate() {
            let s = p.shard;
            assert_eq!(
                (s.index, s.count, s.total, s.start),
                (i as u32, count, n as u64, next),
                "count {count}"
            );
            assert_eq!(s.end - s.start, p.waves.len() as u64);
            assert_eq!(text(&p.grid), text(&whole.grid));
            next = s.end;
        }
        assert_eq!(next, n as u64, "count {count}: the blocks cover the waves");
        if count as usize > n {
            assert!(
                parts[n..].iter().all(|p| p.waves.is_empty()),
                "count {count}: shards beyond the waves are empty"
            );
        }
        assert_merges(Sweep::ContinuumWorkspace, &parts, &whole, None, count);
        // The report counters are the shards' work: at least the unsharded run's.
        let merged = merge(Sweep::ContinuumWorkspace, files(&parts), None).expect("merges");
        assert!(
            merged["report"]["evaluations"].as_u64() >= Some(whole.report.evaluations),
            "count {count}: {} < {}",
            merged["report"]["evaluations"],
            whole.report.evaluations
        );
    }
}

/// The single-seed sweep is one wave: shard 0 holds it, the others are empty; every sharded
/// answer (an empty one too) is described by the published document.
#[tokio::test]
async fn a_single_seed_sweep_is_one_wave_and_sharded_answers_follow_the_document() {
    let body = json!({"mode": "workspace", "design": {"preset": "keops_d1"},
                      "workspace": {"grid": [5, 5], "stability_check": "none"}});
    let whole = common::post_json(CONTINUUM, &body).await.json();
    let doc = crate::contract::doc();
    let op = &doc["paths"][CONTINUUM]["post"];
    let answers = &op["responses"]["200"]["content"]["application/json"]["schema"];
    let requests = &op["requestBody"]["content"]["application/json"]["schema"];
    for index in 0..3 {
        let req = with_shard(&body, index, 3);
        assert_eq!(
            crate::contract::violations(&doc, requests, &req),
            Vec::<String>::new()
        );
        let r = common::post_json(CONTINUUM, &req).await;
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
        let b = r.json();
        assert_eq!(
            crate::contract::violations(&doc, answers, &b),
            Vec::<String>::new()
        );
        let (start, end) = if index == 0 { (0, 1) } else { (1, 1) };
        assert_eq!(
            b["shard"],
            json!({"index": index, "count": 3, "start": start, "end": end, "total": 1})
        );
        let waves = b["waves"].as_array().expect("waves");
        assert_eq!(waves.len(), end - start);
        assert!(b.get("seed").is_none() && b.get("other_waves").is_none());
        if let Some(w) = waves.first() {
            for key in ["seed", "metrics", "failures"] {
                assert_eq!(w[key], whole[key], "{key}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bad shards over HTTP
// ---------------------------------------------------------------------------------------------

#[tokio::test]
async fn bad_shards_are_422_with_the_fields_pointer() {
    let endpoints = [
        ("/v1/irefc-stress", irefc_body()),
        ("/v1/bus-fuel-economy", bus_body()),
        ("/v1/machining-size/train", train_body()),
        (CONTINUUM, continuum_body()),
    ];
    let cases = [
        (2, 2, "/shard/index"),
        (7, 3, "/shard/index"),
        (0, 0, "/shard/count"),
        (0, 10_001, "/shard/count"),
        (0, 4_000_000_000, "/shard/count"),
    ];
    for (path, body) in &endpoints {
        for (index, count, pointer) in cases {
            let r = common::post_json(path, &with_shard(body, index, count)).await;
            let p = r.problem(422);
            assert_eq!(p["type"], "/problems/invalid-input", "{path}: {p}");
            assert_eq!(r.pointers(), vec![pointer], "{path} {index}/{count}");
        }
    }
    // A shard of a mode without a sweep, or of a training without k-fold CV.
    let mut single = irefc_body();
    single["mode"] = json!("single");
    single["Z2"] = json!(26);
    single["chi"] = json!(1.4);
    single.as_object_mut().map(|o| o.remove("sweep"));
    let r = common::post_json("/v1/irefc-stress", &with_shard(&single, 0, 2)).await;
    r.problem(422);
    assert_eq!(r.pointers(), vec!["/shard"]);
    let mut no_cv = train_body();
    no_cv["validation"] = json!({"test_fraction": 0.2});
    let r = common::post_json("/v1/machining-size/train", &with_shard(&no_cv, 0, 2)).await;
    r.problem(422);
    assert_eq!(r.pointers(), vec!["/shard"]);
    // The continuum modes fk and assembly_modes are one job: any shard (even the whole, count
    // 1) is refused, as IREFC's mode "single" does.
    let fk = json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.15, 0.2225]});
    let modes = json!({"mode": "assembly_modes", "design": {"preset": "keops_d1"},
                       "inputs_m": [-0.22, 0.2425], "assembly_modes": {"n_grid": 2}});
    for body in [fk, modes] {
        for count in [1, 2] {
            let r = common::post_json(CONTINUUM, &with_shard(&body, 0, count)).await;
            let p = r.problem(422);
            assert_eq!(p["type"], "/problems/invalid-input", "{p}");
            assert_eq!(r.pointers(), vec!["/shard"], "{p}");
        }
    }
}

#[tokio::test]
async fn a_sharded_http_answer_states_its_block() {
    let r = common::post_json("/v1/irefc-stress", &with_shard(&irefc_body(), 1, 3)).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert_eq!(
        b["shard"],
        json!({"index": 1, "count": 3, "start": 14, "end": 28, "total": 42})
    );
    assert_eq!(b["records"].as_array().map(Vec::len), Some(14));
}
