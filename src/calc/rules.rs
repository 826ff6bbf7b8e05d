//! One declaration per request rule, read twice: by the check at the door and by the document.
//!
//! A per-field rule is a `#[rule(...)]` attribute on the field of a wire type that derives
//! [`Rules`] (`mechcalc_derive::Rules`):
//!
//! | attribute | applies to | JSON Schema keyword(s) |
//! |---|---|---|
//! | `range = R` | a number, or an `Option` of one | `minimum` / `exclusiveMinimum` / `maximum` / `exclusiveMaximum` (and `integer`) |
//! | `items = R` | each number of a list | the same keywords under `items` |
//! | `items_items = R` | each number of a list of lists | under `items/items` |
//! | `values = R` | each value of a map | under `additionalProperties` |
//! | `min_items = n`, `max_items = n` | a list (or a string: `min_length`, `max_length`) | `minItems` / `maxItems` (`minLength` / `maxLength`) |
//! | `code = "BAD_RANGE"` | the field's failures carry the spec's code (default `INVALID_INPUT`) | |
//!
//! and on the type: `#[rules(code = "...")]` (the code of every rule of the type) and
//! `#[rules(one_of("a", "b"))]` (exactly one of the optional fields `a`, `b` is given; written as
//! a `oneOf` of the alternatives; a failure points at the field to remove or to add;
//! `one_of_object(...)`: at the object itself). `R` is a [`Range`] constant of the module's `wire.rs`.
//!
//! * [`Rules::check_rules`] walks a decoded request once and records every broken rule with the
//!   field's JSON pointer (from the wire names), its quantity, its unit (from the field's doc) and
//!   the limit: `t_b [x] must be in [-1e12, 1e12], got 5e13`. The HTTP layer runs it at the door,
//!   before anything is queued ([`check`]).
//! * [`Rules::document_rules`] lists the same rules for the OpenAPI document
//!   (`src/http/openapi.rs` writes them into the schemas).
//!
//! Rules between fields (an array's length tied to another field, physical feasibility) are not
//! JSON Schema rules: each is a [`CrossRule`] with its own code, checked in the module's
//! `input.rs` and listed under the operation's `x-cross-field-rules`.

use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet, HashMap};

use serde::{Deserialize, Deserializer};

use super::bounds::Range;
use super::problem::{CalcFailure, ProblemClass, Validator};

pub use mechcalc_derive::Rules;

/// Where a value sits in the request: a JSON pointer built only when a rule fails.
#[derive(Debug, Clone, Copy)]
pub enum At<'a> {
    /// The request body itself.
    Root,
    /// Member `key` of the object at the parent.
    Key(&'a At<'a>, &'a str),
    /// Item `index` of the array at the parent.
    Index(&'a At<'a>, usize),
}

impl<'a> At<'a> {
    /// The member `key` below this place.
    #[must_use]
    pub const fn key(&'a self, key: &'a str) -> At<'a> {
        At::Key(self, key)
    }

    /// The item `index` below this place.
    #[must_use]
    pub const fn index(&'a self, index: usize) -> At<'a> {
        At::Index(self, index)
    }

    /// The RFC 6901 JSON pointer of this place.
    #[must_use]
    pub fn pointer(&self) -> String {
        let mut out = String::new();
        self.write(&mut out);
        out
    }

    fn write(&self, out: &mut String) {
        match self {
            Self::Root => {}
            Self::Key(parent, key) => {
                parent.write(out);
                out.push('/');
                out.push_str(&key.replace('~', "~0").replace('/', "~1"));
            }
            Self::Index(parent, i) => {
                parent.write(out);
                out.push('/');
                out.push_str(&i.to_string());
            }
        }
    }
}

/// What a message says of a field: its wire name, its unit and the code of its failures.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// Wire name.
    pub name: &'static str,
    /// Unit from the field's doc (may be empty).
    pub unit: &'static str,
    /// The spec's code for this field's failures (`None`: `INVALID_INPUT`).
    pub code: Option<&'static str>,
}

impl Field {
    fn label(&self, index: Option<usize>) -> String {
        let mut s = self.name.to_owned();
        if let Some(i) = index {
            s.push_str(&format!("[{i}]"));
        }
        if !self.unit.is_empty() {
            s.push_str(&format!(" [{}]", self.unit));
        }
        s
    }

    fn record(&self, v: &mut Validator, at: At<'_>, detail: String) {
        v.push_code(
            self.code.unwrap_or(super::INVALID_INPUT),
            at.pointer(),
            detail,
        );
    }
}

/// A request type whose per-field rules are declared with `#[rule(...)]` (derive [`Rules`]).
pub trait Rules {
    /// `true` for numbers, strings and other values without rules (a list of them is not walked).
    const LEAF: bool = false;

    /// Record every broken rule of this value, which sits at `at` in the request.
    fn check_rules(&self, at: At<'_>, v: &mut Validator);

    /// Add this type's rules (and those of the types it holds) to the document's list.
    fn document_rules(out: &mut DocRules)
    where
        Self: Sized;
}

/// Check every per-field rule of a decoded request: `Ok` or one 422 listing every broken rule.
///
/// # Errors
/// The failure lists each broken rule with its JSON pointer and the field's code.
pub fn check<T: Rules>(request: &T) -> Result<(), CalcFailure> {
    let mut v = Validator::new();
    request.check_rules(At::Root, &mut v);
    v.finish()
}

/// The failure of a conversion that met a request whose per-field rules were not checked (the
/// caller skipped the door: check the request with [`check`] first, as the HTTP layer and each
/// module's `run` do).
#[must_use]
pub fn door_skipped(pointer: &str) -> CalcFailure {
    CalcFailure::field(
        ProblemClass::InvalidInput,
        super::INVALID_INPUT,
        pointer,
        "breaks a per-field rule of the request schema (the request was not checked at the door)",
    )
}

macro_rules! leaf {
    ($($t:ty),*) => {$(
        impl Rules for $t {
            const LEAF: bool = true;
            #[inline]
            fn check_rules(&self, _at: At<'_>, _v: &mut Validator) {}
            fn document_rules(_out: &mut DocRules) {}
        }
    )*};
}
leaf!(
    f64,
    f32,
    bool,
    u8,
    u16,
    u32,
    u64,
    usize,
    i8,
    i16,
    i32,
    i64,
    String,
    char,
    serde_json::Value
);

impl<T: Rules> Rules for Option<T> {
    #[inline]
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        if let Some(x) = self {
            x.check_rules(at, v);
        }
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

impl<T: Rules> Rules for Box<T> {
    #[inline]
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        (**self).check_rules(at, v);
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

impl<T: Rules> Rules for Vec<T> {
    #[inline]
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        self.as_slice().check_rules(at, v);
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

impl<T: Rules, const N: usize> Rules for [T; N] {
    #[inline]
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        self.as_slice().check_rules(at, v);
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

impl<T: Rules> Rules for [T] {
    #[inline]
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        if T::LEAF {
            return;
        }
        for (i, x) in self.iter().enumerate() {
            x.check_rules(at.index(i), v);
        }
    }
}

impl<K: AsRef<str>, T: Rules, S> Rules for HashMap<K, T, S> {
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        for (k, x) in self {
            x.check_rules(at.key(k.as_ref()), v);
        }
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

impl<K: AsRef<str>, T: Rules> Rules for BTreeMap<K, T> {
    fn check_rules(&self, at: At<'_>, v: &mut Validator) {
        for (k, x) in self {
            x.check_rules(at.key(k.as_ref()), v);
        }
    }
    fn document_rules(out: &mut DocRules) {
        T::document_rules(out);
    }
}

// ---------------------------------------------------------------------------------------------
// The rules
// ---------------------------------------------------------------------------------------------

/// A number a range rule reads.
pub trait Number: Copy {
    /// The value as `f64` (request integers are far below 2^53: exact).
    fn to_f64(self) -> f64;
}

macro_rules! number {
    ($($t:ty),*) => {$(
        impl Number for $t {
            #[inline]
            #[allow(clippy::cast_precision_loss, clippy::cast_lossless, reason = "request integers are far below 2^53")]
            fn to_f64(self) -> f64 { self as f64 }
        }
    )*};
}
number!(f64, f32, u8, u16, u32, u64, usize, i8, i16, i32, i64);

/// A field a range rule applies to: a number or an optional number.
pub trait Scalar {
    /// The number, when given.
    fn value(&self) -> Option<f64>;
}

impl<T: Number> Scalar for T {
    #[inline]
    fn value(&self) -> Option<f64> {
        Some(self.to_f64())
    }
}

impl<T: Number> Scalar for Option<T> {
    #[inline]
    fn value(&self) -> Option<f64> {
        self.map(Number::to_f64)
    }
}

/// A field that holds a list (or an optional list).
pub trait List {
    /// Item type.
    type Item;
    /// The items, when given.
    fn list(&self) -> Option<&[Self::Item]>;
}

impl<T> List for Vec<T> {
    type Item = T;
    #[inline]
    fn list(&self) -> Option<&[T]> {
        Some(self)
    }
}

impl<T, const N: usize> List for [T; N] {
    type Item = T;
    #[inline]
    fn list(&self) -> Option<&[T]> {
        Some(self)
    }
}

impl<L: List> List for Option<L> {
    type Item = L::Item;
    #[inline]
    fn list(&self) -> Option<&[L::Item]> {
        self.as_ref().and_then(List::list)
    }
}

/// A field with a length: a list (items) or a string (characters).
pub trait HasLen {
    /// `true` for strings (`minLength`/`maxLength`), `false` for lists (`minItems`/`maxItems`).
    const STRING: bool;
    /// The length, when given.
    fn length(&self) -> Option<usize>;
}

impl<T> HasLen for Vec<T> {
    const STRING: bool = false;
    fn length(&self) -> Option<usize> {
        Some(self.len())
    }
}

impl HasLen for String {
    const STRING: bool = true;
    fn length(&self) -> Option<usize> {
        Some(self.chars().count())
    }
}

impl<K, V, S> HasLen for HashMap<K, V, S> {
    const STRING: bool = false;
    fn length(&self) -> Option<usize> {
        Some(self.len())
    }
}

impl<T: HasLen> HasLen for Option<T> {
    const STRING: bool = T::STRING;
    fn length(&self) -> Option<usize> {
        self.as_ref().and_then(HasLen::length)
    }
}

/// A field that holds a map of numbers (or an optional one).
pub trait NumberMap {
    /// Every `(key, number)`, in the map's order.
    fn entries(&self) -> Vec<(&str, f64)>;
}

impl<K: AsRef<str>, T: Number, S> NumberMap for HashMap<K, T, S> {
    fn entries(&self) -> Vec<(&str, f64)> {
        let mut e: Vec<(&str, f64)> = self.iter().map(|(k, x)| (k.as_ref(), x.to_f64())).collect();
        e.sort_by(|a, b| a.0.cmp(b.0));
        e
    }
}

impl<K: AsRef<str>, T: Number> NumberMap for BTreeMap<K, T> {
    fn entries(&self) -> Vec<(&str, f64)> {
        self.iter().map(|(k, x)| (k.as_ref(), x.to_f64())).collect()
    }
}

impl<M: NumberMap> NumberMap for Option<M> {
    fn entries(&self) -> Vec<(&str, f64)> {
        self.as_ref().map(NumberMap::entries).unwrap_or_default()
    }
}

/// Whether an optional field is given (for `one_of`).
pub trait Present {
    /// `true` when given (not absent, not `null`).
    fn present(&self) -> bool;
}

impl<T> Present for Option<T> {
    fn present(&self) -> bool {
        self.is_some()
    }
}

/// `range = R`: the number (when given) lies in `r`.
pub fn range<T: Scalar + ?Sized>(x: &T, f: &Field, r: Range, at: At<'_>, v: &mut Validator) {
    if let Some(x) = x.value()
        && !r.contains(x)
    {
        f.record(v, at, format!("{} must be {r}, got {x}", f.label(None)));
    }
}

/// `items = R`: every number of the list lies in `r` (the first offender is named, with a count
/// of the others, so a list of 10^5 numbers cannot produce 10^5 errors).
pub fn items<L>(x: &L, f: &Field, r: Range, at: At<'_>, v: &mut Validator)
where
    L: List + ?Sized,
    L::Item: Number,
{
    let Some(list) = x.list() else { return };
    let mut bad = list
        .iter()
        .enumerate()
        .filter(|(_, x)| !r.contains(x.to_f64()));
    if let Some((i, x)) = bad.next() {
        let more = bad.count();
        let tail = if more > 0 {
            format!(" ({more} more out of range follow)")
        } else {
            String::new()
        };
        f.record(
            v,
            at.index(i),
            format!("{} must be {r}, got {}{tail}", f.label(Some(i)), x.to_f64()),
        );
    }
}

/// `items_items = R`: every number of a list of lists lies in `r` (the first offender per row).
pub fn items_items<L>(x: &L, f: &Field, r: Range, at: At<'_>, v: &mut Validator)
where
    L: List + ?Sized,
    L::Item: List,
    <L::Item as List>::Item: Number,
{
    let Some(rows) = x.list() else { return };
    for (i, row) in rows.iter().enumerate() {
        let Some(row) = row.list() else { continue };
        if let Some((j, y)) = row
            .iter()
            .enumerate()
            .find(|(_, y)| !r.contains(y.to_f64()))
        {
            let at_row = at.index(i);
            f.record(
                v,
                at_row.index(j),
                format!("{}[{i}][{j}] must be {r}, got {}", f.name, y.to_f64()),
            );
            return;
        }
    }
}

/// `values = R`: every number of a map lies in `r`.
pub fn values<M: NumberMap + ?Sized>(x: &M, f: &Field, r: Range, at: At<'_>, v: &mut Validator) {
    for (k, y) in x.entries() {
        if !r.contains(y) {
            f.record(
                v,
                at.key(k),
                format!("{}[{k:?}] must be {r}, got {y}", f.name),
            );
        }
    }
}

/// `min_items`/`max_items` (`min_length`/`max_length` for a string).
pub fn len<T: HasLen + ?Sized>(
    x: &T,
    f: &Field,
    min: Option<usize>,
    max: Option<usize>,
    at: At<'_>,
    v: &mut Validator,
) {
    let Some(n) = x.length() else { return };
    let what = if T::STRING { "characters" } else { "items" };
    let bound = match (min, max) {
        (Some(a), Some(b)) if a == b => format!("exactly {a} {what}"),
        (Some(a), Some(b)) => format!("{a} to {b} {what}"),
        (Some(a), None) => format!("at least {a} {what}"),
        (None, Some(b)) => format!("at most {b} {what}"),
        (None, None) => return,
    };
    if min.is_some_and(|a| n < a) || max.is_some_and(|b| n > b) {
        f.record(
            v,
            at,
            format!("{} must hold {bound}, got {n}", f.label(None)),
        );
    }
}

/// `one_of(...)`: exactly one of the named optional fields is given.
pub fn one_of(
    given: &[(&'static str, bool)],
    code: Option<&'static str>,
    at_object: bool,
    at: At<'_>,
    v: &mut Validator,
) {
    let n = given.iter().filter(|(_, p)| *p).count();
    if n == 1 {
        return;
    }
    let names: Vec<String> = given.iter().map(|(k, _)| format!("`{k}`")).collect();
    let list = match names.as_slice() {
        [a, b] => format!("{a} or {b}"),
        _ => names.join(", "),
    };
    let got = if n == 0 {
        "neither".to_owned()
    } else {
        let which: Vec<&str> = given.iter().filter(|(_, p)| *p).map(|(k, _)| *k).collect();
        if n == 2 && given.len() == 2 {
            "both".to_owned()
        } else {
            which.join(", ")
        }
    };
    // Point at the field to remove (the last one given) or to add (the first one listed).
    let field = if n == 0 {
        given[0].0
    } else {
        given
            .iter()
            .rev()
            .find(|(_, p)| *p)
            .map_or(given[0].0, |g| g.0)
    };
    let pointer = if at_object {
        at.pointer()
    } else {
        at.key(field).pointer()
    };
    v.push_code(
        code.unwrap_or(super::INVALID_INPUT),
        pointer,
        format!("give exactly one of {list}, got {got}"),
    );
}

// ---------------------------------------------------------------------------------------------
// The document side
// ---------------------------------------------------------------------------------------------

/// What a rule says in JSON Schema terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// A number's range.
    Range(Range),
    /// A list's item count or a string's character count.
    Len {
        /// Least count.
        min: Option<usize>,
        /// Largest count.
        max: Option<usize>,
        /// Characters of a string rather than items of a list.
        string: bool,
    },
    /// Exactly one of these properties is given (not absent, not `null`).
    OneOf(&'static [&'static str]),
}

/// One rule for the document: the schema, the place inside it and what it says.
#[derive(Debug, Clone)]
pub struct DocRule {
    /// Schema name (`ToSchema::name`), e.g. `cognates.Links`.
    pub schema: Cow<'static, str>,
    /// JSON pointer inside that schema (`/properties/x/items`; empty: the schema itself).
    pub pointer: &'static str,
    /// The rule.
    pub kind: Kind,
}

/// The rules of every request type, collected for the document (each type once).
#[derive(Debug, Default)]
pub struct DocRules {
    seen: BTreeSet<String>,
    /// The rules in the order the types were visited.
    pub rules: Vec<DocRule>,
}

impl DocRules {
    /// Whether the type named `schema` is visited for the first time.
    pub fn enter(&mut self, schema: &str) -> bool {
        self.seen.insert(schema.to_owned())
    }

    /// Add one rule.
    pub fn push(&mut self, schema: &str, pointer: &'static str, kind: Kind) {
        self.rules.push(DocRule {
            schema: Cow::Owned(schema.to_owned()),
            pointer,
            kind,
        });
    }

    /// The rules of the request type `T` and everything inside it.
    #[must_use]
    pub fn of<T: Rules>(mut self) -> Self {
        T::document_rules(&mut self);
        self
    }
}

// ---------------------------------------------------------------------------------------------
// Null means absent
// ---------------------------------------------------------------------------------------------

/// `deserialize_with` of an optional field that is not an `Option`: `null` reads as the type's
/// default, exactly as if the field were absent (the document marks every optional request field
/// nullable, and generated clients send `null` for unset fields).
///
/// # Errors
/// The value's own decoding error.
pub fn null_default<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de> + Default,
{
    Ok(Option::<T>::deserialize(d)?.unwrap_or_default())
}

/// `deserialize_with` of an integer field inside an internally tagged enum (serde buffers those,
/// so the door's strict reader does not see them): a whole number written with a fraction part
/// (`8.0`, an integer to JSON Schema) reads as that integer; a fraction or a value out of range
/// is refused.
///
/// # Errors
/// The value is not a whole number in the type's range.
pub fn whole<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: TryFrom<u64>,
{
    let x = serde_json::Number::deserialize(d)?;
    let n = x.as_u64().or_else(|| {
        x.as_f64()
            .filter(|f| f.fract() == 0.0 && (0.0..=9_007_199_254_740_992.0).contains(f))
            .map(|f| {
                #[expect(
                    clippy::cast_possible_truncation,
                    clippy::cast_sign_loss,
                    reason = "whole, non-negative and below 2^53: exact"
                )]
                let n = f as u64;
                n
            })
    });
    n.and_then(|n| T::try_from(n).ok()).ok_or_else(|| {
        serde::de::Error::custom(format!(
            "invalid value: {x}, expected a whole number in range"
        ))
    })
}

/// `deserialize_with` of an optional boolean whose default is `true`: `null` reads as `true`.
///
/// # Errors
/// The value's own decoding error.
pub fn null_true<'de, D: Deserializer<'de>>(d: D) -> Result<bool, D::Error> {
    Ok(Option::<bool>::deserialize(d)?.unwrap_or(true))
}

// ---------------------------------------------------------------------------------------------
// Rules between fields
// ---------------------------------------------------------------------------------------------

/// A rule between fields (or of physical feasibility) that JSON Schema cannot state: checked in
/// a module's `input.rs` (or found by its computation), listed under the operation's
/// `x-cross-field-rules`, and reported with its own code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CrossRule {
    /// The code a failure of this rule carries.
    pub code: &'static str,
    /// The fields it relates (JSON pointers; `*` stands for any array index).
    pub pointers: &'static [&'static str],
    /// The rule in one sentence.
    pub rule: &'static str,
    /// Its failure class.
    pub class: ProblemClass,
}

impl CrossRule {
    /// An invalid-input rule between fields.
    #[must_use]
    pub const fn invalid(
        code: &'static str,
        pointers: &'static [&'static str],
        rule: &'static str,
    ) -> Self {
        Self {
            code,
            pointers,
            rule,
            class: ProblemClass::InvalidInput,
        }
    }

    /// A rule of physical feasibility (the request describes something that cannot exist).
    #[must_use]
    pub const fn infeasible(
        code: &'static str,
        pointers: &'static [&'static str],
        rule: &'static str,
    ) -> Self {
        Self {
            code,
            pointers,
            rule,
            class: ProblemClass::Infeasible,
        }
    }

    /// A method that may stop short of its tolerance.
    #[must_use]
    pub const fn not_converged(
        code: &'static str,
        pointers: &'static [&'static str],
        rule: &'static str,
    ) -> Self {
        Self {
            code,
            pointers,
            rule,
            class: ProblemClass::NotConverged,
        }
    }

    /// Work or an answer over the service's limits.
    #[must_use]
    pub const fn too_large(
        code: &'static str,
        pointers: &'static [&'static str],
        rule: &'static str,
    ) -> Self {
        Self {
            code,
            pointers,
            rule,
            class: ProblemClass::TooLarge,
        }
    }

    /// A failure of this rule at `pointer`.
    #[must_use]
    pub fn fail(&self, pointer: impl Into<String>, detail: impl Into<String>) -> CalcFailure {
        CalcFailure::field(self.class, self.code, pointer, detail)
    }

    /// A failure of this rule not tied to one field.
    #[must_use]
    pub fn fail_general(&self, detail: impl Into<String>) -> CalcFailure {
        CalcFailure::general(self.class, self.code, detail)
    }
}

/// Declares a module's [`CrossRule`] constants, each in two lines, and (with a leading
/// `pub const NAME: &[CrossRule];`) the list the document publishes, in the order written:
///
/// ```text
/// cross_rules! {
///     /// The rules between fields of `POST /v1/x`, as the document lists them.
///     pub const CROSS_FIELD_RULES: &[CrossRule];
///     invalid ABSCISSA_ORDER ["/abscissa/values/*", "/abscissa/grid/end"]
///         "Abscissae strictly increase; a grid's `end` is greater than its `start`.";
///     infeasible ZERO_MEAN(super::error::GRA_ZERO_MEAN) ["/gra"] "No series has a mean of 0.";
///     listed common::RESPONSE_TOO_LARGE_RULE;
/// }
/// ```
///
/// A rule is its class (the [`CrossRule`] constructor: `invalid`, `infeasible`, `not_converged`,
/// `too_large`), its name, its code in parentheses when it is not the name, its pointers and its
/// sentence, which is also its doc (after any doc written above it). `listed PATH;` adds a rule
/// declared elsewhere to the list.
macro_rules! cross_rules {
    (@code $name:ident) => { stringify!($name) };
    (@code $name:ident $code:expr) => { $code };
    (@munch [$($acc:tt)*] [$(#[$meta:meta])* $list:ident]) => {
        $(#[$meta])*
        pub const $list: &[$crate::calc::CrossRule] = &[$($acc)*];
    };
    (@munch [$($acc:tt)*] []) => {};
    (@munch [$($acc:tt)*] $head:tt listed $rule:path; $($rest:tt)*) => {
        $crate::calc::rules::cross_rules!(@munch [$($acc)* $rule,] $head $($rest)*);
    };
    (@munch [$($acc:tt)*] $head:tt $(#[$m:meta])* $class:ident $name:ident $(($code:expr))?
        [$($p:literal),* $(,)?] $rule:literal; $($rest:tt)*) => {
        $(#[$m])*
        #[doc = $rule]
        #[allow(
            rustdoc::broken_intra_doc_links,
            reason = "the sentence is the published plain text: `[j]` is an index, not a link"
        )]
        pub const $name: $crate::calc::CrossRule = $crate::calc::CrossRule::$class(
            $crate::calc::rules::cross_rules!(@code $name $($code)?),
            &[$($p),*],
            $rule,
        );
        $crate::calc::rules::cross_rules!(@munch [$($acc)* $name,] $head $($rest)*);
    };
    ($(#[$meta:meta])* pub const $list:ident: &[CrossRule]; $($body:tt)*) => {
        $crate::calc::rules::cross_rules!(@munch [] [$(#[$meta])* $list] $($body)*);
    };
    ($($body:tt)*) => {
        $crate::calc::rules::cross_rules!(@munch [] [] $($body)*);
    };
}
pub(crate) use cross_rules;

/// Records a failure of a rule between fields ([`CrossRule`]) at a pointer:
/// `rule!(v, RULE, pointer; "message {x}", args…)`. The message takes `format!` arguments, so a
/// check reads as one line: the rule, where, and what is wrong with which value and limit.
macro_rules! rule {
    ($v:expr, $rule:expr, $ptr:expr; $fmt:literal) => {
        $v.rule(&$rule, $ptr, ::std::fmt::format(format_args!($fmt)))
    };
    ($v:expr, $rule:expr, $ptr:expr; $fmt:literal, $($arg:expr),+ $(,)?) => {
        $v.rule(&$rule, $ptr, format!($fmt, $($arg),+))
    };
}
pub(crate) use rule;

/// Checks a rule between fields: `ensure_rule!(v, ok, RULE, pointer; "message {x}", args…)`
/// records a failure of `RULE` at the pointer unless `ok`, and is `ok`. The pointer and the
/// message are formatted only when the rule fails.
macro_rules! ensure_rule {
    ($v:expr, $ok:expr, $rule:expr, $ptr:expr; $($msg:tt)+) => {{
        let ok: bool = $ok;
        if !ok {
            $crate::calc::rules::rule!($v, $rule, $ptr; $($msg)+);
        }
        ok
    }};
}
pub(crate) use ensure_rule;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pointers_escape_and_nest() {
        let root = At::Root;
        let a = root.key("a/b");
        let i = a.index(3);
        let k = i.key("m~n");
        assert_eq!(k.pointer(), "/a~1b/3/m~0n");
        assert_eq!(root.pointer(), "");
    }

    #[test]
    fn range_items_and_len_name_the_field_unit_and_limit() {
        let f = Field {
            name: "t_b",
            unit: "x",
            code: None,
        };
        let mut v = Validator::new();
        range(
            &5.0_f64,
            &f,
            Range::closed(0.0, 1.0),
            At::Root.key("t_b"),
            &mut v,
        );
        range(
            &Some(0.5_f64),
            &f,
            Range::closed(0.0, 1.0),
            At::Root,
            &mut v,
        );
        range(&None::<f64>, &f, Range::closed(0.0, 1.0), At::Root, &mut v);
        items(
            &vec![0.5, -1.0, 2.0],
            &f,
            Range::closed(0.0, 1.0),
            At::Root.key("xs"),
            &mut v,
        );
        len(
            &vec![1.0; 3],
            &f,
            Some(7),
            Some(7),
            At::Root.key("c"),
            &mut v,
        );
        let e = v.finish().expect_err("three rules are broken");
        let got: Vec<(&str, &str)> = e
            .errors
            .iter()
            .map(|i| (i.pointer.as_str(), i.detail.as_str()))
            .collect();
        assert_eq!(
            got,
            [
                ("/t_b", "t_b [x] must be in [0, 1], got 5"),
                (
                    "/xs/1",
                    "t_b[1] [x] must be in [0, 1], got -1 (1 more out of range follow)"
                ),
                ("/c", "t_b [x] must hold exactly 7 items, got 3"),
            ]
        );
    }

    #[test]
    fn one_of_counts_given_fields_and_points_at_the_field_or_the_object() {
        let mut v = Validator::new();
        one_of(&[("a", true), ("b", false)], None, false, At::Root, &mut v);
        assert!(v.is_clean());
        let p = At::Root.key("p");
        one_of(&[("a", true), ("b", true)], Some("X"), false, p, &mut v);
        one_of(&[("a", false), ("b", false)], None, false, At::Root, &mut v);
        one_of(
            &[("a", true), ("b", true)],
            None,
            true,
            At::Root.key("q"),
            &mut v,
        );
        let e = v.finish().expect_err("three groups are broken");
        let pointers: Vec<&str> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
        assert_eq!(pointers, ["/p/b", "/a", "/q"]);
        assert_eq!(
            e.errors[0].detail,
            "X: give exactly one of `a` or `b`, got both"
        );
    }

    #[test]
    fn null_reads_as_the_default() {
        #[derive(Deserialize, crate::calc::Rules)]
        struct S {
            #[serde(default, deserialize_with = "null_default")]
            flag: bool,
            #[serde(default = "yes", deserialize_with = "null_true")]
            on: bool,
        }
        fn yes() -> bool {
            true
        }
        let s: S = serde_json::from_str(r#"{"flag": null, "on": null}"#).expect("nulls read");
        assert!(!s.flag && s.on);
        let s: S = serde_json::from_str("{}").expect("absent reads");
        assert!(!s.flag && s.on);
    }
}
