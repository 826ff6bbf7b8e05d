//! Forward kinematics, stability and workspace of planar parallel continuum manipulators (elastic
//! rods clamped on linear-actuator carriages and pinned to a rigid platform; the planar Keops-Delta).
//! Endpoint `POST /v1/continuum-workspace`. Spec: `shared/specs/continuum_workspace.md`.
//!
//! # Method
//! * Each rod is a planar Kirchhoff rod (optionally axially extensible) integrated in nondimensional
//!   form by fixed-step RK4 together with its exact sensitivities ([`rod`], spec 4.1, paper eq. 8).
//! * FK is Newton's method with backtracking on the full residual (rod closure, pinned-tip moments,
//!   platform force and moment balance, [`model`], [`newton`], paper eqs. 16-19, 22), started by
//!   continuation from the stress-free home or from a given state or assembly mode ([`fk`], 4.3).
//!   The continuation from home is adaptive by default (issue 17; `start.continuation`): tangent
//!   predictor, first step `1/K` of the spec's K, doubled after a step whose chord-Newton
//!   corrector (the last evaluated Jacobian, kept across steps while it converges in <= 2
//!   iterations) reaches 1e-6 in <= 3 iterations, halved when the corrector fails or moves more
//!   than half the predictor step (trust region), at most 1/4 of the path per step, and full
//!   Newton to `solver.tol` at the target. `continuation: fixed` is the spec 4.3 path (K equal
//!   steps, full Newton each), with which the spec's reference values were produced.
//! * Stability: the smallest eigenvalue of the constrained Hessian of a discretised potential
//!   ([`stability`], 4.5), plus the cheap det J sign companion.
//! * Assembly modes ("full FK"): a grid over the closed-form elastica (elliptic integrals, paper
//!   eqs. 12-15 with the branch fix of 4.9-1) refined by Newton ([`modes`], 4.6) — NOT certified.
//! * Workspace: wave propagation over the joint-space grid, one wave per assembly mode, stopping at
//!   unstable, singular or limit-violating nodes ([`sweep`], 4.7), and the derived metrics (union
//!   area of the possibly folded cell map, parasitic angle, stresses; [`area`], 4.8).
//!
//! # References
//! * Planar continuum Keops-Delta workspace paper (`shared/papers/planar-continuum-delta-workspace.txt`):
//!   Kirchhoff rods, shooting FK, elliptic-integral full FK, wave-propagation workspace, parasitic
//!   angle, vertical payload.
//! * B. C. Carlson, Numerical computation of real or complex elliptic integrals, Numer. Algorithms
//!   10 (1995) 13-26 (the elliptic integrals in [`crate::numerics::elliptic`]).
//!
//! # Conventions
//! Plane XY, angles counter-clockwise from +X, `a x b = a_x b_y - a_y b_x`. `n_i` is the force the
//! platform applies to the tip of rod i (the rod pushes the platform with `-n_i`); `theta_EE` is the
//! platform rotation (parasitic angle), reported wrapped to (-180, 180] deg but continuous inside
//! sweeps. Workspace node arrays are row-major `n1 x n2` (index `i * n2 + j`, `i` over `lambda1`).
//!
//! # Validity and accuracy
//! * Inputs: 2..8 rods on 1..4 linear guides (exactly 2 for sweeps), slender rods (L/d >= 20; 5..20
//!   warned, < 5 rejected), loads up to `1e4 EI_ref/L_ref^2`. Presets use ASSUMED geometry (the paper
//!   gives none) and say so in the response.
//! * Achieved error (tests/it/paper_continuum_workspace.rs, benches/RESULTS.md): closed-form elastica
//!   (with the branch fix) vs RK4 shooting agree to 1.6e-12 L on 60 random rods (spec: 1e-9 L);
//!   FK at the default 32 RK4 steps is 2.8e-8 m, 4.3e-6 deg and 1.1e-5 N from the 4096-step
//!   reference (error ~ steps^-4; spec 6.2 tolerances 1e-7 m, 1e-5 deg, 1e-4 N, met on all seven
//!   reference rows); the stability test gives the Euler loads 20.165 / 20.184 (clamped-pinned) and
//!   2.4671 / 2.4673 (clamped-free) at M = 40 / 80 (margin error ~ M^-2, 0.2 % at M = 40);
//!   actuator forces equal the derivative of the potential energy to 3.5e-10 relative; the
//!   symmetric design keeps theta_EE = 0 to 5e-14 deg; the design-1 sweeps reproduce the spec's
//!   node counts, union areas, folded cells and maximum angles (717 vs ~705 nodes, 0.2333 m^2,
//!   35 cells, 3.18 deg); the assembly-mode search finds the spec's 4 solutions (2 stable) of
//!   design 1 at (-0.22, 0.2425) with N_grid 6 / Tol 0.45 and all 10 (5 stable) with the 3-rod
//!   default N_grid 9 / Tol 0.5, stable poses to 1e-6 m.
//! * Adaptive vs fixed continuation from home (benches/RESULTS.md, issue 17): on the spec 9 FK
//!   request (d1, F = (0, -50) N, no stability) the adaptive path takes 9 steps, 38 Newton and
//!   chord iterations and 57 rod-system evaluations against the fixed path's 20 / 40 / 61, about
//!   half the compute (0.45 vs 0.90 ms median of `run()` on the loaded 2-core machine), and the
//!   same pose (1e-16 m apart, 1.6e-9 m from the 4096-step reference for both). Over 300 random
//!   targets in design 1's stable workspace (loads up to 20 N) both land on the same
//!   equilibrium: platform positions 9.5e-12 m apart at worst (criterion 1e-9 L_ref), angles
//!   1.9e-10 rad, scaled unknowns 5.8e-10, rod forces 6.1e-9 N (both end solves stop at
//!   `||g||_inf < 1e-10`, which bounds how closely they can agree); 6.1 steps on average (max 9)
//!   instead of 16.0 (max 26). Where the adaptive walk stalls (the symmetric preset's straight
//!   rods make the Jacobian singular at home; design 1's far row (0.05, 0.0725)) the fixed steps
//!   are walked from the same start and the answer says so (`continuation_fallback`), so an
//!   adaptive request never fails where the fixed one arrives. The six spec 6.2 FK rows meet their tolerances on both paths
//!   (tests/it/paper_continuum_workspace.rs).
//! * Outside the range: nodes/solves that do not converge are reported (`no_convergence`,
//!   `taut_rod i`), straight rods of over-constrained designs give `singular` (forces indeterminate:
//!   not returned; enable `axial_extensibility`), unstable equilibria are flagged and stop the wave.
//!   The assembly-mode list is never certified complete (`complete: false`). The maximum parasitic
//!   angle of a sweep sits on the workspace boundary and does not converge with grid refinement
//!   unless a physical limit (stress, stroke, gap) defines the boundary.

pub mod area;
pub mod closed_form;
pub mod compute;
pub mod error;
pub mod fk;
pub mod input;
pub mod model;
pub mod modes;
pub mod newton;
pub mod presets;
pub mod rod;
pub mod stability;
pub mod sweep;
pub mod wire;

use std::collections::BTreeMap;
use std::time::Duration;

pub use error::ContinuumError;
pub use input::Input;
pub use wire::{ContinuumWorkspaceRequest, ContinuumWorkspaceResponse};

use self::compute::{FkOutput, ModesOutput, Output, WaveOutput, WorkspaceOutput};
use self::presets::Preset;
use self::sweep::NodeStatus;
use self::wire::{
    ActuatorRequest, AssemblyModeOut, AssemblyModesResponse, DiagnosticsOut, FkResponse, GridOut,
    MetricsOut, Mode, ModeSearchOut, NodesOut, PlatformOut, PresetName, PresetOut, RodOut,
    RodRequest, SeedOut, SolverState, StabilityOut, WaveOut, WorkspaceResponse,
};
use crate::calc::CalcFailure;
use crate::calc::common::ResponseSize;
use crate::numerics::angles::wrap_pi;
use crate::numerics::{Budget, SolverReport, StopReason};

/// Validate, compute and build the wire response (called on the blocking pool).
pub fn run(
    req: ContinuumWorkspaceRequest,
    budget: &Budget,
) -> Result<ContinuumWorkspaceResponse, CalcFailure> {
    let input = Input::try_from(&req)?;
    response_size(&input).check(budget)?;
    let budget = match input.time_limit {
        Some(t) => budget.clone().capped(t),
        None => budget.clone(),
    };
    let out = compute::compute(&input, &budget)?;
    Ok(respond(&input, out, &budget))
}

/// Bytes of one node in `nodes` at most: a status code and 8 numbers (or nulls).
const NODE_BYTES: u64 = 24 + 8 * 25;

/// Upper estimate of the answer's size from the validated request (checked before computing):
/// fixed fields, the rod shapes of `fk` (rods × `rod_shape_points` × 4 numbers), and for
/// `workspace` the grid axes and, with `return_nodes`, one node record per grid node and wave.
/// The number of waves of seed `all_stable_modes` is known only after the assembly-mode search;
/// the estimate counts one (the encoded answer is still checked against the limit).
#[must_use]
pub fn response_size(input: &Input) -> ResponseSize {
    let rods = input.model.design.rods.len() as u64;
    let mut size = ResponseSize::fixed(16 * 1024 + rods * 1024);
    if input.mode == Mode::Fk && input.shape_points > 0 {
        size = size.numbers(
            "/outputs/rod_shape_points",
            rods * 4 * input.shape_points as u64,
        );
    }
    if let (Mode::Workspace, Some(sw)) = (input.mode, &input.sweep) {
        let [n1, n2] = sw.settings.grid.map(|n| n as u64);
        size = size.numbers("/workspace/grid", n1 + n2);
        if sw.return_nodes {
            size = size.bytes("/workspace/grid", n1 * n2 * NODE_BYTES);
        }
    }
    size
}

/// The request's own time limit (`time_limit_ms`, capped at the service maximum).
#[must_use]
pub fn time_limit(req: &ContinuumWorkspaceRequest) -> Option<Duration> {
    req.time_limit_ms
        .map(|ms| Duration::from_millis(ms.clamp(1, input::MAX_TIME_LIMIT_MS)))
}

fn wire_preset(p: Preset) -> PresetName {
    match p {
        Preset::KeopsD1 => PresetName::KeopsD1,
        Preset::KeopsD2 => PresetName::KeopsD2,
        Preset::KeopsD3 => PresetName::KeopsD3,
        Preset::KeopsD4 => PresetName::KeopsD4,
        Preset::KeopsD1OptA => PresetName::KeopsD1OptA,
        Preset::Symmetric => PresetName::Symmetric,
    }
}

fn preset_out(input: &Input) -> Option<PresetOut> {
    let p = input.preset?;
    let d = p.design();
    Some(PresetOut {
        name: wire_preset(p),
        assumed_geometry: true,
        description: p.description(),
        actuators: d
            .actuators
            .iter()
            .map(|a| ActuatorRequest {
                origin_m: a.origin,
                direction: a.dir,
                stroke_m: a.stroke,
            })
            .collect(),
        rods: d
            .rods
            .iter()
            .map(|r| RodRequest {
                actuator: r.actuator,
                offset_m: Some(r.offset),
                clamp_angle_deg: r.clamp.to_degrees(),
                length_m: r.length,
                diameter_m: r.diameter,
                ei_nm2: None,
                youngs_modulus_pa: Some(2.1e11),
                attach_m: r.attach,
            })
            .collect(),
        home_inputs_m: d.home,
    })
}

fn report(stop: StopReason, iterations: u64, evaluations: u64, budget: &Budget) -> SolverReport {
    SolverReport {
        stop_reason: stop,
        iterations,
        evaluations,
        elapsed_ms: budget.elapsed_ms(),
    }
}

fn u64_of(x: usize) -> u64 {
    u64::try_from(x).unwrap_or(u64::MAX)
}

fn platform(pos: [f64; 2], angle: f64) -> PlatformOut {
    PlatformOut {
        position_m: pos,
        parasitic_angle_deg: wrap_deg(angle),
    }
}

/// Wrap an angle [rad] to (-180, 180] deg.
fn wrap_deg(t: f64) -> f64 {
    let d = wrap_pi(t).to_degrees();
    if d <= -180.0 { d + 360.0 } else { d }
}

fn respond(input: &Input, out: Output, budget: &Budget) -> ContinuumWorkspaceResponse {
    match out {
        Output::Fk(f) => ContinuumWorkspaceResponse::Fk(Box::new(fk_response(input, *f, budget))),
        Output::Workspace(w) => {
            ContinuumWorkspaceResponse::Workspace(Box::new(workspace_response(input, *w, budget)))
        }
        Output::Modes(m) => {
            ContinuumWorkspaceResponse::AssemblyModes(Box::new(modes_response(input, *m, budget)))
        }
    }
}

fn fk_response(input: &Input, f: FkOutput, budget: &Budget) -> FkResponse {
    let model = &input.model;
    let determinate = f.status == wire::FkStatus::Ok;
    let (platform_out, rods, actuator_forces, stability, state, steps_used) = match &f.solution {
        Some((sol, d)) => {
            let rods = (0..model.n_rods())
                .map(|i| RodOut {
                    tip_force_n: determinate.then_some(d.forces[i]),
                    base_moment_nm: d.base_moments[i],
                    max_bending_stress_pa: d.stresses[i],
                    elastic_energy_j: d.energies[i],
                    shape: d.shapes.as_ref().map(|s| s[i].clone()),
                })
                .collect();
            let stability = f.segments.map(|m| StabilityOut {
                stable: d.margin.is_some_and(|x| x > fk::STABLE_MARGIN),
                margin: d.margin,
                det_sign: d.det_sign,
                segments: u32::try_from(m).unwrap_or(u32::MAX),
            });
            (
                Some(platform(d.position, d.angle)),
                Some(rods),
                determinate.then(|| d.actuator_forces.clone()),
                stability,
                Some(SolverState { v: sol.v.clone() }),
                sol.steps.iter().map(|&s| u64_of(s)).collect(),
            )
        }
        None => (None, None, None, None, None, Vec::new()),
    };
    FkResponse {
        mode: Mode::Fk,
        status: f.status,
        platform: platform_out,
        rods,
        actuator_forces_n: actuator_forces,
        stability,
        diagnostics: DiagnosticsOut {
            newton_iterations: u64_of(f.newton_iterations),
            residual_inf: f.residual_inf,
            jacobian_condition: f.cond,
            continuation_steps: u64_of(f.continuation_steps),
            continuation: f.continuation.map(|s| match s {
                newton::Stepping::Adaptive => wire::ContinuationKind::Adaptive,
                newton::Stepping::Fixed => wire::ContinuationKind::Fixed,
            }),
            rk4_steps: u32::try_from(model.base_steps).unwrap_or(u32::MAX),
            rk4_steps_used: steps_used,
            warnings: f.warnings,
        },
        solver_state: state,
        preset: preset_out(input),
        report: report(f.stop, u64_of(f.total_iterations), f.evaluations, budget),
    }
}

fn wave_out(input: &Input, w: &WaveOutput, return_nodes: bool) -> WaveOut {
    let status = &w.wave.status;
    let mut failures: BTreeMap<String, u64> = BTreeMap::new();
    for st in status {
        if *st != NodeStatus::Ok {
            *failures.entry(st.code().to_string()).or_insert(0) += 1;
        }
    }
    let full = input
        .sweep
        .as_ref()
        .is_some_and(|s| s.settings.stability == sweep::StabilityCheck::Full);
    let nodes = return_nodes.then(|| {
        let nd = &w.wave.nodes;
        NodesOut {
            status: status.iter().map(|s| s.code()).collect(),
            px_m: nd
                .iter()
                .map(|d| d.as_ref().map(|d| d.position[0]))
                .collect(),
            py_m: nd
                .iter()
                .map(|d| d.as_ref().map(|d| d.position[1]))
                .collect(),
            parasitic_angle_deg: nd
                .iter()
                .map(|d| d.as_ref().map(|d| d.angle.to_degrees()))
                .collect(),
            stability_margin: full.then(|| {
                nd.iter()
                    .map(|d| d.as_ref().and_then(|d| d.margin))
                    .collect()
            }),
            max_stress_pa: nd
                .iter()
                .map(|d| d.as_ref().and_then(|d| d.max_stress))
                .collect(),
            actuator_forces_n: nd
                .iter()
                .map(|d| {
                    d.as_ref().map(|d| {
                        [
                            d.actuator_forces[0],
                            d.actuator_forces.get(1).copied().unwrap_or(0.0),
                        ]
                    })
                })
                .collect(),
        }
    });
    let m = &w.metrics;
    WaveOut {
        seed: SeedOut {
            kind: w.seed_kind,
            node: [u64_of(w.seed_node.0), u64_of(w.seed_node.1)],
            inputs_m: w.seed_inputs,
            status: w.seed_status.code(),
            assembly_mode_index: w.seed_mode_index.map(u64_of),
            platform: w.seed_pose.map(|(p, a)| platform(p, a)),
        },
        nodes,
        metrics: MetricsOut {
            n_accepted: u64_of(m.n_accepted),
            n_cells: u64_of(m.n_cells),
            area_union_m2: m.area_union,
            area_sum_m2: m.area_sum,
            folded_cells: u64_of(m.folded_cells),
            quasi_translational_area_m2: m.qt_area,
            max_abs_parasitic_deg: m.max_abs_angle.to_degrees(),
            mean_abs_parasitic_deg: m.mean_abs_angle.to_degrees(),
            max_bending_stress_pa: m.max_stress,
        },
        failures,
    }
}

fn workspace_response(input: &Input, w: WorkspaceOutput, budget: &Budget) -> WorkspaceResponse {
    let (grid, return_nodes) = match &input.sweep {
        Some(sw) => {
            let s = &sw.settings;
            (
                GridOut {
                    lambda1_m: (0..s.grid[0])
                        .map(|i| sweep::lambda_at(s, i, 0)[0])
                        .collect(),
                    lambda2_m: (0..s.grid[1])
                        .map(|j| sweep::lambda_at(s, 0, j)[1])
                        .collect(),
                },
                sw.return_nodes,
            )
        }
        None => (
            GridOut {
                lambda1_m: Vec::new(),
                lambda2_m: Vec::new(),
            },
            false,
        ),
    };
    let mut waves: Vec<WaveOut> = w
        .waves
        .iter()
        .map(|x| wave_out(input, x, return_nodes))
        .collect();
    let first = if waves.is_empty() {
        WaveOut {
            seed: SeedOut {
                kind: wire::SeedKind::Home,
                node: [0, 0],
                inputs_m: [0.0, 0.0],
                status: NodeStatus::Unvisited.code(),
                assembly_mode_index: None,
                platform: None,
            },
            nodes: None,
            metrics: MetricsOut {
                n_accepted: 0,
                n_cells: 0,
                area_union_m2: None,
                area_sum_m2: 0.0,
                folded_cells: 0,
                quasi_translational_area_m2: 0.0,
                max_abs_parasitic_deg: 0.0,
                mean_abs_parasitic_deg: 0.0,
                max_bending_stress_pa: None,
            },
            failures: BTreeMap::new(),
        }
    } else {
        waves.remove(0)
    };
    WorkspaceResponse {
        mode: Mode::Workspace,
        grid,
        wave: first,
        other_waves: (!waves.is_empty()).then_some(waves),
        timing_ms: budget.elapsed_ms(),
        warnings: w.warnings,
        preset: preset_out(input),
        report: report(w.stop, w.attempts, w.evaluations, budget),
    }
}

fn modes_response(input: &Input, m: ModesOutput, budget: &Budget) -> AssemblyModesResponse {
    let model = &input.model;
    let solutions = m
        .result
        .solutions
        .iter()
        .map(|s| {
            let v = &s.solution.v;
            let pose = platform(model.position(v), model.angle(v));
            AssemblyModeOut {
                parasitic_angle_deg: pose.parasitic_angle_deg,
                pose,
                stable: s.stable,
                margin: s.margin,
                det_sign: s.solution.lu.det_sign(),
                rod_forces: s.solution.eval.forces.clone(),
                solver_state: SolverState { v: v.clone() },
            }
        })
        .collect();
    AssemblyModesResponse {
        mode: Mode::AssemblyModes,
        solutions,
        candidates: m.result.candidates,
        refined: m.result.refined,
        combinations: m.result.combinations,
        search: ModeSearchOut {
            n_grid: u64_of(input.modes.n_grid),
            tol: input.modes.tol,
            cell: u64_of(input.modes.cell),
            max_refine: u64_of(input.modes.max_refine),
        },
        complete: false,
        note: "Non-certified: a grid over the closed-form rod shapes (buckling mode 1, |k| <= 0.999) refined by Newton \
               can miss equilibria; raise n_grid/tol/max_refine to search wider."
            .to_string(),
        warnings: m.warnings,
        preset: preset_out(input),
        report: report(m.result.stop, m.result.refined, m.evaluations, budget),
    }
}
