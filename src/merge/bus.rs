//! `/v1/bus-fuel-economy` (rule: `BusFuelEconomyResponse::shard`): `results` and
//! `motor_maps` concatenated in shard order; `comparison` (omitted in a sharded answer: it
//! needs every motor) recomputed from the merged results' `fe_km_per_kwh` and `energy_in_kwh`
//! with paper eq. 11-13 and the request's normalised `desirability_weights`; `report` counters
//! added.

use serde_json::Value;

use crate::calc::bus_fuel_economy::BusFuelEconomyRequest;
use crate::calc::bus_fuel_economy::compute::compare;
use crate::calc::bus_fuel_economy::input::BusFuelEconomyInput;

use super::{MergeError, Part, concat, insert_after, remove, report, set, sum_u64};

const PATH: &str = "/v1/bus-fuel-economy";

pub(super) fn merge(parts: &[Part], request: Option<&Value>) -> Result<Value, MergeError> {
    let results = concat(parts, "/results")?;
    let maps: Option<Vec<Value>> = parts
        .iter()
        .any(|p| p.answer.get("motor_maps").is_some())
        .then(|| {
            parts
                .iter()
                .filter_map(|p| p.answer.get("motor_maps").and_then(Value::as_array))
                .flatten()
                .cloned()
                .collect()
        });
    let comparison = comparison(&results, request)?;
    let mut out = parts[0].answer.clone();
    set(&mut out, "/results", Value::Array(results));
    if let Some(m) = maps {
        set(&mut out, "/motor_maps", Value::Array(m));
    }
    remove(&mut out, "/shard");
    let counters = (
        sum_u64(parts, "/report/iterations")?,
        sum_u64(parts, "/report/evaluations")?,
    );
    set(&mut out, "/report", report(parts, "/report", counters)?);
    if let (Some(c), Value::Object(obj)) = (comparison, &mut out) {
        *obj = insert_after(std::mem::take(obj), "results", "comparison", c);
    }
    Ok(out)
}

/// A text member of a result.
fn text<'a>(r: &'a Value, key: &str) -> Result<&'a str, MergeError> {
    r.get(key)
        .and_then(Value::as_str)
        .ok_or_else(|| MergeError::Malformed {
            name: "the merged results".to_owned(),
            what: format!("a result has no {key}"),
        })
}

/// The comparison of the merged results (≥ 2 motors), as `output::merged_comparison` builds
/// it for typed results.
fn comparison(results: &[Value], request: Option<&Value>) -> Result<Option<Value>, MergeError> {
    let motors_in_results: Vec<&str> = {
        let mut ids: Vec<&str> = Vec::new();
        for r in results {
            let m = text(r, "motor")?;
            if ids.last() != Some(&m) {
                ids.push(m);
            }
        }
        ids
    };
    let Some(request) = request else {
        if motors_in_results.len() >= 2 {
            return Err(MergeError::NeedsRequest {
                path: PATH,
                why: "the comparison of the motors uses the request's desirability weights, \
                      which the shards' answers do not carry",
            });
        }
        return Ok(None);
    };
    let req: BusFuelEconomyRequest = serde_json::from_value(request.clone())
        .map_err(|e| MergeError::Request(format!("not a {PATH} request: {e}")))?;
    let input = BusFuelEconomyInput::try_from(&req)
        .map_err(|e| MergeError::Request(format!("invalid: {e}")))?;
    let (n_m, n_c) = (req.motors.len(), req.cycles.len());
    if results.len() != n_m * n_c {
        return Err(MergeError::Request(format!(
            "it has {n_m} motors × {n_c} cycles, but the shards hold {} results",
            results.len()
        )));
    }
    let ids: Vec<String> = req.motors.iter().map(|m| m.id().to_owned()).collect();
    let cycles: Vec<String> = results[..n_c]
        .iter()
        .map(|r| text(r, "cycle").map(str::to_owned))
        .collect::<Result<_, _>>()?;
    for (k, r) in results.iter().enumerate() {
        let (motor, cycle) = (text(r, "motor")?, text(r, "cycle")?);
        if motor != ids[k / n_c] || cycle != cycles[k % n_c] {
            return Err(MergeError::Request(format!(
                "result {k} is motor {motor:?} on cycle {cycle:?}, but the request's pair {k} \
                 is motor {:?} on cycle {:?}",
                ids[k / n_c],
                cycles[k % n_c]
            )));
        }
    }
    if n_m < 2 {
        return Ok(None);
    }
    let fe: Vec<Option<f64>> = results
        .iter()
        .map(|r| r.get("fe_km_per_kwh").and_then(Value::as_f64))
        .collect();
    let energy: Vec<f64> = results
        .iter()
        .map(|r| {
            r.get("energy_in_kwh")
                .and_then(Value::as_f64)
                .ok_or_else(|| MergeError::Malformed {
                    name: "the merged results".to_owned(),
                    what: "a result has no energy_in_kwh".to_owned(),
                })
        })
        .collect::<Result<_, _>>()?;
    let weights = &input.weights;
    let c = compare(&fe, &energy, n_m, n_c, weights);
    let wire = crate::calc::bus_fuel_economy::output::comparison_wire(&ids, cycles, weights, &c);
    serde_json::to_value(wire)
        .map(Some)
        .map_err(|e| MergeError::Request(format!("cannot encode the comparison: {e}")))
}
