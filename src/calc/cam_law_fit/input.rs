//! The rules between fields of a fit request (spec §2 "Reject with 422", §3.3 data preparation),
//! turning it into a [`FitInput`]. Every per-field rule (ranges, lengths, exactly one of
//! `values`/`grid`) is declared on the wire types and checked at the door; what is left here is
//! what JSON Schema cannot state, each rule with its own code ([`CROSS_FIELD_RULES`]).

use crate::calc::cam_law::law::{
    BoundaryConditions, K1, LawError, LawNotice, Quantity, SevenSegmentLaw,
};
use crate::calc::cam_law::wire::Units;
use crate::calc::rules::rule;
use crate::calc::{CalcFailure, Validator};

use super::optim::ga::GaParams;
use super::wire::{Channels, FitCamLawRequest, GaIn, MAX_CURVE_COUNT, Method, MetricName};
use crate::numerics::grid;

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/fit-cam-law`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid ABSCISSA_ORDER ["/abscissa/values/*", "/abscissa/grid/end", "/abscissa/grid"]
        "Abscissae strictly increase; a grid's `end` is greater than its `start`, and its `count` \
         points stay strictly increasing in f64.";
    invalid NO_CHANNEL ["/channels"]
        "At least one of `channels.displacement`, `channels.velocity`, `channels.acceleration` is given.";
    invalid CHANNEL_LENGTH ["/channels/displacement", "/channels/velocity",
        "/channels/acceleration", "/abscissa"]
        "Every supplied channel holds exactly one value per abscissa (N values).";
    invalid FIT_CHANNEL("FIT_CHANNEL_MISSING") ["/fit_on", "/derive_missing", "/channels"]
        "The `fit_on` channel (default acceleration) is supplied, or `derive_missing` is true and a \
         lower channel (s → v → a) is supplied to differentiate.";
    invalid END_DISPLACEMENT("END_DISPLACEMENT_REQUIRED") ["/constraints/s_a", "/constraints/s_b",
        "/channels/displacement"]
        "`constraints.s_a` and `constraints.s_b` are given when no displacement channel is supplied.";
    invalid SEGMENT_INTERVAL ["/constraints/t_a", "/constraints/t_b"]
        "t_b > t_a (each defaulting to the first/last abscissa), and t_b − t_a exceeds \
         1e-12·max(|t_a|, |t_b|) so the knots stay distinct.";
    invalid ABSCISSA_OUTSIDE ["/abscissa/values/*", "/abscissa/grid", "/constraints/t_a",
        "/constraints/t_b"]
        "Every sample abscissa lies in [t_a, t_b] within 1e-9·(t_b − t_a) (values within that \
         tolerance are clamped).";
    invalid DTW_WINDOW_SAMPLES ["/objective/dtw_window", "/abscissa"]
        "objective.dtw_window ≤ N, the number of samples.";
    invalid METHOD_METRIC ["/optimizer/method", "/objective/metric"]
        "optimizer.method `lsq` is used only with objective.metric `euclidean`.";
    invalid INITIAL_EXCLUSIVE ["/initial_coefficients", "/initial_law"]
        "At most one of `initial_coefficients` and `initial_law` is given.";
    invalid INITIAL_LAW_CLASS ["/initial_law"]
        "initial_law is a 7-segment law: constant_acceleration, simple_harmonic, cycloidal, \
         modified_trapezoid or modified_sine.";
    invalid EMPTY_PULSE ["/fixed_zero", "/initial_coefficients", "/initial_law"]
        "Both acceleration pulses of the initial solution (c0..c2 and c4..c6, after `fixed_zero`) \
         keep a free segment with a positive duration.";
    too_large FIT_TOO_EXPENSIVE ["/optimizer/max_evaluations", "/abscissa", "/objective/dtw_window"]
        "max_evaluations × N × (metric dtw ? 2w+1 : 1) ≤ 2e10 cell operations.";
    infeasible INFEASIBLE_CONSTRAINTS ["/constraints"]
        "Some 7-segment law over [t_a, t_b] meets the end conditions in f64 (the initial law's \
         peaks stay finite).";
    /// The fitted law exists in f64 (found while computing).
    too_large LAW_OVERFLOW ["/constraints"] "The fitted law's peaks stay finite in f64.";
    /// Every reported number is finite (found while computing).
    too_large RESULT_OVERFLOW ["/channels", "/constraints"]
        "Every reported number of the fitted law is finite in f64 (rescale the units of the data).";
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

/// Samples may lie this fraction of Δt outside `[t_a, t_b]` (they are clamped), spec §2.
pub const ABSCISSA_TOL: f64 = 1e-9;
/// Largest accepted cost estimate `max_evaluations × N × (2w+1)` in cell operations (spec §2:
/// a request beyond it would run for minutes).
pub const MAX_COST: f64 = 2e10;
/// Default evaluation cap (spec §2).
pub const DEFAULT_MAX_EVALUATIONS: u64 = 50_000;
/// Default time limit \[ms\] (spec §2).
pub const DEFAULT_TIME_LIMIT_MS: u64 = 10_000;
/// Largest accepted time limit \[ms\] (spec §2; the end of the shared `time_limit_ms` bound, a whole
/// number: the conversion is exact).
pub const MAX_TIME_LIMIT_MS: u64 = crate::calc::common::TIME_LIMIT_MS.hi as u64;
/// Default zero-snap threshold (spec §3.5.2 step 4).
pub const DEFAULT_SNAP_TOL: f64 = 2e-3;
/// Default IPOP restarts for DTW in `auto` (spec §2).
pub const DEFAULT_DTW_RESTARTS: u32 = 3;

/// A validated fit request (SI is not imposed: units are the caller's, spec §2).
#[derive(Debug, Clone)]
pub struct FitInput {
    /// The samples.
    pub data: FitData,
    /// Boundary conditions.
    pub bc: BoundaryConditions,
    /// What is compared, and how.
    pub objective: ObjectiveSpec,
    /// Optimizer settings (the request's evaluation cap in `max_evaluations`).
    pub settings: Settings,
    /// Optional outputs asked for.
    pub outputs: FitOutputs,
    /// Unit labels to echo.
    pub units: Option<Units>,
    /// Findings of validation.
    pub warnings: Vec<LawNotice>,
}

/// The samples of a fit.
#[derive(Debug, Clone)]
pub struct FitData {
    /// Sample abscissae as given (strictly increasing).
    pub xs: Vec<f64>,
    /// Abscissae clamped into `[t_a, t_b]` (where the model is sampled).
    pub xs_model: Vec<f64>,
    /// Channels s, v, a (supplied or derived), indexed by [`Channel::index`].
    pub channels: [Option<Vec<f64>>; 3],
    /// Which channels were derived numerically.
    pub derived: [bool; 3],
}

/// The objective of a fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ObjectiveSpec {
    /// The channel compared.
    pub on: Channel,
    /// Distance.
    pub metric: MetricKind,
    /// DTW band radius (the request's, or 1 for the error table of Euclidean fits).
    pub dtw_window: usize,
}

/// The optional outputs of a fit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FitOutputs {
    /// Dense-curve point count (0 = none).
    pub curve_count: usize,
    /// Dense-curve quantities.
    pub curve_quantities: Vec<Quantity>,
    /// Compute the error table.
    pub error_table: bool,
    /// Record the history.
    pub history: bool,
    /// Classify against the catalogue.
    pub classify: bool,
}

/// A measured channel: the request's quantity.
pub use super::wire::FitQuantity as Channel;

impl Channel {
    /// s, v, a.
    pub const ALL: [Self; 3] = [Self::Displacement, Self::Velocity, Self::Acceleration];

    /// Index in [`FitData::channels`]: s = 0, v = 1, a = 2.
    #[must_use]
    pub const fn index(self) -> usize {
        match self {
            Self::Displacement => 0,
            Self::Velocity => 1,
            Self::Acceleration => 2,
        }
    }

    /// The law quantity of the channel.
    #[must_use]
    pub const fn quantity(self) -> Quantity {
        match self {
            Self::Displacement => Quantity::S,
            Self::Velocity => Quantity::V,
            Self::Acceleration => Quantity::A,
        }
    }

    /// Wire name of the channel.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Displacement => "displacement",
            Self::Velocity => "velocity",
            Self::Acceleration => "acceleration",
        }
    }
}

/// The distance between model and data: the request's metric.
pub use super::wire::MetricName as MetricKind;

/// The optimizer of a fit (spec §3.5): the request's `optimizer.method`.
pub use super::wire::Method as Algorithm;

/// Optimizer settings of one fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Method.
    pub method: Algorithm,
    /// RNG seed.
    pub seed: u64,
    /// GA settings.
    pub ga: GaParams,
    /// IPOP restarts for DTW in `auto`.
    pub dtw_global_restarts: u32,
    /// Least-squares + snap polish after the stochastic methods (EN only).
    pub polish: bool,
    /// Zero-snap threshold on normalized coefficients.
    pub snap_tol: f64,
    /// Initial coefficients (normalized, fixed genes zero).
    pub initial: [f64; 7],
    /// Segments held at zero.
    pub fixed_zero: [bool; 7],
    /// Request's evaluation cap (the `lsq` method's single run may use all of it).
    pub max_evaluations: u64,
}

/// The sample abscissae (exactly one of `values`/`grid`, their lengths and the grid's count are
/// checked at the door).
fn abscissa(req: &FitCamLawRequest, v: &mut Validator) -> Option<Vec<f64>> {
    match (&req.abscissa.values, &req.abscissa.grid) {
        (Some(_), Some(_)) | (None, None) => None,
        (Some(values), None) => {
            if let Some(i) = values.windows(2).position(|w| w[1] <= w[0]) {
                rule!(v, ABSCISSA_ORDER, format!("/abscissa/values/{}", i + 1);
                    "abscissae must be strictly increasing, got {} after {}", values[i + 1],
                    values[i]);
                return None;
            }
            Some(values.clone())
        }
        (None, Some(g)) => {
            if g.end <= g.start {
                rule!(v, ABSCISSA_ORDER, "/abscissa/grid/end";
                    "must be > start = {}, got {}", g.start, g.end);
                return None;
            }
            // count ≤ 200 000 (checked at the door): the conversion cannot fail.
            let count = usize::try_from(g.count).ok()?;
            let xs = grid::linspace(g.start, g.end, count);
            if xs.windows(2).any(|w| w[1] <= w[0]) {
                rule!(v, ABSCISSA_ORDER, "/abscissa/grid";
                    "the grid [{}, {}] with {count} points is too fine to be strictly increasing in f64",
                    g.start, g.end);
                return None;
            }
            Some(xs)
        }
    }
}

/// The supplied channels s, v, a.
fn supplied(req: &FitCamLawRequest) -> [Option<&Vec<f64>>; 3] {
    [
        req.channels.displacement.as_ref(),
        req.channels.velocity.as_ref(),
        req.channels.acceleration.as_ref(),
    ]
}

/// Channels: one value per abscissa (their magnitudes are checked at the door); the fitted
/// channel supplied or derivable. Returns whether every supplied channel is valid, and the
/// fitted channel.
fn check_channels(req: &FitCamLawRequest, n: Option<usize>, v: &mut Validator) -> (bool, Channel) {
    let supplied = supplied(req);
    if supplied.iter().all(Option::is_none) {
        rule!(v, NO_CHANNEL, "/channels";
            "supply at least one of displacement, velocity, acceleration");
    }
    let mut channels_ok = true;
    for (q, ch) in Channel::ALL.iter().zip(supplied) {
        if let Some(values) = ch {
            let p = format!("/channels/{}", q.name());
            if let Some(n) = n
                && values.len() != n
            {
                rule!(v, CHANNEL_LENGTH, &p;
                    "must have one value per abscissa ({n}), got {}", values.len());
                channels_ok = false;
            }
        }
    }
    let fit_on = req.fit_on.unwrap_or(Channel::Acceleration);
    let fit_idx = fit_on.index();
    if supplied[fit_idx].is_none() && !supplied.iter().all(Option::is_none) {
        if !req.derive_missing {
            rule!(v, FIT_CHANNEL, "/fit_on";
                "the {} channel is not supplied: supply it, fit on a supplied channel, or set derive_missing: true",
                fit_on.name());
        } else if supplied[..fit_idx].iter().all(Option::is_none) {
            rule!(v, FIT_CHANNEL, "/fit_on";
                "cannot derive {} from the supplied channels: only differentiation s → v → a is offered (no integration); fit on a supplied channel",
                fit_on.name());
        }
    }

    (channels_ok, fit_on)
}

/// Boundary conditions (given, or taken from the first and last samples; their magnitudes are
/// checked at the door) and every sample inside `[t_a, t_b]`.
fn check_constraints(
    req: &FitCamLawRequest,
    xs: Option<&[f64]>,
    v: &mut Validator,
) -> Option<BoundaryConditions> {
    let c = req.constraints;
    let supplied = supplied(req);
    let first = xs.as_ref().and_then(|x| x.first().copied());
    let last = xs.as_ref().and_then(|x| x.last().copied());
    let t_a = c.t_a.or(first);
    let t_b = c.t_b.or(last);
    let s_data = supplied[0];
    let s_a = c.s_a.or_else(|| s_data.and_then(|s| s.first().copied()));
    let s_b = c.s_b.or_else(|| s_data.and_then(|s| s.last().copied()));
    // (With no channel at all, `/channels` already says what is missing.)
    let any_channel = supplied.iter().any(Option::is_some);
    for (name, given, end) in [("s_a", s_a, "start"), ("s_b", s_b, "end")] {
        if given.is_none() && s_data.is_none() && any_channel {
            rule!(v, END_DISPLACEMENT, format!("/constraints/{name}");
                "required when no displacement channel is supplied (the {end} displacement)");
        }
    }
    let mut bc = None;
    if let (Some(t_a), Some(t_b), Some(s_a), Some(s_b)) = (t_a, t_b, s_a, s_b)
        && t_a.is_finite()
        && t_b.is_finite()
    {
        let cand = BoundaryConditions {
            t_a,
            t_b,
            s_a,
            s_b,
            v_a: c.v_a.unwrap_or(0.0),
            v_b: c.v_b.unwrap_or(0.0),
            a_a: c.a_a.unwrap_or(0.0),
            a_b: c.a_b.unwrap_or(0.0),
        };
        match cand.check() {
            Ok(()) => bc = Some(cand),
            Err(LawError::IntervalNotIncreasing { .. }) => {
                rule!(v, SEGMENT_INTERVAL, "/constraints/t_b";
                "t_b must be greater than t_a = {t_a}, got {t_b}")
            }
            Err(e @ LawError::IntervalTooShort { .. }) => {
                rule!(v, SEGMENT_INTERVAL, "/constraints/t_b"; "{}", e.to_string());
            }
            // Every given value and every sample is within DATA_VALUE (the door), so the
            // magnitude cap cannot be broken; should it be, it is the segment's rule.
            Err(e) => rule!(v, SEGMENT_INTERVAL, "/constraints"; "{}", e.to_string()),
        }
    }
    // Samples inside [t_a, t_b] up to the tolerance.
    if let (Some(bc), Some(xs)) = (bc.as_ref(), xs.as_ref()) {
        let tol = ABSCISSA_TOL * (bc.t_b - bc.t_a);
        let pointer_base = if req.abscissa.values.is_some() {
            "/abscissa/values"
        } else {
            "/abscissa/grid"
        };
        if let Some((i, x)) = xs
            .iter()
            .enumerate()
            .find(|(_, x)| **x < bc.t_a - tol || **x > bc.t_b + tol)
        {
            let p = if req.abscissa.values.is_some() {
                format!("{pointer_base}/{i}")
            } else {
                pointer_base.to_owned()
            };
            rule!(v, ABSCISSA_OUTSIDE, p;
                "sample x = {x} lies outside the segment [t_a, t_b] = [{}, {}]: set constraints t_a/t_b to cover every sample, or drop the samples outside",
                bc.t_a, bc.t_b);
        }
    }

    bc
}

/// The GA settings (spec §3.5.1 defaults for every field not given; ranges checked at the door).
fn ga_params(ga_in: Option<GaIn>) -> GaParams {
    let d = GaParams::default();
    let Some(g) = ga_in else { return d };
    GaParams {
        // ≤ 10 000 (checked at the door): the conversion cannot fail.
        population: g
            .population
            .map_or(d.population, |p| usize::try_from(p).unwrap_or(100)),
        generations: g.generations.unwrap_or(d.generations),
        p_crossover: g.p_crossover.unwrap_or(d.p_crossover),
        p_inversion: g.p_inversion.unwrap_or(d.p_inversion),
        p_range_mutation: g.p_range_mutation.unwrap_or(d.p_range_mutation),
        range0: g.range0.unwrap_or(d.range0),
        range_factor: g.range_factor.unwrap_or(d.range_factor),
        range_every: g.range_every.unwrap_or(d.range_every),
        p_mutation: g.p_mutation.unwrap_or(d.p_mutation),
        stall_generations: g.stall_generations.unwrap_or(d.stall_generations),
    }
}

/// Initial coefficients (normalized, fixed genes zeroed), the fixed-zero mask, and the pointer
/// of the field that gave the initial law.
fn check_initial(
    req: &FitCamLawRequest,
    v: &mut Validator,
) -> ([f64; 7], [bool; 7], Option<&'static str>) {
    let mut fixed_zero = [false; 7];
    // 7 flags: checked at the door.
    if let Some(fz) = &req.fixed_zero
        && fz.len() == 7
    {
        fixed_zero.copy_from_slice(fz);
        for (pulse, cs, which) in [
            (0..3, "c0, c1, c2", "first"),
            (4..7, "c4, c5, c6", "second"),
        ] {
            if fixed_zero[pulse].iter().all(|z| *z) {
                rule!(v, EMPTY_PULSE, "/fixed_zero";
                    "fixes all of {cs}: the {which} acceleration pulse would be empty; free at least one of them");
            }
        }
    }
    let mut initial = [1.0 / 7.0; 7];
    let mut initial_pointer = None;
    match (&req.initial_coefficients, req.initial_law) {
        (Some(_), Some(_)) => rule!(v, INITIAL_EXCLUSIVE, "/initial_law";
            "give at most one of initial_coefficients and initial_law"),
        (Some(ic), None) => {
            initial_pointer = Some("/initial_coefficients");
            // 7 numbers ≥ 0: checked at the door.
            if ic.len() == 7 {
                initial.copy_from_slice(ic);
            }
        }
        (None, Some(law)) => {
            initial_pointer = Some("/initial_law");
            match law.seven_segment_coefficients() {
                Some(cv) => initial = cv,
                None => rule!(v, INITIAL_LAW_CLASS, "/initial_law";
                    "{} is not a 7-segment law: use constant_acceleration, simple_harmonic, cycloidal, modified_trapezoid or modified_sine, or give initial_coefficients",
                    law.wire_name()),
            }
        }
        (None, None) => {}
    }
    for (c, z) in initial.iter_mut().zip(fixed_zero) {
        if z {
            *c = 0.0;
        }
    }
    let sum: f64 = initial.iter().sum();
    let pulse1 = K1.mul_add(initial[0], K1.mul_add(initial[2], initial[1]));
    let pulse2 = K1.mul_add(initial[4], K1.mul_add(initial[6], initial[5]));
    let p = initial_pointer.unwrap_or("/fixed_zero");
    if sum.is_finite() && sum > 0.0 {
        initial.iter_mut().for_each(|c| *c /= sum);
        for (pulse, cs, which) in [
            (pulse1, "c0, c1, c2", "first"),
            (pulse2, "c4, c5, c6", "second"),
        ] {
            if pulse <= 0.0 {
                rule!(v, EMPTY_PULSE, p;
                    "{cs} (after fixed_zero) are all zero: the {which} acceleration pulse is empty; give at least one of them a positive value");
            }
        }
    } else if sum.is_finite() {
        rule!(v, EMPTY_PULSE, p;
            "the coefficients (after fixed_zero) are all zero: both acceleration pulses are empty");
    }

    (initial, fixed_zero, initial_pointer)
}

/// Dense-curve point count and quantities (each once, in request order; the count's range is
/// checked at the door).
fn curves(req: &FitCamLawRequest) -> (usize, Vec<Quantity>) {
    match &req.outputs.curves {
        Some(cv) => {
            let mut qs: Vec<Quantity> = Vec::new();
            for q in cv
                .quantities
                .clone()
                .unwrap_or_else(|| Quantity::ALL.to_vec())
            {
                if !qs.contains(&q) {
                    qs.push(q);
                }
            }
            (
                usize::try_from(cv.count.min(MAX_CURVE_COUNT)).unwrap_or(0),
                qs,
            )
        }
        None => (0, Vec::new()),
    }
}

/// Infeasible boundary conditions: the initial law must exist in f64.
fn check_feasible(
    initial: &[f64; 7],
    bc: &BoundaryConditions,
    initial_pointer: Option<&'static str>,
) -> Result<(), CalcFailure> {
    match SevenSegmentLaw::try_new(initial, bc) {
        Ok(_) => {}
        Err(e @ (LawError::EmptyFirstPulse { .. } | LawError::EmptySecondPulse { .. })) => {
            return Err(EMPTY_PULSE.fail(
                initial_pointer.unwrap_or("/fixed_zero"),
                format!("{e}: give the segments of that pulse a longer initial duration"),
            ));
        }
        // The boundary conditions and the coefficients passed their checks above, so the law
        // fails only by overflowing f64.
        Err(e) => {
            return Err(INFEASIBLE_CONSTRAINTS.fail(
                "/constraints",
                format!(
                    "no 7-segment law over Δt = {} can meet these end conditions in f64 ({e}): widen [t_a, t_b], reduce the end rates or rescale the units",
                    bc.t_b - bc.t_a
                ),
            ));
        }
    }
    Ok(())
}

/// The channels s, v, a with the ones the fit needs derived (spec §3.3, s → v → a up to the
/// fitted channel) when `derive_missing` is set, which of them were derived, and the findings.
fn with_derived(
    req_channels: Channels,
    derive_missing: bool,
    fit_idx: usize,
    xs: &[f64],
    bc: &BoundaryConditions,
) -> ([Option<Vec<f64>>; 3], [bool; 3], Vec<LawNotice>) {
    let mut channels: [Option<Vec<f64>>; 3] = [
        req_channels.displacement,
        req_channels.velocity,
        req_channels.acceleration,
    ];
    let mut derived = [false; 3];
    let mut warnings = Vec::new();
    if derive_missing {
        // Only the channels the fit needs are derived (s → v → a up to `fit_on`).
        for k in 1..=fit_idx {
            if channels[k].is_none()
                && let Some(lower) = channels[k - 1].as_ref()
            {
                channels[k] = Some(grid::gradient(lower, xs));
                derived[k] = true;
            }
        }
        if derived[fit_idx] {
            warnings.push(LawNotice::DerivedChannelNoiseGain);
        }
    }
    if bc.s_b - bc.s_a == 0.0 && bc.zero_end_rates() {
        warnings.push(LawNotice::NonIdentifiable);
    }
    (channels, derived, warnings)
}

/// Check the rules between fields of a request whose per-field rules passed the door, turning
/// it into a [`FitInput`].
///
/// # Errors
/// Every broken rule of [`CROSS_FIELD_RULES`] with its pointer (invalid input listed at once);
/// [`FIT_TOO_EXPENSIVE`] when the cost estimate exceeds [`MAX_COST`];
/// [`INFEASIBLE_CONSTRAINTS`] when the boundary conditions admit no representable law of this
/// duration (the initial law overflows f64).
pub fn validate(req: FitCamLawRequest) -> Result<FitInput, CalcFailure> {
    let mut v = Validator::new();
    let xs = abscissa(&req, &mut v);
    let n = xs.as_ref().map(Vec::len);

    let (channels_ok, fit_on) = check_channels(&req, n, &mut v);
    let fit_idx = fit_on.index();
    let bc = check_constraints(&req, xs.as_deref(), &mut v);

    // Objective.
    let metric = req.objective.metric;
    let mut dtw_window = 1usize;
    if let Some(w) = req.objective.dtw_window {
        // 0 ≤ w ≤ 2e5 (checked at the door); at most N, the number of samples.
        match (usize::try_from(w), n) {
            (Ok(wu), Some(max)) if wu <= max => dtw_window = wu,
            (Ok(_), None) => {}
            _ => rule!(v, DTW_WINDOW_SAMPLES, "/objective/dtw_window";
                "must be in [0, N = {}] samples, got {w}", n.unwrap_or_default()),
        }
    }

    // Optimizer.
    let o = req.optimizer;
    let method = o.method;
    if metric == MetricName::Dtw && method == Method::Lsq {
        rule!(v, METHOD_METRIC, "/optimizer/method";
            "`lsq` minimizes a sum of squares and cannot fit the DTW metric: use `auto`, `cmaes`, `de` or `ga`");
    }
    let max_evaluations = o.max_evaluations.unwrap_or(DEFAULT_MAX_EVALUATIONS);
    let ga = ga_params(o.ga);

    let (initial, fixed_zero, initial_pointer) = check_initial(&req, &mut v);
    let (curve_count, curve_quantities) = curves(&req);

    v.finish()?;
    // Every `None` below was reported above or is a per-field rule the door checks (exactly one
    // of `values`/`grid`), so `finish` has failed already unless the door was skipped.
    let (Some(xs), Some(bc)) = (xs, bc) else {
        return Err(crate::calc::rules::door_skipped("/abscissa"));
    };
    if !channels_ok {
        return Err(crate::calc::rules::door_skipped("/channels"));
    }
    let n = xs.len();

    // Cost guard (spec §2).
    let cost = {
        let w = if metric == MetricName::Dtw {
            2.0f64.mul_add(dtw_window.min(n - 1) as f64, 1.0)
        } else {
            1.0
        };
        max_evaluations as f64 * n as f64 * w
    };
    if cost > MAX_COST {
        return Err(FIT_TOO_EXPENSIVE.fail(
            "/optimizer/max_evaluations",
            format!(
                "estimated cost max_evaluations × N × (2w+1) = {cost:.3e} cell operations exceeds {MAX_COST:e}: lower max_evaluations, decimate the samples or narrow dtw_window"
            ),
        ));
    }

    check_feasible(&initial, &bc, initial_pointer)?;

    let (channels, derived, warnings) =
        with_derived(req.channels, req.derive_missing, fit_idx, &xs, &bc);
    let xs_model = xs.iter().map(|x| x.clamp(bc.t_a, bc.t_b)).collect();
    let dtw_window = if metric == MetricName::Dtw {
        dtw_window.min(n)
    } else {
        1
    };

    Ok(FitInput {
        data: FitData {
            xs,
            xs_model,
            channels,
            derived,
        },
        bc,
        objective: ObjectiveSpec {
            on: fit_on,
            metric,
            dtw_window,
        },
        settings: Settings {
            method,
            seed: o.seed.unwrap_or(0),
            ga,
            dtw_global_restarts: o.dtw_global_restarts.unwrap_or(DEFAULT_DTW_RESTARTS),
            polish: o.polish.unwrap_or(true),
            snap_tol: o.snap_tol.unwrap_or(DEFAULT_SNAP_TOL),
            initial,
            fixed_zero,
            max_evaluations,
        },
        outputs: FitOutputs {
            curve_count,
            curve_quantities,
            error_table: req.outputs.error_table.unwrap_or(true),
            history: req.outputs.history.unwrap_or(false),
            classify: req.outputs.classify.unwrap_or(true),
        },
        units: req.units,
        warnings,
    })
}

impl TryFrom<FitCamLawRequest> for FitInput {
    type Error = CalcFailure;

    /// The rules between fields ([`validate`]); the per-field rules are checked at the door.
    fn try_from(req: FitCamLawRequest) -> Result<Self, CalcFailure> {
        validate(req)
    }
}
