//! Assembly-mode search ("full FK", spec 4.6, paper Fig. 7): tabulate the closed-form rod shapes,
//! combine one grid point per rod, keep combinations whose normalised residual is below `Tol`, keep
//! the best candidate per coarse cell and refine it with the FK Newton. NOT certified: a grid search
//! can miss solutions (near-looped rods with `|k| > 0.999`, higher buckling modes, cells it prunes).

use std::collections::BTreeMap;
use std::f64::consts::PI;

use crate::numerics::angles::wrap_pi;

use super::closed_form::{self, c_of};
use super::fk::{self, STABLE_MARGIN};
use super::model::{Model, Params, cross, rot};
use super::newton::{self, Counter, NewtonFailure, NewtonOptions, Solution};
use crate::numerics::{Budget, StopReason};

/// Two refined solutions closer than this (inf-norm of `v` after wrapping theta) are the same
/// (spec 4.6).
const DEDUP_TOL: f64 = 1e-6;
/// Lower end offset of the `|k|` grid above `|c|` (spec 4.6: `|c| + 1e-6`).
const K_LOW_OFFSET: f64 = 1e-6;
/// Upper end of the `|k|` grid (spec 4.6 and 7: cap `|k| <= 0.999`).
const K_HIGH: f64 = 0.999;
/// Default `Tol` (spec 6.2, the N_grid 9 reference case).
pub const DEFAULT_TOL: f64 = 0.5;
/// Largest default `N_grid` (spec 6.2 reference case: 10 modes, 5 stable, for design 1).
pub const DEFAULT_N_GRID_MAX: usize = 9;
/// The default `N_grid` keeps the grid at or below this many combinations: N_grid 9 for 3 rods
/// (3.4e7 combinations, 0.6 s, all 10 reference modes of design 1; N_grid 6 costs 80 ms but misses
/// 6, benches/RESULTS.md), N_grid 4 for 4 rods (1.7e7, ~2 s; N_grid 5 is 1e8 and ~10 s).
pub const DEFAULT_COMBINATIONS: f64 = 3.5e7;
/// Default `N_grid` of the search that picks the start of a design without a stress-free home
/// (spec 4.3 rule 2: the stable mode with the smallest |theta_EE|). Spec 6.2's reference values of
/// designs 3 and 4 (max angle 55.5 / 50.2 deg) come from the mode this grid finds; N_grid 9 also
/// finds a stable mode at 3.6 deg for design 3 and the wave from it is another workspace.
pub const HOME_FALLBACK_N_GRID: usize = 6;
/// Default `Tol` of that search (spec 6.2's first assembly-mode case).
pub const HOME_FALLBACK_TOL: f64 = 0.45;
/// Default coarse cell (spec 4.6).
pub const DEFAULT_CELL: usize = 2;
/// Default refinement cap (spec 4.6).
pub const DEFAULT_MAX_REFINE: usize = 4000;

/// Default `N_grid` for a design with `n_rods` rods: the largest `N_grid <= 9` whose grid has at
/// most [`DEFAULT_COMBINATIONS`] combinations (at least 1).
#[must_use]
pub fn default_n_grid(n_rods: usize) -> usize {
    (1..=DEFAULT_N_GRID_MAX)
        .rev()
        .find(|&n| combinations(n, n_rods) <= DEFAULT_COMBINATIONS)
        .unwrap_or(1)
}

/// Settings of the search.
#[derive(Debug, Clone, Copy)]
pub struct ModeSearch {
    /// `N_grid`.
    pub n_grid: usize,
    /// `Tol` on the normalised grid residual.
    pub tol: f64,
    /// Coarse cell size in grid indices.
    pub cell: usize,
    /// Maximum number of Newton refinements.
    pub max_refine: usize,
}

/// One refined equilibrium.
#[derive(Debug, Clone)]
pub struct ModeSolution {
    /// The solution (theta wrapped to (-pi, pi]).
    pub solution: Solution,
    /// Stability margin (None when undefined).
    pub margin: Option<f64>,
    /// Margin > 1e-8.
    pub stable: bool,
}

/// Outcome of a search.
#[derive(Debug, Clone)]
pub struct ModeResult {
    /// Distinct solutions, sorted by decreasing stability margin.
    pub solutions: Vec<ModeSolution>,
    /// Grid combinations below `Tol`.
    pub candidates: u64,
    /// Newton refinements run.
    pub refined: u64,
    /// Grid combinations examined.
    pub combinations: u64,
    /// How the search stopped.
    pub stop: StopReason,
}

#[derive(Debug, Clone, Copy)]
struct GridPoint {
    tip: [f64; 2],
    force: [f64; 2],
    m0: f64,
    /// Zero-based index of `psi` in its grid (`psi_{psi_idx + 1}` of spec 4.6).
    psi_idx: u32,
    /// Zero-based index of `|k|` among the interior grid points.
    k_idx: u32,
    negative: bool,
}

/// Tabulate the closed-form rod `i` at inputs `lambda` (spec 4.6).
fn table(model: &Model, i: usize, lambda: &[f64], n_grid: usize) -> Vec<GridPoint> {
    let r = &model.design.rods[i];
    let base = model.base_point(i, lambda);
    let npsi = 2 * n_grid;
    let mut out = Vec::with_capacity(npsi * 2 * n_grid);
    for kp in 1..=npsi {
        let psi = -PI + kp as f64 * 2.0 * PI / npsi as f64;
        let c = c_of(psi, r.clamp).abs();
        let lo = c + K_LOW_OFFSET;
        if lo >= K_HIGH {
            continue;
        }
        for m in 1..=n_grid {
            let kabs = lo + (K_HIGH - lo) * m as f64 / (n_grid + 1) as f64;
            for negative in [false, true] {
                let k = if negative { -kabs } else { kabs };
                if let Some(e) = closed_form::elastica(r.ei, r.length, r.clamp, psi, k, 1) {
                    out.push(GridPoint {
                        tip: [base[0] + e.tip[0], base[1] + e.tip[1]],
                        force: e.force,
                        m0: e.base_moment,
                        psi_idx: u32::try_from(kp - 1).unwrap_or(u32::MAX),
                        k_idx: u32::try_from(m - 1).unwrap_or(u32::MAX),
                        negative,
                    });
                }
            }
        }
    }
    out
}

/// Procrustes fit of the platform to the tips: `(theta, p)` (spec 4.6).
fn procrustes(attach: &[[f64; 2]], tips: &[[f64; 2]]) -> (f64, [f64; 2]) {
    let n = attach.len() as f64;
    let rc = attach
        .iter()
        .fold([0.0, 0.0], |a, r| [a[0] + r[0] / n, a[1] + r[1] / n]);
    let bc = tips
        .iter()
        .fold([0.0, 0.0], |a, b| [a[0] + b[0] / n, a[1] + b[1] / n]);
    let (mut sx, mut sd) = (0.0, 0.0);
    for (r, b) in attach.iter().zip(tips) {
        let rr = [r[0] - rc[0], r[1] - rc[1]];
        let bb = [b[0] - bc[0], b[1] - bc[1]];
        sx += cross(rr, bb);
        sd += rr[0].mul_add(bb[0], rr[1] * bb[1]);
    }
    let theta = sx.atan2(sd);
    let rr = rot(theta, rc);
    (theta, [bc[0] - rr[0], bc[1] - rr[1]])
}

#[derive(Debug, Clone)]
struct Candidate {
    residual: f64,
    points: Vec<usize>,
    theta: f64,
    position: [f64; 2],
}

/// Number of grid combinations `(2 N_grid)^(2N)` (spec 4.6 limit), saturating.
#[must_use]
pub fn combinations(n_grid: usize, n_rods: usize) -> f64 {
    (2.0 * n_grid as f64).powi(i32::try_from(2 * n_rods).unwrap_or(i32::MAX))
}

/// The candidates of the grid scan (spec 4.6): every combination of tabulated rod solutions whose
/// force and moment balance and platform fit are within `tol`, the best one per cell.
struct Scan {
    /// Best candidate per cell key.
    best: BTreeMap<Vec<u32>, Candidate>,
    /// Combinations within tolerance.
    candidates: u64,
    /// Combinations examined.
    combos: u64,
    /// Completed, or the budget's stop reason.
    stop: StopReason,
}

/// Scan the combinations of the rods' grid tables `tables` (odometer over all rods but the
/// last, a window query on the sorted force of the last rod) and keep the best candidate per
/// cell.
fn scan_grid(
    model: &Model,
    params: &Params,
    tables: &[Vec<GridPoint>],
    settings: ModeSearch,
    budget: &Budget,
    counter: &mut Counter,
) -> Scan {
    let nr = model.n_rods();
    let attach: Vec<[f64; 2]> = model.design.rods.iter().map(|r| r.attach).collect();
    let (l_ref, f_ref) = (model.l_ref, model.f_ref);
    let tol = settings.tol;
    let cell = settings.cell.max(1);
    // Last rod sorted by force x for a window query on the force balance.
    let last = nr - 1;
    let mut last_sorted: Vec<usize> = (0..tables[last].len()).collect();
    last_sorted.sort_by(|&a, &b| tables[last][a].force[0].total_cmp(&tables[last][b].force[0]));
    let last_fx: Vec<f64> = last_sorted
        .iter()
        .map(|&k| tables[last][k].force[0])
        .collect();
    let mut best: BTreeMap<Vec<u32>, Candidate> = BTreeMap::new();
    let mut candidates = 0u64;
    let mut combos = 0u64;
    let mut stop = StopReason::Completed;
    let mut idx = vec![0usize; nr];
    let lens: Vec<usize> = tables.iter().map(Vec::len).collect();
    let mut tips = vec![[0.0; 2]; nr];
    if lens.iter().all(|&l| l > 0) {
        'outer: loop {
            if let Some(s) = budget.check(counter.evaluations) {
                stop = s;
                break;
            }
            // Partial force sum over rods 0..nr-1.
            let mut fsum = [0.0, 0.0];
            for (i, &k) in idx.iter().enumerate().take(last) {
                fsum[0] += tables[i][k].force[0];
                fsum[1] += tables[i][k].force[1];
            }
            let need = [params.force[0] - fsum[0], params.force[1] - fsum[1]];
            let lo = last_fx.partition_point(|&x| x < tol.mul_add(-f_ref, need[0]));
            let hi = last_fx.partition_point(|&x| x <= tol.mul_add(f_ref, need[0]));
            combos += lens[last] as u64;
            for &kl in &last_sorted[lo..hi] {
                let gl = &tables[last][kl];
                let fres = [
                    (gl.force[0] - need[0]) / f_ref,
                    (gl.force[1] - need[1]) / f_ref,
                ];
                let f2 = fres[0].mul_add(fres[0], fres[1] * fres[1]);
                if f2 >= tol * tol {
                    continue;
                }
                idx[last] = kl;
                for i in 0..nr {
                    tips[i] = tables[i][idx[i]].tip;
                }
                let (theta, pos) = procrustes(&attach, &tips);
                let mut r2 = f2;
                let mut mom = -params.moment;
                for i in 0..nr {
                    let rr = rot(theta, attach[i]);
                    let e = [
                        (tips[i][0] - pos[0] - rr[0]) / l_ref,
                        (tips[i][1] - pos[1] - rr[1]) / l_ref,
                    ];
                    r2 += e[0].mul_add(e[0], e[1] * e[1]);
                    let g = &tables[i][idx[i]];
                    mom += cross([tips[i][0] - pos[0], tips[i][1] - pos[1]], g.force);
                }
                let mres = mom / (f_ref * l_ref);
                r2 += mres * mres;
                if r2 >= tol * tol {
                    continue;
                }
                candidates += 1;
                // Cells group zero-based indices {0, 1}, {2, 3}, ... (array indices, as the
                // reference counts). One-based grouping ({1}, {2, 3}, ...) shifts every cell
                // boundary: with N_grid 9 / Tol 0.5 its 4 000 best cells reach only 2 of the
                // spec's 10 modes, the zero-based ones all 10.
                let mut key = Vec::with_capacity(3 * nr);
                for i in 0..nr {
                    let g = &tables[i][idx[i]];
                    key.push(g.psi_idx / u32::try_from(cell).unwrap_or(u32::MAX));
                    key.push(g.k_idx / u32::try_from(cell).unwrap_or(u32::MAX));
                    key.push(u32::from(g.negative));
                }
                let res = r2.sqrt();
                let better = best.get(&key).is_none_or(|c| res < c.residual);
                if better {
                    best.insert(
                        key,
                        Candidate {
                            residual: res,
                            points: idx.clone(),
                            theta,
                            position: pos,
                        },
                    );
                }
            }
            // Odometer over rods 0..nr-1.
            let mut d = 0;
            loop {
                if d == last {
                    break 'outer;
                }
                idx[d] += 1;
                if idx[d] < lens[d] {
                    break;
                }
                idx[d] = 0;
                d += 1;
            }
        }
    }
    Scan {
        best,
        candidates,
        combos,
        stop,
    }
}

/// Run the search at `params`.
pub fn search(
    model: &Model,
    params: &Params,
    settings: ModeSearch,
    opts: NewtonOptions,
    segments: usize,
    budget: &Budget,
    counter: &mut Counter,
) -> ModeResult {
    let nr = model.n_rods();
    let tables: Vec<Vec<GridPoint>> = (0..nr)
        .map(|i| table(model, i, &params.lambda, settings.n_grid))
        .collect();
    let l_ref = model.l_ref;
    let scan = scan_grid(model, params, &tables, settings, budget, counter);
    let (candidates, combos, mut stop) = (scan.candidates, scan.combos, scan.stop);
    let mut cands: Vec<Candidate> = scan.best.into_values().collect();
    cands.sort_by(|a, b| a.residual.total_cmp(&b.residual));
    let mut solutions: Vec<ModeSolution> = Vec::new();
    let mut refined = 0u64;
    for c in cands.iter().take(settings.max_refine) {
        if stop != StopReason::Completed {
            break;
        }
        if let Some(s) = budget.check(counter.evaluations) {
            stop = s;
            break;
        }
        refined += 1;
        let mut v0 = vec![0.0; model.n_unknowns()];
        for i in 0..nr {
            let g = &tables[i][c.points[i]];
            let r = &model.design.rods[i];
            v0[3 * i] = g.m0 * r.length / r.ei;
            v0[3 * i + 1] = g.force[0] / model.k(i);
            v0[3 * i + 2] = g.force[1] / model.k(i);
        }
        v0[3 * nr] = c.position[0] / l_ref;
        v0[3 * nr + 1] = c.position[1] / l_ref;
        v0[3 * nr + 2] = c.theta;
        match newton::solve(model, params, &v0, opts, budget, counter) {
            Ok(mut sol) => {
                let th = &mut sol.v[3 * nr + 2];
                *th = wrap_pi(*th);
                let dup = solutions.iter().any(|s| {
                    s.solution
                        .v
                        .iter()
                        .zip(&sol.v)
                        .enumerate()
                        .all(|(k, (a, b))| {
                            let d = if k == 3 * nr + 2 {
                                wrap_pi(a - b)
                            } else {
                                a - b
                            };
                            d.abs() < DEDUP_TOL
                        })
                });
                if !dup {
                    let margin = fk::margin_of(model, &sol, segments);
                    let stable = margin.is_some_and(|m| m > STABLE_MARGIN);
                    solutions.push(ModeSolution {
                        solution: sol,
                        margin,
                        stable,
                    });
                }
            }
            Err(f) => {
                if let NewtonFailure::Budget(s) = f.reason {
                    stop = s;
                    break;
                }
            }
        }
    }
    solutions.sort_by(|a, b| {
        let ma = a.margin.unwrap_or(f64::NEG_INFINITY);
        let mb = b.margin.unwrap_or(f64::NEG_INFINITY);
        mb.total_cmp(&ma)
    });
    ModeResult {
        solutions,
        candidates,
        refined,
        combinations: combos,
        stop,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_grid_follows_the_rod_count() {
        // (2*9)^6 = 3.4e7, (2*4)^8 = 1.7e7 (N_grid 5 would be 1e8), (2*2)^10 = 1.0e6, (2*2)^12 = 1.7e7.
        for (rods, want) in [(2, 9), (3, 9), (4, 4), (5, 2), (6, 2), (12, 1)] {
            assert_eq!(default_n_grid(rods), want, "{rods} rods");
            assert!(combinations(want, rods) <= DEFAULT_COMBINATIONS || want == 1);
        }
    }
}
