//! The one place that builds the wire response of `POST /v1/continuum-workspace` from the
//! domain output (one shape per mode: FK, workspace sweep, assembly modes), and the estimate of
//! its size checked before computing.

use std::collections::BTreeMap;

use super::compute::{self, FkOutput, ModesOutput, Output, WaveOutput, WorkspaceOutput};
use super::fk;
use super::input::{self as domain, Input};
use super::newton;
use super::presets::Preset;
use super::sweep::{self, NodeStatus};
use super::wire::{
    self, ActuatorRequest, AssemblyModeOut, AssemblyModesResponse, ContinuumWorkspaceResponse,
    DiagnosticsOut, FkResponse, GridOut, MetricsOut, Mode, ModeSearchOut, NodesOut, PlatformOut,
    PresetName, PresetOut, RodOut, RodRequest, SeedOut, SolverState, StabilityOut, WaveOut,
    WorkspaceResponse, WorkspaceShardResponse,
};
use crate::calc::common::ResponseSize;
use crate::numerics::angles::wrap_pi;
use crate::numerics::{Budget, SolverReport, StopReason};

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
    if input.mode == domain::Mode::Fk && input.shape_points > 0 {
        size = size.numbers(
            "/outputs/rod_shape_points",
            rods * 4 * input.shape_points as u64,
        );
    }
    if let (domain::Mode::Workspace, Some(sw)) = (input.mode, &input.sweep) {
        let [n1, n2] = sw.settings.grid.map(|n| n as u64);
        size = size.numbers("/workspace/grid", n1 + n2);
        if sw.return_nodes {
            size = size.bytes("/workspace/grid", n1 * n2 * NODE_BYTES);
        }
    }
    size
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

/// Builds the response of the requested mode (report times from `budget`).
#[must_use]
pub fn respond(input: &Input, out: Output, budget: &Budget) -> ContinuumWorkspaceResponse {
    match out {
        Output::Fk(f) => ContinuumWorkspaceResponse::Fk(Box::new(fk_response(input, *f, budget))),
        Output::Workspace(w) => workspace_response(input, *w, budget),
        Output::Modes(m) => {
            ContinuumWorkspaceResponse::AssemblyModes(Box::new(modes_response(input, *m, budget)))
        }
    }
}

fn fk_response(input: &Input, f: FkOutput, budget: &Budget) -> FkResponse {
    let model = &input.model;
    let determinate = f.status == compute::FkStatus::Ok;
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
        status: fk_status(f.status),
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

fn fk_status(s: compute::FkStatus) -> wire::FkStatus {
    match s {
        compute::FkStatus::Ok => wire::FkStatus::Ok,
        compute::FkStatus::NoConvergence => wire::FkStatus::NoConvergence,
        compute::FkStatus::Singular => wire::FkStatus::Singular,
    }
}

fn wave_out(
    input: &Input,
    w: &WaveOutput,
    return_nodes: bool,
    seed_kind: wire::SeedKind,
) -> WaveOut {
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
            kind: seed_kind,
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

/// The answer of a sweep: unsharded, the first wave flattened at the top level and the others
/// in `other_waves`; with `shard`, the shard's waves as a list with the shard statement (the
/// merge rule is documented on `WorkspaceShardResponse::shard`).
fn workspace_response(
    input: &Input,
    w: WorkspaceOutput,
    budget: &Budget,
) -> ContinuumWorkspaceResponse {
    let (grid, return_nodes, seed_kind) = match &input.sweep {
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
                sw.seed.kind,
            )
        }
        // No sweep settings: the computation returns no wave.
        None => (
            GridOut {
                lambda1_m: Vec::new(),
                lambda2_m: Vec::new(),
            },
            false,
            wire::SeedKind::Home,
        ),
    };
    let mut waves: Vec<WaveOut> = w
        .waves
        .iter()
        .map(|x| wave_out(input, x, return_nodes, seed_kind))
        .collect();
    if let Some(shard) = input.shard {
        return ContinuumWorkspaceResponse::WorkspaceShard(Box::new(WorkspaceShardResponse {
            mode: Mode::Workspace,
            grid,
            waves,
            shard: shard.out(w.n_waves),
            timing_ms: budget.elapsed_ms(),
            warnings: w.warnings,
            preset: preset_out(input),
            report: report(w.stop, w.attempts, w.evaluations, budget),
        }));
    }
    let first = if waves.is_empty() {
        no_wave()
    } else {
        waves.remove(0)
    };
    ContinuumWorkspaceResponse::Workspace(Box::new(WorkspaceResponse {
        mode: Mode::Workspace,
        grid,
        wave: first,
        other_waves: (!waves.is_empty()).then_some(waves),
        timing_ms: budget.elapsed_ms(),
        warnings: w.warnings,
        preset: preset_out(input),
        report: report(w.stop, w.attempts, w.evaluations, budget),
    }))
}

/// The top-level wave of an answer without waves (no sweep settings).
fn no_wave() -> WaveOut {
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
