//! The answers of shards `0..count` of one sweep, merged into the answer of the unsharded
//! request (`mechcalc merge`).
//!
//! A sweep request with `shard: {index, count}` computes block `index` of `count` contiguous
//! blocks of its items, and its answer states the block (`ShardOut {index, count, start, end,
//! total}`) and documents how the blocks merge. This module applies that rule to the answers as
//! JSON ([`serde_json::Value`]), so shards computed anywhere (`mechcalc run --shard`, the pods
//! of a Kubernetes Indexed Job, a Slurm array, `curl` against the service) merge without the
//! response types having to be read back:
//!
//! | endpoint | items | merged |
//! |---|---|---|
//! | `/v1/irefc-stress` (mode `sweep`) | `records` | `n_valid`, `n_invalid`, `n_not_evaluated`, `meta.n_combinations` added; `best`/`worst` the shards' picks with the smallest/largest `sigma_max_MPa`, the lowest index on ties |
//! | `/v1/bus-fuel-economy` | `results`, `motor_maps` | `comparison` recomputed from the merged results with the request's normalised desirability weights (paper eq. 11-13) |
//! | `/v1/machining-size/train` (k-fold CV) | `metrics.cv.folds` | `R2_mean`, `R2_sd`, `RMSE_mean`, `RMSE_sd`, `MAE_mean` recomputed over the merged folds |
//! | `/v1/continuum-workspace` (mode `workspace`) | `waves` | the first wave at the top level, the others as `other_waves` |
//!
//! Everything else in a shard's answer (settings, the trained model, the grid, `total`, `count`)
//! is the same in every shard of one request: the merge refuses shards that differ there (a
//! different request), shards of different `count` or `total`, a duplicated or a missing
//! index, and a block that is not the one `Shard::range` gives. Shards may be given in any
//! order. The merged answer equals the unsharded answer number for number (numbers compared
//! as JSON text), except for what describes each run rather than the request:
//!
//! * timings (`elapsed_ms`, `compute_ms`, `timing_ms`) are the sum over the shards, i.e. the
//!   compute time spent on the whole sweep (a parallel run takes less wall-clock time);
//! * the IREFC sweep's `meta.threads` is the largest of the shards' (each shard uses at most
//!   as many threads as it has combinations);
//! * `report.stop_reason` is the first shard's that is not `completed`/`converged` (a budget
//!   ran out there), else the first shard's; `report.iterations` and `report.evaluations` are
//!   exact for the IREFC sweep and the bus comparison (the shards' counts add up) and for the
//!   training (the model's trees once plus every fold's), and for the continuum workspace the
//!   sum over the shards: every shard repeats the assembly-mode search that seeds the waves,
//!   so that sum is the work done, more than an unsharded run does.
//!
//! A shard that holds no item (more shards than items) is valid and merges to nothing.
//!
//! Two requests that differ only in a value no shard echoes (a load, a material constant)
//! give answers whose shared parts are equal: `mechcalc run --shard` therefore adds the
//! SHA-256 of the request without its `shard` ([`request_digest`]) to each shard's answer as
//! [`DIGEST_MEMBER`], and the merge refuses shards whose digests differ, or differ from the
//! digest of the request given with `--request`, and drops the member from the merged answer.
//! Shards fetched from the service have no digest and are checked by their answers alone.

mod bus;
mod continuum;
mod irefc;
mod machining;

use std::fmt::Write as _;

use serde_json::{Map, Value};
use sha2::{Digest, Sha256};

use crate::calc::common::Shard;

/// Member that `mechcalc run --shard` adds to a shard's answer: the [`request_digest`] of the
/// request it computed.
pub const DIGEST_MEMBER: &str = "shard_request_sha256";

/// SHA-256 (hex) of a request without its top-level `shard`, over its canonical JSON (object
/// members sorted by name, no white space, numbers as parsed): the same for every shard of
/// one request however its file is laid out, different for two different requests.
#[must_use]
pub fn request_digest(request: &Value) -> String {
    fn canonical(v: &Value) -> Value {
        match v {
            Value::Object(m) => {
                let mut keys: Vec<&String> = m.keys().collect();
                keys.sort();
                Value::Object(
                    keys.into_iter()
                        .map(|k| (k.clone(), canonical(&m[k])))
                        .collect(),
                )
            }
            Value::Array(a) => Value::Array(a.iter().map(canonical).collect()),
            _ => v.clone(),
        }
    }
    let mut v = canonical(request);
    if let Some(o) = v.as_object_mut() {
        o.shift_remove("shard");
    }
    let digest = Sha256::digest(v.to_string().as_bytes());
    digest.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// A sweep endpoint whose sharded answers merge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sweep {
    /// `POST /v1/irefc-stress`, mode `sweep`: the design combinations.
    IrefcStress,
    /// `POST /v1/bus-fuel-economy`: the motor × cycle pairs.
    BusFuelEconomy,
    /// `POST /v1/machining-size/train` with `validation.k_fold`: the cross-validation folds.
    MachiningTrain,
    /// `POST /v1/continuum-workspace`, mode `workspace`: the waves of the sweep.
    ContinuumWorkspace,
}

impl Sweep {
    /// Every shardable endpoint.
    pub const ALL: [Self; 4] = [
        Self::IrefcStress,
        Self::BusFuelEconomy,
        Self::MachiningTrain,
        Self::ContinuumWorkspace,
    ];

    /// The endpoint's path.
    #[must_use]
    pub const fn path(self) -> &'static str {
        match self {
            Self::IrefcStress => "/v1/irefc-stress",
            Self::BusFuelEconomy => "/v1/bus-fuel-economy",
            Self::MachiningTrain => "/v1/machining-size/train",
            Self::ContinuumWorkspace => "/v1/continuum-workspace",
        }
    }

    /// The shardable endpoint at `path` (a full path such as `/v1/irefc-stress`).
    #[must_use]
    pub fn from_path(path: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.path() == path)
    }

    /// JSON pointer of the shard statement (`ShardOut`) in a sharded answer.
    #[must_use]
    pub const fn shard_pointer(self) -> &'static str {
        match self {
            Self::MachiningTrain => "/metrics/cv/shard",
            _ => "/shard",
        }
    }

    /// JSON pointer of the per-item array of a sharded answer.
    #[must_use]
    pub const fn items_pointer(self) -> &'static str {
        match self {
            Self::IrefcStress => "/records",
            Self::BusFuelEconomy => "/results",
            Self::MachiningTrain => "/metrics/cv/folds",
            Self::ContinuumWorkspace => "/waves",
        }
    }

    /// What the endpoint splits, for messages.
    #[must_use]
    pub const fn items(self) -> &'static str {
        match self {
            Self::IrefcStress => "design combinations (mode \"sweep\")",
            Self::BusFuelEconomy => "motor × cycle pairs",
            Self::MachiningTrain => "cross-validation folds (validation.k_fold)",
            Self::ContinuumWorkspace => "waves of a workspace sweep (mode \"workspace\")",
        }
    }

    /// Pointers of what differs from shard to shard of one request: the items, what is merged
    /// from them, the shard statement, warnings and the per-run cost. Everything else must be
    /// equal in every shard.
    const fn per_shard(self) -> &'static [&'static str] {
        match self {
            Self::IrefcStress => &[
                "/records",
                "/worst",
                "/best",
                "/shard",
                "/n_valid",
                "/n_invalid",
                "/n_not_evaluated",
                "/warnings",
                "/meta/n_combinations",
                "/meta/threads",
                "/meta/compute_ms",
                "/meta/solver",
            ],
            Self::BusFuelEconomy => &[
                "/results",
                "/comparison",
                "/motor_maps",
                "/shard",
                "/report",
            ],
            Self::MachiningTrain => &["/metrics/cv", "/report", "/warnings"],
            Self::ContinuumWorkspace => &["/waves", "/shard", "/timing_ms", "/warnings", "/report"],
        }
    }
}

/// One shard's answer and where it came from (a file name, for messages).
#[derive(Debug, Clone)]
pub struct ShardFile {
    /// Where the answer came from (a file name).
    pub name: String,
    /// The shard's answer, as the endpoint sent it.
    pub answer: Value,
}

/// Why shards cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No shard was given.
    #[error("no shard answers to merge")]
    NoShards,
    /// A shard's answer is a problem document: that shard failed.
    #[error("{name} is not an answer but a problem (status {status}): {detail}")]
    Problem {
        /// The shard.
        name: String,
        /// Its HTTP status.
        status: u64,
        /// Its title and detail.
        detail: String,
    },
    /// A shard's answer states no shard: it is not a sharded answer of this endpoint.
    #[error(
        "{name} has no shard statement at {pointer}: it is not an answer of {path} computed \
         with a shard (the endpoint splits {items})"
    )]
    NoShard {
        /// The shard.
        name: String,
        /// Where the statement should be.
        pointer: &'static str,
        /// The endpoint.
        path: &'static str,
        /// What it splits.
        items: &'static str,
    },
    /// A shard's answer is an answer of another endpoint.
    #[error("{name} is not an answer of {path}: it has no {pointer}")]
    WrongEndpoint {
        /// The shard.
        name: String,
        /// The endpoint.
        path: &'static str,
        /// The per-item array it lacks.
        pointer: &'static str,
    },
    /// A shard's answer is not of the expected shape.
    #[error("{name}: {what}")]
    Malformed {
        /// The shard.
        name: String,
        /// What is wrong.
        what: String,
    },
    /// Two shards split the sweep into a different number of blocks.
    #[error(
        "{a} is shard {a_index} of {a_count} but {b} is shard {b_index} of {b_count}: shards of \
         one run have one count"
    )]
    CountMismatch {
        /// First shard.
        a: String,
        /// Its index.
        a_index: u64,
        /// Its count.
        a_count: u64,
        /// The other shard.
        b: String,
        /// Its index.
        b_index: u64,
        /// Its count.
        b_count: u64,
    },
    /// Two shards split sweeps of different sizes: different requests.
    #[error(
        "{a} splits a sweep of {a_total} items but {b} one of {b_total}: the shards come from \
         different requests"
    )]
    TotalMismatch {
        /// First shard.
        a: String,
        /// Its total.
        a_total: u64,
        /// The other shard.
        b: String,
        /// Its total.
        b_total: u64,
    },
    /// Two answers of the same shard index.
    #[error("shard {index} is given twice: {a} and {b}")]
    Duplicate {
        /// The index.
        index: u64,
        /// First answer.
        a: String,
        /// Second answer.
        b: String,
    },
    /// Shards missing from `0..count`.
    #[error("{missing} of {count} shards missing: index {list}")]
    Missing {
        /// How many are missing.
        missing: usize,
        /// Shards in all.
        count: u64,
        /// The missing indices (the first ones).
        list: String,
    },
    /// Two shards differ where every shard of one request is the same.
    #[error(
        "{b} differs from {a} at {pointer} ({left} vs {right}): every shard of one request has \
         the same value there, so the shards come from different requests"
    )]
    Differs {
        /// The reference shard.
        a: String,
        /// The differing shard.
        b: String,
        /// Where.
        pointer: String,
        /// The reference value (JSON, shortened).
        left: String,
        /// The other value (JSON, shortened).
        right: String,
    },
    /// The merge needs the request and none was given.
    #[error("merging {path} shards needs the request (--request FILE): {why}")]
    NeedsRequest {
        /// The endpoint.
        path: &'static str,
        /// What the request supplies.
        why: &'static str,
    },
    /// The request given does not fit the shards or is invalid.
    #[error("the request: {0}")]
    Request(String),
    /// Shards computed from different requests (their request digests differ).
    #[error(
        "{b} was computed from another request than {a} ({DIGEST_MEMBER} {b_digest} vs \
         {a_digest}): the shards come from different requests"
    )]
    DigestMismatch {
        /// The reference shard (or `--request`).
        a: String,
        /// Its digest.
        a_digest: String,
        /// The other shard.
        b: String,
        /// Its digest (`none` when absent).
        b_digest: String,
    },
}

/// One shard's statement of its block, read from its answer.
#[derive(Debug, Clone, Copy)]
struct Block {
    index: u64,
    count: u64,
    start: u64,
    end: u64,
    total: u64,
}

/// A shard's answer with its block.
struct Part {
    name: String,
    block: Block,
    answer: Value,
}

/// The answer of the unsharded request from the answers of its shards `0..count` (given in any
/// order). `request` is the request the shards were computed from (without or with a `shard`
/// member); the bus comparison needs it (its desirability weights are not in the shards'
/// answers) and then checks that it fits the shards.
///
/// # Errors
/// [`MergeError`]: a shard missing, duplicated, of another count, sweep or request, not a
/// sharded answer of this endpoint, or a request that does not fit.
pub fn merge(
    sweep: Sweep,
    shards: Vec<ShardFile>,
    request: Option<&Value>,
) -> Result<Value, MergeError> {
    let mut parts = order(sweep, shards)?;
    same_digest(&mut parts, request)?;
    same_request(sweep, &parts)?;
    match sweep {
        Sweep::IrefcStress => irefc::merge(&parts),
        Sweep::BusFuelEconomy => bus::merge(&parts, request),
        Sweep::MachiningTrain => machining::merge(&parts),
        Sweep::ContinuumWorkspace => continuum::merge(&parts),
    }
}

/// The request with `shard` set to `index` of `count` (replacing any `shard` it has), after
/// checking that `path` is a shardable endpoint.
///
/// # Errors
/// The endpoint splits nothing, or the request is not a JSON object.
pub fn with_shard(path: &str, request: &Value, shard: Shard) -> Result<Value, String> {
    if Sweep::from_path(path).is_none() {
        return Err(format!(
            "{path} cannot be sharded: it has no sweep to split. Shardable endpoints: {}",
            Sweep::ALL
                .iter()
                .map(|s| format!("{} ({})", s.path(), s.items()))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let mut req = request.clone();
    let Some(obj) = req.as_object_mut() else {
        return Err("the request is not a JSON object".to_owned());
    };
    obj.insert(
        "shard".to_owned(),
        serde_json::json!({"index": shard.index, "count": shard.count}),
    );
    Ok(req)
}

/// Reads every shard's block, checks that the blocks are exactly `0..count` of one sweep and
/// returns the shards in index order.
fn order(sweep: Sweep, shards: Vec<ShardFile>) -> Result<Vec<Part>, MergeError> {
    if shards.is_empty() {
        return Err(MergeError::NoShards);
    }
    let mut parts = Vec::with_capacity(shards.len());
    for f in shards {
        let block = block(sweep, &f)?;
        parts.push(Part {
            name: f.name,
            block,
            answer: f.answer,
        });
    }
    let first = &parts[0];
    for p in &parts[1..] {
        if p.block.count != first.block.count {
            return Err(MergeError::CountMismatch {
                a: first.name.clone(),
                a_index: first.block.index,
                a_count: first.block.count,
                b: p.name.clone(),
                b_index: p.block.index,
                b_count: p.block.count,
            });
        }
        if p.block.total != first.block.total {
            return Err(MergeError::TotalMismatch {
                a: first.name.clone(),
                a_total: first.block.total,
                b: p.name.clone(),
                b_total: p.block.total,
            });
        }
    }
    // A stable sort: of two answers of one index, the first given is named first.
    parts.sort_by_key(|p| p.block.index);
    for w in parts.windows(2) {
        if w[0].block.index == w[1].block.index {
            return Err(MergeError::Duplicate {
                index: w[0].block.index,
                a: w[0].name.clone(),
                b: w[1].name.clone(),
            });
        }
    }
    let count = parts[0].block.count;
    if parts.len() as u64 != count {
        let have: std::collections::BTreeSet<u64> = parts.iter().map(|p| p.block.index).collect();
        let missing: Vec<u64> = (0..count).filter(|i| !have.contains(i)).collect();
        let mut list = missing
            .iter()
            .take(20)
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", ");
        if missing.len() > 20 {
            let _ = write!(list, " and {} more", missing.len() - 20);
        }
        return Err(MergeError::Missing {
            missing: missing.len(),
            count,
            list,
        });
    }
    Ok(parts)
}

/// The block a shard's answer states, checked against `Shard::range`.
fn block(sweep: Sweep, f: &ShardFile) -> Result<Block, MergeError> {
    let malformed = |what: String| MergeError::Malformed {
        name: f.name.clone(),
        what,
    };
    let Some(obj) = f.answer.as_object() else {
        return Err(malformed("the answer is not a JSON object".to_owned()));
    };
    if let (Some(status), Some(Value::String(_))) =
        (obj.get("status").and_then(Value::as_u64), obj.get("type"))
    {
        let text = |k: &str| obj.get(k).and_then(Value::as_str).unwrap_or("").to_owned();
        return Err(MergeError::Problem {
            name: f.name.clone(),
            status,
            detail: format!("{}: {}", text("title"), text("detail")),
        });
    }
    let pointer = sweep.shard_pointer();
    let Some(s) = f.answer.pointer(pointer) else {
        return Err(MergeError::NoShard {
            name: f.name.clone(),
            pointer,
            path: sweep.path(),
            items: sweep.items(),
        });
    };
    if f.answer.pointer(sweep.items_pointer()).is_none() {
        return Err(MergeError::WrongEndpoint {
            name: f.name.clone(),
            path: sweep.path(),
            pointer: sweep.items_pointer(),
        });
    }
    let field = |k: &str| {
        s.get(k).and_then(Value::as_u64).ok_or_else(|| {
            malformed(format!(
                "{pointer}/{k} is missing or not a non-negative integer"
            ))
        })
    };
    let b = Block {
        index: field("index")?,
        count: field("count")?,
        start: field("start")?,
        end: field("end")?,
        total: field("total")?,
    };
    let (Ok(index), Ok(count), Ok(total)) = (
        u32::try_from(b.index),
        u32::try_from(b.count),
        usize::try_from(b.total),
    ) else {
        return Err(malformed(format!("{pointer} is out of range")));
    };
    if count == 0 || index >= count {
        return Err(malformed(format!(
            "{pointer} states shard {index} of {count}"
        )));
    }
    let r = Shard { index, count }.range(total);
    if (r.start as u64, r.end as u64) != (b.start, b.end) {
        return Err(malformed(format!(
            "{pointer} states items {}..{}, but shard {index} of {count} of {total} items holds \
             {}..{}",
            b.start, b.end, r.start, r.end
        )));
    }
    Ok(b)
}

/// Checks that every shard carries the same request digest as the first (all or none) and as
/// `request` when given, and removes the digests from the answers.
fn same_digest(parts: &mut [Part], request: Option<&Value>) -> Result<(), MergeError> {
    let digests: Vec<Option<Value>> = parts
        .iter_mut()
        .map(|p| {
            p.answer
                .as_object_mut()
                .and_then(|o| o.shift_remove(DIGEST_MEMBER))
        })
        .collect();
    let text = |d: &Option<Value>| match d {
        Some(Value::String(s)) => s.clone(),
        Some(v) => v.to_string(),
        None => "none".to_owned(),
    };
    for (p, d) in parts.iter().zip(&digests).skip(1) {
        if d != &digests[0] {
            return Err(MergeError::DigestMismatch {
                a: parts[0].name.clone(),
                a_digest: text(&digests[0]),
                b: p.name.clone(),
                b_digest: text(d),
            });
        }
    }
    if let (Some(req), Some(d)) = (request, &digests[0]) {
        let want = Value::String(request_digest(req));
        if &want != d {
            return Err(MergeError::DigestMismatch {
                a: "the request given (--request)".to_owned(),
                a_digest: text(&Some(want)),
                b: parts[0].name.clone(),
                b_digest: text(&digests[0]),
            });
        }
    }
    Ok(())
}

/// Checks that every shard equals the first outside what differs from shard to shard.
fn same_request(sweep: Sweep, parts: &[Part]) -> Result<(), MergeError> {
    let strip = |v: &Value| {
        let mut v = v.clone();
        for p in sweep.per_shard() {
            remove(&mut v, p);
        }
        v
    };
    let reference = strip(&parts[0].answer);
    for p in &parts[1..] {
        let other = strip(&p.answer);
        if let Some((pointer, left, right)) = first_difference(&reference, &other, "") {
            return Err(MergeError::Differs {
                a: parts[0].name.clone(),
                b: p.name.clone(),
                pointer: if pointer.is_empty() {
                    "/".to_owned()
                } else {
                    pointer
                },
                left: short(&left),
                right: short(&right),
            });
        }
    }
    Ok(())
}

/// Where `a` and `b` first differ (numbers compared as JSON text), with the two values there.
fn first_difference(a: &Value, b: &Value, at: &str) -> Option<(String, Value, Value)> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                match y.get(k) {
                    Some(vb) => {
                        if let Some(d) = first_difference(va, vb, &p) {
                            return Some(d);
                        }
                    }
                    None => return Some((p, va.clone(), Value::Null)),
                }
            }
            y.iter().find(|(k, _)| !x.contains_key(*k)).map(|(k, vb)| {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                (p, Value::Null, vb.clone())
            })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (va, vb))| first_difference(va, vb, &format!("{at}/{i}"))),
        // As JSON text: -0.0 and 0.0 differ, as they do in the answers.
        _ if same_text(a, b) => None,
        _ => Some((at.to_owned(), a.clone(), b.clone())),
    }
}

/// Whether two values have the same JSON text.
fn same_text(a: &Value, b: &Value) -> bool {
    let (x, y) = (a.to_string(), b.to_string());
    x == y
}

/// A value as JSON, shortened for a message.
fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 60 {
        let head: String = s.chars().take(57).collect();
        format!("{head}...")
    } else {
        s
    }
}

/// Removes the member at `pointer` (keeping the order of the others).
fn remove(v: &mut Value, pointer: &str) -> Option<Value> {
    let (parent, key) = pointer.rsplit_once('/')?;
    let obj = if parent.is_empty() {
        v.as_object_mut()?
    } else {
        v.pointer_mut(parent)?.as_object_mut()?
    };
    obj.shift_remove(key)
}

/// The array at `pointer` of a shard, checked to hold the shard's block of items.
fn items<'a>(p: &'a Part, pointer: &str) -> Result<&'a [Value], MergeError> {
    let a = p
        .answer
        .pointer(pointer)
        .and_then(Value::as_array)
        .ok_or_else(|| MergeError::Malformed {
            name: p.name.clone(),
            what: format!("{pointer} is missing or not an array"),
        })?;
    if a.len() as u64 != p.block.end - p.block.start {
        return Err(MergeError::Malformed {
            name: p.name.clone(),
            what: format!(
                "{pointer} has {} items, but the shard states items {}..{}",
                a.len(),
                p.block.start,
                p.block.end
            ),
        });
    }
    Ok(a)
}

/// The per-item arrays at `pointer` of every shard, concatenated in shard order.
fn concat(parts: &[Part], pointer: &str) -> Result<Vec<Value>, MergeError> {
    let mut out = Vec::new();
    for p in parts {
        out.extend(items(p, pointer)?.iter().cloned());
    }
    Ok(out)
}

/// A number at `pointer` of a shard.
fn number<'a>(p: &'a Part, pointer: &str) -> Result<&'a serde_json::Number, MergeError> {
    match p.answer.pointer(pointer) {
        Some(Value::Number(n)) => Ok(n),
        _ => Err(MergeError::Malformed {
            name: p.name.clone(),
            what: format!("{pointer} is missing or not a number"),
        }),
    }
}

/// The sum over the shards of the counter at `pointer`.
fn sum_u64(parts: &[Part], pointer: &str) -> Result<u64, MergeError> {
    let mut s = 0u64;
    for p in parts {
        let n = number(p, pointer)?
            .as_u64()
            .ok_or_else(|| MergeError::Malformed {
                name: p.name.clone(),
                what: format!("{pointer} is not a non-negative integer"),
            })?;
        s = s.saturating_add(n);
    }
    Ok(s)
}

/// The sum over the shards of the time at `pointer` \[ms\].
fn sum_ms(parts: &[Part], pointer: &str) -> Result<f64, MergeError> {
    let mut s = 0.0;
    for p in parts {
        s += number(p, pointer)?.as_f64().unwrap_or(0.0);
    }
    Ok(s)
}

/// The union of the shards' warnings at `pointer`, in order of first appearance.
fn warnings(parts: &[Part], pointer: &str) -> Value {
    let mut out: Vec<Value> = Vec::new();
    for p in parts {
        for w in p
            .answer
            .pointer(pointer)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if !out.contains(w) {
                out.push(w.clone());
            }
        }
    }
    Value::Array(out)
}

/// The merged `report` (`SolverReport`) at `pointer`: the stop reason as the module docs say,
/// `iterations` and `evaluations` from `counters`, `elapsed_ms` summed.
fn report(parts: &[Part], pointer: &str, counters: (u64, u64)) -> Result<Value, MergeError> {
    let reasons: Vec<&str> = parts
        .iter()
        .map(|p| {
            p.answer
                .pointer(&format!("{pointer}/stop_reason"))
                .and_then(Value::as_str)
                .ok_or_else(|| MergeError::Malformed {
                    name: p.name.clone(),
                    what: format!("{pointer}/stop_reason is missing"),
                })
        })
        .collect::<Result<_, _>>()?;
    let stop = reasons
        .iter()
        .find(|r| !matches!(**r, "completed" | "converged"))
        .unwrap_or(&reasons[0]);
    let mut out = Map::new();
    out.insert("stop_reason".to_owned(), Value::from(*stop));
    out.insert("iterations".to_owned(), Value::from(counters.0));
    out.insert("evaluations".to_owned(), Value::from(counters.1));
    out.insert(
        "elapsed_ms".to_owned(),
        Value::from(sum_ms(parts, &format!("{pointer}/elapsed_ms"))?),
    );
    Ok(Value::Object(out))
}

/// Sets the member at `pointer` (its parent must exist), keeping its place when it exists.
fn set(v: &mut Value, pointer: &str, value: Value) {
    if let Some(slot) = v.pointer_mut(pointer) {
        *slot = value;
        return;
    }
    if let Some((parent, key)) = pointer.rsplit_once('/') {
        let obj = if parent.is_empty() {
            v.as_object_mut()
        } else {
            v.pointer_mut(parent).and_then(Value::as_object_mut)
        };
        if let Some(o) = obj {
            o.insert(key.to_owned(), value);
        }
    }
}

/// `obj` with `(key, value)` inserted right after `after` (at the end when `after` is absent).
fn insert_after(
    obj: Map<String, Value>,
    after: &str,
    key: &str,
    value: Value,
) -> Map<String, Value> {
    let mut out = Map::new();
    let mut value = Some(value);
    for (k, v) in obj {
        let here = k == after;
        out.insert(k, v);
        if here && let Some(v) = value.take() {
            out.insert(key.to_owned(), v);
        }
    }
    if let Some(v) = value {
        out.insert(key.to_owned(), v);
    }
    out
}
