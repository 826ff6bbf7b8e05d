//! The rules between fields of a [`ContinuumWorkspaceRequest`] (spec 3), turning it into the SI
//! domain [`Input`]. Every per-field rule (ranges, list lengths, the 4-or-8 neighbours, the
//! power-of-two sub-steps) is declared on the wire types and checked at the door; what is left
//! here is what JSON Schema cannot state, each rule with its own code ([`CROSS_FIELD_RULES`]).

use std::time::Duration;

use super::fk::{self, HOME_REL_TOL};
use super::model::{Actuator, Design, Model, Params, Rod};
use super::modes::{self, ModeSearch};
use super::newton::{NewtonOptions, Stepping};
use super::presets::Preset;
use super::sweep::{Limits, StabilityCheck, SweepSettings};
use super::wire::{
    self, ActuatorRequest, AreaMethod, ContinuationKind, ContinuumWorkspaceRequest, DesignRequest,
    PresetName, RodCrossing, RodRequest, SeedRequest, SolverState, StabilityCheckName, StartKind,
    StartRequest, WorkspaceRequest,
};
use crate::calc::common::{self, Shard};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/continuum-workspace`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid DESIGN_SOURCE ["/design/preset", "/design/actuators", "/design/rods",
        "/design/home_inputs_m"]
        "Give either design.preset (with at most sigma_allow_pa) or both design.actuators and \
         design.rods (home_inputs_m only with an explicit design).";
    invalid DIRECTION_NORM ["/design/actuators/*/direction"]
        "The norm of each guide direction exceeds 1e-12.";
    invalid STROKE_ORDER ["/design/actuators/*/stroke_m"]
        "Each stroke_m is [min, max] with min < max.";
    invalid UNKNOWN_ACTUATOR ["/design/rods/*/actuator", "/design/actuators"]
        "Each rod's actuator is an index of design.actuators.";
    invalid ACTUATOR_WITHOUT_ROD ["/design/actuators/*", "/design/rods/*/actuator"]
        "Every actuator carries at least one rod (else its input is undetermined).";
    invalid ROD_STIFFNESS ["/design/rods/*/diameter_m", "/design/rods/*/ei_nm2"]
        "Each rod gives diameter_m or ei_nm2 (or both).";
    invalid SLENDERNESS ["/design/rods/*/diameter_m", "/design/rods/*/length_m"]
        "Each rod's slenderness length_m / diameter_m is at least 5 (below 20 it is warned).";
    invalid COINCIDENT_ATTACHMENTS ["/design/rods"]
        "The rods' attachment points attach_m do not all coincide (spread above 1e-9 L_ref).";
    invalid HOME_INPUTS_COUNT ["/design/home_inputs_m", "/design/actuators"]
        "design.home_inputs_m has one entry per actuator.";
    invalid HOME_NOT_STRESS_FREE ["/design/home_inputs_m"]
        "At design.home_inputs_m every rod is straight and unloaded with theta_EE = 0 (closure \
         residual at most 1e-6 L_ref).";
    invalid EXTENSIBILITY_NEEDS_DIAMETER ["/solver/axial_extensibility",
        "/design/rods/*/diameter_m"]
        "solver.axial_extensibility needs diameter_m on every rod (EA = E pi d^2/4).";
    invalid LOAD_LIMIT ["/load/force_n", "/load/moment_nm"]
        "|load.force_n| <= 1e4 EI_ref/L_ref^2 and |load.moment_nm| <= 1e4 EI_ref/L_ref (EI_ref, \
         L_ref: the rods' mean bending stiffness and length).";
    invalid INPUTS_REQUIRED ["/inputs_m", "/mode"]
        "inputs_m is given for mode fk and assembly_modes.";
    invalid INPUTS_COUNT ["/inputs_m", "/design/actuators"]
        "inputs_m (mode fk and assembly_modes) has one entry per actuator.";
    invalid INPUT_OUTSIDE_STROKE ["/inputs_m/*", "/design/actuators/*/stroke_m"]
        "Each input of inputs_m (mode fk and assembly_modes) lies inside its actuator's stroke_m.";
    invalid STATE_REQUIRED ["/start/state", "/start/kind", "/workspace/seed/state",
        "/workspace/seed/kind"]
        "start.state (seed.state) is given when start.kind (seed.kind) is guess.";
    invalid STATE_LENGTH ["/start/state/v", "/workspace/seed/state/v", "/design/rods"]
        "A solver state v has 3N+3 entries for N rods.";
    invalid WORKSPACE_ACTUATORS ["/design/actuators", "/mode"]
        "Mode workspace needs exactly 2 actuators (a 2-D input grid).";
    invalid RANGE_ORDER ["/workspace/ranges_m/*"]
        "Each workspace.ranges_m entry is [min, max] with min < max.";
    too_large GRID_TOO_LARGE ["/workspace/grid"]
        "workspace.grid has n1 * n2 <= 40401 nodes (split the ranges into tiles, which can run in \
         parallel).";
    too_large SEARCH_TOO_LARGE ["/assembly_modes/n_grid", "/design/rods"]
        "When the assembly-mode search runs, (2 N_grid)^(2N) <= 1e8 grid combinations for N rods.";
    listed common::SHARD_INDEX_BELOW_COUNT;
    invalid SHARD_NOT_APPLICABLE ["/shard", "/mode"]
        "shard is given only with mode workspace (modes fk and assembly_modes are one job).";
    /// The search found the requested assembly mode (found while computing).
    not_converged ASSEMBLY_MODE_NOT_FOUND(super::error::ASSEMBLY_MODE_NOT_FOUND) ["/start/index",
        "/workspace/seed/index"]
        "The (non-certified) assembly-mode search finds more solutions than the requested index.";
    listed common::RESPONSE_TOO_LARGE_RULE;
}

/// Default Young's modulus (steel) [Pa] (spec 3.1).
const DEFAULT_E: f64 = 2.1e11;
/// Rods with L/d below this are rejected (spec 3.1).
const MIN_SLENDERNESS: f64 = 5.0;
/// Rods with L/d below this get a warning: slender-rod theory becomes inaccurate (spec 7).
const WARN_SLENDERNESS: f64 = 20.0;
/// Guide directions shorter than this cannot be normalised (spec 3.1).
const MIN_DIRECTION_NORM: f64 = 1e-12;
/// Attachments closer than this fraction of L_ref to each other are coincident (spec 3.1).
const COINCIDENT_REL: f64 = 1e-9;
/// Load limit in units of `F_ref = EI_ref/L_ref^2` (spec 3.2); the moment limit uses `F_ref L_ref`.
const MAX_LOAD_REL: f64 = 1e4;
/// Largest number of grid nodes (spec 4.7).
const MAX_GRID_NODES: u64 = 40_401;
/// Largest number of closed-form grid combinations (spec 4.6).
const MAX_COMBINATIONS: f64 = 1e8;
/// Service-side ceiling of a request's own time limit \[ms\] (the upper end of
/// [`common::TIME_LIMIT_MS`]).
pub const MAX_TIME_LIMIT_MS: u64 = 600_000;
/// Default stability segments in sweeps (spec 8 targets use M = 20; the sign is what matters).
const DEFAULT_SWEEP_SEGMENTS: u32 = 20;
/// Upper limit on worker threads of the sweep: none of its own, the job's budget decides (the
/// compute pool's threads per job); results do not depend on it.
pub const SWEEP_THREADS: usize = usize::MAX;

/// What the request computes: the request's `mode`.
pub use super::wire::Mode;

/// How the waves of a sweep are seeded at the seed node: the request's `workspace.seed.kind`.
pub use super::wire::SeedKind;

/// How the FK starts.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    /// Home continuation (fallback: the stable assembly mode with the smallest |theta|).
    Home,
    /// Newton from a given state.
    Guess(Vec<f64>),
    /// Assembly mode `index` of the margin-sorted search result.
    AssemblyMode(usize),
}

/// Seed of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedInput {
    /// Kind.
    pub kind: SeedKind,
    /// Inputs near which the seed node is chosen \[m\].
    pub inputs: Option<[f64; 2]>,
    /// State for `guess`.
    pub state: Option<Vec<f64>>,
    /// Mode index for `assembly_mode`.
    pub index: usize,
}

/// Sweep inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepInput {
    /// Wave settings.
    pub settings: SweepSettings,
    /// Seed.
    pub seed: SeedInput,
    /// Quasi-translational threshold \[rad\].
    pub qt_threshold: f64,
    /// Compute the union area.
    pub union: bool,
    /// Return node arrays.
    pub return_nodes: bool,
}

/// The validated domain input (SI units).
#[derive(Debug, Clone)]
pub struct Input {
    /// Mode.
    pub mode: Mode,
    /// Model (design, scales, RK4 steps, extensibility).
    pub model: Model,
    /// Preset used, if any.
    pub preset: Option<Preset>,
    /// Inputs and loads (for workspace: loads only; lambda = seed inputs placeholder).
    pub params: Params,
    /// Newton settings.
    pub newton: NewtonOptions,
    /// FK start.
    pub start: Start,
    /// Continuation step override.
    pub continuation_steps: Option<usize>,
    /// Step control of the continuation from home.
    pub stepping: Stepping,
    /// Run the FK stability test.
    pub stability: bool,
    /// Stability segments of FK and mode search.
    pub segments: usize,
    /// Shape points per rod.
    pub shape_points: usize,
    /// Mode search settings (mode `assembly_modes`, `start.kind = assembly_mode`, seeds of kind
    /// `assembly_mode` / `all_stable_modes`).
    pub modes: ModeSearch,
    /// Mode search settings of the fallback start of a design without a stress-free home (spec
    /// 4.3 rule 2): the request's values where given, else [`modes::HOME_FALLBACK_N_GRID`] and
    /// [`modes::HOME_FALLBACK_TOL`].
    pub home_fallback_modes: ModeSearch,
    /// Sweep, for mode = workspace.
    pub sweep: Option<SweepInput>,
    /// The block of the sweep's waves this request runs (mode workspace only; `None`: the
    /// whole sweep, answered in the unsharded shape).
    pub shard: Option<Shard>,
    /// Warnings found during validation.
    pub warnings: Vec<String>,
    /// Request time limit.
    pub time_limit: Option<Duration>,
}

fn preset_of(p: PresetName) -> Preset {
    match p {
        PresetName::KeopsD1 => Preset::KeopsD1,
        PresetName::KeopsD2 => Preset::KeopsD2,
        PresetName::KeopsD3 => Preset::KeopsD3,
        PresetName::KeopsD4 => Preset::KeopsD4,
        PresetName::KeopsD1OptA => Preset::KeopsD1OptA,
        PresetName::Symmetric => Preset::Symmetric,
    }
}

fn usize_of(x: u32) -> usize {
    usize::try_from(x).unwrap_or(usize::MAX)
}

/// The design of a preset (the request's explicit design fields must be absent).
fn preset_design(v: &mut Validator, d: &DesignRequest, p: PresetName) -> (Design, Option<Preset>) {
    for (present, name) in [
        (d.actuators.is_some(), "actuators"),
        (d.rods.is_some(), "rods"),
        (d.home_inputs_m.is_some(), "home_inputs_m"),
    ] {
        if present {
            rule!(v, DESIGN_SOURCE, format!("/design/{name}");
                "must be absent when design.preset is given (presets fix the geometry)");
        }
    }
    let preset = preset_of(p);
    let mut design = preset.design();
    design.sigma_allow = d.sigma_allow_pa;
    (design, Some(preset))
}

/// Actuator `j`: origin, guide direction (normalised; `[1, 0]` when it cannot be) and stroke.
fn actuator(v: &mut Validator, j: usize, a: &ActuatorRequest) -> Actuator {
    let p = format!("/design/actuators/{j}");
    let mut dir = [1.0, 0.0];
    let nrm = a.direction[0].hypot(a.direction[1]);
    if ensure_rule!(v, nrm > MIN_DIRECTION_NORM, DIRECTION_NORM, format!("{p}/direction");
        "norm must be > {MIN_DIRECTION_NORM}, got {nrm}")
    {
        dir = [a.direction[0] / nrm, a.direction[1] / nrm];
    }
    ensure_rule!(v, a.stroke_m[0] < a.stroke_m[1], STROKE_ORDER, format!("{p}/stroke_m");
        "min must be < max, got [{}, {}]", a.stroke_m[0], a.stroke_m[1]);
    Actuator {
        origin: a.origin_m,
        dir,
        stroke: a.stroke_m,
    }
}

/// The actuators of an explicit design (1..4 of them: checked at the door).
fn actuators(v: &mut Validator, acts: Option<&[ActuatorRequest]>) -> Vec<Actuator> {
    let Some(acts) = acts else {
        rule!(v, DESIGN_SOURCE, "/design/actuators"; "required (or give design.preset)");
        return Vec::new();
    };
    acts.iter()
        .enumerate()
        .map(|(j, a)| actuator(v, j, a))
        .collect()
}

/// The diameter of rod `i` (`p` = `/design/rods/{i}`) if given, with its slenderness checked.
fn rod_diameter(
    v: &mut Validator,
    (i, p): (usize, &str),
    r: &RodRequest,
    warnings: &mut Vec<String>,
) -> Option<f64> {
    let dm = r.diameter_m?;
    let slender = r.length_m / dm;
    if slender < MIN_SLENDERNESS {
        rule!(v, SLENDERNESS, format!("{p}/diameter_m");
            "slenderness L/d = {slender:.3} is below {MIN_SLENDERNESS}: the rod model does not apply");
    } else if slender < WARN_SLENDERNESS {
        warnings.push(format!(
            "slender_rod {i}: L/d = {slender:.2} < {WARN_SLENDERNESS}, slender-rod (Kirchhoff) theory is inaccurate"
        ));
    }
    Some(dm)
}

/// Rod `i` of a design with `n_act` actuators (placeholders where invalid).
fn rod(
    v: &mut Validator,
    i: usize,
    r: &RodRequest,
    n_act: usize,
    warnings: &mut Vec<String>,
) -> Rod {
    let p = format!("/design/rods/{i}");
    ensure_rule!(v, r.actuator < n_act, UNKNOWN_ACTUATOR, format!("{p}/actuator");
        "unknown actuator index {} (design has {n_act} actuators)", r.actuator);
    let offset = r.offset_m.unwrap_or([0.0, 0.0]);
    let e = r.youngs_modulus_pa.unwrap_or(DEFAULT_E);
    let diameter = rod_diameter(v, (i, &p), r, warnings);
    ensure_rule!(v, r.diameter_m.is_some() || r.ei_nm2.is_some(),
        ROD_STIFFNESS, format!("{p}/diameter_m"); "required unless ei_nm2 is given");
    let ei = match (r.ei_nm2, diameter) {
        (Some(ei), _) => ei,
        (None, Some(dm)) => e * std::f64::consts::PI * dm.powi(4) / 64.0,
        _ => 1.0,
    };
    let ea = diameter.map(|dm| e * std::f64::consts::PI * dm * dm / 4.0);
    Rod {
        actuator: r.actuator.min(n_act.saturating_sub(1)),
        offset,
        clamp: r.clamp_angle_deg.to_radians(),
        length: r.length_m,
        ei: if ei.is_finite() && ei > 0.0 { ei } else { 1.0 },
        ea,
        diameter,
        attach: r.attach_m,
    }
}

/// The rods of an explicit design with `n_act` actuators (2..8 of them: checked at the door);
/// then every actuator must carry a rod and, when everything so far is valid, the attachment
/// points must not all coincide.
fn rods(
    v: &mut Validator,
    rs: Option<&[RodRequest]>,
    n_act: usize,
    warnings: &mut Vec<String>,
) -> Vec<Rod> {
    let Some(rs) = rs else {
        rule!(v, DESIGN_SOURCE, "/design/rods"; "required (or give design.preset)");
        return Vec::new();
    };
    let rods: Vec<Rod> = rs
        .iter()
        .enumerate()
        .map(|(i, r)| rod(v, i, r, n_act, warnings))
        .collect();
    for j in 0..n_act {
        ensure_rule!(v, rs.iter().any(|r| r.actuator == j),
            ACTUATOR_WITHOUT_ROD, format!("/design/actuators/{j}");
            "carries no rod: its input would be undetermined");
    }
    if rods.len() >= 2 && v.is_clean() {
        let l_ref = rods.iter().map(|r| r.length).sum::<f64>() / rods.len() as f64;
        let r0 = rods[0].attach;
        let spread = rods.iter().fold(0.0f64, |m, r| {
            m.max((r.attach[0] - r0[0]).hypot(r.attach[1] - r0[1]))
        });
        ensure_rule!(v, spread > COINCIDENT_REL * l_ref, COINCIDENT_ATTACHMENTS, "/design/rods";
            "all attachment points attach_m coincide: the platform rotation is undetermined");
    }
    rods
}

/// The design part; returns the design (possibly partial when invalid).
fn design_of(
    req: &ContinuumWorkspaceRequest,
    v: &mut Validator,
    warnings: &mut Vec<String>,
) -> (Design, Option<Preset>) {
    let d = &req.design;
    if let Some(p) = d.preset {
        return preset_design(v, d, p);
    }
    let actuators = actuators(v, d.actuators.as_deref());
    let n_act = actuators.len();
    let rods = rods(v, d.rods.as_deref(), n_act, warnings);
    if let Some(h) = &d.home_inputs_m {
        ensure_rule!(v, h.len() == n_act, HOME_INPUTS_COUNT, "/design/home_inputs_m";
            "must have {n_act} entries (one per actuator), got {}", h.len());
    }
    let design = Design {
        actuators,
        rods,
        home: d.home_inputs_m.clone(),
        sigma_allow: d.sigma_allow_pa,
    };
    (design, None)
}

/// The solver settings (RK4 steps, Newton tolerance and iterations, extensibility) of `design`.
fn solver(
    v: &mut Validator,
    req: &ContinuumWorkspaceRequest,
    design: &Design,
) -> (u32, f64, u32, bool) {
    let solver = req.solver.clone().unwrap_or_default();
    let base_steps = solver.rk4_steps.unwrap_or(32);
    let tol = solver.tol.unwrap_or(1e-10);
    let max_iter = solver.max_iter.unwrap_or(50);
    let extensible = solver.axial_extensibility.unwrap_or(false);
    ensure_rule!(v, !(extensible && design.rods.iter().any(|r| r.ea.is_none())),
        EXTENSIBILITY_NEEDS_DIAMETER, "/solver/axial_extensibility";
        "needs diameter_m (and youngs_modulus_pa) on every rod to compute EA");
    (base_steps, tol, max_iter, extensible)
}

/// Given home inputs of an explicit design must really be stress-free.
fn home(v: &mut Validator, model: &Model, preset: Option<Preset>) {
    let (Some(h), None) = (&model.design.home, preset) else {
        return;
    };
    let fit = fk::home_fit(model, Some(h));
    if fit.residual.is_nan() || fit.residual > HOME_REL_TOL * model.l_ref {
        rule!(v, HOME_NOT_STRESS_FREE, "/design/home_inputs_m";
            "rods are not straight and unloaded with theta_EE = 0 at these inputs (closure residual {:.3e} m > {:.1e} L_ref)",
            fit.residual, HOME_REL_TOL);
    }
}

/// The platform load (force \[N\], moment [N m]) within [`MAX_LOAD_REL`] of the model's scales.
fn load(v: &mut Validator, req: &ContinuumWorkspaceRequest, model: &Model) -> ([f64; 2], f64) {
    let load = req.load.clone().unwrap_or_default();
    let force = load.force_n.unwrap_or([0.0, 0.0]);
    let moment = load.moment_nm.unwrap_or(0.0);
    let fmax = MAX_LOAD_REL * model.f_ref;
    let fnorm = force[0].hypot(force[1]);
    ensure_rule!(v, fnorm <= fmax, LOAD_LIMIT, "/load/force_n";
        "|F| = {fnorm} N exceeds 1e4 EI_ref/L_ref^2 = {fmax} N");
    let mmax = MAX_LOAD_REL * model.f_ref * model.l_ref;
    ensure_rule!(v, moment.abs() <= mmax, LOAD_LIMIT, "/load/moment_nm";
        "|M| = {} N m exceeds 1e4 EI_ref/L_ref = {mmax} N m", moment.abs());
    (force, moment)
}

/// The actuator inputs of modes `fk` and `assembly_modes`, each within its stroke (zeros for
/// mode `workspace`).
fn inputs(v: &mut Validator, req: &ContinuumWorkspaceRequest, model: &Model) -> Vec<f64> {
    let n_act = model.n_act();
    let mut lambda = vec![0.0; n_act];
    if !matches!(req.mode, wire::Mode::Fk | wire::Mode::AssemblyModes) {
        return lambda;
    }
    match &req.inputs_m {
        None => rule!(v, INPUTS_REQUIRED, "/inputs_m"; "required for mode fk and assembly_modes"),
        Some(l) if l.len() != n_act => {
            rule!(v, INPUTS_COUNT, "/inputs_m";
                "must have {n_act} entries (one per actuator), got {}", l.len());
        }
        Some(l) => {
            for (j, (&x, a)) in l.iter().zip(&model.design.actuators).enumerate() {
                let [lo, hi] = a.stroke;
                ensure_rule!(v, (lo..=hi).contains(&x),
                    INPUT_OUTSIDE_STROKE, format!("/inputs_m/{j}");
                    "inputs_m[{j}] [m] must be in [{lo}, {hi}] (the stroke of actuator {j}), got {x}");
            }
            lambda.clone_from(l);
        }
    }
    lambda
}

/// A solver state `st` at `ptr` (`…/state/v`): 3N+3 numbers for `nr` rods.
fn state(v: &mut Validator, ptr: &str, st: &SolverState, nr: usize) -> Vec<f64> {
    ensure_rule!(v, st.v.len() == 3 * nr + 3, STATE_LENGTH, ptr;
        "must have 3N+3 = {} entries, got {}", 3 * nr + 3, st.v.len());
    st.v.clone()
}

/// The FK start, its continuation step override and step control, for `nr` rods.
fn start(
    v: &mut Validator,
    start_req: Option<&StartRequest>,
    nr: usize,
) -> (Start, Option<usize>, Stepping) {
    let start = match start_req {
        None => Start::Home,
        Some(s) => match s.kind {
            StartKind::Home => Start::Home,
            StartKind::AssemblyMode => Start::AssemblyMode(s.index.unwrap_or(0)),
            StartKind::Guess => match &s.state {
                None => {
                    rule!(v, STATE_REQUIRED, "/start/state"; "required when start.kind = guess");
                    Start::Home
                }
                Some(st) => Start::Guess(state(v, "/start/state/v", st, nr)),
            },
        },
    };
    let continuation_steps = start_req.and_then(|s| s.continuation_steps).map(usize_of);
    let stepping = match start_req.and_then(|s| s.continuation) {
        Some(ContinuationKind::Fixed) => Stepping::Fixed,
        Some(ContinuationKind::Adaptive) | None => Stepping::Adaptive,
    };
    (start, continuation_steps, stepping)
}

/// The outputs: stability test on or off, its segments, shape points per rod.
fn outputs(req: &ContinuumWorkspaceRequest) -> (bool, u32, u32) {
    let outputs = req.outputs.clone().unwrap_or_default();
    let stability = outputs.stability.unwrap_or(true);
    let segments = outputs.stability_segments.unwrap_or(40);
    let shape_points = outputs.rod_shape_points.unwrap_or(0);
    (stability, segments, shape_points)
}

/// The mode search settings for `nr` rods, and those of the home fallback.
fn mode_search(req: &ContinuumWorkspaceRequest, nr: usize) -> (ModeSearch, ModeSearch) {
    let am = req.assembly_modes.clone().unwrap_or_default();
    let default_n_grid = u32::try_from(modes::default_n_grid(nr)).unwrap_or(1);
    let n_grid = am.n_grid.unwrap_or(default_n_grid);
    let mtol = am.tol.unwrap_or(modes::DEFAULT_TOL);
    let default_cell = u32::try_from(modes::DEFAULT_CELL).unwrap_or(2);
    let cell = am.cell.unwrap_or(default_cell);
    let default_max_refine = u32::try_from(modes::DEFAULT_MAX_REFINE).unwrap_or(4000);
    let max_refine = am.max_refine.unwrap_or(default_max_refine);
    let modes = ModeSearch {
        n_grid: usize_of(n_grid),
        tol: mtol,
        cell: usize_of(cell),
        max_refine: usize_of(max_refine),
    };
    let home_fallback_modes = ModeSearch {
        n_grid: if am.n_grid.is_some() {
            modes.n_grid
        } else {
            modes.n_grid.min(modes::HOME_FALLBACK_N_GRID)
        },
        tol: if am.tol.is_some() {
            modes.tol
        } else {
            modes::HOME_FALLBACK_TOL
        },
        ..modes
    };
    (modes, home_fallback_modes)
}

/// The sweep grid (each side 2..401: checked at the door); a grid of more than
/// [`MAX_GRID_NODES`] nodes is a separate failure (reported only when everything else is valid).
fn grid(grid: Option<[u32; 2]>) -> ([u32; 2], Option<CalcFailure>) {
    let grid = grid.unwrap_or([31, 31]);
    let nodes = u64::from(grid[0]) * u64::from(grid[1]);
    let too_large = (nodes > MAX_GRID_NODES).then(|| {
        GRID_TOO_LARGE.fail(
            "/workspace/grid",
            format!(
                "{} x {} = {nodes} nodes exceeds the limit of {MAX_GRID_NODES}; split the ranges into tiles (they can run in parallel)",
                grid[0], grid[1]
            ),
        )
    });
    (grid, too_large)
}

/// The input ranges of the sweep (default: the strokes of the two actuators).
fn ranges(v: &mut Validator, ranges: Option<[[f64; 2]; 2]>, model: &Model) -> [[f64; 2]; 2] {
    let strokes = if model.n_act() == 2 {
        [
            model.design.actuators[0].stroke,
            model.design.actuators[1].stroke,
        ]
    } else {
        [[0.0, 1.0], [0.0, 1.0]]
    };
    let ranges = ranges.unwrap_or(strokes);
    for (k, r) in ranges.iter().enumerate() {
        ensure_rule!(v, r[0] < r[1], RANGE_ORDER, format!("/workspace/ranges_m/{k}");
            "min must be < max, got [{}, {}]", r[0], r[1]);
    }
    ranges
}

/// The physical limits of the sweep (allowable stress: the design's unless given).
fn limits(w: &WorkspaceRequest, model: &Model) -> Limits {
    let lim = w.limits.clone().unwrap_or_default();
    Limits {
        min_gap: lim.min_actuator_gap_m,
        sigma_allow: lim.sigma_allow_pa.or(model.design.sigma_allow),
        rod_crossing: lim.rod_crossing == Some(RodCrossing::Reject),
    }
}

/// The wave settings of the sweep after its grid and ranges: neighbours, sub-steps, tries,
/// jump limits, conditioning, stability test and physical limits (every value within its range:
/// checked at the door).
fn sweep_settings(
    w: &WorkspaceRequest,
    (grid, ranges): ([u32; 2], [[f64; 2]; 2]),
    model: &Model,
) -> SweepSettings {
    let neighbours = w.neighbours.map_or(4, |n| n.0);
    let max_substeps = w.max_substeps.map_or(8, |n| n.0);
    let max_tries = w.max_tries.unwrap_or(4);
    let substep_max_iter = w.substep_max_iter.unwrap_or(20);
    let jl = w.jump_limits.clone().unwrap_or_default();
    let angle_jump = jl.angle_deg.unwrap_or(5.0);
    let position_factor = jl.position_factor.unwrap_or(5.0);
    let cond_max = w.cond_max.unwrap_or(1e12);
    let stability = match w.stability_check.unwrap_or(StabilityCheckName::Full) {
        StabilityCheckName::Full => StabilityCheck::Full,
        StabilityCheckName::DetSign => StabilityCheck::DetSign,
        StabilityCheckName::None => StabilityCheck::None,
    };
    let segments = w.stability_segments.unwrap_or(DEFAULT_SWEEP_SEGMENTS);
    let limits = limits(w, model);
    SweepSettings {
        grid: [usize_of(grid[0]), usize_of(grid[1])],
        ranges,
        diagonal_neighbours: neighbours == 8,
        predictor: w.predictor.unwrap_or(true),
        max_substeps: usize_of(max_substeps),
        max_tries: usize_of(max_tries),
        substep_max_iter: usize_of(substep_max_iter),
        angle_jump: angle_jump.to_radians(),
        position_factor,
        cond_max,
        stability,
        segments: usize_of(segments),
        limits,
        threads: SWEEP_THREADS,
    }
}

/// The seed of the sweep, for `nr` rods.
fn seed(v: &mut Validator, seed: Option<&SeedRequest>, nr: usize) -> SeedInput {
    let Some(s) = seed else {
        return SeedInput {
            kind: SeedKind::Home,
            inputs: None,
            state: None,
            index: 0,
        };
    };
    let kind = s.kind;
    let state = match (kind, &s.state) {
        (SeedKind::Guess, None) => {
            rule!(v, STATE_REQUIRED, "/workspace/seed/state"; "required when seed.kind = guess");
            None
        }
        (SeedKind::Guess, Some(st)) => Some(state(v, "/workspace/seed/state/v", st, nr)),
        _ => None,
    };
    SeedInput {
        kind,
        inputs: s.inputs_m,
        state,
        index: s.index.unwrap_or(0),
    }
}

/// The sweep of mode `workspace` (`None` for the other modes), and a too-large grid's failure.
fn workspace(
    v: &mut Validator,
    req: &ContinuumWorkspaceRequest,
    model: &Model,
) -> (Option<SweepInput>, Option<CalcFailure>) {
    if req.mode != wire::Mode::Workspace {
        return (None, None);
    }
    let n_act = model.n_act();
    ensure_rule!(v, n_act == 2, WORKSPACE_ACTUATORS, "/design/actuators";
        "mode workspace needs exactly 2 actuators (2-D grid), got {n_act}");
    let w = req.workspace.clone().unwrap_or_default();
    let (grid, too_large) = grid(w.grid);
    let ranges = ranges(v, w.ranges_m, model);
    let settings = sweep_settings(&w, (grid, ranges), model);
    let qt = w.quasi_translational_deg.unwrap_or(1.0);
    let seed = seed(v, w.seed.as_ref(), model.n_rods());
    let sweep = SweepInput {
        settings,
        seed,
        qt_threshold: qt.to_radians(),
        union: w.area_method.unwrap_or(AreaMethod::Union) == AreaMethod::Union,
        return_nodes: w.return_nodes.unwrap_or(false),
    };
    (Some(sweep), too_large)
}

/// The request's `shard` (its index below its count), which only a workspace sweep takes: its
/// items are the waves, one per seed (see the `shard` field of the request).
fn shard(v: &mut Validator, req: &ContinuumWorkspaceRequest) -> Option<Shard> {
    let shard = common::shard_rule(v, req.shard);
    let one_job = match req.mode {
        wire::Mode::Workspace => None,
        wire::Mode::Fk => Some("fk"),
        wire::Mode::AssemblyModes => Some("assembly_modes"),
    };
    if let (Some(mode), Some(_)) = (one_job, req.shard) {
        rule!(v, SHARD_NOT_APPLICABLE, "/shard";
            "shard splits the waves of a workspace sweep; mode \"{mode}\" has no sweep");
    }
    shard
}

/// Whether the mode search runs: when asked for, or when there is no stress-free home
/// (`has_home`) to start from.
fn search_needed(
    req: &ContinuumWorkspaceRequest,
    start: &Start,
    sweep: Option<&SweepInput>,
    has_home: bool,
) -> bool {
    req.mode == wire::Mode::AssemblyModes
        || matches!(start, Start::AssemblyMode(_))
        || sweep.is_some_and(|s| {
            matches!(
                s.seed.kind,
                SeedKind::AssemblyMode | SeedKind::AllStableModes
            ) || (s.seed.kind == SeedKind::Home && !has_home)
        })
        || (req.mode == wire::Mode::Fk && *start == Start::Home && !has_home)
}

/// The mode search of `n_grid` for `nr` rods within [`MAX_COMBINATIONS`].
fn search_size(n_grid: usize, nr: usize, has_home: bool) -> Result<(), CalcFailure> {
    let combos = modes::combinations(n_grid, nr);
    if combos <= MAX_COMBINATIONS {
        return Ok(());
    }
    let why = if has_home {
        ""
    } else {
        " (the design has no stress-free home, so the FK starts from the mode search)"
    };
    Err(SEARCH_TOO_LARGE.fail(
        "/assembly_modes/n_grid",
        format!(
            "(2 N_grid)^(2N) = {combos:.3e} grid combinations for N_grid = {n_grid} and N = {nr} rods exceeds {MAX_COMBINATIONS:e}; lower n_grid{why}"
        ),
    ))
}

impl TryFrom<ContinuumWorkspaceRequest> for Input {
    type Error = CalcFailure;

    /// The rules between fields of a request whose per-field rules were checked at the door.
    fn try_from(req: ContinuumWorkspaceRequest) -> Result<Self, CalcFailure> {
        Self::try_from(&req)
    }
}

impl TryFrom<&ContinuumWorkspaceRequest> for Input {
    type Error = CalcFailure;

    /// The rules between fields of a request whose per-field rules were checked at the door
    /// ([`crate::calc::rules::check`]).
    fn try_from(req: &ContinuumWorkspaceRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let mut warnings = Vec::new();
        let (design, preset) = design_of(req, &mut v, &mut warnings);
        let (base_steps, tol, max_iter, extensible) = solver(&mut v, req, &design);
        // Structural problems make everything below meaningless: stop here.
        v.finish()?;
        let mut v = Validator::new();
        let model = Model::new(design, usize_of(base_steps), extensible);
        let nr = model.n_rods();
        home(&mut v, &model, preset);
        let (force, moment) = load(&mut v, req, &model);
        let lambda = inputs(&mut v, req, &model);
        let (start, continuation_steps, stepping) = start(&mut v, req.start.as_ref(), nr);
        let (stability, segments, shape_points) = outputs(req);
        let (modes, home_fallback_modes) = mode_search(req, nr);
        let time_limit = req.time_limit_ms.map(Duration::from_millis);
        let shard = shard(&mut v, req);
        let (sweep, too_large) = workspace(&mut v, req, &model);
        let has_home = model.design.home.is_some()
            || fk::home_fit(&model, None).residual <= HOME_REL_TOL * model.l_ref;
        let search_needed = search_needed(req, &start, sweep.as_ref(), has_home);
        v.finish()?;
        if let Some(t) = too_large {
            return Err(t);
        }
        if search_needed {
            search_size(modes.n_grid, nr, has_home)?;
        }
        Ok(Self {
            mode: req.mode,
            model,
            preset,
            params: Params {
                lambda,
                force,
                moment,
            },
            newton: NewtonOptions::new(tol, usize_of(max_iter)),
            start,
            continuation_steps,
            stepping,
            stability,
            segments: usize_of(segments),
            shape_points: usize_of(shape_points),
            modes,
            home_fallback_modes,
            sweep,
            shard,
            warnings,
            time_limit,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calc::continuum_workspace::ContinuumWorkspaceRequest;

    /// A `workspace` request without settings gets exactly `SweepSettings::with_defaults` (the
    /// documented defaults the bench and the property tests start from).
    #[test]
    fn empty_workspace_settings_are_the_sweep_defaults() {
        let req: ContinuumWorkspaceRequest = serde_json::from_value(serde_json::json!({
            "mode": "workspace", "design": {"preset": "keops_d1"}
        }))
        .expect("request decodes");
        crate::calc::rules::check(&req).expect("per-field rules hold");
        let input = Input::try_from(&req).expect("valid");
        let got = input.sweep.expect("workspace mode").settings;
        assert_eq!(got, SweepSettings::with_defaults(got.grid, got.ranges));
    }
}
