//! Wire conventions shared by every endpoint, so a client learns them once:
//!
//! * `time_limit_ms` (top level, optional): the request's own wall-clock budget, bounded by
//!   [`TIME_LIMIT_MS`] and capped by the service's `--max-time-budget-ms`;
//! * `report` ([`SolverReport`](crate::numerics::SolverReport), schema `Report`): how the work
//!   stopped and what it cost, on every endpoint with iterative or swept work;
//! * `warnings`: a list of [`Warning`] `{code, message, pointer?}`;
//! * a sign (assembly mode, branch, side) is the integer `1` or `-1`: [`Sign`] (schema `Sign`),
//!   its meaning given by the field's description;
//! * optional outputs are omitted when not requested, never sent as `null`;
//! * `shard` (top level, optional, on the sweeps): [`Shard`] `{index, count}` splits a sweep into
//!   `count` contiguous blocks of near-equal size, the answer says which block it holds
//!   ([`ShardOut`]) and the blocks' answers merge into exactly the unsharded answer;
//! * the size of an answer is estimated from the validated request before computing
//!   ([`ResponseSize`]); an estimate above the service's `--max-response-bytes` is a 422
//!   `RESPONSE_TOO_LARGE` naming the option to change.

use crate::calc::rules::ensure_rule;
use std::ops::Range as Span;
use std::time::Duration;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;
use utoipa::openapi::RefOr;
use utoipa::openapi::schema::{ObjectBuilder, Schema, SchemaType, Type};

use super::bounds::Range;
use super::problem::{CalcFailure, FieldIssue, ProblemClass, Validator};
use super::rules::CrossRule;
use crate::numerics::Budget;

/// Bound of every request's `time_limit_ms` \[ms\]: from 1 ms to 10 minutes.
pub const TIME_LIMIT_MS: Range = Range::int(1, 600_000);

/// Something the caller should know about an answer that is nevertheless returned.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, ToSchema)]
pub struct Warning {
    /// Stable machine-readable code (e.g. `NEAR_SINGULAR`), from the module's spec.
    pub code: String,
    /// Human-readable explanation naming the quantity and the value.
    pub message: String,
    /// JSON pointer into the request of the field the warning is about, when it is about one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pointer: Option<String>,
}

impl Warning {
    /// A warning not tied to one request field.
    #[must_use]
    pub fn new(code: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            code: code.into(),
            message: message.into(),
            pointer: None,
        }
    }

    /// A warning about the request field at `pointer`.
    #[must_use]
    pub fn at(
        code: impl Into<String>,
        pointer: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            code: code.into(),
            message: message.into(),
            pointer: Some(pointer.into()),
        }
    }
}

/// A sign on the wire: the integer `1` or `-1` (schema `Sign`). What it selects (an assembly
/// mode, a branch, a side) is stated by the field that carries it.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, crate::calc::Rules,
)]
#[serde(try_from = "i64", into = "i64")]
pub enum Sign {
    /// `1`.
    #[default]
    Plus,
    /// `-1`.
    Minus,
}

impl TryFrom<i64> for Sign {
    type Error = String;
    fn try_from(v: i64) -> Result<Self, Self::Error> {
        match v {
            1 => Ok(Self::Plus),
            -1 => Ok(Self::Minus),
            _ => Err(format!("must be 1 or -1, got {v}")),
        }
    }
}

impl From<Sign> for i64 {
    fn from(s: Sign) -> Self {
        match s {
            Sign::Plus => 1,
            Sign::Minus => -1,
        }
    }
}

impl utoipa::PartialSchema for Sign {
    fn schema() -> RefOr<Schema> {
        ObjectBuilder::new()
            .schema_type(SchemaType::new(Type::Integer))
            .enum_values(Some([1, -1]))
            .description(Some("A sign: 1 or -1."))
            .into()
    }
}

impl ToSchema for Sign {
    fn name() -> std::borrow::Cow<'static, str> {
        std::borrow::Cow::Borrowed("Sign")
    }
}

/// Validates an optional top-level `time_limit_ms` and converts it.
pub fn time_limit(v: &mut Validator, time_limit_ms: Option<u64>) -> Option<Duration> {
    let ms = time_limit_ms?;
    v.uint("/time_limit_ms", "time_limit_ms", ms, TIME_LIMIT_MS)
        .then(|| Duration::from_millis(ms))
}

/// A request type with the top-level `time_limit_ms` of the wire convention; the HTTP layer reads
/// it before the job is queued, so the budget covers queueing too.
pub trait TimeLimited {
    /// The request's own time limit, if it gives one (unvalidated; out-of-range values are
    /// rejected by the module's validator and only ever shorten the budget here).
    fn time_limit(&self) -> Option<Duration>;
}

/// Bound of `shard.count`: 1 (unsharded) to 10 000 replicas.
pub const SHARD_COUNT: Range = Range::int(1, 10_000);
/// Bound of `shard.index` (also below `shard.count`, a cross-field rule).
pub const SHARD_INDEX: Range = Range::int(0, 9_999);

/// Which part of a sweep this request computes: block `index` of `count` contiguous blocks of
/// near-equal size (sizes differ by at most one, the larger blocks first), so a large sweep can
/// be split deterministically across replicas or the pods of a Kubernetes Indexed Job
/// (`index` = `JOB_COMPLETION_INDEX`, `count` = `completions`).
///
/// Every item is computed exactly as in the unsharded request (same inputs, same order of
/// operations), so the answers of shards `0..count`, merged by the rule of the endpoint's
/// [`ShardOut`], equal the unsharded answer number for number. Budgets (`time_limit_ms`) apply
/// to each shard on its own.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[serde(deny_unknown_fields)]
pub struct Shard {
    /// Block computed by this request, 0 ≤ index < count.
    #[rule(range = SHARD_INDEX)]
    #[schema(example = 0)]
    pub index: u32,
    /// Number of blocks the sweep is split into (1 = the whole sweep).
    #[rule(range = SHARD_COUNT)]
    #[schema(example = 4)]
    pub count: u32,
}

impl Shard {
    /// The whole sweep (one block).
    pub const WHOLE: Self = Self { index: 0, count: 1 };

    /// Items `start..end` of `len` that this shard computes: the first `len % count` blocks
    /// hold `len / count + 1` items, the others `len / count`; blocks are contiguous and in
    /// index order, so concatenating the blocks of shards `0..count` gives `0..len`. Empty when
    /// there are more shards than items.
    #[must_use]
    pub fn range(self, len: usize) -> Span<usize> {
        let count = (self.count as usize).max(1);
        let index = (self.index as usize).min(count);
        let (base, extra) = (len / count, len % count);
        let start = index * base + index.min(extra);
        let end = if index < count {
            start + base + usize::from(index < extra)
        } else {
            start
        };
        start.min(len)..end.min(len)
    }

    /// Whether this is more than the whole sweep in one block.
    #[must_use]
    pub fn is_split(self) -> bool {
        self.count > 1
    }

    /// The answer's statement of this shard over `len` items.
    #[must_use]
    pub fn out(self, len: usize) -> ShardOut {
        let r = self.range(len);
        ShardOut {
            index: self.index,
            count: self.count,
            start: r.start as u64,
            end: r.end as u64,
            total: len as u64,
        }
    }
}

/// The part of a sweep a sharded answer holds: items `start..end` (global indices, end
/// exclusive) of `total`.
///
/// Merge rule (every sharded endpoint): request shards `0..count` with the same body, then
/// concatenate the per-item arrays in shard index order (item `start + i` of the whole sweep is
/// item `i` of the shard whose range contains it); global indices in a shard's answer (e.g.
/// `best`/`worst`) already count from the start of the whole sweep; counters over items add
/// up; everything else that is not per item (settings, `total`) is the same in every shard.
/// Reductions over all items (minima, maxima, means, comparisons) are named by each endpoint
/// and recomputed from the merged items as it documents. Timings and the `report` are per
/// shard.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
pub struct ShardOut {
    /// Block index (as requested).
    pub index: u32,
    /// Number of blocks (as requested).
    pub count: u32,
    /// Global index of this block's first item.
    pub start: u64,
    /// Global index one past this block's last item (`start` when the block is empty).
    pub end: u64,
    /// Items of the whole (unsharded) sweep.
    pub total: u64,
}

/// A shard's index lies below its count.
pub const SHARD_INDEX_BELOW_COUNT: CrossRule = CrossRule::invalid(
    "SHARD_INDEX_BELOW_COUNT",
    &["/shard/index", "/shard/count"],
    "shard.index < shard.count.",
);

/// The rule between the two fields of a top-level `shard` (their ranges are checked at the door).
pub fn shard_rule(v: &mut Validator, shard: Option<Shard>) -> Option<Shard> {
    let s = shard?;
    ensure_rule!(v, s.index < s.count, SHARD_INDEX_BELOW_COUNT, "/shard/index";
        "shard.index must be below shard.count = {}, got {}", s.count, s.index)
    .then_some(s)
}

/// Validates an optional top-level `shard` (pointers `/shard/index`, `/shard/count`).
pub fn shard(v: &mut Validator, shard: Option<Shard>) -> Option<Shard> {
    let s = shard?;
    let count_ok = v.uint(
        "/shard/count",
        "shard.count",
        u64::from(s.count),
        SHARD_COUNT,
    );
    let mut ok = v.uint(
        "/shard/index",
        "shard.index",
        u64::from(s.index),
        SHARD_INDEX,
    );
    if ok && count_ok {
        ok = v.ensure(s.index < s.count, "/shard/index", || {
            format!(
                "shard.index must be below shard.count = {}, got {}",
                s.count, s.index
            )
        });
    }
    (ok && count_ok).then_some(s)
}

/// The result of a module's own validation with the problems of shared fields (validated by
/// `v`) added, so that one 422 lists every offending field.
///
/// # Errors
/// The module's failure with `v`'s problems appended, or `v`'s problems alone.
pub fn with_issues<T>(v: Validator, parsed: Result<T, CalcFailure>) -> Result<T, CalcFailure> {
    if v.is_clean() {
        return parsed;
    }
    let shared: Vec<FieldIssue> = v.issues().cloned().collect();
    let parsed = match parsed {
        Err(mut f) if f.class == ProblemClass::InvalidInput => {
            f.errors.extend(shared);
            f.detail = format!("{} fields failed validation", f.errors.len());
            return Err(f);
        }
        other => other,
    };
    // `v` has problems: this is its 422.
    v.finish()?;
    parsed
}

/// Conservative size of one number in a JSON answer \[bytes\]: the longest shortest-round-trip
/// f64 (`-2.2250738585072014e-308`, 24 characters) plus its separator.
pub const BYTES_PER_NUMBER: u64 = 25;

/// An upper estimate of an answer's size, made from the validated request before computing:
/// a fixed part plus parts driven by request options, each attributed to the JSON pointer of
/// the option that drives it.
#[derive(Debug, Clone, Default)]
pub struct ResponseSize {
    fixed: u64,
    parts: Vec<(String, u64)>,
}

impl ResponseSize {
    /// An estimate of `bytes` that no option changes (scalars, names, settings).
    #[must_use]
    pub fn fixed(bytes: u64) -> Self {
        Self {
            fixed: bytes,
            parts: Vec::new(),
        }
    }

    /// Add `bytes` driven by the request option at `pointer`.
    #[must_use]
    pub fn bytes(mut self, pointer: impl Into<String>, bytes: u64) -> Self {
        let pointer = pointer.into();
        match self.parts.iter_mut().find(|(p, _)| *p == pointer) {
            Some((_, b)) => *b = b.saturating_add(bytes),
            None => self.parts.push((pointer, bytes)),
        }
        self
    }

    /// Add `count` numbers (at [`BYTES_PER_NUMBER`] each) driven by the option at `pointer`.
    #[must_use]
    pub fn numbers(self, pointer: impl Into<String>, count: u64) -> Self {
        self.bytes(pointer, count.saturating_mul(BYTES_PER_NUMBER))
    }

    /// The estimate \[bytes\].
    #[must_use]
    pub fn total(&self) -> u64 {
        self.parts
            .iter()
            .fold(self.fixed, |a, (_, b)| a.saturating_add(*b))
    }

    /// The option driving the largest part of the answer, if any.
    #[must_use]
    pub fn driver(&self) -> Option<&str> {
        self.parts
            .iter()
            .max_by_key(|(_, b)| *b)
            .map(|(p, _)| p.as_str())
    }

    /// `Ok` when the estimate is within the budget's response limit (or there is none), else a
    /// 422 `RESPONSE_TOO_LARGE` pointing at the option that drives the largest part, giving the
    /// estimate and the limit. Called before computing.
    ///
    /// # Errors
    /// The estimate exceeds `budget.max_response_bytes()`.
    pub fn check(&self, budget: &Budget) -> Result<(), CalcFailure> {
        let Some(limit) = budget.max_response_bytes() else {
            return Ok(());
        };
        let total = self.total();
        if total <= limit {
            return Ok(());
        }
        let pointer = self.driver().unwrap_or("").to_owned();
        let change = if pointer.is_empty() {
            "request fewer points or fewer optional outputs".to_owned()
        } else {
            format!("reduce {pointer} (or split the request)")
        };
        let detail = format!(
            "the answer would be about {total} bytes (estimated before computing, \
             {BYTES_PER_NUMBER} bytes per number), over the service's limit of {limit} bytes \
             (max_response_bytes); {change}"
        );
        let errors = if pointer.is_empty() {
            Vec::new()
        } else {
            vec![FieldIssue {
                pointer,
                detail: detail.clone(),
            }]
        };
        Err(CalcFailure {
            class: ProblemClass::TooLarge,
            code: RESPONSE_TOO_LARGE,
            detail,
            errors,
        })
    }
}

/// Code of an answer that would exceed the service's `--max-response-bytes`.
pub const RESPONSE_TOO_LARGE: &str = "RESPONSE_TOO_LARGE";

/// Every number of an answer is finite (every endpoint lists it): the last guard before an answer
/// is sent (`/problems/infeasible`: these inputs describe a design whose results leave f64, e.g.
/// a beam with E·I near 1e-300 and an infinite compliance). Reaching it is logged as an error:
/// the module should have refused such inputs with a code of its own.
pub const NON_FINITE_ANSWER_RULE: CrossRule = CrossRule::infeasible(
    "NON_FINITE_ANSWER",
    &[],
    "Every number of the answer is finite in f64; inputs at the extremes of their ranges whose \
     results leave f64 are refused with this code rather than answered with a non-number.",
);

/// The answer fits the service's `--max-response-bytes` (every endpoint lists it).
pub const RESPONSE_TOO_LARGE_RULE: CrossRule = CrossRule::too_large(
    RESPONSE_TOO_LARGE,
    &[],
    "The answer, estimated from the request before computing (and measured after encoding), \
     fits the service's --max-response-bytes; the failure points at the option driving its size.",
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_tile_the_items_in_order() {
        for len in [0usize, 1, 2, 5, 7, 10, 101] {
            for count in [1u32, 2, 3, 7, 16] {
                let mut next = 0;
                let mut sizes = Vec::new();
                for index in 0..count {
                    let r = Shard { index, count }.range(len);
                    assert_eq!(r.start, next, "len {len} count {count} index {index}");
                    next = r.end;
                    sizes.push(r.len());
                }
                assert_eq!(next, len);
                let (lo, hi) = (sizes.iter().min(), sizes.iter().max());
                assert!(hi.zip(lo).is_some_and(|(h, l)| h - l <= 1), "{sizes:?}");
            }
        }
        assert_eq!(Shard::WHOLE.range(9), 0..9);
    }

    #[test]
    fn bad_shards_point_at_their_field() {
        let pointers = |s: Shard| {
            let mut v = Validator::new();
            let ok = shard(&mut v, Some(s)).is_some();
            (
                ok,
                v.issues().map(|i| i.pointer.clone()).collect::<Vec<_>>(),
            )
        };
        assert_eq!(pointers(Shard { index: 2, count: 2 }).1, ["/shard/index"]);
        assert_eq!(pointers(Shard { index: 0, count: 0 }).1, ["/shard/count"]);
        assert_eq!(
            pointers(Shard {
                index: 0,
                count: 1_000_000
            })
            .1,
            ["/shard/count"]
        );
        assert_eq!(pointers(Shard { index: 1, count: 2 }), (true, Vec::new()));
    }

    #[test]
    fn the_largest_part_names_the_option() {
        let est = ResponseSize::fixed(100)
            .numbers("/a", 10)
            .numbers("/b", 1000);
        assert_eq!(est.total(), 100 + 25 * 1010);
        let b = Budget::unlimited().with_max_response_bytes(1000);
        let e = est.check(&b).expect_err("over the limit");
        assert_eq!(e.code, RESPONSE_TOO_LARGE);
        assert_eq!(e.errors[0].pointer, "/b");
        assert!(e.detail.contains("25350") && e.detail.contains("1000"));
        assert!(est.check(&Budget::unlimited()).is_ok());
    }
}
