//! `/v1/irefc-stress` mode `sweep` (rule: `StressSweepResponse::shard`): `records`
//! concatenated in shard order; `n_valid`, `n_invalid`, `n_not_evaluated` and
//! `meta.n_combinations` added; `best`/`worst` among the shards' picks the smallest/largest
//! `sigma_max_MPa`, the lowest index on ties.

use serde_json::Value;

use super::{MergeError, Part, concat, remove, report, set, sum_ms, sum_u64, warnings};

pub(super) fn merge(parts: &[Part]) -> Result<Value, MergeError> {
    let records = concat(parts, "/records")?;
    let mut out = parts[0].answer.clone();
    set(&mut out, "/records", Value::Array(records));
    set(&mut out, "/worst", pick(parts, "/worst", true)?);
    set(&mut out, "/best", pick(parts, "/best", false)?);
    remove(&mut out, "/shard");
    for counter in [
        "/n_valid",
        "/n_invalid",
        "/n_not_evaluated",
        "/meta/n_combinations",
    ] {
        set(&mut out, counter, Value::from(sum_u64(parts, counter)?));
    }
    set(&mut out, "/warnings", warnings(parts, "/warnings"));
    let threads = parts
        .iter()
        .filter_map(|p| p.answer.pointer("/meta/threads").and_then(Value::as_u64))
        .max()
        .unwrap_or(1);
    set(&mut out, "/meta/threads", Value::from(threads));
    set(
        &mut out,
        "/meta/compute_ms",
        Value::from(sum_ms(parts, "/meta/compute_ms")?),
    );
    let counters = (
        sum_u64(parts, "/meta/solver/iterations")?,
        sum_u64(parts, "/meta/solver/evaluations")?,
    );
    set(
        &mut out,
        "/meta/solver",
        report(parts, "/meta/solver", counters)?,
    );
    Ok(out)
}

/// The merged `best` (`worst`: largest): among the shards' picks (global indices) the one with
/// the smallest (largest) `sigma_max_MPa`, the lowest index on ties; `null` when no shard has
/// a valid record.
fn pick(parts: &[Part], pointer: &str, largest: bool) -> Result<Value, MergeError> {
    let mut out: Option<(u64, f64)> = None;
    for p in parts {
        let Some(i) = p.answer.pointer(pointer).and_then(Value::as_u64) else {
            continue;
        };
        let bad = |what: String| MergeError::Malformed {
            name: p.name.clone(),
            what,
        };
        let local = i
            .checked_sub(p.block.start)
            .filter(|&l| i < p.block.end && usize::try_from(l).is_ok())
            .ok_or_else(|| {
                bad(format!(
                    "{pointer} = {i} is outside the shard's records {}..{}",
                    p.block.start, p.block.end
                ))
            })?;
        let s = p
            .answer
            .pointer(&format!("/records/{local}/sigma_max_MPa"))
            .and_then(Value::as_f64)
            .ok_or_else(|| bad(format!("record {i} ({pointer}) has no sigma_max_MPa")))?;
        // Shards come in index order: a strict comparison keeps the lowest index on ties.
        let better = out.is_none_or(|(_, o)| if largest { s > o } else { s < o });
        if better {
            out = Some((i, s));
        }
    }
    Ok(out.map_or(Value::Null, |(i, _)| Value::from(i)))
}
