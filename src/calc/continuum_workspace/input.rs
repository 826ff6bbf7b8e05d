//! Validation of the request into the SI domain input (spec 3), collecting every offending field.

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
use crate::calc::{CalcFailure, ProblemClass, Validator};

use super::wire::{
    ASSEMBLY_MODES_TOL, CELL, COND_MAX, CONTINUATION_STEPS, COORDINATE_M, DIAMETER_M, EI_NM2,
    GRID_SIDE, JUMP_LIMITS_ANGLE_DEG, JUMP_LIMITS_POSITION_FACTOR, LENGTH_M, MAX_ACTUATORS,
    MAX_REFINE, MAX_SUBSTEPS, MAX_TRIES, N_GRID, QUASI_TRANSLATIONAL_DEG, RK4_STEPS,
    ROD_SHAPE_POINTS, SIGMA_ALLOW_PA, SOLVER_MAX_ITER, SOLVER_TOL, STABILITY_SEGMENTS,
    SUBSTEP_MAX_ITER, YOUNGS_MODULUS_PA,
};
use crate::calc::Range;

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
/// Service-side ceiling of a request's own time limit \[ms\].
pub const MAX_TIME_LIMIT_MS: u64 = 600_000;
/// Default stability segments in sweeps (spec 8 targets use M = 20; the sign is what matters).
const DEFAULT_SWEEP_SEGMENTS: u32 = 20;
/// Upper limit on worker threads of the sweep: none of its own, the job's budget decides (the
/// compute pool's threads per job); results do not depend on it.
pub const SWEEP_THREADS: usize = usize::MAX;

/// What the request computes (the domain form of the wire `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Forward kinematics at one input.
    Fk,
    /// Workspace sweep over the 2-D input grid, one wave per seed.
    Workspace,
    /// Assembly-mode search at one input.
    AssemblyModes,
}

impl From<wire::Mode> for Mode {
    fn from(m: wire::Mode) -> Self {
        match m {
            wire::Mode::Fk => Self::Fk,
            wire::Mode::Workspace => Self::Workspace,
            wire::Mode::AssemblyModes => Self::AssemblyModes,
        }
    }
}

/// How the waves of a sweep are seeded at the seed node (the domain form of the wire
/// `workspace.seed.kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeedKind {
    /// Continuation from the stress-free home (without one: the stable assembly mode with the
    /// smallest |theta_EE|): one wave.
    Home,
    /// Newton from a given state: one wave.
    Guess,
    /// One assembly mode of the search: one wave.
    AssemblyMode,
    /// Every stable assembly mode of the search: one wave each.
    AllStableModes,
}

impl From<wire::SeedKind> for SeedKind {
    fn from(k: wire::SeedKind) -> Self {
        match k {
            wire::SeedKind::Home => Self::Home,
            wire::SeedKind::Guess => Self::Guess,
            wire::SeedKind::AssemblyMode => Self::AssemblyMode,
            wire::SeedKind::AllStableModes => Self::AllStableModes,
        }
    }
}

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

/// An optional integer in `range` (the default when absent or out of range, which is reported).
fn u32_in(v: &mut Validator, ptr: &str, x: Option<u32>, range: Range, default: u32) -> u32 {
    match x {
        Some(x) if !v.uint(ptr, "", u64::from(x), range) => default,
        Some(x) => x,
        None => default,
    }
}

/// An optional number in `range` (the default when absent or out of range, which is reported).
fn f64_in(v: &mut Validator, ptr: &str, x: Option<f64>, range: Range, default: f64) -> f64 {
    match x {
        Some(x) if v.range(ptr, "", x, range) => x,
        Some(_) => default,
        None => default,
    }
}

/// Require every element finite and within [`COORDINATE_M`].
fn coords(v: &mut Validator, ptr: &str, values: &[f64]) -> bool {
    v.all_in(ptr, "", values, COORDINATE_M)
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
            v.push(
                format!("/design/{name}"),
                "must be absent when design.preset is given (presets fix the geometry)",
            );
        }
    }
    let preset = preset_of(p);
    let mut design = preset.design();
    design.sigma_allow = d.sigma_allow_pa;
    if let Some(s) = d.sigma_allow_pa {
        v.range("/design/sigma_allow_pa", "", s, SIGMA_ALLOW_PA);
    }
    (design, Some(preset))
}

/// Actuator `j`: origin, guide direction (normalised; `[1, 0]` when invalid) and stroke.
fn actuator(v: &mut Validator, j: usize, a: &ActuatorRequest) -> Actuator {
    let p = format!("/design/actuators/{j}");
    coords(v, &format!("{p}/origin_m"), &a.origin_m);
    let mut dir = [1.0, 0.0];
    if v.all_finite(&format!("{p}/direction"), &a.direction) {
        let nrm = a.direction[0].hypot(a.direction[1]);
        if nrm > MIN_DIRECTION_NORM {
            dir = [a.direction[0] / nrm, a.direction[1] / nrm];
        } else {
            v.push(
                format!("{p}/direction"),
                format!("norm must be > {MIN_DIRECTION_NORM}, got {nrm}"),
            );
        }
    }
    if coords(v, &format!("{p}/stroke_m"), &a.stroke_m) && a.stroke_m[0] >= a.stroke_m[1] {
        v.push(
            format!("{p}/stroke_m"),
            format!(
                "min must be < max, got [{}, {}]",
                a.stroke_m[0], a.stroke_m[1]
            ),
        );
    }
    Actuator {
        origin: a.origin_m,
        dir,
        stroke: a.stroke_m,
    }
}

/// The actuators of an explicit design.
fn actuators(v: &mut Validator, acts: Option<&[ActuatorRequest]>) -> Vec<Actuator> {
    let Some(acts) = acts else {
        v.push("/design/actuators", "required (or give design.preset)");
        return Vec::new();
    };
    if acts.is_empty() || acts.len() > MAX_ACTUATORS {
        v.push(
            "/design/actuators",
            format!("must list 1..{MAX_ACTUATORS} actuators, got {}", acts.len()),
        );
    }
    acts.iter()
        .enumerate()
        .map(|(j, a)| actuator(v, j, a))
        .collect()
}

/// The diameter of rod `i` (`p` = `/design/rods/{i}`) if given and valid, with its slenderness
/// checked when the length is valid (`len_ok`).
fn rod_diameter(
    v: &mut Validator,
    (i, p): (usize, &str),
    r: &RodRequest,
    len_ok: bool,
    warnings: &mut Vec<String>,
) -> Option<f64> {
    let dm = r.diameter_m?;
    if !v.range(&format!("{p}/diameter_m"), "", dm, DIAMETER_M) {
        return None;
    }
    if len_ok {
        let slender = r.length_m / dm;
        if slender < MIN_SLENDERNESS {
            v.push(
                format!("{p}/diameter_m"),
                format!(
                    "slenderness L/d = {slender:.3} is below {MIN_SLENDERNESS}: the rod model does not apply"
                ),
            );
        } else if slender < WARN_SLENDERNESS {
            warnings.push(format!(
                "slender_rod {i}: L/d = {slender:.2} < {WARN_SLENDERNESS}, slender-rod (Kirchhoff) theory is inaccurate"
            ));
        }
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
    if r.actuator >= n_act {
        v.push(
            format!("{p}/actuator"),
            format!(
                "unknown actuator index {} (design has {n_act} actuators)",
                r.actuator
            ),
        );
    }
    let offset = r.offset_m.unwrap_or([0.0, 0.0]);
    coords(v, &format!("{p}/offset_m"), &offset);
    v.finite(&format!("{p}/clamp_angle_deg"), r.clamp_angle_deg);
    let len_ok = v.range(&format!("{p}/length_m"), "", r.length_m, LENGTH_M);
    coords(v, &format!("{p}/attach_m"), &r.attach_m);
    let e = r.youngs_modulus_pa.unwrap_or(DEFAULT_E);
    let e_ok = v.range(&format!("{p}/youngs_modulus_pa"), "", e, YOUNGS_MODULUS_PA);
    let diameter = rod_diameter(v, (i, &p), r, len_ok, warnings);
    if let Some(ei) = r.ei_nm2 {
        v.range(&format!("{p}/ei_nm2"), "", ei, EI_NM2);
    }
    if r.diameter_m.is_none() && r.ei_nm2.is_none() {
        v.push(format!("{p}/diameter_m"), "required unless ei_nm2 is given");
    }
    let ei = match (r.ei_nm2, diameter) {
        (Some(ei), _) => ei,
        (None, Some(dm)) => e * std::f64::consts::PI * dm.powi(4) / 64.0,
        _ => 1.0,
    };
    let ea = match (diameter, e_ok) {
        (Some(dm), true) => Some(e * std::f64::consts::PI * dm * dm / 4.0),
        _ => None,
    };
    Rod {
        actuator: r.actuator.min(n_act.saturating_sub(1)),
        offset,
        clamp: r.clamp_angle_deg.to_radians(),
        length: if len_ok { r.length_m } else { 1.0 },
        ei: if ei.is_finite() && ei > 0.0 { ei } else { 1.0 },
        ea,
        diameter,
        attach: r.attach_m,
    }
}

/// The rods of an explicit design with `n_act` actuators; then every actuator must carry a rod
/// and, when everything so far is valid, the attachment points must not all coincide.
fn rods(
    v: &mut Validator,
    rs: Option<&[RodRequest]>,
    n_act: usize,
    warnings: &mut Vec<String>,
) -> Vec<Rod> {
    let Some(rs) = rs else {
        v.push("/design/rods", "required (or give design.preset)");
        return Vec::new();
    };
    if rs.len() < 2 || rs.len() > 8 {
        v.push(
            "/design/rods",
            format!("must list 2..8 rods, got {}", rs.len()),
        );
    }
    let rods: Vec<Rod> = rs
        .iter()
        .enumerate()
        .map(|(i, r)| rod(v, i, r, n_act, warnings))
        .collect();
    for j in 0..n_act {
        if !rs.iter().any(|r| r.actuator == j) {
            v.push(
                format!("/design/actuators/{j}"),
                "carries no rod: its input would be undetermined",
            );
        }
    }
    if rods.len() >= 2 && v.is_clean() {
        let l_ref = rods.iter().map(|r| r.length).sum::<f64>() / rods.len() as f64;
        let r0 = rods[0].attach;
        let spread = rods.iter().fold(0.0f64, |m, r| {
            m.max((r.attach[0] - r0[0]).hypot(r.attach[1] - r0[1]))
        });
        if spread <= COINCIDENT_REL * l_ref {
            v.push(
                "/design/rods",
                "all attachment points attach_m coincide: the platform rotation is undetermined",
            );
        }
    }
    rods
}

/// Validate the design part; returns the design (possibly partial when invalid).
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
    if let Some(s) = d.sigma_allow_pa {
        v.range("/design/sigma_allow_pa", "", s, SIGMA_ALLOW_PA);
    }
    if let Some(h) = &d.home_inputs_m {
        if h.len() != n_act {
            v.push(
                "/design/home_inputs_m",
                format!(
                    "must have {n_act} entries (one per actuator), got {}",
                    h.len()
                ),
            );
        } else {
            coords(v, "/design/home_inputs_m", h);
        }
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
    let base_steps = u32_in(v, "/solver/rk4_steps", solver.rk4_steps, RK4_STEPS, 32);
    let tol = f64_in(v, "/solver/tol", solver.tol, SOLVER_TOL, 1e-10);
    let max_iter = u32_in(v, "/solver/max_iter", solver.max_iter, SOLVER_MAX_ITER, 50);
    let extensible = solver.axial_extensibility.unwrap_or(false);
    if extensible && design.rods.iter().any(|r| r.ea.is_none()) {
        v.push(
            "/solver/axial_extensibility",
            "needs diameter_m (and youngs_modulus_pa) on every rod to compute EA",
        );
    }
    (base_steps, tol, max_iter, extensible)
}

/// Given home inputs of an explicit design must really be stress-free.
fn home(v: &mut Validator, model: &Model, preset: Option<Preset>) {
    let (Some(h), None) = (&model.design.home, preset) else {
        return;
    };
    let fit = fk::home_fit(model, Some(h));
    if fit.residual.is_nan() || fit.residual > HOME_REL_TOL * model.l_ref {
        v.push(
            "/design/home_inputs_m",
            format!(
                "rods are not straight and unloaded with theta_EE = 0 at these inputs (closure residual {:.3e} m > {:.1e} L_ref)",
                fit.residual, HOME_REL_TOL
            ),
        );
    }
}

/// The platform load (force \[N\], moment [N m]) within [`MAX_LOAD_REL`] of the model's scales.
fn load(v: &mut Validator, req: &ContinuumWorkspaceRequest, model: &Model) -> ([f64; 2], f64) {
    let load = req.load.clone().unwrap_or_default();
    let force = load.force_n.unwrap_or([0.0, 0.0]);
    let moment = load.moment_nm.unwrap_or(0.0);
    if v.all_finite("/load/force_n", &force) {
        let fmax = MAX_LOAD_REL * model.f_ref;
        let fnorm = force[0].hypot(force[1]);
        if fnorm > fmax {
            v.push(
                "/load/force_n",
                format!("|F| = {fnorm} N exceeds 1e4 EI_ref/L_ref^2 = {fmax} N"),
            );
        }
    }
    if v.finite("/load/moment_nm", moment) {
        let mmax = MAX_LOAD_REL * model.f_ref * model.l_ref;
        if moment.abs() > mmax {
            v.push(
                "/load/moment_nm",
                format!(
                    "|M| = {} N m exceeds 1e4 EI_ref/L_ref = {mmax} N m",
                    moment.abs()
                ),
            );
        }
    }
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
        None => v.push("/inputs_m", "required for mode fk and assembly_modes"),
        Some(l) if l.len() != n_act => {
            v.push(
                "/inputs_m",
                format!(
                    "must have {n_act} entries (one per actuator), got {}",
                    l.len()
                ),
            );
        }
        Some(l) => {
            for (j, (&x, a)) in l.iter().zip(&model.design.actuators).enumerate() {
                v.in_range(&format!("/inputs_m/{j}"), x, a.stroke[0], a.stroke[1]);
            }
            lambda.clone_from(l);
        }
    }
    lambda
}

/// A solver state `st` at `ptr` (`…/state/v`): 3N+3 finite numbers for `nr` rods.
fn state(v: &mut Validator, ptr: &str, st: &SolverState, nr: usize) -> Vec<f64> {
    if st.v.len() != 3 * nr + 3 {
        v.push(
            ptr,
            format!(
                "must have 3N+3 = {} entries, got {}",
                3 * nr + 3,
                st.v.len()
            ),
        );
    } else {
        v.all_finite(ptr, &st.v);
    }
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
                    v.push("/start/state", "required when start.kind = guess");
                    Start::Home
                }
                Some(st) => Start::Guess(state(v, "/start/state/v", st, nr)),
            },
        },
    };
    let continuation_steps = start_req.and_then(|s| s.continuation_steps).map(|k| {
        usize_of(u32_in(
            v,
            "/start/continuation_steps",
            Some(k),
            CONTINUATION_STEPS,
            30,
        ))
    });
    let stepping = match start_req.and_then(|s| s.continuation) {
        Some(ContinuationKind::Fixed) => Stepping::Fixed,
        Some(ContinuationKind::Adaptive) | None => Stepping::Adaptive,
    };
    (start, continuation_steps, stepping)
}

/// The outputs: stability test on or off, its segments, shape points per rod.
fn outputs(v: &mut Validator, req: &ContinuumWorkspaceRequest) -> (bool, u32, u32) {
    let outputs = req.outputs.clone().unwrap_or_default();
    let stability = outputs.stability.unwrap_or(true);
    let segments = u32_in(
        v,
        "/outputs/stability_segments",
        outputs.stability_segments,
        STABILITY_SEGMENTS,
        40,
    );
    let shape_points = u32_in(
        v,
        "/outputs/rod_shape_points",
        outputs.rod_shape_points,
        ROD_SHAPE_POINTS,
        0,
    );
    (stability, segments, shape_points)
}

/// The mode search settings for `nr` rods, and those of the home fallback.
fn mode_search(
    v: &mut Validator,
    req: &ContinuumWorkspaceRequest,
    nr: usize,
) -> (ModeSearch, ModeSearch) {
    let am = req.assembly_modes.clone().unwrap_or_default();
    let default_n_grid = u32::try_from(modes::default_n_grid(nr)).unwrap_or(1);
    let n_grid = u32_in(
        v,
        "/assembly_modes/n_grid",
        am.n_grid,
        N_GRID,
        default_n_grid,
    );
    let mtol = f64_in(
        v,
        "/assembly_modes/tol",
        am.tol,
        ASSEMBLY_MODES_TOL,
        modes::DEFAULT_TOL,
    );
    let default_cell = u32::try_from(modes::DEFAULT_CELL).unwrap_or(2);
    let cell = u32_in(v, "/assembly_modes/cell", am.cell, CELL, default_cell);
    let default_max_refine = u32::try_from(modes::DEFAULT_MAX_REFINE).unwrap_or(4000);
    let max_refine = u32_in(
        v,
        "/assembly_modes/max_refine",
        am.max_refine,
        MAX_REFINE,
        default_max_refine,
    );
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

/// The sweep grid; a grid of more than [`MAX_GRID_NODES`] nodes is a separate failure (reported
/// only when everything else is valid).
fn grid(v: &mut Validator, grid: Option<[u32; 2]>) -> ([u32; 2], Option<CalcFailure>) {
    let grid = grid.unwrap_or([31, 31]);
    for (k, &g) in grid.iter().enumerate() {
        v.uint(&format!("/workspace/grid/{k}"), "", u64::from(g), GRID_SIDE);
    }
    let nodes = u64::from(grid[0]) * u64::from(grid[1]);
    let too_large = (nodes > MAX_GRID_NODES).then(|| {
        CalcFailure::field(
            ProblemClass::TooLarge,
            "GRID_TOO_LARGE",
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
        if coords(v, &format!("/workspace/ranges_m/{k}"), r) && r[0] >= r[1] {
            v.push(
                format!("/workspace/ranges_m/{k}"),
                format!("min must be < max, got [{}, {}]", r[0], r[1]),
            );
        }
    }
    ranges
}

/// The physical limits of the sweep (allowable stress: the design's unless given).
fn limits(v: &mut Validator, w: &WorkspaceRequest, model: &Model) -> Limits {
    let lim = w.limits.clone().unwrap_or_default();
    if let Some(g) = lim.min_actuator_gap_m {
        v.range("/workspace/limits/min_actuator_gap_m", "", g, COORDINATE_M);
    }
    if let Some(s) = lim.sigma_allow_pa {
        v.range("/workspace/limits/sigma_allow_pa", "", s, SIGMA_ALLOW_PA);
    }
    Limits {
        min_gap: lim.min_actuator_gap_m,
        sigma_allow: lim.sigma_allow_pa.or(model.design.sigma_allow),
        rod_crossing: lim.rod_crossing == Some(RodCrossing::Reject),
    }
}

/// The wave settings of the sweep after its grid and ranges: neighbours, sub-steps, tries,
/// jump limits, conditioning, stability test and physical limits.
fn sweep_settings(
    v: &mut Validator,
    w: &WorkspaceRequest,
    (grid, ranges): ([u32; 2], [[f64; 2]; 2]),
    model: &Model,
) -> SweepSettings {
    // 4 or 8 is enforced when the request is decoded (`Neighbours`).
    let neighbours = w.neighbours.map_or(4, |n| n.0);
    let max_substeps = u32_in(
        v,
        "/workspace/max_substeps",
        w.max_substeps,
        MAX_SUBSTEPS,
        8,
    );
    if !max_substeps.is_power_of_two() {
        v.push(
            "/workspace/max_substeps",
            format!("must be a power of two (1, 2, 4, ..., 64), got {max_substeps}"),
        );
    }
    let [max_tries, substep_max_iter] = [
        ("/workspace/max_tries", w.max_tries, MAX_TRIES, 4),
        (
            "/workspace/substep_max_iter",
            w.substep_max_iter,
            SUBSTEP_MAX_ITER,
            20,
        ),
    ]
    .map(|(ptr, x, range, default)| u32_in(v, ptr, x, range, default));
    let jl = w.jump_limits.clone().unwrap_or_default();
    let [angle_jump, position_factor, cond_max] = [
        (
            "/workspace/jump_limits/angle_deg",
            jl.angle_deg,
            JUMP_LIMITS_ANGLE_DEG,
            5.0,
        ),
        (
            "/workspace/jump_limits/position_factor",
            jl.position_factor,
            JUMP_LIMITS_POSITION_FACTOR,
            5.0,
        ),
        ("/workspace/cond_max", w.cond_max, COND_MAX, 1e12),
    ]
    .map(|(ptr, x, range, default)| f64_in(v, ptr, x, range, default));
    let stability = match w.stability_check.unwrap_or(StabilityCheckName::Full) {
        StabilityCheckName::Full => StabilityCheck::Full,
        StabilityCheckName::DetSign => StabilityCheck::DetSign,
        StabilityCheckName::None => StabilityCheck::None,
    };
    let segments = u32_in(
        v,
        "/workspace/stability_segments",
        w.stability_segments,
        STABILITY_SEGMENTS,
        DEFAULT_SWEEP_SEGMENTS,
    );
    let limits = limits(v, w, model);
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
    if let Some(i) = &s.inputs_m {
        coords(v, "/workspace/seed/inputs_m", i);
    }
    let kind = SeedKind::from(s.kind);
    let state = match (kind, &s.state) {
        (SeedKind::Guess, None) => {
            v.push("/workspace/seed/state", "required when seed.kind = guess");
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
    if n_act != 2 {
        v.push(
            "/design/actuators",
            format!("mode workspace needs exactly 2 actuators (2-D grid), got {n_act}"),
        );
    }
    let w = req.workspace.clone().unwrap_or_default();
    let (grid, too_large) = grid(v, w.grid);
    let ranges = ranges(v, w.ranges_m, model);
    let settings = sweep_settings(v, &w, (grid, ranges), model);
    let qt = f64_in(
        v,
        "/workspace/quasi_translational_deg",
        w.quasi_translational_deg,
        QUASI_TRANSLATIONAL_DEG,
        1.0,
    );
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

/// The request's `shard` (validated by [`common::shard`]), which only a workspace sweep takes:
/// its items are the waves, one per seed (see the `shard` field of the request).
fn shard(v: &mut Validator, req: &ContinuumWorkspaceRequest) -> Option<Shard> {
    let shard = common::shard(v, req.shard);
    let one_job = match req.mode {
        wire::Mode::Workspace => None,
        wire::Mode::Fk => Some("fk"),
        wire::Mode::AssemblyModes => Some("assembly_modes"),
    };
    if let (Some(mode), Some(_)) = (one_job, req.shard) {
        v.push(
            "/shard",
            format!("shard splits the waves of a workspace sweep; mode \"{mode}\" has no sweep"),
        );
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
    Err(CalcFailure::field(
        ProblemClass::TooLarge,
        "SEARCH_TOO_LARGE",
        "/assembly_modes/n_grid",
        format!(
            "(2 N_grid)^(2N) = {combos:.3e} grid combinations for N_grid = {n_grid} and N = {nr} rods exceeds {MAX_COMBINATIONS:e}; lower n_grid{why}"
        ),
    ))
}

impl TryFrom<&ContinuumWorkspaceRequest> for Input {
    type Error = CalcFailure;

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
        let (stability, segments, shape_points) = outputs(&mut v, req);
        let (modes, home_fallback_modes) = mode_search(&mut v, req, nr);
        let time_limit = common::time_limit(&mut v, req.time_limit_ms);
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
            mode: Mode::from(req.mode),
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
        let input = Input::try_from(&req).expect("valid");
        let got = input.sweep.expect("workspace mode").settings;
        assert_eq!(got, SweepSettings::with_defaults(got.grid, got.ranges));
    }
}
