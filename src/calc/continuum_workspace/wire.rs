//! Wire types of `POST /v1/continuum-workspace` (spec 3, 5 and 9; the spec's JSON examples are the
//! contract). Additions to the spec's examples are marked "(extension)" in the field docs.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{Shard, ShardOut};
use crate::numerics::SolverReport;

/// What to compute.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::Mode)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Forward kinematics at one input.
    Fk,
    /// Workspace sweep over a 2-D input grid (exactly 2 actuators).
    Workspace,
    /// Assembly-mode search at one input (non-certified).
    AssemblyModes,
}

/// A named design with ASSUMED geometry (spec 6.2); the response states the geometry.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::PresetName)]
pub enum PresetName {
    /// Design 1.
    #[serde(rename = "keops_d1")]
    KeopsD1,
    /// Design 2.
    #[serde(rename = "keops_d2")]
    KeopsD2,
    /// Design 3 (no stress-free home).
    #[serde(rename = "keops_d3")]
    KeopsD3,
    /// Design 4 (no stress-free home).
    #[serde(rename = "keops_d4")]
    KeopsD4,
    /// Optimised design 1, reading A.
    #[serde(rename = "keops_d1_opt_A")]
    KeopsD1OptA,
    /// Symmetric 4-rod design.
    #[serde(rename = "symmetric")]
    Symmetric,
}

/// The request.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::ContinuumWorkspaceRequest)]
#[serde(deny_unknown_fields)]
pub struct ContinuumWorkspaceRequest {
    /// `fk`, `workspace` or `assembly_modes`.
    pub mode: Mode,
    /// Mechanism design (explicit, or a preset).
    pub design: DesignRequest,
    /// Actuator inputs `lambda_j` \[m\] (fk, assembly_modes; inside the strokes).
    #[serde(default)]
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([-0.15, 0.2225]))]
    pub inputs_m: Option<Vec<f64>>,
    /// Platform load.
    #[serde(default)]
    #[schema(nullable = false)]
    pub load: Option<LoadRequest>,
    /// Solver settings.
    #[serde(default)]
    #[schema(nullable = false)]
    pub solver: Option<SolverRequest>,
    /// Starting point of the FK (which equilibrium you get).
    #[serde(default)]
    #[schema(nullable = false)]
    pub start: Option<StartRequest>,
    /// Optional FK outputs.
    #[serde(default)]
    #[schema(nullable = false)]
    pub outputs: Option<OutputsRequest>,
    /// Workspace sweep settings (mode = workspace).
    #[serde(default)]
    #[schema(nullable = false)]
    pub workspace: Option<WorkspaceRequest>,
    /// Assembly-mode search settings (mode = assembly_modes, start kind assembly_mode, designs
    /// without a stress-free home).
    #[serde(default)]
    #[schema(nullable = false)]
    pub assembly_modes: Option<AssemblyModesRequest>,
    /// Wall-clock limit for this request \[ms\] (extension; capped by the service limit).
    #[serde(default)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(example = 10_000)]
    pub time_limit_ms: Option<u64>,
    /// Run only block `index` of `count` near-equal contiguous blocks of the sweep's WAVES
    /// (extension; mode `workspace` only, a 422 at `/shard` on the other modes). The waves are
    /// the items, in their order: one per seed (seed kind `all_stable_modes`: one per stable
    /// assembly mode found at the seed node; every other kind: exactly one). A wave cannot be
    /// split into blocks of nodes, because it spreads breadth-first and every node is solved
    /// from an accepted neighbour, so a single-seed sweep is one item: its shard 0 holds the
    /// wave and shards 1.. are empty. Every shard runs the seed search (the same in each: it
    /// gives the number of waves and their seeds), then only its waves, each exactly as in the
    /// unsharded sweep. The answer then has the shape `WorkspaceShardResponse`; merging the
    /// answers of shards 0..count as its `shard` says gives the unsharded answer.
    #[serde(default)]
    #[schema(nullable = false)]
    pub shard: Option<Shard>,
}

impl crate::calc::common::TimeLimited for ContinuumWorkspaceRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Mechanism design (spec 3.1): either `preset` alone (optionally with `sigma_allow_pa`) or
/// `actuators` + `rods`.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::DesignRequest)]
#[serde(deny_unknown_fields)]
pub struct DesignRequest {
    /// Named preset with ASSUMED geometry (extension, spec 6.2).
    #[serde(default)]
    #[schema(nullable = false)]
    pub preset: Option<PresetName>,
    /// Linear guides (1..4).
    #[serde(default)]
    #[rule(min_items = 1, max_items = MAX_ACTUATORS)]
    pub actuators: Option<Vec<ActuatorRequest>>,
    /// Rods (2..8).
    #[serde(default)]
    #[rule(min_items = MIN_RODS, max_items = MAX_RODS)]
    pub rods: Option<Vec<RodRequest>>,
    /// Inputs at which every rod is straight and unloaded with `theta_EE = 0` \[m\]; computed by
    /// least squares when absent.
    #[serde(default)]
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([-0.25, 0.2725]))]
    pub home_inputs_m: Option<Vec<f64>>,
    /// Allowable bending stress \[Pa\]: FK warnings and default workspace stress limit.
    #[serde(default)]
    #[rule(range = SIGMA_ALLOW_PA)]
    #[schema(example = 1.2e9)]
    pub sigma_allow_pa: Option<f64>,
}

/// One linear guide.
#[derive(Debug, Clone, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::ActuatorRequest)]
#[serde(deny_unknown_fields)]
pub struct ActuatorRequest {
    /// Point on the guide `o_j` \[m\].
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([0.0, 0.0]))]
    pub origin_m: [f64; 2],
    /// Guide direction `d_j` (normalised by the service; norm > 1e-12).
    #[rule(items = Range::FINITE)]
    #[schema(example = json!([1.0, 0.0]))]
    pub direction: [f64; 2],
    /// Admissible inputs `[min, max]` \[m\], min < max.
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([-0.7, 0.2]))]
    pub stroke_m: [f64; 2],
}

/// One rod.
#[derive(Debug, Clone, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::RodRequest)]
#[serde(deny_unknown_fields)]
pub struct RodRequest {
    /// Index `j(i)` of the actuator carrying the clamp (below the number of actuators).
    #[rule(range = ACTUATOR_INDEX)]
    #[schema(example = 0)]
    pub actuator: usize,
    /// Clamp offset `c_i` on the carriage \[m\] (default `[0, 0]`).
    #[serde(default)]
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([-0.0225, 0.0]))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset_m: Option<[f64; 2]>,
    /// Clamp angle `theta_c,i` \[deg\] (tangent direction at s = 0, counter-clockwise from +X).
    #[rule(range = Range::FINITE)]
    #[schema(example = -60.0)]
    pub clamp_angle_deg: f64,
    /// Rod length `L_i` \[m\].
    #[rule(range = LENGTH_M)]
    #[schema(example = 0.5)]
    pub length_m: f64,
    /// Solid round section diameter `d_i` \[m\] (L/d >= 20 recommended, >= 5 required; required
    /// unless `ei_nm2` is given).
    #[serde(default)]
    #[rule(range = DIAMETER_M)]
    #[schema(example = 0.004)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diameter_m: Option<f64>,
    /// Bending stiffness `EI_i` [N m^2] (alternative to the diameter; overrides `E pi d^4/64`).
    #[serde(default)]
    #[rule(range = EI_NM2)]
    #[schema(example = 2.63894)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ei_nm2: Option<f64>,
    /// Young's modulus `E_i` \[Pa\] (default 2.1e11).
    #[serde(default)]
    #[rule(range = YOUNGS_MODULUS_PA)]
    #[schema(example = 2.1e11)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub youngs_modulus_pa: Option<f64>,
    /// Platform point `r_i` in the platform frame \[m\].
    #[rule(items = COORDINATE_M)]
    #[schema(example = json!([-0.0225, 0.0]))]
    pub attach_m: [f64; 2],
}

/// Dead load on the platform.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::LoadRequest)]
#[serde(deny_unknown_fields)]
pub struct LoadRequest {
    /// Force `F` at P \[N\]; `|F| <= 1e4 EI_ref/L_ref^2` (default `[0, 0]`).
    #[serde(default)]
    #[rule(items = Range::FINITE)]
    #[schema(example = json!([0.0, -50.0]))]
    pub force_n: Option<[f64; 2]>,
    /// Couple `M` [N m]; `|M| <= 1e4 EI_ref/L_ref` (extension of "finite"; default 0).
    #[serde(default)]
    #[rule(range = Range::FINITE)]
    #[schema(example = 0.0)]
    pub moment_nm: Option<f64>,
}

/// Solver settings (spec 3.2).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::SolverRequest)]
#[serde(deny_unknown_fields)]
pub struct SolverRequest {
    /// Base RK4 steps per rod (raised by the load rule of spec 4.1; default 32).
    #[serde(default)]
    #[rule(range = RK4_STEPS)]
    #[schema(example = 32)]
    pub rk4_steps: Option<u32>,
    /// Newton stop on the scaled residual (inf-norm; default 1e-10).
    #[serde(default)]
    #[rule(range = SOLVER_TOL)]
    #[schema(example = 1e-10)]
    pub tol: Option<f64>,
    /// Newton iterations per solve (default 50).
    #[serde(default)]
    #[rule(range = SOLVER_MAX_ITER)]
    #[schema(example = 50)]
    pub max_iter: Option<u32>,
    /// Add axial compliance `EA = E pi d^2/4` (recommended for N >= 4).
    #[serde(default)]
    #[schema(example = false)]
    pub axial_extensibility: Option<bool>,
}

/// Which equilibrium the FK starts from (spec 4.3).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::StartKind)]
#[serde(rename_all = "snake_case")]
pub enum StartKind {
    /// Continue from the stress-free home (mode AM1).
    Home,
    /// Newton from a previous `solver_state`.
    Guess,
    /// Run the assembly-mode search and take the solution `index`.
    AssemblyMode,
}

/// A solver state for warm starts.
#[derive(Debug, Clone, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::SolverState)]
#[serde(deny_unknown_fields)]
pub struct SolverState {
    /// Unknown vector `[mb0_1, nbx_1, nby_1, ..., px/L_ref, py/L_ref, theta_EE]` (length 3N+3).
    #[rule(items = Range::FINITE)]
    pub v: Vec<f64>,
}

/// FK start.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::StartRequest)]
#[serde(deny_unknown_fields)]
pub struct StartRequest {
    /// `home` (default), `guess` or `assembly_mode`.
    pub kind: StartKind,
    /// Previous `solver_state` (kind = guess).
    #[serde(default)]
    #[schema(nullable = false)]
    pub state: Option<SolverState>,
    /// Assembly-mode index in the margin-sorted list (kind = assembly_mode; default 0).
    #[serde(default)]
    #[rule(range = INDEX)]
    #[schema(example = 0)]
    pub index: Option<usize>,
    /// Override of the number of equal continuation steps from home (extension; default
    /// `max(10, ceil(max |dlambda| / (0.01 L_ref)))`).
    #[serde(default)]
    #[rule(range = CONTINUATION_STEPS)]
    #[schema(example = 30)]
    pub continuation_steps: Option<u32>,
    /// Step control of the continuation from home (kind = home; the path runs in the
    /// continuation parameter t from 0 = home inputs, no load, to 1 = the request's inputs and
    /// load): `adaptive` (default) starts with the step `1/continuation_steps`, doubles it (up
    /// to 1/4 of the path) after a step whose chord-Newton corrector (the previous point's
    /// Jacobian) converged in at most 3 iterations, and halves it when the corrector fails or
    /// moves more than half the predictor's step away from the tangent prediction (down to
    /// `1/(continuation_steps 2^8)`); `fixed` is the spec 4.3 path: `continuation_steps` equal
    /// steps, each solved by full Newton, halved only on failure (the path of the spec's
    /// reference values). Both end with full Newton to `solver.tol` at the target and land on
    /// the same equilibrium branch: over 300 random stable targets of design 1 their platform
    /// positions agree to 1e-9 `L_ref` (tests/slow/props_continuum_workspace.rs).
    #[serde(default)]
    #[schema(nullable = false)]
    pub continuation: Option<ContinuationKind>,
}

/// Step control of the continuation from home (spec 4.3).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::ContinuationKind)]
#[serde(rename_all = "snake_case")]
pub enum ContinuationKind {
    /// Adaptive step length, tangent predictor, chord Newton corrector (default). Where it
    /// stalls (e.g. a singular Jacobian at home, a path close to a fold) the fixed steps are
    /// walked from the same start instead; `diagnostics.continuation` then says `fixed` and a
    /// `continuation_fallback` warning says where the adaptive walk stopped.
    #[default]
    Adaptive,
    /// The spec's `K` equal steps with full Newton per step.
    Fixed,
}

/// Optional FK outputs.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::OutputsRequest)]
#[serde(deny_unknown_fields)]
pub struct OutputsRequest {
    /// Run the stability test (spec 4.5; default true).
    #[serde(default)]
    #[schema(example = true)]
    pub stability: Option<bool>,
    /// Segments per rod `M` of the stability test (default 40).
    #[serde(default)]
    #[rule(range = STABILITY_SEGMENTS)]
    #[schema(example = 40)]
    pub stability_segments: Option<u32>,
    /// Sample points per rod of the returned shapes (0 = none, the default).
    #[serde(default)]
    #[rule(range = ROD_SHAPE_POINTS)]
    #[schema(example = 0)]
    pub rod_shape_points: Option<u32>,
}

/// Seed of a workspace wave.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::SeedKind)]
#[serde(rename_all = "snake_case")]
pub enum SeedKind {
    /// Home continuation to the seed node (default).
    Home,
    /// Newton from a given `state` at the seed node.
    Guess,
    /// Assembly mode `index` at the seed node.
    AssemblyMode,
    /// One wave per stable assembly mode at the seed node (extension).
    AllStableModes,
}

/// Seed of the sweep.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::SeedRequest)]
#[serde(deny_unknown_fields)]
pub struct SeedRequest {
    /// `home`, `guess`, `assembly_mode` or `all_stable_modes`.
    pub kind: SeedKind,
    /// Inputs near which the seed node is chosen \[m\] (default: home inputs, else the range centre).
    #[serde(default)]
    #[rule(items = COORDINATE_M)]
    pub inputs_m: Option<[f64; 2]>,
    /// Solver state (kind = guess).
    #[serde(default)]
    #[schema(nullable = false)]
    pub state: Option<SolverState>,
    /// Assembly-mode index (kind = assembly_mode; default 0).
    #[serde(default)]
    #[rule(range = INDEX)]
    pub index: Option<usize>,
}

/// Jump limits of one sub-step.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::JumpLimits)]
#[serde(deny_unknown_fields)]
pub struct JumpLimits {
    /// Largest platform rotation per sub-step \[deg\] (default 5).
    #[serde(default)]
    #[rule(range = JUMP_LIMITS_ANGLE_DEG)]
    #[schema(example = 5.0)]
    pub angle_deg: Option<f64>,
    /// Largest platform displacement per sub-step as a multiple of the input change (default 5).
    #[serde(default)]
    #[rule(range = JUMP_LIMITS_POSITION_FACTOR)]
    #[schema(example = 5.0)]
    pub position_factor: Option<f64>,
}

/// Stability test per node.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::StabilityCheckName)]
#[serde(rename_all = "snake_case")]
pub enum StabilityCheckName {
    /// Full test (spec 4.5).
    Full,
    /// det J sign only (proves instability on a flip).
    DetSign,
    /// None.
    None,
}

/// Rod-crossing limit.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::RodCrossing)]
#[serde(rename_all = "snake_case")]
pub enum RodCrossing {
    /// Do not check.
    Ignore,
    /// Reject nodes where two rod centre lines cross.
    Reject,
}

/// Workspace limits.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::WorkspaceLimits)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceLimits {
    /// Minimum carriage gap \[m\] (clamp points of carriage 2 minus those of carriage 1, along guide
    /// 1); null = none.
    #[serde(default)]
    #[rule(range = COORDINATE_M)]
    #[schema(example = 0.05)]
    pub min_actuator_gap_m: Option<f64>,
    /// Allowable bending stress \[Pa\]; null = `design.sigma_allow_pa` or none.
    #[serde(default)]
    #[rule(range = SIGMA_ALLOW_PA)]
    pub sigma_allow_pa: Option<f64>,
    /// `ignore` (default) or `reject`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub rod_crossing: Option<RodCrossing>,
}

/// Area method.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = continuum_workspace::AreaMethod)]
#[serde(rename_all = "snake_case")]
pub enum AreaMethod {
    /// Area of the union of the cell polygons (rasterised; correct for folded maps).
    Union,
    /// Only the sum of |cell areas| (cheap; over-counts folded cells).
    Sum,
}

/// Workspace sweep settings (spec 4.7).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::WorkspaceRequest)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceRequest {
    /// Grid `[n1, n2]`, 2..401 each, n1*n2 <= 40401 (default `[31, 31]`).
    #[serde(default)]
    #[rule(items = GRID_SIDE)]
    #[schema(example = json!([31, 31]))]
    pub grid: Option<[u32; 2]>,
    /// Input ranges `[[min1, max1], [min2, max2]]` \[m\], min < max (default: the strokes).
    #[serde(default)]
    #[rule(items_items = COORDINATE_M)]
    #[schema(example = json!([[-0.70, 0.20], [-0.1775, 0.7225]]))]
    pub ranges_m: Option<[[f64; 2]; 2]>,
    /// Seed of the wave (default home).
    #[serde(default)]
    #[schema(nullable = false)]
    pub seed: Option<SeedRequest>,
    /// 4 (default) or 8 neighbours.
    #[serde(default)]
    #[schema(nullable = false, example = 4)]
    pub neighbours: Option<Neighbours>,
    /// Tangent predictor (default true).
    #[serde(default)]
    pub predictor: Option<bool>,
    /// Largest number of sub-steps, a power of two 1..64 (default 8).
    #[serde(default)]
    #[schema(nullable = false, example = 8)]
    pub max_substeps: Option<Substeps>,
    /// Attempts per node 1..8 (default 4).
    #[serde(default)]
    #[rule(range = MAX_TRIES)]
    #[schema(example = 4)]
    pub max_tries: Option<u32>,
    /// Newton iterations per sub-step solve, capped by `solver.max_iter` (default 20; extension:
    /// a sub-step started from the tangent predictor converges in 2-7 iterations, a solve still
    /// wandering after 20 is abandoned for smaller sub-steps).
    #[serde(default)]
    #[rule(range = SUBSTEP_MAX_ITER)]
    #[schema(example = 20)]
    pub substep_max_iter: Option<u32>,
    /// Jump limits per sub-step.
    #[serde(default)]
    #[schema(nullable = false)]
    pub jump_limits: Option<JumpLimits>,
    /// Largest accepted condition number of the scaled Jacobian (default 1e12).
    #[serde(default)]
    #[rule(range = COND_MAX)]
    #[schema(example = 1e12)]
    pub cond_max: Option<f64>,
    /// `full` (default), `det_sign` or `none`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub stability_check: Option<StabilityCheckName>,
    /// Segments per rod of the stability test (default 20 in sweeps).
    #[serde(default)]
    #[rule(range = STABILITY_SEGMENTS)]
    #[schema(example = 20)]
    pub stability_segments: Option<u32>,
    /// Physical limits.
    #[serde(default)]
    #[schema(nullable = false)]
    pub limits: Option<WorkspaceLimits>,
    /// Threshold of the quasi-translational area \[deg\] (default 1).
    #[serde(default)]
    #[rule(range = QUASI_TRANSLATIONAL_DEG)]
    #[schema(example = 1.0)]
    pub quasi_translational_deg: Option<f64>,
    /// `union` (default) or `sum`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub area_method: Option<AreaMethod>,
    /// Return the per-node arrays (default false).
    #[serde(default)]
    pub return_nodes: Option<bool>,
}

/// Assembly-mode search settings (spec 4.6).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = continuum_workspace::AssemblyModesRequest)]
#[serde(deny_unknown_fields)]
pub struct AssemblyModesRequest {
    /// `N_grid`: psi and |k| grid points per rod; `(2 N_grid)^(2N) <= 1e8` for N rods.
    /// Default: the largest N_grid <= 9 with at most 3.5e7 combinations (9 for 3 rods, 4 for
    /// 4 rods, 2 for 5 or more); the search that picks the start of a design without a
    /// stress-free home defaults to min(6, that).
    #[serde(default)]
    #[rule(range = N_GRID)]
    #[schema(example = 9)]
    pub n_grid: Option<u32>,
    /// `Tol` on the normalised grid residual, dimensionless (default 0.5; 0.45 for the start of a
    /// design without a stress-free home).
    #[serde(default)]
    #[rule(range = ASSEMBLY_MODES_TOL)]
    #[schema(example = 0.5)]
    pub tol: Option<f64>,
    /// Coarse cell size (default 2).
    #[serde(default)]
    #[rule(range = CELL)]
    #[schema(example = 2)]
    pub cell: Option<u32>,
    /// Maximum Newton refinements (default 4000).
    #[serde(default)]
    #[rule(range = MAX_REFINE)]
    #[schema(example = 4000)]
    pub max_refine: Option<u32>,
}

// ----------------------------------------------------------------------------------- responses

/// Assembly-mode search settings actually used.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::ModeSearchOut)]
pub struct ModeSearchOut {
    /// `N_grid`.
    pub n_grid: u64,
    /// `Tol` on the normalised grid residual, dimensionless.
    pub tol: f64,
    /// Coarse cell size in grid indices.
    pub cell: u64,
    /// Newton refinement cap.
    pub max_refine: u64,
}

/// The response: one shape per mode.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::ContinuumWorkspaceResponse)]
#[serde(untagged)]
pub enum ContinuumWorkspaceResponse {
    /// mode = fk.
    Fk(Box<FkResponse>),
    /// mode = workspace.
    Workspace(Box<WorkspaceResponse>),
    /// mode = workspace with `shard` in the request.
    WorkspaceShard(Box<WorkspaceShardResponse>),
    /// mode = assembly_modes.
    AssemblyModes(Box<AssemblyModesResponse>),
}

/// Outcome of an FK solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = continuum_workspace::FkStatus)]
#[serde(rename_all = "snake_case")]
pub enum FkStatus {
    /// Converged and well conditioned.
    Ok,
    /// Newton did not converge (no pose is returned).
    NoConvergence,
    /// Converged, but the Jacobian is singular (rod forces indeterminate: not returned).
    Singular,
}

/// Platform pose.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::PlatformOut)]
pub struct PlatformOut {
    /// Position of P \[m\].
    pub position_m: [f64; 2],
    /// Parasitic angle `theta_EE` \[deg\], wrapped to (-180, 180].
    pub parasitic_angle_deg: f64,
}

/// Per-rod FK results.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::RodOut)]
pub struct RodOut {
    /// Rod force `n_i` \[N\] = force of the platform on the rod tip (omitted when indeterminate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip_force_n: Option<[f64; 2]>,
    /// Base moment `m_i(0)` [N m].
    pub base_moment_nm: f64,
    /// Largest bending stress over the RK4 nodes \[Pa\] (omitted without a diameter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_bending_stress_pa: Option<f64>,
    /// Bending energy `int m^2/(2EI) ds` \[J\] (extension).
    pub elastic_energy_j: f64,
    /// `[x_m, y_m, theta_deg, m_nm]` at `rod_shape_points` points (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<Vec<[f64; 4]>>,
}

/// Stability of an FK solution.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::StabilityOut)]
pub struct StabilityOut {
    /// margin > 1e-8.
    pub stable: bool,
    /// Smallest constrained eigenvalue times `L_ref^2/EI_ref` (omitted when undefined).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// Sign of det J (stable solutions have +1; -1 proves instability).
    pub det_sign: i8,
    /// Segments per rod used.
    pub segments: u32,
}

/// FK diagnostics.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::DiagnosticsOut)]
pub struct DiagnosticsOut {
    /// Newton iterations of the final solve (the total over all continuation steps, chord
    /// iterations of the adaptive continuation included, is in `report.iterations`).
    pub newton_iterations: u64,
    /// `||g||_inf` at the returned point.
    pub residual_inf: f64,
    /// 2-norm condition number of the scaled Jacobian (capped at 1e20).
    pub jacobian_condition: f64,
    /// Accepted continuation steps (home start; 0 otherwise).
    pub continuation_steps: u64,
    /// Step control of the continuation from home that was walked (`start.continuation`);
    /// absent when the start was not the continuation from home.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub continuation: Option<ContinuationKind>,
    /// Base RK4 steps per rod.
    pub rk4_steps: u32,
    /// RK4 steps actually used per rod (load rule of spec 4.1; extension).
    pub rk4_steps_used: Vec<u64>,
    /// Warnings (`taut_rod i`, `slender_rod i`, `stress_above_allowable i`, ...).
    pub warnings: Vec<String>,
}

/// Preset statement.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::PresetOut)]
pub struct PresetOut {
    /// Preset name.
    pub name: PresetName,
    /// Always true: the paper gives no geometry.
    pub assumed_geometry: bool,
    /// Plain statement of the assumed geometry.
    pub description: String,
    /// The full design used.
    pub actuators: Vec<ActuatorRequest>,
    /// The rods used.
    pub rods: Vec<RodRequest>,
    /// Home inputs \[m\], if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub home_inputs_m: Option<Vec<f64>>,
}

/// mode = fk.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::FkResponse)]
pub struct FkResponse {
    /// Always `fk`.
    pub mode: Mode,
    /// `ok`, `no_convergence` or `singular`.
    pub status: FkStatus,
    /// Platform pose (omitted when not converged).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub platform: Option<PlatformOut>,
    /// Per-rod results (omitted when not converged).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rods: Option<Vec<RodOut>>,
    /// Actuator forces `f_j = -sum n_i . d_j` \[N\] (omitted unless status ok).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actuator_forces_n: Option<Vec<f64>>,
    /// Stability (when requested and converged).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub stability: Option<StabilityOut>,
    /// Diagnostics.
    pub diagnostics: DiagnosticsOut,
    /// State for warm starts (omitted when not converged).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub solver_state: Option<SolverState>,
    /// Preset statement when a preset was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub preset: Option<PresetOut>,
    /// Cost and stop reason: `iterations` counts the Newton iterations over all solves (on a
    /// home start: every continuation step, the adaptive path's chord iterations included, and
    /// the final solve; the steps are in `diagnostics.continuation_steps`), `evaluations` the
    /// rod-system evaluations (residual, with or without Jacobian).
    pub report: SolverReport,
}

/// Joint-space grid.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::GridOut)]
pub struct GridOut {
    /// `lambda1` values \[m\].
    pub lambda1_m: Vec<f64>,
    /// `lambda2` values \[m\].
    pub lambda2_m: Vec<f64>,
}

/// Per-node arrays, row-major `n1 x n2` (index `i * n2 + j`, `i` over `lambda1`); null where not
/// accepted.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::NodesOut)]
pub struct NodesOut {
    /// Status codes.
    pub status: Vec<&'static str>,
    /// Platform x \[m\].
    pub px_m: Vec<Option<f64>>,
    /// Platform y \[m\].
    pub py_m: Vec<Option<f64>>,
    /// Parasitic angle \[deg\] (continuous along the wave).
    pub parasitic_angle_deg: Vec<Option<f64>>,
    /// Stability margin (full stability only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability_margin: Option<Vec<Option<f64>>>,
    /// Largest rod bending stress \[Pa\].
    pub max_stress_pa: Vec<Option<f64>>,
    /// Actuator forces \[N\].
    pub actuator_forces_n: Vec<Option<[f64; 2]>>,
}

/// Workspace metrics of one wave (spec 4.8).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::MetricsOut)]
pub struct MetricsOut {
    /// Accepted nodes.
    pub n_accepted: u64,
    /// Cells with 4 accepted corners.
    pub n_cells: u64,
    /// Area of the union of the cell polygons [m^2] (area_method = union).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area_union_m2: Option<f64>,
    /// Sum of |cell areas| [m^2].
    pub area_sum_m2: f64,
    /// Cells whose signed area has the minority sign (folded map).
    pub folded_cells: u64,
    /// Area of cells whose 4 corners have |theta_EE| below the threshold [m^2] (union or sum).
    pub quasi_translational_area_m2: f64,
    /// Largest |theta_EE| over accepted nodes \[deg\].
    pub max_abs_parasitic_deg: f64,
    /// Mean |theta_EE| over accepted nodes \[deg\].
    pub mean_abs_parasitic_deg: f64,
    /// Largest bending stress over accepted nodes \[Pa\] (omitted without diameters).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_bending_stress_pa: Option<f64>,
}

/// Seed of a wave.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::SeedOut)]
pub struct SeedOut {
    /// Seed kind.
    pub kind: SeedKind,
    /// Grid node `[i, j]`.
    pub node: [u64; 2],
    /// Inputs of the seed node \[m\].
    pub inputs_m: [f64; 2],
    /// Status of the seed node (`ok` or why the wave could not start).
    pub status: &'static str,
    /// Assembly-mode index (seeds from the assembly-mode search).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub assembly_mode_index: Option<u64>,
    /// Seed pose, when solved.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub platform: Option<PlatformOut>,
}

/// One wave (one assembly mode).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::WaveOut)]
pub struct WaveOut {
    /// Seed.
    pub seed: SeedOut,
    /// Per-node arrays (return_nodes).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub nodes: Option<NodesOut>,
    /// Metrics.
    pub metrics: MetricsOut,
    /// Failure histogram by status code (visited, not accepted nodes; `unvisited` counted too).
    pub failures: BTreeMap<String, u64>,
}

/// mode = workspace.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::WorkspaceResponse)]
pub struct WorkspaceResponse {
    /// Always `workspace`.
    pub mode: Mode,
    /// Grid.
    pub grid: GridOut,
    /// First wave (seed, nodes, metrics, failures) at the top level as in the spec's example.
    #[serde(flatten)]
    pub wave: WaveOut,
    /// Further waves (seed kind all_stable_modes), each with its own seed/nodes/metrics/failures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other_waves: Option<Vec<WaveOut>>,
    /// Wall-clock time \[ms\].
    pub timing_ms: f64,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Preset statement when a preset was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<PresetOut>,
    /// Cost and stop reason (deadline: partial sweep).
    pub report: SolverReport,
}

/// mode = workspace with `shard` in the request: the shard's block of the sweep's waves, each
/// wave whole (seed, nodes, metrics, failures) as in the unsharded answer.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::WorkspaceShardResponse)]
pub struct WorkspaceShardResponse {
    /// Always `workspace`.
    pub mode: Mode,
    /// Grid (the whole grid: the same in every shard).
    pub grid: GridOut,
    /// The waves `shard.start..shard.end` of the whole sweep, in order (empty when the sweep
    /// has fewer waves than shards).
    pub waves: Vec<WaveOut>,
    /// Which waves this answer holds (`total`: the waves of the whole sweep).
    /// Merge rule: request shards 0..count with the same body and concatenate their `waves`
    /// in shard order (wave `start + i` of the sweep is `waves[i]` of the shard holding it).
    /// The unsharded answer is then: `mode`, `grid` and `preset` of any shard (the same in
    /// every shard); the first merged wave's `seed`, `nodes`, `metrics` and `failures` at the
    /// top level and the other merged waves, in order, as `other_waves` (omitted when the
    /// sweep has one wave); `warnings` the union of the shards' warnings in order of first
    /// appearance (every shard repeats those of validation and of the seed search; a shard
    /// whose budget ran out adds `budget_exhausted`). There is nothing to add up or
    /// recompute: every metric belongs to one wave. `timing_ms` and `report` are per shard
    /// (every shard's report counts its seed search too).
    pub shard: ShardOut,
    /// Wall-clock time of this shard \[ms\].
    pub timing_ms: f64,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Preset statement when a preset was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub preset: Option<PresetOut>,
    /// Cost and stop reason of this shard (the seed search and its waves; deadline: partial).
    pub report: SolverReport,
}

/// One assembly mode.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::AssemblyModeOut)]
pub struct AssemblyModeOut {
    /// Platform pose.
    pub pose: PlatformOut,
    /// Parasitic angle \[deg\] (as in `pose`, spec 5 field list).
    pub parasitic_angle_deg: f64,
    /// margin > 1e-8.
    pub stable: bool,
    /// Stability margin.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// Sign of det J.
    pub det_sign: i8,
    /// Rod forces `n_i` \[N\].
    pub rod_forces: Vec<[f64; 2]>,
    /// State for warm starts.
    pub solver_state: SolverState,
}

/// mode = assembly_modes.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = continuum_workspace::AssemblyModesResponse)]
pub struct AssemblyModesResponse {
    /// Always `assembly_modes`.
    pub mode: Mode,
    /// Distinct solutions sorted by decreasing margin.
    pub solutions: Vec<AssemblyModeOut>,
    /// Grid combinations below Tol.
    pub candidates: u64,
    /// Newton refinements run.
    pub refined: u64,
    /// Grid combinations examined.
    pub combinations: u64,
    /// The search settings used (request values or defaults).
    pub search: ModeSearchOut,
    /// Always false: a grid search cannot certify that every equilibrium was found.
    pub complete: bool,
    /// Why the list is not certified.
    pub note: String,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Preset statement when a preset was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub preset: Option<PresetOut>,
    /// Cost and stop reason.
    pub report: SolverReport,
}

// The per-field rules of this module's wire types (`#[rule(...)]` on the fields above: the door
// checks them and the document states them).
/// Largest accepted coordinate, stroke or length magnitude \[m\]: the scales the service is
/// tested at run from 1e-6 m to 1e6 m; beyond, products such as EI or B x n leave the range
/// where the scaled residual is meaningful.
pub const MAX_COORD_M: f64 = 1e6;
/// A coordinate, stroke end or actuator input \[m\].
pub const COORDINATE_M: Range = Range::FINITE.min(-MAX_COORD_M).max(MAX_COORD_M);
/// A rod length \[m\] (see [`MAX_COORD_M`]).
pub const LENGTH_M: Range = Range::FINITE.min(1e-7).max(MAX_COORD_M);
/// A rod diameter \[m\] (EI ~ d^4 must stay a normal float).
pub const DIAMETER_M: Range = Range::FINITE.min(1e-9).max(MAX_COORD_M);
/// Young's modulus \[Pa\] (gels to beyond diamond).
pub const YOUNGS_MODULUS_PA: Range = Range::closed(1.0, 1e13);
/// Bending stiffness given directly [N m^2].
pub const EI_NM2: Range = Range::closed(1e-30, 1e20);
/// Allowable stress \[Pa\].
pub const SIGMA_ALLOW_PA: Range = Range::FINITE.min(f64::MIN_POSITIVE).max(1e15);

/// RK4 steps per rod (spec 4.1).
pub const RK4_STEPS: Range = Range::int(4, 4096);
/// Newton tolerance on the scaled residual (spec 4.2).
pub const SOLVER_TOL: Range = Range::closed(1e-14, 1e-4);
/// Newton iterations per solve.
pub const SOLVER_MAX_ITER: Range = Range::int(5, 200);
/// Continuation steps from home.
pub const CONTINUATION_STEPS: Range = Range::int(1, 10_000);
/// Segments per rod of the stability test (spec 4.5).
pub const STABILITY_SEGMENTS: Range = Range::int(10, 400);
/// Sample points per returned rod shape.
pub const ROD_SHAPE_POINTS: Range = Range::int(0, 1000);
/// Coarse grid of the assembly-mode search (spec 4.6).
pub const N_GRID: Range = Range::int(1, 50);
/// Clustering tolerance of the assembly-mode search.
pub const ASSEMBLY_MODES_TOL: Range = Range::closed(f64::MIN_POSITIVE, 10.0);
/// Search-cell size of the assembly-mode search.
pub const CELL: Range = Range::int(1, 100);
/// Largest number of refined cells of the assembly-mode search.
pub const MAX_REFINE: Range = Range::int(1, 20_000);
/// Substeps of one workspace edge.
pub const MAX_SUBSTEPS: Range = Range::int(1, 64);
/// Attempts per workspace node.
pub const MAX_TRIES: Range = Range::int(1, 8);
/// Newton iterations per substep.
pub const SUBSTEP_MAX_ITER: Range = Range::int(5, 200);
/// Largest accepted jump of the platform angle between neighbours \[deg\].
pub const JUMP_LIMITS_ANGLE_DEG: Range = Range::closed(1e-6, 180.0);
/// Largest accepted position jump, in units of the grid step.
pub const JUMP_LIMITS_POSITION_FACTOR: Range = Range::closed(1e-6, 1000.0);
/// Largest accepted Jacobian condition number.
pub const COND_MAX: Range = Range::closed(10.0, 1e18);
/// Parasitic-angle threshold of the quasi-translational area \[deg\].
pub const QUASI_TRANSLATIONAL_DEG: Range = Range::closed(1e-9, 180.0);
/// Nodes per side of the workspace grid (spec 4.7).
pub const GRID_SIDE: Range = Range::int(2, 401);
/// Most actuators of a design.
pub const MAX_ACTUATORS: usize = 4;
/// Fewest rods of a design (spec 3.1).
pub const MIN_RODS: usize = 2;
/// Most rods of a design (spec 3.1).
pub const MAX_RODS: usize = 8;
/// Index of a design's actuator (below the number of actuators: a cross-field rule).
pub const ACTUATOR_INDEX: Range = Range::int(0, MAX_ACTUATORS as i64 - 1);
/// An index into a list (assembly mode, seed node).
pub const INDEX: Range = Range::INTEGER.min(0.0);

/// Neighbourhood of the workspace wave: the integer 4 or 8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, crate::calc::Rules)]
#[serde(try_from = "u32")]
pub struct Neighbours(pub u32);

impl TryFrom<u32> for Neighbours {
    type Error = String;
    fn try_from(n: u32) -> Result<Self, String> {
        if n == 4 || n == 8 {
            Ok(Self(n))
        } else {
            Err(format!("must be 4 or 8, got {n}"))
        }
    }
}

impl utoipa::PartialSchema for Neighbours {
    fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
        utoipa::openapi::schema::ObjectBuilder::new()
            .schema_type(utoipa::openapi::schema::SchemaType::new(
                utoipa::openapi::schema::Type::Integer,
            ))
            .enum_values(Some([4, 8]))
            .description(Some("4 or 8 neighbours."))
            .into()
    }
}

impl ToSchema for Neighbours {
    fn name() -> std::borrow::Cow<'static, str> {
        std::borrow::Cow::Borrowed("continuum_workspace.Neighbours")
    }
}

/// Largest number of sub-steps of one workspace edge: a power of two, 1..64.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, crate::calc::Rules)]
#[serde(try_from = "u32")]
pub struct Substeps(pub u32);

impl TryFrom<u32> for Substeps {
    type Error = String;
    fn try_from(n: u32) -> Result<Self, String> {
        if n.is_power_of_two() && MAX_SUBSTEPS.contains(f64::from(n)) {
            Ok(Self(n))
        } else {
            Err(format!(
                "must be a power of two (1, 2, 4, ..., 64), got {n}"
            ))
        }
    }
}

impl utoipa::PartialSchema for Substeps {
    fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
        utoipa::openapi::schema::ObjectBuilder::new()
            .schema_type(utoipa::openapi::schema::SchemaType::new(
                utoipa::openapi::schema::Type::Integer,
            ))
            .enum_values(Some([1, 2, 4, 8, 16, 32, 64]))
            .description(Some("A power of two, 1..64."))
            .into()
    }
}

impl ToSchema for Substeps {
    fn name() -> std::borrow::Cow<'static, str> {
        std::borrow::Cow::Borrowed("continuum_workspace.Substeps")
    }
}
