//! The three computations (FK, workspace sweep, assembly-mode search) on the validated input.

use super::area::{self, Quad};
use super::error::ContinuumError;
use super::fk::{self, Described, HOME_REL_TOL, Home};
use super::input::{Input, Mode, SeedInput, SeedKind, Start, SweepInput};
use super::model::{Model, Params};
use super::modes::{self, ModeResult, ModeSolution};
use super::newton::{self, Counter, Failed, NewtonFailure, Solution, Stepping};
use super::sweep::{self, NodeData, NodeStatus, WaveResult};
use crate::calc::common::Shard;
use crate::numerics::{Budget, StopReason};

/// Largest condition number of the scaled Jacobian for an FK answer with determinate rod forces
/// (the sweep default `cond_max` of spec 4.7; straight over-constrained states reach 1e16-1e18).
pub const FK_COND_MAX: f64 = 1e12;

/// Outcome of an FK solve (wire form in output.rs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FkStatus {
    /// Converged and well conditioned.
    Ok,
    /// Newton did not converge (no pose).
    NoConvergence,
    /// Converged, but the Jacobian is singular (rod forces indeterminate).
    Singular,
}

/// FK result.
#[derive(Debug, Clone)]
pub struct FkOutput {
    /// Status.
    pub status: FkStatus,
    /// Solution and its description (converged only).
    pub solution: Option<(Solution, Described)>,
    /// `||g||_inf` at the returned (or last) point.
    pub residual_inf: f64,
    /// Condition number of the scaled Jacobian (converged only; else the cap).
    pub cond: f64,
    /// Newton iterations of the final solve.
    pub newton_iterations: usize,
    /// Newton iterations over all solves (continuation steps included).
    pub total_iterations: usize,
    /// Continuation steps.
    pub continuation_steps: usize,
    /// Step control of the continuation walked from home (None: no continuation from home).
    pub continuation: Option<Stepping>,
    /// Stability segments used (when the test ran).
    pub segments: Option<usize>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Residual evaluations.
    pub evaluations: u64,
    /// How the solver stopped.
    pub stop: StopReason,
}

/// One wave of a sweep with its metrics.
#[derive(Debug, Clone)]
pub struct WaveOutput {
    /// Seed node.
    pub seed_node: (usize, usize),
    /// Seed inputs.
    pub seed_inputs: [f64; 2],
    /// Seed status.
    pub seed_status: NodeStatus,
    /// Assembly-mode index of the seed.
    pub seed_mode_index: Option<usize>,
    /// Seed pose (position, angle) when solved.
    pub seed_pose: Option<([f64; 2], f64)>,
    /// The wave.
    pub wave: WaveResult,
    /// Metrics.
    pub metrics: Metrics,
}

/// Metrics of spec 4.8.
#[derive(Debug, Clone, Default)]
pub struct Metrics {
    /// Accepted nodes.
    pub n_accepted: usize,
    /// Cells with 4 accepted corners.
    pub n_cells: usize,
    /// Union area [m^2].
    pub area_union: Option<f64>,
    /// Sum of |cell areas| [m^2].
    pub area_sum: f64,
    /// Folded cells.
    pub folded_cells: usize,
    /// Quasi-translational area [m^2].
    pub qt_area: f64,
    /// Max |theta| \[rad\].
    pub max_abs_angle: f64,
    /// Mean |theta| \[rad\].
    pub mean_abs_angle: f64,
    /// Max stress \[Pa\].
    pub max_stress: Option<f64>,
}

/// Sweep result.
#[derive(Debug, Clone)]
pub struct WorkspaceOutput {
    /// One entry per wave run, in seed order: every wave, or with `input.shard` the waves of
    /// the shard's block (`Shard::range(n_waves)`).
    pub waves: Vec<WaveOutput>,
    /// Waves of the whole sweep (one per seed found at the seed node).
    pub n_waves: usize,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Evaluations.
    pub evaluations: u64,
    /// Node attempts.
    pub attempts: u64,
    /// How it stopped.
    pub stop: StopReason,
}

/// Mode-search result.
#[derive(Debug, Clone)]
pub struct ModesOutput {
    /// The search.
    pub result: ModeResult,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Evaluations.
    pub evaluations: u64,
}

/// Output per mode.
#[derive(Debug, Clone)]
pub enum Output {
    /// FK.
    Fk(Box<FkOutput>),
    /// Sweep.
    Workspace(Box<WorkspaceOutput>),
    /// Mode search.
    Modes(Box<ModesOutput>),
}

/// Run the computation.
pub fn compute(input: &Input, budget: &Budget) -> Result<Output, ContinuumError> {
    match input.mode {
        Mode::Fk => Ok(Output::Fk(Box::new(run_fk(input, budget)?))),
        Mode::Workspace => Ok(Output::Workspace(Box::new(run_workspace(input, budget)?))),
        Mode::AssemblyModes => {
            let mut counter = Counter::default();
            let result = modes::search(
                &input.model,
                &input.params,
                input.modes,
                input.newton,
                input.segments,
                budget,
                &mut counter,
            );
            Ok(Output::Modes(Box::new(ModesOutput {
                result,
                warnings: input.warnings.clone(),
                evaluations: counter.evaluations,
            })))
        }
    }
}

/// The stress-free home, if the design has one.
#[must_use]
pub fn resolve_home(model: &Model) -> Option<Home> {
    let fit = fk::home_fit(model, model.design.home.as_deref());
    (fit.residual <= HOME_REL_TOL * model.l_ref).then_some(fit)
}

/// A start that came from the mode search: solution plus which mode.
struct FromModes {
    solution: Solution,
    index: usize,
}

/// Spec 4.3 rule 2 fallback: the stable solution with the smallest |theta_EE|.
fn smallest_angle_stable(model: &Model, res: &ModeResult) -> Option<FromModes> {
    res.solutions
        .iter()
        .enumerate()
        .filter(|(_, s)| s.stable)
        .min_by(|a, b| {
            model
                .angle(&a.1.solution.v)
                .abs()
                .total_cmp(&model.angle(&b.1.solution.v).abs())
        })
        .map(|(index, s)| FromModes {
            solution: s.solution.clone(),
            index,
        })
}

fn stop_of(f: &Failed) -> StopReason {
    match f.reason {
        NewtonFailure::Budget(s) => s,
        NewtonFailure::MaxIterations => StopReason::MaxIterations,
        NewtonFailure::LineSearch | NewtonFailure::NonFinite | NewtonFailure::Stall => {
            StopReason::Stall
        }
    }
}

fn run_fk(input: &Input, budget: &Budget) -> Result<FkOutput, ContinuumError> {
    let model = &input.model;
    let target = &input.params;
    let mut counter = Counter::default();
    let mut warnings = input.warnings.clone();
    let mut walk = Walk::default();
    let result = fk_start(input, budget, &mut counter, &mut warnings, &mut walk)?;
    match result {
        Err(f) => {
            if input.start == Start::Home
                && f.progress > 0.0
                && !matches!(f.reason, NewtonFailure::Budget(_))
            {
                warnings.push(format!(
                    "continuation_stalled: the path from home was followed for {:.1} % of the way; beyond lies a fold (snap-through), taut rods or no equilibrium on this branch",
                    100.0 * f.progress
                ));
            }
            for i in fk::taut_rods(model, target, &f.v) {
                warnings.push(format!(
                    "taut_rod {i}: chord/L > {} in the last iterate",
                    fk::TAUT_CHORD
                ));
            }
            Ok(FkOutput {
                status: FkStatus::NoConvergence,
                solution: None,
                residual_inf: if f.residual_inf.is_finite() {
                    f.residual_inf
                } else {
                    f64::MAX
                },
                cond: crate::numerics::dense::COND_CAP,
                newton_iterations: f.iterations,
                total_iterations: walk.total_iterations.max(f.iterations),
                continuation_steps: walk.continuation_steps,
                continuation: walk.continuation,
                segments: None,
                warnings,
                evaluations: counter.evaluations,
                stop: stop_of(&f),
            })
        }
        Ok(sol) => {
            let cond = fk::condition(model, &sol);
            let segments = input.stability.then_some(input.segments);
            let described = fk::describe(model, &sol, input.shape_points, segments);
            let status = if cond > FK_COND_MAX {
                warnings.push(format!(
                    "indeterminate_rod_forces: the Jacobian is singular (condition {cond:.2e}); the pose is returned but the rod forces are not{}",
                    if model.n_rods() >= 4 && !model.extensible {
                        " (straight rods of an over-constrained design: enable solver.axial_extensibility)"
                    } else {
                        ""
                    }
                ));
                FkStatus::Singular
            } else {
                FkStatus::Ok
            };
            if let Some(lim) = model.design.sigma_allow {
                for (i, s) in described.stresses.iter().enumerate() {
                    if let Some(s) = s.filter(|s| *s > lim) {
                        warnings.push(format!(
                            "stress_above_allowable {i}: {s:.4e} Pa > sigma_allow {lim:.4e} Pa"
                        ));
                    }
                }
            }
            if described.margin.is_some_and(|m| m <= fk::STABLE_MARGIN) {
                warnings.push(
                    "unstable: the equilibrium found is unstable (stability margin <= 0)"
                        .to_string(),
                );
            }
            Ok(FkOutput {
                status,
                residual_inf: sol.eval.norm_inf(),
                cond,
                newton_iterations: sol.iterations,
                total_iterations: walk.total_iterations.max(sol.iterations),
                continuation_steps: walk.continuation_steps,
                continuation: walk.continuation,
                segments,
                solution: Some((sol, described)),
                warnings,
                evaluations: counter.evaluations,
                stop: StopReason::Converged,
            })
        }
    }
}

/// Continuation statistics of an FK solve.
#[derive(Debug, Default)]
struct Walk {
    /// Continuation steps taken from home.
    continuation_steps: usize,
    /// Step control of the continuation walked from home (None: no continuation from home).
    continuation: Option<Stepping>,
    /// Newton iterations over all solves so far.
    total_iterations: usize,
}

/// The FK solve from the requested start (spec 4.3): Newton from a guess, assembly mode `index`
/// of a search, or continuation from the stress-free home (without one: the stable mode with
/// the smallest |theta_EE|). The inner result is the solve's; the outer error a missing mode.
fn fk_start(
    input: &Input,
    budget: &Budget,
    counter: &mut Counter,
    warnings: &mut Vec<String>,
    walk: &mut Walk,
) -> Result<Result<Solution, Failed>, ContinuumError> {
    let model = &input.model;
    let target = &input.params;
    let result = match &input.start {
        Start::Guess(v) => {
            newton::solve(model, target, v, input.newton, budget, counter).inspect(|s| {
                walk.total_iterations = s.iterations;
            })
        }
        Start::AssemblyMode(index) => {
            let res = modes::search(
                model,
                target,
                input.modes,
                input.newton,
                input.segments,
                budget,
                counter,
            );
            warnings.push(format!(
                "assembly_mode_search: non-certified grid search found {} solution(s) ({} stable)",
                res.solutions.len(),
                res.solutions.iter().filter(|s| s.stable).count()
            ));
            match res.solutions.get(*index) {
                Some(ModeSolution { solution, .. }) => Ok(solution.clone()),
                None => {
                    return Err(ContinuumError::AssemblyModeNotFound {
                        index: *index,
                        found: res.solutions.len(),
                        pointer: "/start/index",
                    });
                }
            }
        }
        Start::Home => match resolve_home(model) {
            Some(home) => {
                let k = input
                    .continuation_steps
                    .unwrap_or_else(|| fk::continuation_steps(model, &home.lambda, &target.lambda));
                walk.continuation = Some(input.stepping);
                fk::from_home(
                    model,
                    &home,
                    target,
                    k,
                    input.stepping,
                    input.newton,
                    budget,
                    counter,
                )
                .map(|r| {
                    walk.continuation_steps = r.steps;
                    walk.total_iterations = r.newton_iterations;
                    walk.continuation = Some(r.walked);
                    if let Some(at) = r.fell_back_at {
                        warnings.push(format!(
                            "continuation_fallback: the adaptive path from home stalled at {:.1} % of the way; the spec's {k} equal steps were walked instead",
                            100.0 * at
                        ));
                    }
                    r.solution
                })
            }
            None => {
                let res = modes::search(
                    model,
                    target,
                    input.home_fallback_modes,
                    input.newton,
                    input.segments,
                    budget,
                    counter,
                );
                match smallest_angle_stable(model, &res) {
                    Some(f) => {
                        warnings.push(format!(
                            "no_stress_free_home: started from assembly mode {} (the stable solution with the smallest |theta_EE| of a non-certified search with N_grid {}, Tol {}, spec 4.3)",
                            f.index,
                            input.home_fallback_modes.n_grid,
                            input.home_fallback_modes.tol
                        ));
                        Ok(f.solution)
                    }
                    None => {
                        warnings.push(
                            "no_stress_free_home: the design has no stress-free home and the assembly-mode search found no stable solution"
                                .to_string(),
                        );
                        Err(Failed {
                            reason: match res.stop {
                                StopReason::Deadline | StopReason::MaxEvaluations => {
                                    NewtonFailure::Budget(res.stop)
                                }
                                _ => NewtonFailure::LineSearch,
                            },
                            v: model.home_state([0.0, 0.0]),
                            residual_inf: f64::INFINITY,
                            iterations: 0,
                            progress: 0.0,
                        })
                    }
                }
            }
        },
    };
    Ok(result)
}

/// Seed candidates of the sweep: (kind, mode index, solution or failure status).
type SeedResult = (Option<usize>, Result<Solution, NodeStatus>);

fn nearest_node(s: &sweep::SweepSettings, x: [f64; 2]) -> (usize, usize) {
    let pick = |k: usize| {
        let n = s.grid[k];
        let r = s.ranges[k];
        let t = ((x[k] - r[0]) / (r[1] - r[0]) * (n - 1) as f64).round();
        if t.is_finite() {
            t.clamp(0.0, (n - 1) as f64) as usize
        } else {
            0
        }
    };
    (pick(0), pick(1))
}

/// The workspace sweep (spec 4.7): the seeds at the seed node, then one wave per seed, in
/// seed order; with `input.shard` only the waves of the shard's block run (the seeds are found
/// in every shard: they say how many waves there are and where each starts).
fn run_workspace(input: &Input, budget: &Budget) -> Result<WorkspaceOutput, ContinuumError> {
    let model = &input.model;
    let Some(sw) = &input.sweep else {
        return Ok(WorkspaceOutput {
            waves: Vec::new(),
            n_waves: 0,
            warnings: input.warnings.clone(),
            evaluations: 0,
            attempts: 0,
            stop: StopReason::Completed,
        });
    };
    let s = &sw.settings;
    let mut warnings = input.warnings.clone();
    let mut counter = Counter::default();
    let home = resolve_home(model);
    let SeedInput { inputs, .. } = &sw.seed;
    let seed_x = inputs.unwrap_or_else(|| match &home {
        Some(h) => [h.lambda[0], h.lambda[1]],
        None => [
            0.5 * (s.ranges[0][0] + s.ranges[0][1]),
            0.5 * (s.ranges[1][0] + s.ranges[1][1]),
        ],
    });
    let node = nearest_node(s, seed_x);
    let lam0 = sweep::lambda_at(s, node.0, node.1);
    let params0 = Params {
        lambda: lam0.to_vec(),
        force: input.params.force,
        moment: input.params.moment,
    };
    let seeds = workspace_seeds(
        input,
        &sw.seed,
        home.as_ref(),
        (lam0, &params0),
        budget,
        &mut counter,
        &mut warnings,
    )?;
    let n_waves = seeds.len();
    let mine = input.shard.unwrap_or(Shard::WHOLE).range(n_waves);
    let mut waves = Vec::with_capacity(mine.len());
    let mut evaluations = counter.evaluations;
    let mut attempts = 0u64;
    let mut stop = StopReason::Completed;
    for (mode_index, seed) in seeds.into_iter().skip(mine.start).take(mine.len()) {
        let w = seed_wave(input, sw, (node, lam0), (mode_index, seed), budget);
        evaluations += w.wave.evaluations;
        attempts += w.wave.attempts;
        if w.wave.stop != StopReason::Completed {
            stop = w.wave.stop;
        }
        waves.push(w);
    }
    if budget.expired() && stop == StopReason::Completed {
        stop = StopReason::Deadline;
    }
    if stop == StopReason::Deadline || stop == StopReason::MaxEvaluations {
        warnings.push(
            "budget_exhausted: the sweep stopped early; unvisited nodes were not attempted"
                .to_string(),
        );
    }
    Ok(WorkspaceOutput {
        waves,
        n_waves,
        warnings,
        evaluations,
        attempts,
        stop,
    })
}

/// One wave from its seed at the seed node `(node, lam0)`: an accepted seed (input limits,
/// conditioning, stability) spreads the wave over the grid; otherwise the wave is the seed
/// node alone, with the reason it failed. Depends on nothing but the input and its seed, so
/// every wave is the same in a shard as in the whole sweep.
fn seed_wave(
    input: &Input,
    sw: &SweepInput,
    (node, lam0): ((usize, usize), [f64; 2]),
    (mode_index, seed): SeedResult,
    budget: &Budget,
) -> WaveOutput {
    let model = &input.model;
    let s = &sw.settings;
    let n = s.grid[0] * s.grid[1];
    let seed_pose = seed
        .as_ref()
        .ok()
        .map(|sol| (model.position(&sol.v), model.angle(&sol.v)));
    let accepted: Result<NodeData, NodeStatus> = seed.and_then(|sol| {
        if let Some(st) = sweep::input_limits(model, s, &lam0) {
            return Err(st);
        }
        sweep::accept(model, s, &lam0, &sol, None)
    });
    let (seed_status, wave) = match accepted {
        Ok(d) => {
            let w = sweep::wave(model, &input.params, s, node, d, input.newton, budget);
            (NodeStatus::Ok, w)
        }
        Err(st) => {
            let mut status = vec![NodeStatus::Unvisited; n];
            status[node.0 * s.grid[1] + node.1] = st;
            let stop = if budget.expired() {
                StopReason::Deadline
            } else {
                StopReason::Completed
            };
            (
                st,
                WaveResult {
                    status,
                    nodes: vec![None; n],
                    stop,
                    attempts: 0,
                    evaluations: 0,
                },
            )
        }
    };
    let metrics = metrics(model, s.grid, &wave, sw.qt_threshold, sw.union);
    WaveOutput {
        seed_node: node,
        seed_inputs: lam0,
        seed_status,
        seed_mode_index: mode_index,
        seed_pose,
        wave,
        metrics,
    }
}

/// The seeds of the sweep's waves at the seed node (spec 4.7), by seed kind: continuation from
/// home (without a home: the stable assembly mode with the smallest |theta_EE|), Newton from a
/// given state, one assembly mode, or every stable assembly mode (one wave each).
fn workspace_seeds(
    input: &Input,
    seed: &SeedInput,
    home: Option<&Home>,
    (lam0, p0): ([f64; 2], &Params),
    budget: &Budget,
    counter: &mut Counter,
    warnings: &mut Vec<String>,
) -> Result<Vec<SeedResult>, ContinuumError> {
    let model = &input.model;
    let SeedInput {
        kind, state, index, ..
    } = seed;
    let fail = |f: Failed| match f.reason {
        NewtonFailure::Budget(_) => NodeStatus::Unvisited,
        _ => NodeStatus::NoConvergence,
    };
    let mut seeds: Vec<SeedResult> = Vec::new();
    let search = |counter: &mut Counter, settings: modes::ModeSearch| {
        modes::search(
            model,
            p0,
            settings,
            input.newton,
            input.segments,
            budget,
            counter,
        )
    };
    match kind {
        SeedKind::Home => {
            match home {
                Some(h) => {
                    let k = fk::continuation_steps(model, &h.lambda, &lam0);
                    let r = fk::from_home(
                        model,
                        h,
                        p0,
                        k,
                        input.stepping,
                        input.newton,
                        budget,
                        counter,
                    );
                    seeds.push((None, r.map(|r| r.solution).map_err(fail)));
                }
                None => {
                    let res = search(counter, input.home_fallback_modes);
                    match smallest_angle_stable(model, &res) {
                        Some(f) => {
                            warnings.push(format!(
                            "no_stress_free_home: the wave starts from assembly mode {} (stable, smallest |theta_EE|, non-certified search with N_grid {}, Tol {})",
                            f.index,
                            input.home_fallback_modes.n_grid,
                            input.home_fallback_modes.tol
                        ));
                            seeds.push((Some(f.index), Ok(f.solution)));
                        }
                        None => {
                            warnings.push("no_stress_free_home: no stable assembly mode found at the seed node".to_string());
                            seeds.push((None, Err(NodeStatus::Unstable)));
                        }
                    }
                }
            }
        }
        SeedKind::Guess => {
            let v0 = state
                .clone()
                .unwrap_or_else(|| model.home_state([0.0, 0.0]));
            let r = newton::solve(model, p0, &v0, input.newton, budget, counter);
            seeds.push((None, r.map_err(fail)));
        }
        SeedKind::AssemblyMode => {
            let res = search(counter, input.modes);
            match res.solutions.get(*index) {
                Some(m) => seeds.push((Some(*index), Ok(m.solution.clone()))),
                None => {
                    return Err(ContinuumError::AssemblyModeNotFound {
                        index: *index,
                        found: res.solutions.len(),
                        pointer: "/workspace/seed/index",
                    });
                }
            }
        }
        SeedKind::AllStableModes => {
            let res = search(counter, input.modes);
            for (i, m) in res.solutions.iter().enumerate().filter(|(_, m)| m.stable) {
                seeds.push((Some(i), Ok(m.solution.clone())));
            }
            if seeds.is_empty() {
                warnings.push(
                    "all_stable_modes: the non-certified search found no stable assembly mode"
                        .to_string(),
                );
                seeds.push((None, Err(NodeStatus::Unstable)));
            }
        }
    }
    Ok(seeds)
}

/// Metrics of one wave (spec 4.8).
#[must_use]
pub fn metrics(
    model: &Model,
    grid: [usize; 2],
    wave: &WaveResult,
    qt: f64,
    union: bool,
) -> Metrics {
    let (n1, n2) = (grid[0], grid[1]);
    let node = |i: usize, j: usize| wave.nodes[i * n2 + j].as_ref();
    let accepted: Vec<&NodeData> = wave.nodes.iter().flatten().collect();
    let mut m = Metrics {
        n_accepted: accepted.len(),
        ..Metrics::default()
    };
    if !accepted.is_empty() {
        m.max_abs_angle = accepted.iter().fold(0.0f64, |a, d| a.max(d.angle.abs()));
        m.mean_abs_angle =
            accepted.iter().map(|d| d.angle.abs()).sum::<f64>() / accepted.len() as f64;
        m.max_stress = accepted
            .iter()
            .try_fold(0.0f64, |a, d| d.max_stress.map(|s| a.max(s)));
    }
    let mut quads: Vec<Quad> = Vec::new();
    let mut signed: Vec<f64> = Vec::new();
    let mut qt_quads: Vec<Quad> = Vec::new();
    let mut qt_sum = 0.0;
    for i in 0..n1.saturating_sub(1) {
        for j in 0..n2.saturating_sub(1) {
            let (Some(a), Some(b), Some(c), Some(d)) = (
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ) else {
                continue;
            };
            let q: Quad = [a.position, b.position, c.position, d.position];
            let sa = area::signed_area(&q);
            if [a, b, c, d].iter().all(|x| x.angle.abs() < qt) {
                qt_quads.push(q);
                qt_sum += sa.abs();
            }
            quads.push(q);
            signed.push(sa);
        }
    }
    m.n_cells = quads.len();
    m.area_sum = signed.iter().map(|a| a.abs()).sum();
    let pos = signed.iter().filter(|a| **a > 0.0).count();
    let neg = signed.iter().filter(|a| **a < 0.0).count();
    m.folded_cells = pos.min(neg);
    if union {
        m.area_union = Some(area::union_area(&quads, model.l_ref));
        m.qt_area = area::union_area(&qt_quads, model.l_ref);
    } else {
        m.qt_area = qt_sum;
    }
    m
}
