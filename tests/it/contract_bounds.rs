//! Every documented bound is the enforced bound, and every enforced bound is documented.
//!
//! The document is walked alongside each `api/` example request. For every number in the request
//! whose schema states a bound, the value is replaced by one just outside (the service must answer
//! 422 with that field's JSON pointer) and one just inside (the service must not reject that
//! field). For every number whose schema states no bound, a few extreme values (0, −1, ±1e300)
//! are sent: a 422 `invalid-input` naming that field means the code enforces a bound the document
//! does not state. Cross-field rules (e.g. `t_b > t_a`) cannot be written as a JSON Schema bound;
//! the fields they reject are listed in [`CROSS_FIELD`] with the rule.

use crate::common;
use crate::contract::{doc, examples};

use serde_json::{Value, json};

/// Fields whose rejection depends on other fields (`endpoint`, pointer): the rule is in the
/// field's description in the document.
#[rustfmt::skip]
const CROSS_FIELD: &[(&str, &str, &str)] = &[
    ("/v1/cam-law/evaluate", "/constraints/t_b", "t_b > t_a, with t_b − t_a resolvable at the offset"),
    ("/v1/cam-law/evaluate", "/abscissa/values/0", "abscissae increase and lie in [t_a, t_b]"),
    ("/v1/cam-law/evaluate", "/abscissa/grid/start", "the grid lies in [t_a, t_b]"),
    ("/v1/cam-law/evaluate", "/abscissa/grid/end", "end > start, and the grid lies in [t_a, t_b]"),
    ("/v1/component-importance", "/overrides/0/time_h", "one of times_h"),
    ("/v1/component-importance", "/options/o_out", "q_in + o_out = 1"),
    ("/v1/fit-cam-law", "/constraints/t_b", "t_b > t_a"),
    ("/v1/fit-cam-law", "/abscissa/grid/end", "end > start"),
    ("/v1/fit-cam-law", "/objective/dtw_window", "≤ N, the number of samples"),
    ("/v1/irefc-stress", "/sweep/Z2/to", "to ≥ from"),
    ("/v1/irefc-stress", "/sweep/chi/to", "to ≥ from"),
    ("/v1/irefc-stress", "/lb_mm", "lb_mm ≤ 100·r2 (every r2 of a sweep)"),
    ("/v1/irefc-stress", "/rb_mm", "rb_mm < min(rb_overlap, rb_undercut) of (r2, Z2, χ) (422 infeasible otherwise)"),
    ("/v1/irefc-efficiency", "/rb_mm", "rb_mm < min(rb_overlap, rb_undercut) of (r2, Z2, χ) (422 infeasible otherwise)"),
    ("/v1/irefc-efficiency", "/phase_deg", "phase_deg < 360/Z2"),
    ("/v1/cognates", "/crank", "≥ 1e-12·L, L the largest length of the linkage"),
    ("/v1/cognates", "/coupler", "≥ 1e-12·L, L the largest length of the linkage"),
    ("/v1/cognates", "/rocker", "≥ 1e-12·L, L the largest length of the linkage"),
    ("/v1/cognates", "/coupler_point/d", "(b, d, e) close a triangle within 1e-12·max(b, d, e)"),
    ("/v1/cognates", "/coupler_point/e", "(b, d, e) close a triangle within 1e-12·max(b, d, e)"),
    ("/v1/continuum-workspace", "/inputs_m/0", "within the actuator's stroke"),
    ("/v1/continuum-workspace", "/design/rods/0/actuator", "an index of design.actuators"),
    ("/v1/bus-fuel-economy", "/motors/0/lq_h", "lq_h ≥ ld_h"),
    ("/v1/bus-fuel-economy", "/motors/0/n_max_rpm", "above the cycles' top motor speed"),
    ("/v1/bus-fuel-economy/motor-map", "/motor/lq_h", "lq_h ≥ ld_h"),
    ("/v1/continuum-workspace", "/design/rods/0/diameter_m", "slenderness length_m / diameter_m ≥ 5"),
    ("/v1/continuum-workspace", "/load/moment_nm", "within 1e4 F_ref L_ref of the design's own scale"),
    ("/v1/continuum-workspace", "/load/force_n/0", "within 1e4 F_ref of the design's own scale"),
    ("/v1/machining-size/train", "/params/colsample_bytree", "⌊colsample_bytree·d⌋ ≥ 1, d = features left after dropping constant columns"),
    ("/v1/machining-size/train", "/params/min_child_weight", "the training split needs ≥ 2·max(1, min_child_weight) rows"),
    ("/v1/spatial-coupling", "/alpha_deg", "|cos 2α| ≥ 1e-9 (α ≠ ±45°, perpendicular shafts)"),
    ("/v1/spatial-coupling", "/beta_deg", "with a sweep: cos(α−β)·cos 2α·cos(α+β) > 0 (422 infeasible otherwise)"),
    ("/v1/vibration-absorber", "/absorber/position_m", "x_a ≤ beam.length_m"),
    ("/v1/vibration-absorber", "/excitation/position_m", "x_p ≤ beam.length_m"),
    ("/v1/vibration-absorber", "/excitation/resonance_of_mode", "k ≤ beam.n_modes"),
    ("/v1/vibration-absorber", "/excitation/harmonics/0/resonance_of_mode", "k ≤ beam.n_modes"),
    ("/v1/vibration-absorber", "/absorber/passive_tuning_mode", "k ≤ beam.n_modes"),
    ("/v1/vibration-absorber", "/control/tuning_mode", "k ≤ beam.n_modes"),
    ("/v1/vibration-absorber", "/outputs/frequency_response/f_max_hz", "f_max_hz > f_min_hz"),
    ("/v1/vibration-absorber", "/outputs/frequency_response/points_m/0", "x_o ≤ beam.length_m"),
    ("/v1/vibration-absorber", "/outputs/time_response/points_m/0", "x_o ≤ beam.length_m"),
    ("/v1/vibration-absorber", "/outputs/time_response/dt_s", "t_end_s / dt_s ≤ 2e6 samples"),
    ("/v1/vibration-absorber", "/actuator/force_constant_n_a", "≠ 0 with control.mode = active"),
];

/// A number in an example request with its documented bound, if any.
#[derive(Debug, Clone)]
struct Slot {
    pointer: String,
    integer: bool,
    lo: Option<(f64, bool)>,
    hi: Option<(f64, bool)>,
}

fn resolve<'a>(doc: &'a Value, s: &'a Value) -> &'a Value {
    let mut s = s;
    for _ in 0..32 {
        match s.get("$ref").and_then(Value::as_str) {
            Some(r) => {
                s = doc
                    .pointer(r.trim_start_matches('#'))
                    .unwrap_or_else(|| panic!("dangling $ref {r}"));
            }
            None => return s,
        }
    }
    s
}

fn is_type(s: &Value, ty: &str) -> bool {
    match s.get("type") {
        Some(Value::String(t)) => t == ty,
        Some(Value::Array(a)) => a.iter().any(|t| t == ty),
        _ => false,
    }
}

/// The variant of a `oneOf` that `instance` matches (by discriminator, else by validation).
fn pick_variant<'a>(doc: &'a Value, s: &'a Value, instance: &Value) -> Option<&'a Value> {
    let variants = s.get("oneOf")?.as_array()?;
    if let Some(tag) = s
        .pointer("/discriminator/propertyName")
        .and_then(Value::as_str)
    {
        let v = instance.get(tag)?.as_str()?;
        let r = s
            .pointer(&format!("/discriminator/mapping/{v}"))?
            .as_str()?;
        return doc.pointer(r.trim_start_matches('#'));
    }
    variants
        .iter()
        .find(|v| crate::contract::violations(doc, v, instance).is_empty())
}

fn walk(doc: &Value, schema: &Value, instance: &Value, pointer: &str, out: &mut Vec<Slot>) {
    let s = resolve(doc, schema);
    if let Some(v) = pick_variant(doc, s, instance) {
        walk(doc, v, instance, pointer, out);
        return;
    }
    if let Some(parts) = s.get("allOf").and_then(Value::as_array) {
        for p in parts {
            walk(doc, p, instance, pointer, out);
        }
    }
    match instance {
        // A number restricted to listed values (`enum`) is documented by that list.
        Value::Number(_)
            if (is_type(s, "number") || is_type(s, "integer"))
                && s.get("enum").is_none()
                && s.get("const").is_none() =>
        {
            let bound = |k: &str, ek: &str| {
                s.get(k)
                    .and_then(Value::as_f64)
                    .map(|x| (x, false))
                    .or_else(|| s.get(ek).and_then(Value::as_f64).map(|x| (x, true)))
            };
            out.push(Slot {
                pointer: pointer.to_owned(),
                integer: is_type(s, "integer"),
                lo: bound("minimum", "exclusiveMinimum"),
                hi: bound("maximum", "exclusiveMaximum"),
            });
        }
        Value::Object(m) => {
            if let Some(props) = s.get("properties").and_then(Value::as_object) {
                for (k, v) in m {
                    if let Some(ps) = props.get(k) {
                        walk(doc, ps, v, &format!("{pointer}/{k}"), out);
                    }
                }
            }
        }
        Value::Array(a) => {
            if let Some(items) = s.get("items") {
                // The first item stands for all (a bound on items is the same for each).
                if let Some(first) = a.first() {
                    walk(doc, items, first, &format!("{pointer}/0"), out);
                }
            }
        }
        _ => {}
    }
}

fn with_value(body: &Value, pointer: &str, x: f64, integer: bool) -> Value {
    let mut b = body.clone();
    let slot = b.pointer_mut(pointer).expect("pointer from the walk");
    *slot = if integer && x.fract() == 0.0 && x.abs() < 9.0e15 {
        json!(x as i64)
    } else {
        json!(x)
    };
    b
}

fn step(x: f64, integer: bool) -> f64 {
    if integer {
        1.0
    } else {
        (x.abs() * 1e-6).max(1e-9)
    }
}

/// Values just outside and just inside each documented end.
fn probes(s: &Slot) -> (Vec<f64>, Vec<f64>) {
    let (mut outside, mut inside) = (Vec::new(), Vec::new());
    if let Some((lo, open)) = s.lo {
        let d = step(lo, s.integer);
        if open {
            outside.push(lo);
            inside.push(lo + d);
        } else {
            outside.push(lo - d);
            inside.push(lo);
        }
    }
    if let Some((hi, open)) = s.hi {
        let d = step(hi, s.integer);
        if open {
            outside.push(hi);
            inside.push(hi - d);
        } else {
            outside.push(hi + d);
            inside.push(hi);
        }
    }
    (outside, inside)
}

struct Answer {
    status: u16,
    problem_type: String,
    pointers: Vec<String>,
}

async fn post(endpoint: &str, body: &Value) -> Answer {
    let r = common::post_json(endpoint, body).await;
    let status = r.status.as_u16();
    let (problem_type, pointers) = if status == 200 {
        (String::new(), Vec::new())
    } else {
        let p = r.json();
        (p["type"].as_str().unwrap_or("").to_owned(), r.pointers())
    };
    Answer {
        status,
        problem_type,
        pointers,
    }
}

fn cross_field(endpoint: &str, pointer: &str) -> bool {
    CROSS_FIELD
        .iter()
        .any(|(e, p, _)| *e == endpoint && *p == pointer)
}

#[tokio::test]
async fn documented_bounds_are_the_enforced_bounds() {
    let doc = doc();
    let mut failures = Vec::new();
    let (mut probed, mut unbounded) = (0usize, 0usize);
    for (file, endpoint, body) in examples() {
        if crate::contract::pending(&file) {
            continue;
        }
        let schema = crate::contract::request_schema(&doc, &endpoint);
        let mut slots = Vec::new();
        walk(&doc, &schema, &body, "", &mut slots);
        for s in slots {
            if s.pointer == "/time_limit_ms" {
                continue;
            }
            let exempt = cross_field(&endpoint, &s.pointer);
            if s.lo.is_none() && s.hi.is_none() {
                unbounded += 1;
                for x in [0.0, -1.0, 1e300, -1e300] {
                    let a = post(&endpoint, &with_value(&body, &s.pointer, x, s.integer)).await;
                    let named = a.pointers.contains(&s.pointer);
                    // A non-integer or negative value for an unsigned integer is a decode error,
                    // which the type (not a bound) documents.
                    let type_rule = s.integer && (x < 0.0 || x.abs() > 1e19);
                    if a.status == 422
                        && a.problem_type == "/problems/invalid-input"
                        && named
                        && !exempt
                        && !type_rule
                    {
                        failures.push(format!(
                            "api/{file} {}: {x} is rejected but the document states no bound",
                            s.pointer
                        ));
                    }
                }
                continue;
            }
            probed += 1;
            let (outside, inside) = probes(&s);
            for x in outside {
                let a = post(&endpoint, &with_value(&body, &s.pointer, x, s.integer)).await;
                if a.status != 422 || !a.pointers.contains(&s.pointer) {
                    failures.push(format!(
                        "api/{file} {}: {x} is outside the documented bound but was answered {} \
                         (pointers {:?})",
                        s.pointer, a.status, a.pointers
                    ));
                }
            }
            for x in inside {
                let a = post(&endpoint, &with_value(&body, &s.pointer, x, s.integer)).await;
                let rejected = a.status == 422
                    && a.problem_type == "/problems/invalid-input"
                    && a.pointers.contains(&s.pointer);
                if rejected && !exempt {
                    failures.push(format!(
                        "api/{file} {}: {x} is inside the documented bound but was rejected",
                        s.pointer
                    ));
                }
            }
        }
    }
    eprintln!("bounds probed: {probed}, unbounded numbers tried: {unbounded}");
    assert!(
        failures.is_empty(),
        "{} bound mismatches:\n  {}",
        failures.len(),
        failures.join("\n  ")
    );
}

/// The wire convention's `time_limit_ms` is accepted at the top level of every operation's
/// request, documented there with the shared bound [1, 600 000] ms, and enforced: 0 and 600 001
/// are 422 naming `/time_limit_ms`, the bound's ends are answered like the example itself.
#[tokio::test]
async fn every_operation_takes_the_top_level_time_limit() {
    let doc = doc();
    let mut failures = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for (file, endpoint, body) in examples() {
        if !seen.insert(endpoint.clone()) {
            continue;
        }
        let schema = resolve(&doc, &crate::contract::request_schema(&doc, &endpoint)).clone();
        let prop = resolve(&doc, &schema["properties"]["time_limit_ms"]);
        if prop["minimum"] != json!(1) || prop["maximum"] != json!(600_000) {
            failures.push(format!(
                "{endpoint}: time_limit_ms documented as {prop} (want minimum 1, maximum 600000)"
            ));
        }
        let base = post(&endpoint, &body).await.status;
        for (ms, want_rejected) in [(0u64, true), (600_001, true), (1, false), (600_000, false)] {
            let mut b = body.clone();
            b["time_limit_ms"] = json!(ms);
            let a = post(&endpoint, &b).await;
            let named = a.pointers.iter().any(|p| p == "/time_limit_ms");
            if want_rejected && !(a.status == 422 && named) {
                failures.push(format!(
                    "api/{file}: time_limit_ms = {ms} answered {} (pointers {:?}), want 422 at \
                     /time_limit_ms",
                    a.status, a.pointers
                ));
            }
            // 1 ms may legitimately run out on a heavy example (a 422 deadline answer); it must
            // never be rejected as an invalid time_limit_ms.
            if !want_rejected && (named || (ms == 600_000 && a.status != base)) {
                failures.push(format!(
                    "api/{file}: time_limit_ms = {ms} answered {} (pointers {:?}), the example \
                     alone {base}",
                    a.status, a.pointers
                ));
            }
        }
    }
    let posts = doc["paths"]
        .as_object()
        .expect("paths")
        .iter()
        .filter(|(_, item)| item.get("post").is_some())
        .count();
    assert_eq!(
        seen.len(),
        posts,
        "every POST operation has an api/ example (seen {seen:?})"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
