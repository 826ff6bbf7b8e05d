//! `/v1/continuum-workspace` mode `workspace` (rule: `WorkspaceShardResponse::shard`): the
//! shards' `waves` concatenated in shard order; the first merged wave's members at the top
//! level and the others, in order, as `other_waves` (omitted with one wave); `mode`, `grid` and
//! `preset` of any shard; `warnings` the union in order of first appearance.

use serde_json::{Map, Value};

use super::{MergeError, Part, concat, report, sum_ms, sum_u64, warnings};

pub(super) fn merge(parts: &[Part]) -> Result<Value, MergeError> {
    let first = &parts[0];
    let mut waves = concat(parts, "/waves")?.into_iter();
    let Some(Value::Object(wave)) = waves.next() else {
        return Err(MergeError::Malformed {
            name: first.name.clone(),
            what: "the sweep has no wave (or a wave is not an object)".to_owned(),
        });
    };
    let other: Vec<Value> = waves.collect();
    let get = |k: &str| first.answer.get(k).cloned();
    let mut out = Map::new();
    // The member order of the unsharded answer (`WorkspaceResponse`).
    for k in ["mode", "grid"] {
        if let Some(v) = get(k) {
            out.insert(k.to_owned(), v);
        }
    }
    out.extend(wave);
    if !other.is_empty() {
        out.insert("other_waves".to_owned(), Value::Array(other));
    }
    out.insert(
        "timing_ms".to_owned(),
        Value::from(sum_ms(parts, "/timing_ms")?),
    );
    out.insert("warnings".to_owned(), warnings(parts, "/warnings"));
    if let Some(p) = get("preset") {
        out.insert("preset".to_owned(), p);
    }
    // Every shard's report counts the assembly-mode search that seeds the waves: the sum is
    // the work done by all shards (see the module docs).
    let counters = (
        sum_u64(parts, "/report/iterations")?,
        sum_u64(parts, "/report/evaluations")?,
    );
    out.insert("report".to_owned(), report(parts, "/report", counters)?);
    Ok(Value::Object(out))
}
