//! Numerical certificate that the three curves coincide (spec §4.9): `sync` (pose map, constraint
//! residuals, independent re-solve), `implicit` (the original's coupler-curve sextic) and `hausdorff`
//! (polyline distance with a uniform-grid index).

use super::geometry::{
    C64, Family, Pose, Sign, Solve, TOGGLE_REL, cognate1_branch, mag, map_pose, sextic,
};

/// Cognate dyad height `h_i/b_i` below which a sample counts as near a toggle (spec §4.9).
pub const NEAR_TOGGLE_REL: f64 = 1e-6;
/// `sync` passes when every constraint residual is below this fraction of L (spec §6.3: measured
/// 9e-15·L on random linkages; one decade of margin).
pub const SYNC_RESIDUAL_PASS_REL: f64 = 1e-12;
/// `sync` passes when the regular re-solve deviation is below this fraction of L (ε·L²/h at
/// h/b = 1e-6 is ~2e-10·L; the spec's bound 1e-12·L holds where h/b ≥ 1e-2).
pub const SYNC_DEV_PASS_REL: f64 = 1e-9;
/// `implicit` passes below this fraction of L (spec: expect ≤ 1e-12·L; margin for rounding of the
/// degree-6 polynomial far from the pivots).
pub const IMPLICIT_PASS_REL: f64 = 1e-10;
/// Points with `|∇F|` below this fraction of the median are treated as double points (spec §4.9).
pub const DOUBLE_POINT_REL: f64 = 1e-6;

/// Running `sync` statistics (normalised units).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SyncAcc {
    /// Singular-distance tolerances of the three mechanisms (precomputed).
    s_min: [f64; 3],
    /// Largest re-solve deviation.
    pub max_dev: f64,
    /// Largest re-solve deviation away from the cognates' toggles.
    pub max_dev_regular: f64,
    /// Largest constraint residual.
    pub max_constraint_residual: f64,
    /// Samples checked.
    pub n_samples: usize,
    /// Samples with a cognate near a toggle.
    pub n_near_toggle: usize,
    /// Samples whose re-solve was skipped (locked input).
    pub n_skipped_locked: usize,
}

impl SyncAcc {
    /// An empty accumulator for `family`.
    #[must_use]
    pub fn new(family: &Family) -> Self {
        Self {
            s_min: family.mechs.map(|m| m.singular_tol()),
            ..Self::default()
        }
    }

    /// Checks one original configuration `pose` on branch `t1`.
    pub fn add(&mut self, family: &Family, pose: &Pose, t1: Sign) {
        let maps = map_pose(family, pose);
        let orig = &family.mechs[0];
        let mut near = false;
        let mut locked = false;
        let mut dev_sample = 0.0_f64;
        for (i, (m, &(di, ei))) in family.mechs.iter().zip(maps.iter()).enumerate().skip(1) {
            let residual = (mag(di - m.input_pivot) - m.crank)
                .abs()
                .max((mag(ei - di) - m.coupler).abs())
                .max((mag(ei - m.output_pivot) - m.rocker).abs())
                .max(mag(pose.p - (di + m.k * (ei - di))));
            self.max_constraint_residual = self.max_constraint_residual.max(residual);
            let (h, s) = m.dyad_height(di, ei);
            if h < NEAR_TOGGLE_REL * m.coupler {
                near = true;
            }
            if s <= self.s_min[i] {
                locked = true;
                continue;
            }
            let theta = (di - m.input_pivot).arg();
            let branch = if i == 2 {
                Some(t1.flip())
            } else {
                cognate1_branch(orig, pose)
            };
            let s_min = self.s_min[i];
            let resolve = |t: Sign| match m.solve_tol(theta, t, true, s_min) {
                Solve::Pose(q) => Some(mag(q.p - pose.p)),
                Solve::NotAssemblable { .. } | Solve::Singular { .. } => None,
            };
            let dev = match branch {
                Some(t) if h > TOGGLE_REL * m.coupler => resolve(t),
                _ => match (resolve(Sign::Plus), resolve(Sign::Minus)) {
                    (Some(x), Some(y)) => Some(x.min(y)),
                    (x, y) => x.or(y),
                },
            };
            match dev {
                Some(d) => dev_sample = dev_sample.max(d),
                None => locked = true,
            }
        }
        self.n_samples += 1;
        self.max_dev = self.max_dev.max(dev_sample);
        if near {
            self.n_near_toggle += 1;
        } else {
            self.max_dev_regular = self.max_dev_regular.max(dev_sample);
        }
        if locked {
            self.n_skipped_locked += 1;
        }
    }
}

/// Result of the `implicit` check (normalised units).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImplicitResult {
    /// Largest |F|/|∇F|.
    pub max_dist: f64,
    /// Points evaluated.
    pub n_points: usize,
    /// Points skipped as double points.
    pub n_skipped: usize,
}

/// Distance estimates of `points` from the coupler curve of the family's original (spec §4.9).
#[must_use]
pub fn implicit_check<'a>(
    family: &Family,
    points: impl Iterator<Item = &'a C64>,
) -> ImplicitResult {
    let orig = &family.mechs[0];
    let vals: Vec<(f64, f64)> = points.map(|p| sextic(orig, *p)).collect();
    if vals.is_empty() {
        return ImplicitResult::default();
    }
    let mut grads: Vec<f64> = vals.iter().map(|v| v.1).collect();
    let mid = grads.len() / 2;
    let (_, median, _) = grads.select_nth_unstable_by(mid, f64::total_cmp);
    let floor = DOUBLE_POINT_REL * *median;
    let mut out = ImplicitResult {
        n_points: vals.len(),
        ..ImplicitResult::default()
    };
    for (f, g) in vals {
        if g < floor || g <= 0.0 {
            out.n_skipped += 1;
        } else {
            out.max_dist = out.max_dist.max(f.abs() / g);
        }
    }
    out
}

/// A polyline segment.
pub type Segment = (C64, C64);

/// Segments of a set of polylines (each with its `closed` flag).
#[must_use]
pub fn segments<'a>(curves: impl Iterator<Item = (&'a [C64], bool)>) -> Vec<Segment> {
    let mut out = Vec::new();
    for (pts, closed) in curves {
        out.extend(pts.windows(2).map(|w| (w[0], w[1])));
        if closed && pts.len() > 2 {
            out.push((pts[pts.len() - 1], pts[0]));
        }
        if pts.len() == 1 {
            out.push((pts[0], pts[0]));
        }
    }
    out
}

fn point_segment_distance(q: C64, (a, b): Segment) -> f64 {
    super::sampling::point_segment_distance(q, a, b)
}

/// Uniform-grid index of segments for nearest-segment queries (cells in compressed-row form).
struct SegmentGrid<'a> {
    segs: &'a [Segment],
    min: C64,
    cell: f64,
    nx: usize,
    ny: usize,
    /// `items[start[c]..start[c + 1]]` are the segments overlapping cell `c`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> SegmentGrid<'a> {
    fn new(segs: &'a [Segment]) -> Self {
        let (mut lo, mut hi) = (
            C64::new(f64::INFINITY, f64::INFINITY),
            C64::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        let mut total = 0.0;
        for (a, b) in segs {
            total += mag(b - a);
            for p in [a, b] {
                lo = C64::new(lo.re.min(p.re), lo.im.min(p.im));
                hi = C64::new(hi.re.max(p.re), hi.im.max(p.im));
            }
        }
        let extent = (hi.re - lo.re).max(hi.im - lo.im);
        let n = segs.len().max(1) as f64;
        // About two mean segment lengths per cell (a query then scans a handful of segments), but
        // never more than ~4n cells.
        let cell = (2.0 * total / n).max(extent / (2.0 * n.sqrt()));
        let cell = if cell > 0.0 && cell.is_finite() {
            cell
        } else {
            1.0
        };
        let count = |w: f64| -> usize {
            // w/cell ≤ 2·sqrt(n) ≤ ~2e3: the cast is exact and cannot wrap.
            let k = (w / cell).floor() as usize;
            k + 1
        };
        let nx = count(hi.re - lo.re);
        let ny = count(hi.im - lo.im);
        let mut grid = Self {
            segs,
            min: lo,
            cell,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        // Two passes: count per cell, then fill.
        let ranges: Vec<_> = segs
            .iter()
            .map(|(a, b)| {
                let (ix0, iy0) = grid.cell_of(C64::new(a.re.min(b.re), a.im.min(b.im)));
                let (ix1, iy1) = grid.cell_of(C64::new(a.re.max(b.re), a.im.max(b.im)));
                (ix0, iy0, ix1, iy1)
            })
            .collect();
        let mut counts = vec![0_u32; nx * ny];
        for &(ix0, iy0, ix1, iy1) in &ranges {
            for iy in iy0..=iy1 {
                for ix in ix0..=ix1 {
                    counts[iy * nx + ix] += 1;
                }
            }
        }
        let mut acc = 0_u32;
        for (c, k) in counts.iter().enumerate() {
            grid.start[c] = acc;
            acc += k;
        }
        grid.start[nx * ny] = acc;
        let mut fill = grid.start.clone();
        grid.items = vec![0; acc as usize];
        for (idx, &(ix0, iy0, ix1, iy1)) in ranges.iter().enumerate() {
            let id = u32::try_from(idx).unwrap_or(u32::MAX);
            for iy in iy0..=iy1 {
                for ix in ix0..=ix1 {
                    let c = iy * nx + ix;
                    grid.items[fill[c] as usize] = id;
                    fill[c] += 1;
                }
            }
        }
        grid
    }

    fn cell_of(&self, p: C64) -> (usize, usize) {
        let f = |v: f64, n: usize| -> usize {
            let x = (v / self.cell).floor();
            if x <= 0.0 || x.is_nan() {
                0
            } else {
                // Clamped to n − 1 before the cast: cannot wrap.
                x.min((n - 1) as f64) as usize
            }
        };
        (
            f(p.re - self.min.re, self.nx),
            f(p.im - self.min.im, self.ny),
        )
    }

    /// Distance from `q` to the nearest cell outside the block of Chebyshev radius `r` around
    /// `(cx, cy)`; infinite on sides where the block reaches the grid border (no cells beyond).
    fn reach(&self, q: C64, cx: usize, cy: usize, r: usize) -> f64 {
        // Cell indices are ≤ ~2e3: exact in f64.
        let edge = |i: usize| i as f64 * self.cell;
        let left = if cx > r {
            q.re - (self.min.re + edge(cx - r))
        } else {
            f64::INFINITY
        };
        let right = if cx + r + 1 < self.nx {
            self.min.re + edge(cx + r + 1) - q.re
        } else {
            f64::INFINITY
        };
        let below = if cy > r {
            q.im - (self.min.im + edge(cy - r))
        } else {
            f64::INFINITY
        };
        let above = if cy + r + 1 < self.ny {
            self.min.im + edge(cy + r + 1) - q.im
        } else {
            f64::INFINITY
        };
        left.min(right).min(below).min(above)
    }

    fn nearest(&self, q: C64) -> f64 {
        let (cx, cy) = self.cell_of(q);
        let mut best = f64::INFINITY;
        let max_r = self.nx.max(self.ny);
        for r in 0..=max_r {
            let x0 = cx.saturating_sub(r);
            let x1 = (cx + r).min(self.nx - 1);
            let y0 = cy.saturating_sub(r);
            let y1 = (cy + r).min(self.ny - 1);
            for iy in y0..=y1 {
                for ix in x0..=x1 {
                    let on_ring = ix.abs_diff(cx) == r || iy.abs_diff(cy) == r;
                    if !on_ring {
                        continue;
                    }
                    let c = iy * self.nx + ix;
                    for &s in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                        best = best.min(point_segment_distance(q, self.segs[s as usize]));
                    }
                }
            }
            if best <= self.reach(q, cx, cy, r) {
                break;
            }
        }
        best
    }
}

/// Directed Hausdorff distance: largest distance from a vertex of `from` to the segments `to`.
/// Each vertex is queried once (a segment's end is the next one's start along a polyline).
fn directed(from: &[Segment], grid: &SegmentGrid<'_>) -> f64 {
    let mut worst = 0.0_f64;
    for (i, (a, b)) in from.iter().enumerate() {
        worst = worst.max(grid.nearest(*a));
        let shared = from.get(i + 1).is_some_and(|next| next.0 == *b);
        if !shared {
            worst = worst.max(grid.nearest(*b));
        }
    }
    worst
}

/// Symmetric Hausdorff distance between two polyline sets (vertex to segment); `None` when either
/// set is empty.
#[must_use]
pub fn hausdorff(a: &[Segment], b: &[Segment]) -> Option<f64> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let ga = SegmentGrid::new(a);
    let gb = SegmentGrid::new(b);
    Some(directed(a, &gb).max(directed(b, &ga)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hausdorff_of_shifted_square() {
        let sq = |o: f64| {
            let p = [
                C64::new(o, 0.0),
                C64::new(1.0 + o, 0.0),
                C64::new(1.0 + o, 1.0),
                C64::new(o, 1.0),
            ];
            segments(std::iter::once((&p[..], true)))
        };
        let a = sq(0.0);
        let b = sq(0.25);
        assert!((hausdorff(&a, &b).unwrap_or(1.0) - 0.25).abs() < 1e-15);
        assert!(hausdorff(&a, &a).unwrap_or(1.0).abs() < 1e-15);
    }

    #[test]
    fn grid_matches_brute_force() {
        // Two wiggly closed polylines with uneven spacing; brute-force vertex-to-segment distances.
        let curve = |phase: f64, n: usize, amp: f64| -> Vec<C64> {
            (0..n)
                .map(|j| {
                    let t = (j as f64 / n as f64).powi(2) * std::f64::consts::TAU;
                    C64::from_polar(1.0 + amp * (5.0 * t + phase).sin(), t)
                })
                .collect()
        };
        let (pa, pb) = (curve(0.0, 300, 0.1), curve(0.4, 170, 0.12));
        let a = segments(std::iter::once((&pa[..], true)));
        let b = segments(std::iter::once((&pb[..], true)));
        let brute = |from: &[Segment], to: &[Segment]| {
            from.iter()
                .flat_map(|(p, q)| [*p, *q])
                .map(|v| {
                    to.iter()
                        .map(|s| point_segment_distance(v, *s))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        let want = brute(&a, &b).max(brute(&b, &a));
        let got = hausdorff(&a, &b).unwrap_or(f64::NAN);
        assert!((got - want).abs() <= 1e-15, "{got} vs {want}");
    }
}
