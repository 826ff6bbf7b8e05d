//! The rules between fields of an [`IrefcStressRequest`], turning it into SI domain input and
//! collecting every issue. Every per-field range is a `#[rule]` on the wire types (`BAD_RANGE`),
//! checked at the door; what is left here is listed in [`CROSS_FIELD_RULES`] with the spec's
//! codes.

use super::wire::{
    GRID_INTERVALS_MAX, IntRange, IrefcStressRequest, LB_MAX_OVER_R2, LB_MM, STEP_DEG, StepRange,
    StressInclude, StressMode,
};
use crate::calc::common::{self, Shard};
use crate::calc::irefc::error::{BAD_RANGE, GRID_TOO_FINE, MISSING_FIELD, SWEEP_TOO_LARGE};
use crate::calc::irefc::input as design;
use crate::calc::irefc::wire::{MM, PROFILE_POINTS_DEFAULT, Warning};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Range, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/irefc-stress`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid SWEEP_NEEDS_MODE(BAD_RANGE) ["/sweep", "/mode"]
        "`sweep` is given only with mode \"sweep\" (the default when `sweep` is present).";
    invalid SHARD_NEEDS_SWEEP(BAD_RANGE) ["/shard", "/mode"]
        "`shard` is given only in mode \"sweep\" (mode \"single\" has one design).";
    listed common::SHARD_INDEX_BELOW_COUNT;
    invalid MODE_FIELDS(MISSING_FIELD) ["/r2_mm", "/rb_mm", "/Z2", "/chi", "/sweep", "/sweep/r2_mm",
        "/sweep/rb_mm"]
        "Mode \"single\" needs r2_mm, rb_mm, Z2 and chi; mode \"sweep\" needs `sweep`, and r2_mm \
         and rb_mm unless `sweep.r2_mm`/`sweep.rb_mm` are given.";
    invalid SWEEP_RANGE_ORDER(BAD_RANGE) ["/sweep/Z2/to", "/sweep/chi/to"]
        "sweep.Z2.to ≥ sweep.Z2.from and sweep.chi.to ≥ sweep.chi.from.";
    invalid LB_BELOW_R2(BAD_RANGE) ["/lb_mm", "/r2_mm", "/sweep/r2_mm"]
        "lb_mm ≤ 100·r2 for every r2 of the request.";
    too_large GRID_TOO_FINE_RULE(GRID_TOO_FINE) ["/step_deg"]
        "180/step_deg ≤ 2e6 (step_deg ≥ 9e-5).";
    too_large SWEEP_TOO_LARGE_RULE(SWEEP_TOO_LARGE) ["/sweep", "/step_deg"]
        "The sweep has at most 1e5 combinations and at most 5e8 grid points in all.";
    listed design::UNDERCUT;
    listed design::ELEMENT_OVERLAP;
    listed design::NON_FINITE;
    listed design::DEADLINE;
    listed common::RESPONSE_TOO_LARGE_RULE;
}

/// Default φ2 grid step \[deg\]: 1° + refinement is ≤ 1e-10 from the exact maximum and ~40× cheaper than the
/// paper's 0.02° grid (whose error is 1.8e-8); see `benches/RESULTS.md` (## irefc).
pub const STEP_DEG_DEFAULT: f64 = 1.0;
/// The paper's grid step \[deg\] (0.02°, no refinement).
pub const STEP_DEG_PAPER: f64 = 0.02;
/// Largest number of sweep combinations (spec).
pub const SWEEP_COMBINATIONS_MAX: u64 = 100_000;
/// Largest sweep work, combinations × grid points (spec).
pub const SWEEP_WORK_MAX: f64 = 5e8;
/// Tolerance on the last χ of a sweep range: χ_i = from + i·step is kept while ≤ to + this (spec).
pub const CHI_RANGE_TOL: f64 = 1e-12;

/// The output link: the request's `output_link`.
pub use super::wire::OutputLink;

/// How the load is shared: the request's `load_sharing`.
pub use super::wire::LoadSharing;

/// Scalar settings shared by every combination \[SI\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StressParams {
    /// Output torque T_out [N·m].
    pub torque: f64,
    /// Output link.
    pub output_link: OutputLink,
    /// Contact length \[m\]; `None` = 2·rb of each design.
    pub lb: Option<f64>,
    /// Contact modulus E* \[Pa\].
    pub e_star: f64,
    /// Requested grid step \[deg\].
    pub step_deg: f64,
    /// Grid intervals N = round(180/step) (grid points N + 1).
    pub n_intervals: usize,
    /// Refine maxima.
    pub refine: bool,
    /// Load-sharing mode.
    pub load_sharing: LoadSharing,
    /// Report τ_max and its depth.
    pub subsurface: bool,
}

/// One design of the four initial parameters \[SI\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Design {
    /// r2 \[m\].
    pub r2: f64,
    /// Z2.
    pub z2: u32,
    /// χ.
    pub chi: f64,
    /// rb \[m\].
    pub rb: f64,
}

/// Validated single-design input.
#[derive(Debug, Clone, PartialEq)]
pub struct SingleInput {
    /// The design.
    pub design: Design,
    /// Shared settings.
    pub params: StressParams,
    /// Output the element table.
    pub elements: bool,
    /// Output curves with this stride.
    pub curves_stride: Option<usize>,
    /// Output profiles with this many points per wheel.
    pub profile_points: Option<u32>,
}

/// Validated sweep input.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepInput {
    /// Z2 values, ascending.
    pub z2: Vec<u32>,
    /// χ values in order.
    pub chi: Vec<f64>,
    /// rb values \[m\].
    pub rb: Vec<f64>,
    /// r2 values \[m\].
    pub r2: Vec<f64>,
    /// Shared settings.
    pub params: StressParams,
    /// Request-level warnings (ignored fields).
    pub warnings: Vec<Warning>,
}

impl SweepInput {
    /// Number of combinations.
    #[must_use]
    pub fn len(&self) -> usize {
        self.z2.len() * self.chi.len() * self.rb.len() * self.r2.len()
    }

    /// Whether the sweep is empty (never, after validation).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The design of combination `i` (order: Z2, then χ, then rb, then r2 innermost).
    #[must_use]
    pub fn design(&self, i: usize) -> Design {
        let n_r2 = self.r2.len().max(1);
        let n_rb = self.rb.len().max(1);
        let n_chi = self.chi.len().max(1);
        let i_r2 = i % n_r2;
        let i_rb = (i / n_r2) % n_rb;
        let i_chi = (i / (n_r2 * n_rb)) % n_chi;
        let i_z2 = i / (n_r2 * n_rb * n_chi);
        Design {
            r2: self.r2.get(i_r2).copied().unwrap_or(f64::NAN),
            z2: self.z2.get(i_z2).copied().unwrap_or(0),
            chi: self.chi.get(i_chi).copied().unwrap_or(f64::NAN),
            rb: self.rb.get(i_rb).copied().unwrap_or(f64::NAN),
        }
    }
}

/// Validated input of `POST /v1/irefc-stress`.
#[derive(Debug, Clone, PartialEq)]
pub enum StressInput {
    /// One design.
    Single(SingleInput),
    /// The structured array.
    Sweep(SweepInput),
}

/// χ values from + i·step ≤ to (+ tolerance), clamped to `to`; `None` when there would be more than
/// `max` of them.
#[must_use]
pub fn chi_values(from: f64, to: f64, step: f64, max: u64) -> Option<Vec<f64>> {
    let approx = ((to - from + CHI_RANGE_TOL) / step).floor() + 1.0;
    // `max` ≤ 1e5 is exactly representable in f64.
    let maxf = max as f64;
    if !(approx.is_finite() && approx <= maxf + 1.0) {
        return None;
    }
    let mut v = Vec::new();
    for i in 0..=max {
        // i ≤ 1e5: exact in f64.
        let c = step.mul_add(i as f64, from);
        if c > to + CHI_RANGE_TOL {
            break;
        }
        if i == max {
            return None;
        }
        v.push(c.min(to));
    }
    Some(v)
}

impl StressInput {
    /// The rules between fields of a request whose ranges passed the door (spec "Inputs"):
    /// `MISSING_FIELD` and the range rules between fields (`BAD_RANGE`) at once, then grid/sweep
    /// size (`GRID_TOO_FINE`, `SWEEP_TOO_LARGE`). Feasibility (`UNDERCUT`, `ELEMENT_OVERLAP`) is
    /// checked on the geometry by the caller.
    ///
    /// # Errors
    /// Each broken rule ([`CROSS_FIELD_RULES`]).
    pub fn try_from_request(req: &IrefcStressRequest) -> Result<Self, CalcFailure> {
        let mut v = design::validator();
        let mode = mode_of(req);
        if mode == StressMode::Single && req.sweep.is_some() {
            rule!(v, SWEEP_NEEDS_MODE, "/sweep"; "sweep is only allowed with mode \"sweep\"");
        }
        let include = req.include.unwrap_or_default();
        let checked = Checked {
            req,
            params: check_params(&mut v, req, &include),
            include,
            r2: req.r2_mm,
            rb: req.rb_mm,
        };
        match mode {
            StressMode::Single => single(checked, v).map(Self::Single),
            StressMode::Sweep => sweep(checked, v).map(Self::Sweep),
        }
    }
}

/// The request's mode: as given, else "sweep" when `sweep` is present, else "single".
fn mode_of(req: &IrefcStressRequest) -> StressMode {
    match (req.mode, req.sweep.is_some()) {
        (Some(m), _) => m,
        (None, true) => StressMode::Sweep,
        (None, false) => StressMode::Single,
    }
}

/// What `POST /v1/irefc-stress` runs: the validated input and, for a sweep, the shard.
#[derive(Debug, Clone, PartialEq)]
pub struct StressJob {
    /// The validated input.
    pub input: StressInput,
    /// The block of the sweep to compute (`None`: the whole sweep, or a single design).
    pub shard: Option<Shard>,
}

impl TryFrom<IrefcStressRequest> for StressJob {
    type Error = CalcFailure;

    /// The rules between fields ([`StressInput::try_from_request`]) and those of `shard`.
    fn try_from(req: IrefcStressRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let shard = common::shard_rule(&mut v, req.shard);
        if req.shard.is_some() && mode_of(&req) == StressMode::Single {
            rule!(v, SHARD_NEEDS_SWEEP, "/shard";
                "shard splits a sweep; mode \"single\" has one design");
        }
        let input = common::with_issues(v, StressInput::try_from_request(&req))?;
        Ok(Self { input, shard })
    }
}

/// A request with the fields both modes share checked (their problems are in the validator).
struct Checked<'a> {
    req: &'a IrefcStressRequest,
    include: StressInclude,
    /// The shared settings (`lb` is checked per mode, against the r2 values).
    params: StressParams,
    /// Top-level r2 (mm) when given.
    r2: Option<f64>,
    /// Top-level rb (mm) when given.
    rb: Option<f64>,
}

/// The settings shared by every design (`lb` is checked per mode, against the r2 values; the
/// ranges at the door).
fn check_params(
    v: &mut Validator,
    req: &IrefcStressRequest,
    include: &StressInclude,
) -> StressParams {
    let wm = req.wheel_material.unwrap_or_default();
    let rm = req.roller_material.unwrap_or_default();
    let step_deg = req.step_deg.unwrap_or(STEP_DEG_DEFAULT);
    let n_intervals = grid_intervals(v, step_deg).unwrap_or(0);
    StressParams {
        torque: req.torque_nm,
        output_link: req.output_link.unwrap_or_default(),
        lb: None,
        e_star: 1.0 / (wm.compliance() + rm.compliance()),
        step_deg,
        n_intervals,
        refine: req.refine.unwrap_or(true),
        load_sharing: req.load_sharing.unwrap_or_default(),
        subsurface: include.subsurface.unwrap_or(false),
    }
}

/// Grid intervals N = round(180/step) of a step in (0, 10] (the door): `GRID_TOO_FINE` below
/// [`STEP_DEG`].
fn grid_intervals(v: &mut Validator, step_deg: f64) -> Option<usize> {
    if !STEP_DEG.contains(step_deg) {
        rule!(v, GRID_TOO_FINE_RULE, "/step_deg";
            "grid step {step_deg} deg gives 180/step = {} intervals > {GRID_INTERVALS_MAX}",
            180.0 / step_deg);
        return None;
    }
    // 18 ≤ N ≤ 2e6 here: the conversion is exact.
    Some((180.0 / step_deg).round() as usize)
}

/// The validated single design (the shared checks are already in `v`).
fn single(checked: Checked<'_>, mut v: Validator) -> Result<SingleInput, CalcFailure> {
    let Checked {
        req,
        include,
        mut params,
        r2,
        rb,
    } = checked;
    for (pointer, name, given) in [
        ("/r2_mm", "r2_mm", req.r2_mm.is_some()),
        ("/rb_mm", "rb_mm", req.rb_mm.is_some()),
    ] {
        if !given {
            design::missing(&mut v, &MODE_FIELDS, pointer, name);
        }
    }
    let z2 = required(&mut v, req.z2, "/Z2", "Z2 (mode \"single\")").and_then(design::z2);
    let chi = required(&mut v, req.chi, "/chi", "chi (mode \"single\")");
    params.lb = check_lb(&mut v, req.lb_mm, r2.as_slice()).map(|x| x / MM);
    v.finish()?;
    let (Some(r2), Some(z2), Some(chi), Some(rb)) = (r2, z2, chi, rb) else {
        return Err(unreachable_incomplete());
    };
    let curves_stride = include
        .curves
        .unwrap_or(false)
        .then(|| usize::try_from(req.curves_stride.unwrap_or(1)).unwrap_or(usize::MAX));
    let profile_points = include
        .profiles
        .unwrap_or(false)
        .then(|| req.profile_points.unwrap_or(PROFILE_POINTS_DEFAULT));
    Ok(SingleInput {
        design: Design {
            r2: r2 / MM,
            z2,
            chi,
            rb: rb / MM,
        },
        params,
        elements: include.elements.unwrap_or(true),
        curves_stride,
        profile_points,
    })
}

/// The validated structured array (the shared checks are already in `v`).
fn sweep(checked: Checked<'_>, mut v: Validator) -> Result<SweepInput, CalcFailure> {
    let Checked {
        req,
        include,
        mut params,
        r2,
        rb,
    } = checked;
    let Some(sw) = req.sweep.as_ref() else {
        design::missing(&mut v, &MODE_FIELDS, "/sweep", "sweep (mode \"sweep\")");
        v.finish()?;
        return Err(unreachable_incomplete());
    };
    // Scalar Z2 and χ are ignored here, but were held to their documented ranges at the door.
    let warnings = ignored_fields(req, &include);
    let z2s = z2_values(&mut v, &sw.z2);
    let chis = chi_sweep(&mut v, &sw.chi);
    let rbs = sweep_list(&mut v, "rb_mm", sw.rb_mm.as_deref(), rb);
    let r2s = sweep_list(&mut v, "r2_mm", sw.r2_mm.as_deref(), r2);
    params.lb = check_lb(&mut v, req.lb_mm, &r2s).map(|x| x / MM);
    v.checkpoint()?;
    // Sizes (only once the ranges are valid).
    check_size(
        &mut v,
        &z2s,
        chis.as_deref(),
        rbs.len().saturating_mul(r2s.len()),
        params.n_intervals,
    );
    v.finish()?;
    Ok(SweepInput {
        z2: z2s,
        chi: chis.unwrap_or_default(),
        rb: rbs.into_iter().map(|x| x / MM).collect(),
        r2: r2s.into_iter().map(|x| x / MM).collect(),
        params,
        warnings,
    })
}

/// A required field of the mode: `MISSING_FIELD` when absent.
fn required<T>(v: &mut Validator, value: Option<T>, pointer: &str, what: &str) -> Option<T> {
    if value.is_none() {
        design::missing(v, &MODE_FIELDS, pointer, what);
    }
    value
}

/// The failure of a design that validation left incomplete (cannot happen: every missing value
/// recorded a problem and `finish` returned it).
fn unreachable_incomplete() -> CalcFailure {
    crate::calc::rules::door_skipped("/Z2")
}

/// `FIELD_IGNORED` warnings for the single-design fields of a sweep request.
fn ignored_fields(req: &IrefcStressRequest, include: &StressInclude) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if req.z2.is_some() || req.chi.is_some() {
        warnings.push(Warning::new(
            "FIELD_IGNORED",
            "scalar Z2/chi are ignored in mode \"sweep\" (the sweep ranges are used)",
        ));
    }
    if [include.elements, include.curves, include.profiles].contains(&Some(true)) {
        warnings.push(Warning::new(
            "FIELD_IGNORED",
            "include.elements/curves/profiles are forced off in mode \"sweep\"",
        ));
    }
    warnings
}

/// Z2 values of the sweep, ascending (empty when the range is invalid; its ends were checked
/// at the door).
fn z2_values(v: &mut Validator, r: &IntRange) -> Vec<u32> {
    let from = design::z2(r.from);
    let to = design::z2(r.to);
    match (from, to) {
        (Some(a), Some(b)) if a > b => {
            rule!(v, SWEEP_RANGE_ORDER, "/sweep/Z2/to"; "Z2.to = {b} must be >= Z2.from = {a}");
            Vec::new()
        }
        (Some(a), Some(b)) => (a..=b).collect(),
        _ => Vec::new(),
    }
}

/// χ values of the sweep (empty when the range is invalid; its ends and step were checked at the
/// door); `None` when there would be more than [`SWEEP_COMBINATIONS_MAX`] of them.
fn chi_sweep(v: &mut Validator, r: &StepRange) -> Option<Vec<f64>> {
    let (a, b) = (r.from, r.to);
    if a > b {
        rule!(v, SWEEP_RANGE_ORDER, "/sweep/chi/to"; "chi.to = {b} must be >= chi.from = {a}");
        return Some(Vec::new());
    }
    chi_values(a, b, r.step, SWEEP_COMBINATIONS_MAX)
}

/// The values of a sweep list `sweep.<name>` (mm; its items and length were checked at the
/// door), or without the list the top-level `<name>` (`top`; required then).
fn sweep_list(v: &mut Validator, name: &str, list: Option<&[f64]>, top: Option<f64>) -> Vec<f64> {
    let Some(list) = list else {
        if top.is_none() {
            design::missing(
                v,
                &MODE_FIELDS,
                &format!("/{name}"),
                &format!("{name} (or sweep.{name})"),
            );
        }
        return top.into_iter().collect();
    };
    list.to_vec()
}

/// `SWEEP_TOO_LARGE` when the sweep has more than [`SWEEP_COMBINATIONS_MAX`] combinations
/// (`chis` is `None`: more χ values than that alone) or more than [`SWEEP_WORK_MAX`] grid points.
fn check_size(
    v: &mut Validator,
    z2s: &[u32],
    chis: Option<&[f64]>,
    n_lists: usize,
    n_intervals: usize,
) {
    let Some(chis) = chis else {
        rule!(v, SWEEP_TOO_LARGE_RULE, "/sweep";
            "the sweep has more than 100000 combinations > {SWEEP_COMBINATIONS_MAX}");
        return;
    };
    let combos = (z2s.len() as u64)
        .saturating_mul(chis.len() as u64)
        .saturating_mul(n_lists as u64);
    if combos > SWEEP_COMBINATIONS_MAX {
        rule!(v, SWEEP_TOO_LARGE_RULE, "/sweep";
            "the sweep has {combos} combinations > {SWEEP_COMBINATIONS_MAX}");
        return;
    }
    // combos ≤ 1e5, n_intervals ≤ 2e6: both exact in f64.
    let work = combos as f64 * (n_intervals as f64 + 1.0);
    if work > SWEEP_WORK_MAX {
        rule!(v, SWEEP_TOO_LARGE_RULE, "/sweep";
            "combinations x grid points = {combos} x {} = {work} > {SWEEP_WORK_MAX}; use a coarser step_deg",
            n_intervals + 1);
    }
}

/// Check lb (mm) against lb ≤ 100·r2 for every r2 given ([`LB_BELOW_R2`]; lb > 0 is checked at
/// the door); returns it when valid.
fn check_lb(v: &mut Validator, lb: Option<f64>, r2s_mm: &[f64]) -> Option<f64> {
    let x = lb?;
    let r2_min = r2s_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let range: Range = if r2_min.is_finite() {
        LB_MM.max(LB_MAX_OVER_R2 * r2_min)
    } else {
        LB_MM
    };
    ensure_rule!(v, range.contains(x), LB_BELOW_R2, "/lb_mm";
        "contact length lb_mm [mm] must be {range}, got {x}")
    .then_some(x)
}
