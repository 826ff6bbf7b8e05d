//! Workspace sweep by wave propagation (spec 4.7, paper Fig. 9).
//!
//! One wave per assembly mode: from a solved seed node, every accepted node tries its grid
//! neighbours in FIFO (breadth-first) order, marching from its own solution to the neighbour in
//! 1, 2, 4, ... `max_substeps` sub-steps with the tangent predictor, rejecting branch jumps, singular
//! or unstable solutions and limit violations; a neighbour may be retried from another accepted
//! node up to `max_tries` times.
//!
//! Parallel and deterministic: the FIFO queue is processed level by level (a node pushed while
//! level `l` is processed belongs to level `l + 1`). Within a level every attempt depends only on
//! its source node's solution and its target's inputs, so the attempts on different targets run
//! in parallel, while the attempts on one target are made in the sequential FIFO order (first
//! source first, the next only if the previous failed). The accepted set, statuses and solutions
//! are therefore identical to the sequential FIFO algorithm for any number of threads.

// Interpolation and predictor formulas in plain form; without a target FMA unit `mul_add` is a
// libm call per term.

use std::collections::BTreeMap;

use super::fk::{self, STABLE_MARGIN};
use super::model::{Model, Params};
use super::newton::{self, Counter, NewtonFailure, NewtonOptions, Solution};
use crate::numerics::dense;
use crate::numerics::{Budget, StopReason, par_map};

/// Sub-step solves give up when the residual has not halved over this many iterations: from the
/// tangent predictor Newton at least halves it every iteration or two, while creeping damped steps
/// mean the predictor left the basin (a smaller sub-step is tried next). On every reference sweep
/// of spec 6.2 a window of 10 accepts exactly the nodes the plain Newton accepts, at ~75 % of the
/// evaluations (a window of 6-8 lost 22 boundary nodes of the loaded optimised design).
pub const SUBSTEP_STALL_WINDOW: usize = 10;

/// Stability test applied to every node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StabilityCheck {
    /// The full test of spec 4.5 (margin > 1e-8).
    Full,
    /// Only `det J` keeps the sign of the parent node (proves instability when it flips).
    DetSign,
    /// No stability test.
    None,
}

/// Optional physical limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Minimum carriage gap \[m\] (see [`actuator_gap`]).
    pub min_gap: Option<f64>,
    /// Allowable bending stress \[Pa\].
    pub sigma_allow: Option<f64>,
    /// Reject nodes where two rods cross.
    pub rod_crossing: bool,
}

/// Sweep settings (spec 4.7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepSettings {
    /// Grid size `[n1, n2]`.
    pub grid: [usize; 2],
    /// Input ranges `[[min1, max1], [min2, max2]]` \[m\].
    pub ranges: [[f64; 2]; 2],
    /// Also try the 4 diagonal neighbours (after the 4 axis neighbours).
    pub diagonal_neighbours: bool,
    /// Tangent predictor on.
    pub predictor: bool,
    /// Largest number of sub-steps (1, 2, 4, ... up to this).
    pub max_substeps: usize,
    /// Attempts per node.
    pub max_tries: usize,
    /// Newton iterations per sub-step solve (capped by `solver.max_iter`): from the tangent
    /// predictor a sub-step converges in 2-7 iterations; a solve still wandering after this many is
    /// abandoned in favour of smaller sub-steps (on the design-1 reference sweep 20 accepts exactly
    /// the nodes an uncapped Newton accepts at a third of the cost).
    pub substep_max_iter: usize,
    /// Largest platform rotation within one sub-step \[rad\].
    pub angle_jump: f64,
    /// Largest platform displacement within one sub-step, as a multiple of the input change.
    pub position_factor: f64,
    /// Largest accepted 2-norm condition number of the scaled Jacobian.
    pub cond_max: f64,
    /// Stability test.
    pub stability: StabilityCheck,
    /// Segments per rod of the stability test.
    pub segments: usize,
    /// Physical limits.
    pub limits: Limits,
    /// Upper limit on worker threads; the job's budget ([`Budget::threads`]) decides within it
    /// (results do not depend on it).
    pub threads: usize,
}

impl SweepSettings {
    /// The settings of a `workspace` request that gives only the grid and the ranges (spec 4.7
    /// defaults): axis neighbours, predictor on, up to 8 sub-steps of at most 20 Newton iterations,
    /// 4 tries, jump limits 5 deg and 5x the input change, cond(J) <= 1e12, full stability test
    /// with 20 segments per rod, no physical limits, the budget's threads. The request parser takes its
    /// defaults from here.
    #[must_use]
    pub fn with_defaults(grid: [usize; 2], ranges: [[f64; 2]; 2]) -> Self {
        Self {
            grid,
            ranges,
            diagonal_neighbours: false,
            predictor: true,
            max_substeps: 8,
            max_tries: 4,
            substep_max_iter: 20,
            angle_jump: 5f64.to_radians(),
            position_factor: 5.0,
            cond_max: 1e12,
            stability: StabilityCheck::Full,
            segments: 20,
            limits: Limits {
                min_gap: None,
                sigma_allow: None,
                rod_crossing: false,
            },
            threads: usize::MAX,
        }
    }
}

/// Status of a grid node.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum NodeStatus {
    /// Never reached by the wave.
    Unvisited,
    /// Accepted.
    Ok,
    /// Newton failed on every sub-step schedule.
    NoConvergence,
    /// Platform jumped more than the jump limits within a sub-step.
    BranchJump,
    /// Jacobian condition above `cond_max` (or det J sign flip in det-sign mode).
    Singular,
    /// Stability margin <= 1e-8.
    Unstable,
    /// Input outside the actuator stroke.
    LimitStroke,
    /// Carriage gap below the limit.
    LimitActuatorGap,
    /// Bending stress above the limit.
    LimitStress,
    /// Two rods cross.
    LimitRodCrossing,
}

impl NodeStatus {
    /// Wire code.
    #[must_use]
    pub fn code(self) -> &'static str {
        match self {
            Self::Unvisited => "unvisited",
            Self::Ok => "ok",
            Self::NoConvergence => "no_convergence",
            Self::BranchJump => "branch_jump",
            Self::Singular => "singular",
            Self::Unstable => "unstable",
            Self::LimitStroke => "limit_stroke",
            Self::LimitActuatorGap => "limit_actuator_gap",
            Self::LimitStress => "limit_stress",
            Self::LimitRodCrossing => "limit_rod_crossing",
        }
    }
}

/// An accepted node.
#[derive(Debug, Clone)]
pub struct NodeData {
    /// Unknown vector.
    pub v: Vec<f64>,
    /// Tangent `dv/dlambda` (row-major `n x 2`).
    pub tangent: Vec<f64>,
    /// Sign of det J.
    pub det_sign: i8,
    /// Platform position \[m\].
    pub position: [f64; 2],
    /// Platform angle \[rad\] (continuous along the wave).
    pub angle: f64,
    /// Stability margin (full mode only).
    pub margin: Option<f64>,
    /// Largest rod bending stress \[Pa\] (None when a rod has no diameter).
    pub max_stress: Option<f64>,
    /// Actuator forces \[N\].
    pub actuator_forces: Vec<f64>,
    /// Jacobian condition number.
    pub cond: f64,
}

/// Result of one wave.
#[derive(Debug, Clone)]
pub struct WaveResult {
    /// Node statuses, row-major `n1 x n2` (index `i * n2 + j`, `i` over lambda1).
    pub status: Vec<NodeStatus>,
    /// Accepted node data.
    pub nodes: Vec<Option<NodeData>>,
    /// How the wave stopped.
    pub stop: StopReason,
    /// Node attempts made.
    pub attempts: u64,
    /// Residual evaluations.
    pub evaluations: u64,
}

/// Inputs of grid node `(i, j)`.
#[must_use]
pub fn lambda_at(s: &SweepSettings, i: usize, j: usize) -> [f64; 2] {
    let f = |k: usize, n: usize, r: [f64; 2]| {
        if n <= 1 {
            r[0]
        } else {
            r[0] + (r[1] - r[0]) * k as f64 / (n - 1) as f64
        }
    };
    [f(i, s.grid[0], s.ranges[0]), f(j, s.grid[1], s.ranges[1])]
}

/// Carriage gap: `min over rods i on actuator 1 and k on actuator 0 of (a_i - a_k) . d_0`, the
/// clear distance between the clamp points of the two carriages measured along guide 0 (for the
/// presets `lambda2 - (lambda1 + a/2)`, spec 6.2).
#[must_use]
pub fn actuator_gap(model: &Model, lambda: &[f64]) -> f64 {
    let d0 = model.design.actuators[0].dir;
    let mut gap = f64::INFINITY;
    for (i, ri) in model.design.rods.iter().enumerate() {
        if ri.actuator != 1 {
            continue;
        }
        let ai = model.base_point(i, lambda);
        for (k, rk) in model.design.rods.iter().enumerate() {
            if rk.actuator != 0 {
                continue;
            }
            let ak = model.base_point(k, lambda);
            gap = gap.min((ai[0] - ak[0]).mul_add(d0[0], (ai[1] - ak[1]) * d0[1]));
        }
    }
    gap
}

/// Limits that depend on the inputs only (checked before solving).
pub fn input_limits(model: &Model, s: &SweepSettings, lambda: &[f64; 2]) -> Option<NodeStatus> {
    for (j, a) in model.design.actuators.iter().enumerate() {
        if lambda[j] < a.stroke[0] || lambda[j] > a.stroke[1] {
            return Some(NodeStatus::LimitStroke);
        }
    }
    if let Some(g) = s.limits.min_gap
        && actuator_gap(model, lambda) < g
    {
        return Some(NodeStatus::LimitActuatorGap);
    }
    None
}

/// Tangent `-J^-1 dg/dlambda` (row-major `n x n_act`).
fn tangent(model: &Model, sol: &Solution) -> Vec<f64> {
    let n = model.n_unknowns();
    let na = model.n_act();
    let dgl = model.dg_dlambda(&sol.eval.forces);
    let mut t = vec![0.0; n * na];
    for j in 0..na {
        let col: Vec<f64> = (0..n).map(|r| dgl[r * na + j]).collect();
        let x = newton::tangent(sol, n, &col);
        for r in 0..n {
            t[r * na + j] = x[r];
        }
    }
    t
}

/// Whether two polylines properly cross.
fn polylines_cross(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    for sa in a.windows(2) {
        let (amin, amax) = (
            [sa[0][0].min(sa[1][0]), sa[0][1].min(sa[1][1])],
            [sa[0][0].max(sa[1][0]), sa[0][1].max(sa[1][1])],
        );
        for sb in b.windows(2) {
            if sb[0][0].max(sb[1][0]) < amin[0]
                || sb[0][0].min(sb[1][0]) > amax[0]
                || sb[0][1].max(sb[1][1]) < amin[1]
                || sb[0][1].min(sb[1][1]) > amax[1]
            {
                continue;
            }
            let o1 = orient(sa[0], sa[1], sb[0]);
            let o2 = orient(sa[0], sa[1], sb[1]);
            let o3 = orient(sb[0], sb[1], sa[0]);
            let o4 = orient(sb[0], sb[1], sa[1]);
            if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
                return true;
            }
        }
    }
    false
}

/// Acceptance tests on a converged node (spec 4.7): conditioning, stability, stress and crossing
/// limits. `parent_det` is the det J sign of the node it was reached from.
pub fn accept(
    model: &Model,
    s: &SweepSettings,
    lambda: &[f64; 2],
    sol: &Solution,
    parent_det: Option<i8>,
) -> Result<NodeData, NodeStatus> {
    let n = model.n_unknowns();
    let cond = dense::cond2(&sol.eval.jac, n);
    if cond.is_nan() || cond > s.cond_max {
        return Err(NodeStatus::Singular);
    }
    let det_sign = sol.lu.det_sign();
    if s.stability == StabilityCheck::DetSign
        && (det_sign == 0 || parent_det.is_some_and(|p| p != det_sign))
    {
        return Err(NodeStatus::Singular);
    }
    let margin = if s.stability == StabilityCheck::Full {
        let m = fk::margin_of(model, sol, s.segments);
        if !m.is_some_and(|m| m > STABLE_MARGIN) {
            return Err(NodeStatus::Unstable);
        }
        m
    } else {
        None
    };
    let d = fk::describe(model, sol, 0, None);
    let max_stress = d
        .stresses
        .iter()
        .try_fold(0.0f64, |m, s| s.map(|s| m.max(s)));
    if let (Some(lim), Some(st)) = (s.limits.sigma_allow, max_stress)
        && st > lim
    {
        return Err(NodeStatus::LimitStress);
    }
    if s.limits.rod_crossing {
        let lines: Vec<Vec<[f64; 2]>> = (0..model.n_rods())
            .map(|i| {
                let tr = model.trace(&sol.v, i, sol.steps[i]);
                let a = model.base_point(i, lambda);
                let l = model.design.rods[i].length;
                tr.nodes
                    .iter()
                    .map(|z| [l.mul_add(z[0], a[0]), l.mul_add(z[1], a[1])])
                    .collect()
            })
            .collect();
        for i in 0..lines.len() {
            for k in (i + 1)..lines.len() {
                if polylines_cross(&lines[i], &lines[k]) {
                    return Err(NodeStatus::LimitRodCrossing);
                }
            }
        }
    }
    Ok(NodeData {
        v: sol.v.clone(),
        tangent: tangent(model, sol),
        det_sign,
        position: d.position,
        angle: d.angle,
        margin,
        max_stress,
        actuator_forces: d.actuator_forces,
        cond,
    })
}

/// Outcome of one attempt.
enum Attempt {
    Done(Result<NodeData, NodeStatus>),
    Budget(StopReason),
}

/// March from an accepted node to the inputs `to` (spec 4.7 step control) and test the result.
#[expect(
    clippy::too_many_arguments,
    reason = "one call site; the arguments are the attempt's context"
)]
fn attempt(
    model: &Model,
    base: &Params,
    s: &SweepSettings,
    src: &NodeData,
    from: [f64; 2],
    to: [f64; 2],
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Attempt {
    if let Some(stop) = budget.check(counter.evaluations) {
        return Attempt::Budget(stop);
    }
    if let Some(st) = input_limits(model, s, &to) {
        return Attempt::Done(Err(st));
    }
    let n = model.n_unknowns();
    let na = model.n_act();
    let mut nsub = 1usize;
    let mut last_fail = NodeStatus::NoConvergence;
    loop {
        let mut v = src.v.clone();
        let mut tan = src.tangent.clone();
        let mut lam_prev = from;
        let mut pos_prev = src.position;
        let mut th_prev = src.angle;
        let mut ok: Option<Solution> = None;
        let mut failed = false;
        for k in 1..=nsub {
            let f = k as f64 / nsub as f64;
            let lam = [
                from[0] + (to[0] - from[0]) * f,
                from[1] + (to[1] - from[1]) * f,
            ];
            let dl = [lam[0] - lam_prev[0], lam[1] - lam_prev[1]];
            let guess: Vec<f64> = if s.predictor {
                (0..n)
                    .map(|r| v[r] + tan[r * na] * dl[0] + tan[r * na + 1] * dl[1])
                    .collect()
            } else {
                v.clone()
            };
            let guess = if guess.iter().all(|x| x.is_finite()) {
                guess
            } else {
                v.clone()
            };
            let params = Params {
                lambda: lam.to_vec(),
                force: base.force,
                moment: base.moment,
            };
            let capped = NewtonOptions {
                tol: opts.tol,
                max_iter: opts.max_iter.min(s.substep_max_iter),
                stall_window: Some(SUBSTEP_STALL_WINDOW),
            };
            match newton::solve(model, &params, &guess, capped, budget, counter) {
                Ok(sol) => {
                    let pos = model.position(&sol.v);
                    let th = model.angle(&sol.v);
                    let dlam = dl[0].hypot(dl[1]);
                    let dp = (pos[0] - pos_prev[0]).hypot(pos[1] - pos_prev[1]);
                    if (th - th_prev).abs() > s.angle_jump || dp > s.position_factor * dlam {
                        last_fail = NodeStatus::BranchJump;
                        failed = true;
                        break;
                    }
                    if k < nsub {
                        tan = tangent(model, &sol);
                    }
                    v.clone_from(&sol.v);
                    lam_prev = lam;
                    pos_prev = pos;
                    th_prev = th;
                    ok = Some(sol);
                }
                Err(e) => {
                    if let NewtonFailure::Budget(stop) = e.reason {
                        return Attempt::Budget(stop);
                    }
                    last_fail = NodeStatus::NoConvergence;
                    failed = true;
                    break;
                }
            }
        }
        if !failed && let Some(sol) = ok {
            return Attempt::Done(accept(model, s, &to, &sol, Some(src.det_sign)));
        }
        if nsub * 2 > s.max_substeps.max(1) {
            return Attempt::Done(Err(last_fail));
        }
        nsub *= 2;
    }
}

/// Grid neighbours of `(i, j)` in the fixed order (i-1, j), (i+1, j), (i, j-1), (i, j+1), then
/// the diagonals (i-1, j-1), (i-1, j+1), (i+1, j-1), (i+1, j+1) when enabled.
fn neighbours(s: &SweepSettings, i: usize, j: usize) -> Vec<(usize, usize)> {
    let (n1, n2) = (s.grid[0], s.grid[1]);
    let mut out = Vec::with_capacity(8);
    let mut push = |di: isize, dj: isize| {
        let (a, b) = (i.checked_add_signed(di), j.checked_add_signed(dj));
        if let (Some(a), Some(b)) = (a, b)
            && a < n1
            && b < n2
        {
            out.push((a, b));
        }
    };
    push(-1, 0);
    push(1, 0);
    push(0, -1);
    push(0, 1);
    if s.diagonal_neighbours {
        push(-1, -1);
        push(-1, 1);
        push(1, -1);
        push(1, 1);
    }
    out
}

struct Job {
    target: usize,
    source: usize,
}

/// Propagate one wave from the accepted seed node.
pub fn wave(
    model: &Model,
    base: &Params,
    s: &SweepSettings,
    seed: (usize, usize),
    seed_data: NodeData,
    opts: NewtonOptions,
    budget: &Budget,
) -> WaveResult {
    let (n1, n2) = (s.grid[0], s.grid[1]);
    let idx = |i: usize, j: usize| i * n2 + j;
    let mut status = vec![NodeStatus::Unvisited; n1 * n2];
    let mut nodes: Vec<Option<NodeData>> = vec![None; n1 * n2];
    let mut tries = vec![0usize; n1 * n2];
    let seed_idx = idx(seed.0, seed.1);
    status[seed_idx] = NodeStatus::Ok;
    nodes[seed_idx] = Some(seed_data);
    let mut frontier = vec![seed_idx];
    let mut stop = StopReason::Completed;
    // The job's threads (the compute pool's setting), capped by the settings.
    let threads = s.threads.min(budget.threads()).max(1);
    let mut attempts = 0u64;
    let mut evaluations = 0u64;
    let mut n_ok = 1usize;
    while !frontier.is_empty() && stop == StopReason::Completed {
        // Share of the grid reached so far (streaming clients; node counts are exact in f64).
        budget.progress(n_ok as f64 / (n1 * n2) as f64, None);
        // Ordered source lists per target, in FIFO order of (source position, neighbour rank).
        let mut order: Vec<usize> = Vec::new();
        let mut sources: BTreeMap<usize, Vec<(usize, usize, usize)>> = BTreeMap::new();
        for (pos, &src) in frontier.iter().enumerate() {
            let (i, j) = (src / n2, src % n2);
            for (rank, (a, b)) in neighbours(s, i, j).into_iter().enumerate() {
                let t = idx(a, b);
                if status[t] == NodeStatus::Ok {
                    continue;
                }
                let e = sources.entry(t).or_default();
                if e.is_empty() {
                    order.push(t);
                }
                e.push((pos, rank, src));
            }
        }
        let mut cursor: BTreeMap<usize, usize> = BTreeMap::new();
        let mut accepted: Vec<(usize, usize, usize)> = Vec::new();
        loop {
            let mut jobs = Vec::new();
            let mut keys = Vec::new();
            for &t in &order {
                let c = cursor.get(&t).copied().unwrap_or(0);
                let list = &sources[&t];
                if status[t] != NodeStatus::Ok && tries[t] < s.max_tries && c < list.len() {
                    jobs.push(Job {
                        target: t,
                        source: list[c].2,
                    });
                    keys.push((list[c].0, list[c].1));
                }
            }
            if jobs.is_empty() {
                break;
            }
            let results = par_map(threads, &jobs, |_, job| {
                let mut counter = Counter::default();
                let src = nodes[job.source].as_ref();
                let out = match src {
                    Some(src) => {
                        let from = lambda_at(s, job.source / n2, job.source % n2);
                        let to = lambda_at(s, job.target / n2, job.target % n2);
                        attempt(model, base, s, src, from, to, opts, budget, &mut counter)
                    }
                    // Unreachable: sources are accepted nodes; report as a failed attempt.
                    None => Attempt::Done(Err(NodeStatus::NoConvergence)),
                };
                (out, counter.evaluations)
            });
            for ((job, key), (res, ev)) in jobs.iter().zip(keys).zip(results) {
                evaluations += ev;
                match res {
                    Attempt::Budget(st) => stop = st,
                    Attempt::Done(r) => {
                        attempts += 1;
                        tries[job.target] += 1;
                        *cursor.entry(job.target).or_insert(0) += 1;
                        match r {
                            Ok(d) => {
                                status[job.target] = NodeStatus::Ok;
                                n_ok += 1;
                                nodes[job.target] = Some(d);
                                accepted.push((key.0, key.1, job.target));
                            }
                            Err(st) => status[job.target] = st,
                        }
                    }
                }
            }
            if stop != StopReason::Completed {
                break;
            }
        }
        accepted.sort_unstable();
        frontier = accepted.into_iter().map(|(_, _, t)| t).collect();
    }
    WaveResult {
        status,
        nodes,
        stop,
        attempts,
        evaluations,
    }
}
