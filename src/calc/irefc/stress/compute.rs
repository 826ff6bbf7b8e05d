//! Element forces and Hertz contact stresses of one design, and the parallel sweep (spec `irefc_stress.md`,
//! "Algorithm" and "Sweep").

use std::f64::consts::{PI, TAU};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use super::input::{Design, LoadSharing, OutputLink, StressParams, SweepInput};
use crate::calc::irefc::error::IrefcError;
use crate::calc::irefc::geometry::{AnglePoint, Geometry, Trig, Wheel};
use crate::numerics::roots;
use crate::numerics::{Budget, StopReason, par_map_while};

/// Refinement stops when the bracket half-width is below this \[rad\] (spec step 6).
pub const REFINE_TOL_RAD: f64 = 1e-10;
/// Iteration cap of one refinement (Brent needs ~10–40 for the smooth, single-peaked σ near its maximum).
pub const REFINE_MAX_ITER: u32 = 100;
/// Sweeps share one precomputed trig table when the grid has at most this many points (≤ 6 MB).
pub const TRIG_TABLE_MAX_POINTS: usize = 262_145;
/// Maximum subsurface shear stress of a Hertz line contact, τ_max/p0 (Johnson, Contact Mechanics §4.2).
pub const TAU_MAX_RATIO: f64 = 0.300;
/// Depth of τ_max below the surface, z/b.
pub const TAU_DEPTH_RATIO: f64 = 0.786;

/// One element of a load-sharing set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementForce {
    /// Element index k.
    pub k: u32,
    /// Element angle φ_k \[rad\].
    pub phi: f64,
    /// sin α_k.
    pub sin_alpha: f64,
    /// True contact angle α_k \[rad\].
    pub alpha: f64,
    /// Cam lever arm h_k = r1·sin α_k \[m\].
    pub h: f64,
    /// Element force F_k \[N\] (eq. 16).
    pub f: f64,
}

/// Force distribution over one cage phase (spec step 3, eqs 12–17).
#[derive(Debug, Clone, PartialEq)]
pub struct ElementForces {
    /// Fmax = T_cam/(r1·Σsin²α) \[N\] (eq. 17).
    pub fmax: f64,
    /// Σ sin²α over the loaded set.
    pub sum_s2: f64,
    /// Σh² = r1²·Σsin²α \[m²\].
    pub sum_h2: f64,
    /// The loaded elements.
    pub elements: Vec<ElementForce>,
}

/// Element forces for cam torque `t_cam` [N·m] at cage phase fraction `p` ∈ [0, 1) (p = 0: the papers'
/// element set k = 0..⌊Z2/2⌋). Rigid bodies: F_k ∝ h_k, so Σ F_k·h_k = T_cam.
#[must_use]
pub fn element_forces(g: &Geometry, t_cam: f64, p: f64) -> ElementForces {
    let mut elements: Vec<ElementForce> = g
        .loaded_elements(p)
        .map(|(k, phi)| {
            let a = g.at(phi);
            ElementForce {
                k,
                phi,
                sin_alpha: a.sin_alpha,
                alpha: a.alpha,
                h: a.h_cam,
                f: 0.0,
            }
        })
        .collect();
    let sum_s2: f64 = elements.iter().map(|e| e.sin_alpha * e.sin_alpha).sum();
    let fmax = t_cam / (g.r1 * sum_s2);
    for e in &mut elements {
        e.f = fmax * e.sin_alpha;
    }
    ElementForces {
        fmax,
        sum_s2,
        sum_h2: g.r1 * g.r1 * sum_s2,
        elements,
    }
}

/// Cam torque from the output torque (spec step 2).
#[must_use]
pub fn cam_torque(g: &Geometry, t_out: f64, link: OutputLink) -> f64 {
    match link {
        OutputLink::Cam => t_out,
        OutputLink::Crown => t_out * (g.z2f - 1.0) / (g.z2f + 1.0),
    }
}

/// Contact-stress evaluator of one design (spec steps 4–5).
#[derive(Debug, Clone, Copy)]
pub struct Stresser<'g> {
    g: &'g Geometry,
    t_cam: f64,
    fmax: f64,
    /// E*/(π·lb) [Pa/m].
    c: f64,
    e_star: f64,
    lb: f64,
    mode: LoadSharing,
}

/// Stresses at one angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StressSample {
    /// Element force F(φ) \[N\].
    pub f: f64,
    /// σ_cam² \[Pa²\].
    pub s2_cam: f64,
    /// σ_crown² \[Pa²\].
    pub s2_crown: f64,
    /// Smaller cusp margin \[m\] (≤ 0: cusp).
    pub margin: f64,
}

impl<'g> Stresser<'g> {
    /// Evaluator for geometry `g`, cam torque `t_cam` [N·m], Fmax \[N\], E* \[Pa\], contact length `lb` \[m\].
    #[must_use]
    pub fn new(
        g: &'g Geometry,
        t_cam: f64,
        fmax: f64,
        e_star: f64,
        lb: f64,
        mode: LoadSharing,
    ) -> Self {
        Self {
            g,
            t_cam,
            fmax,
            c: e_star / (PI * lb),
            e_star,
            lb,
            mode,
        }
    }

    /// Element force at φ (given sin α and the cage phase fraction p that puts an element at φ).
    #[inline]
    fn force(&self, sin_alpha: f64, p: impl FnOnce() -> f64) -> f64 {
        match self.mode {
            LoadSharing::PaperPhase0 => self.fmax * sin_alpha,
            LoadSharing::PhaseExact => self.t_cam * sin_alpha / (self.g.r1 * self.g.sum_sin2(p())),
        }
    }

    /// σ² of both wheels from trig values; `p` gives the phase fraction (only called in phase-exact mode).
    #[inline]
    pub fn sample(&self, t: &Trig, p: impl FnOnce() -> f64) -> StressSample {
        let k = self.g.kernel(t);
        let f = self.force(k.sin_alpha, p);
        let fc = f * self.c;
        StressSample {
            f,
            s2_cam: fc * k.k_cam,
            s2_crown: fc * k.k_crown,
            margin: k.margin,
        }
    }

    /// σ² of both wheels at any φ \[rad\].
    #[must_use]
    pub fn sample_at(&self, phi: f64) -> StressSample {
        self.sample(&Trig::of(phi), || self.g.phase_fraction_at(phi))
    }

    /// Full state at φ: the sample, the per-angle geometry and σ of both wheels \[Pa\].
    #[must_use]
    pub fn state_at(&self, phi: f64) -> (StressSample, AnglePoint) {
        (self.sample_at(phi), self.g.at(phi))
    }
}

/// Maximum contact stress of one wheel (spec step 7) \[SI\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelMaxResult {
    /// Wheel.
    pub wheel: Wheel,
    /// φ of the maximum \[rad\]; `None` at zero torque (no argmax).
    pub phi: Option<f64>,
    /// σ_H max \[Pa\].
    pub sigma: f64,
    /// Element force there \[N\].
    pub f: f64,
    /// Geometry there (`None` at zero torque).
    pub point: Option<AnglePoint>,
    /// Contact half-width b \[m\].
    pub b: f64,
}

impl WheelMaxResult {
    fn zero(wheel: Wheel) -> Self {
        Self {
            wheel,
            phi: None,
            sigma: 0.0,
            f: 0.0,
            point: None,
            b: 0.0,
        }
    }
}

/// Curves over the grid (SI).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CurveData {
    /// φ \[rad\].
    pub phi: Vec<f64>,
    /// F \[N\].
    pub f: Vec<f64>,
    /// σ_cam \[Pa\].
    pub sigma_cam: Vec<f64>,
    /// σ_crown \[Pa\].
    pub sigma_crown: Vec<f64>,
    /// ρ_cam \[m\] (None at inflection).
    pub rho_cam: Vec<Option<f64>>,
    /// ρ_crown \[m\].
    pub rho_crown: Vec<Option<f64>>,
}

/// Result of one design.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignResult {
    /// Geometry.
    pub geometry: Geometry,
    /// T_cam [N·m].
    pub t_cam: f64,
    /// T_crown [N·m].
    pub t_crown: f64,
    /// Lossless carrier torque [N·m].
    pub t_in: f64,
    /// E* \[Pa\].
    pub e_star: f64,
    /// Contact length \[m\].
    pub lb: f64,
    /// Phase-0 element forces.
    pub forces: ElementForces,
    /// Cam maximum.
    pub cam: WheelMaxResult,
    /// Crown maximum.
    pub crown: WheelMaxResult,
    /// Stress evaluations (grid + refinement).
    pub evaluations: u64,
    /// Grid intervals scanned (see [`scan_intervals`]).
    pub n_intervals: usize,
    /// Curves, when requested.
    pub curves: Option<CurveData>,
}

impl DesignResult {
    /// The governing (larger) maximum; `None` at zero torque.
    #[must_use]
    pub fn governing(&self) -> Option<&WheelMaxResult> {
        self.cam.phi?;
        Some(if self.crown.sigma > self.cam.sigma {
            &self.crown
        } else {
            &self.cam
        })
    }
}

/// Grid angle φ_j = jπ/N with φ_N = π exactly.
#[inline]
#[must_use]
pub fn grid_phi(j: usize, n: usize) -> f64 {
    if j >= n {
        PI
    } else {
        // j < n ≤ 2e6: exact in f64.
        j as f64 * PI / n as f64
    }
}

/// Trig values of the grid φ_j = jπ/N, j = 0..=N, as separate arrays (vectorisable scans).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrigTable {
    /// sin φ_j.
    pub sin: Vec<f64>,
    /// cos φ_j.
    pub cos: Vec<f64>,
    /// sin²(φ_j/2).
    pub half_sin2: Vec<f64>,
}

impl TrigTable {
    /// Table of the grid with `n` intervals.
    #[must_use]
    pub fn new(n: usize) -> Self {
        let mut t = Self::default();
        t.fill(0, n + 1, n);
        t
    }

    /// Replace the contents by the trig values of φ_j, j = j0..j0+len, of the grid with `n` intervals.
    fn fill(&mut self, j0: usize, len: usize, n: usize) {
        self.sin.clear();
        self.cos.clear();
        self.half_sin2.clear();
        for j in j0..j0 + len {
            let t = Trig::of(grid_phi(j, n));
            self.sin.push(t.sin);
            self.cos.push(t.cos);
            self.half_sin2.push(t.half_sin2);
        }
    }

    /// Number of grid points held.
    #[must_use]
    pub fn len(&self) -> usize {
        self.sin.len()
    }

    /// Whether the table is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sin.is_empty()
    }
}

/// Local maxima of a grid sequence, (index, value). Bounded: beyond [`PEAKS_KEEP_MAX`] entries only the
/// largest half is kept (rounding ripples on very fine grids can create many tiny local maxima).
#[derive(Debug, Clone, Default)]
struct Peaks {
    list: Vec<(usize, f64)>,
}

/// Most local maxima kept per wheel during a scan.
const PEAKS_KEEP_MAX: usize = 1024;

impl Peaks {
    #[inline]
    fn offer(&mut self, j: usize, v: f64) {
        self.list.push((j, v));
        if self.list.len() > PEAKS_KEEP_MAX {
            self.list.sort_by(|a, b| b.1.total_cmp(&a.1));
            self.list.truncate(PEAKS_KEEP_MAX / 2);
        }
    }

    /// Refinement candidates (spec step 6, defensive): local maxima by decreasing value whose grid value
    /// is at least [`CANDIDATE_FRACTION`] of the largest, at most `max_candidates`, skipping those whose
    /// bracket overlaps a better candidate's.
    fn candidates(mut self, max_candidates: usize) -> Vec<(usize, f64)> {
        self.list
            .sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let Some(&(_, top)) = self.list.first() else {
            return Vec::new();
        };
        let mut out: Vec<(usize, f64)> = Vec::new();
        for &(j, v) in &self.list {
            if out.len() >= max_candidates || v < CANDIDATE_FRACTION * top {
                break;
            }
            if out.iter().all(|&(k, _)| k.abs_diff(j) > 2) {
                out.push((j, v));
            }
        }
        out
    }
}

/// Local grid maxima down to this fraction of the largest are refined: with "phase_exact" the stress
/// curve has several bumps (the cage phase changes the load sharing) and a coarse grid can rank them
/// wrongly; the spec's "two largest" is the minimum.
pub const CANDIDATE_FRACTION: f64 = 0.5;
/// Most refinements per wheel ("paper_phase0": one smooth bump per wheel, a few spare).
pub const MAX_CANDIDATES: usize = 16;
/// Most refinements per wheel with "phase_exact": near the top of the sin α envelope many load-sharing
/// ripples have nearly equal heights.
pub const MAX_CANDIDATES_PHASE_EXACT: usize = 64;
/// With "phase_exact" and refine, the scan uses at least this many grid intervals per 180°/Z2, the
/// spacing of the load-sharing breakpoints (an element enters or leaves [0, π]; σ is smooth only between
/// them and can have one bump per piece), so that every bump shows up as a grid maximum. Coarser grids
/// missed the bump holding the maximum in the property tests (Z2 = 65, step 1.6°: 7e-5 low).
pub const PHASE_EXACT_POINTS_PER_SEGMENT: usize = 8;

/// Element angles in (lo, hi) where an element of the cage enters or leaves [0, π] when an element sits at
/// φ: φ = 2πm/Z2 (an element at 0) and φ = π − 2πm/Z2 (an element at π), sorted.
#[must_use]
pub fn load_sharing_breakpoints(z2: u32, lo: f64, hi: f64) -> Vec<f64> {
    let per = TAU / f64::from(z2);
    let mut v = Vec::new();
    for base in [0.0, PI] {
        // φ = base ± m·per; m ranges over the integers that land in (lo, hi).
        let (m0, m1) = (((lo - base) / per).ceil(), ((hi - base) / per).floor());
        let mut m = m0;
        while m <= m1 {
            let x = m.mul_add(per, base);
            if x > lo && x < hi {
                v.push(x);
            }
            m += 1.0;
        }
    }
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= REFINE_TOL_RAD);
    v
}

/// Grid intervals actually scanned: the requested N, raised with "phase_exact" + refine to
/// [`PHASE_EXACT_POINTS_PER_SEGMENT`] per 180°/Z2 (N ≥ 8·Z2).
#[must_use]
pub fn scan_intervals(p: &StressParams, z2: u32) -> usize {
    if p.refine && p.load_sharing == LoadSharing::PhaseExact {
        p.n_intervals
            .max(z2 as usize * PHASE_EXACT_POINTS_PER_SEGMENT)
    } else {
        p.n_intervals
    }
}

/// Streaming local-maximum detector of one wheel.
#[derive(Debug, Clone)]
struct PeakTracker {
    prev2: f64,
    prev1: f64,
    peaks: Peaks,
}

impl PeakTracker {
    fn new() -> Self {
        Self {
            prev2: f64::NEG_INFINITY,
            prev1: f64::NEG_INFINITY,
            peaks: Peaks::default(),
        }
    }

    /// Feed value v_j; detects a local maximum at j − 1 (v_{j−1} ≥ v_{j−2} and v_{j−1} > v_j).
    #[inline]
    fn push(&mut self, j: usize, v: f64) {
        if j >= 1 && self.prev1 >= self.prev2 && self.prev1 > v {
            self.peaks.offer(j - 1, self.prev1);
        }
        self.prev2 = self.prev1;
        self.prev1 = v;
    }

    /// Finish after the last value at index `n` (the end is a maximum if still rising).
    fn finish(&mut self, n: usize) {
        if self.prev1 > self.prev2 {
            self.peaks.offer(n, self.prev1);
        }
    }
}

/// Grid scan result of both wheels.
struct ScanResult {
    cam: Peaks,
    crown: Peaks,
    evaluations: u64,
}

/// Grid points evaluated per chunk of the scan (buffers stay in L1; the deadline is polled per chunk).
const SCAN_CHUNK: usize = 1024;

/// Scan the grid (spec steps 4–5) with the trig values of a shared table, or computed chunk by chunk.
///
/// Only the arg max matters here, so the scan tracks a positive multiple of σ_w²: with
/// F = Fmax·χ·sinφ/s ("paper_phase0") and K_w = r2·s³/(rb·m_w), m_w = r2·s³ − rb·D_w,
/// σ_w² = [Fmax·χ·r2·E*/(π·lb·rb)] · sinφ·s²/m_w; "phase_exact" divides by Σsin²α of the cage phase.
/// Candidate values are re-evaluated exactly by [`finish_wheel`].
fn scan(
    st: &Stresser<'_>,
    n: usize,
    table: Option<&TrigTable>,
    budget: Option<&Budget>,
) -> Result<ScanResult, IrefcError> {
    let mut cam = PeakTracker::new();
    let mut crown = PeakTracker::new();
    let g = st.g;
    let exact = st.mode == LoadSharing::PhaseExact;
    let mut local = TrigTable::default();
    let mut v_cam = vec![0.0; SCAN_CHUNK];
    let mut v_crown = vec![0.0; SCAN_CHUNK];
    let mut j0 = 0;
    while j0 <= n {
        if let Some(b) = budget
            && j0 > 0
            && b.expired()
        {
            return Err(IrefcError::Deadline {
                evaluations: j0 as u64,
            });
        }
        let len = SCAN_CHUNK.min(n + 1 - j0);
        let (sin, cos, hs2) = match table {
            Some(t) if t.len() == n + 1 => (
                &t.sin[j0..j0 + len],
                &t.cos[j0..j0 + len],
                &t.half_sin2[j0..j0 + len],
            ),
            _ => {
                local.fill(j0, len, n);
                (&local.sin[..], &local.cos[..], &local.half_sin2[..])
            }
        };
        if scan_kernel(g, sin, cos, hs2, &mut v_cam[..len], &mut v_crown[..len]) {
            // Locate the first cusp of this chunk for the message.
            let j = (j0..j0 + len)
                .find(|&j| g.kernel(&Trig::of(grid_phi(j, n))).margin <= 0.0)
                .unwrap_or(j0);
            let t = Trig::of(grid_phi(j, n));
            return Err(IrefcError::Cusp {
                wheel: cusp_wheel(g, &t),
                phi_deg: grid_phi(j, n).to_degrees(),
            });
        }
        if exact {
            let z2 = g.z2 as usize;
            for i in 0..len {
                // Phase fraction that puts an element at φ_j = jπ/N: frac(j·Z2/(2N)), exact in integers.
                let num = ((j0 + i) * z2) % (2 * n);
                // num < 2N ≤ 4e6: exact in f64.
                let p = num as f64 / (2 * n) as f64;
                let q = g.sum_sin2(p);
                v_cam[i] /= q;
                v_crown[i] /= q;
            }
        }
        for i in 0..len {
            cam.push(j0 + i, v_cam[i]);
            crown.push(j0 + i, v_crown[i]);
        }
        j0 += len;
    }
    cam.finish(n);
    crown.finish(n);
    Ok(ScanResult {
        cam: cam.peaks,
        crown: crown.peaks,
        evaluations: n as u64 + 1,
    })
}

/// The branch-free hot loop: scaled σ² of both wheels for a chunk; returns whether a cusp margin
/// m_w ≤ 0 was met.
///
/// Works in units of r2 (m_w/r2 = s³ − (rb/r2)·D_w is O(1), so the one shared division below can neither
/// overflow nor underflow) and divides once: a/m_cam = a·m_crown/(m_cam·m_crown). Plain `a * b + c`
/// instead of `mul_add`: without the `fma` target feature `mul_add` is a libm call, which is slower and
/// stops the loop from vectorising.
fn scan_kernel(
    g: &Geometry,
    sin: &[f64],
    cos: &[f64],
    hs2: &[f64],
    v_cam: &mut [f64],
    v_crown: &mut [f64],
) -> bool {
    let chi = g.chi;
    let cm1sq = (chi - 1.0) * (chi - 1.0);
    let four_chi = 4.0 * chi;
    let q = g.rb / g.r2;
    // (rb/r2)·D_w = a_w − b_w·cos φ
    let a_cam = q * (g.z2f + chi * chi);
    let b_cam = q * (g.z2f + 1.0) * chi;
    let a_crown = q * (g.z2f - chi * chi);
    let b_crown = q * (g.z2f - 1.0) * chi;
    // A bool OR reduction vectorises; an f64::min reduction (NaN semantics) does not.
    let mut cusp = false;
    for ((((&s, &c), &h), vc), vk) in sin
        .iter()
        .zip(cos)
        .zip(hs2)
        .zip(v_cam.iter_mut())
        .zip(v_crown.iter_mut())
    {
        let s2 = cm1sq + four_chi * h;
        let s3 = s2 * s2.sqrt();
        let m_cam = s3 - (a_cam - b_cam * c);
        let m_crown = s3 - (a_crown - b_crown * c);
        let inv = s * s2 / (m_cam * m_crown);
        *vc = inv * m_crown;
        *vk = inv * m_cam;
        cusp |= (m_cam <= 0.0) | (m_crown <= 0.0);
    }
    cusp
}

/// Which wheel has a non-positive cusp margin at `t`.
fn cusp_wheel(g: &Geometry, t: &Trig) -> Wheel {
    let s2 = g.s2(t);
    let r2s3 = g.r2 * s2 * s2.sqrt();
    if (-g.rb).mul_add(g.d_cam(t), r2s3) <= 0.0 {
        Wheel::Cam
    } else {
        Wheel::Crown
    }
}

/// σ² of wheel w in a sample.
#[inline]
const fn s2_of(s: &StressSample, w: Wheel) -> f64 {
    match w {
        Wheel::Cam => s.s2_cam,
        Wheel::Crown => s.s2_crown,
    }
}

/// Refine the candidates of one wheel and build its maximum (spec steps 6–7).
fn finish_wheel(
    st: &Stresser<'_>,
    w: Wheel,
    peaks: Peaks,
    n: usize,
    refine: bool,
    max_candidates: usize,
    evaluations: &mut u64,
) -> Result<WheelMaxResult, IrefcError> {
    let mut best: Option<(f64, f64)> = None; // (φ, σ²)
    for (j, v) in peaks.candidates(max_candidates) {
        if v <= 0.0 || !v.is_finite() {
            continue;
        }
        let phi_grid = grid_phi(j, n);
        // The scan tracked a scaled σ²; evaluate the candidate exactly.
        let s_grid = st.sample_at(phi_grid);
        *evaluations += 1;
        let mut cand = (phi_grid, s2_of(&s_grid, w));
        if refine {
            let lo = grid_phi(j.saturating_sub(1), n);
            let hi = grid_phi((j + 1).min(n), n);
            // "phase_exact": σ is smooth only between the load-sharing breakpoints (an element enters or
            // leaves [0, π]); maximise each smooth piece of the bracket on its own.
            let mut edges = vec![lo];
            if st.mode == LoadSharing::PhaseExact {
                edges.extend(load_sharing_breakpoints(st.g.z2, lo, hi));
            }
            edges.push(hi);
            for piece in edges.windows(2) {
                let (a, b) = (piece[0], piece[1]);
                if b - a <= REFINE_TOL_RAD {
                    continue;
                }
                let mut cusp = false;
                let r = roots::maximize(
                    |phi| {
                        let s = st.sample_at(phi);
                        if s.margin <= 0.0 {
                            cusp = true;
                            return 0.0;
                        }
                        s2_of(&s, w)
                    },
                    a,
                    b,
                    REFINE_TOL_RAD,
                    REFINE_MAX_ITER,
                );
                *evaluations += r.evaluations;
                if cusp {
                    return Err(IrefcError::Cusp {
                        wheel: w,
                        phi_deg: r.x.to_degrees(),
                    });
                }
                if r.fx > cand.1 {
                    cand = (r.x, r.fx);
                }
            }
        }
        if best.is_none_or(|(_, bv)| cand.1 > bv) {
            best = Some(cand);
        }
    }
    // No positive σ (zero torque, or σ² underflowing at absurdly small torques): no arg max.
    let Some((phi, _)) = best.filter(|&(_, v)| v > 0.0) else {
        return Ok(WheelMaxResult::zero(w));
    };
    let (s, point) = st.state_at(phi);
    let sigma = s2_of(&s, w).sqrt();
    let k = point.curvature_sum(w);
    let b = (4.0 * s.f / (PI * st.lb * st.e_star * k)).sqrt();
    Ok(WheelMaxResult {
        wheel: w,
        phi: Some(phi),
        sigma,
        f: s.f,
        point: Some(point),
        b,
    })
}

/// Source of grid trig values.
#[derive(Debug, Clone, Copy)]
pub enum GridTrig<'a> {
    /// Evaluate Trig::of(jπ/N) chunk by chunk.
    OnTheFly,
    /// Precomputed table of the N + 1 grid points (shared by the combinations of a sweep).
    Table(&'a TrigTable),
}

/// Compute one feasible design (spec steps 2–7). `curves_stride`: also sample curves.
///
/// # Errors
/// [`IrefcError::Infeasible`] if the design cannot be built, [`IrefcError::Cusp`] if a cusp is met at the
/// undercut limit within round-off, [`IrefcError::NonFinite`] on overflow, [`IrefcError::Deadline`] if the
/// budget runs out during the scan.
pub fn compute_design(
    design: &Design,
    p: &StressParams,
    grid: GridTrig<'_>,
    curves_stride: Option<usize>,
    budget: Option<&Budget>,
) -> Result<DesignResult, IrefcError> {
    let g = Geometry::new_unchecked(design.r2, design.z2, design.chi, design.rb);
    let bad = g.infeasibilities();
    if !bad.is_empty() {
        return Err(IrefcError::Infeasible(bad));
    }
    let t_cam = cam_torque(&g, p.torque, p.output_link);
    let t_crown = t_cam * g.r3 / g.r1;
    let t_in = t_cam * 2.0 / (g.z2f - 1.0);
    let lb = p.lb.unwrap_or(2.0 * g.rb);
    let forces = element_forces(&g, t_cam, 0.0);
    finite("Fmax", forces.fmax, None)?;
    let st = Stresser::new(&g, t_cam, forces.fmax, p.e_star, lb, p.load_sharing);
    let n = scan_intervals(p, g.z2);
    let max_candidates = match p.load_sharing {
        LoadSharing::PaperPhase0 => MAX_CANDIDATES,
        LoadSharing::PhaseExact => MAX_CANDIDATES_PHASE_EXACT,
    };

    let (cam, crown, evaluations) = if t_cam > 0.0 {
        let sr = match grid {
            GridTrig::Table(t) => scan(&st, n, Some(t), budget)?,
            GridTrig::OnTheFly => scan(&st, n, None, budget)?,
        };
        let mut ev = sr.evaluations;
        let cam = finish_wheel(
            &st,
            Wheel::Cam,
            sr.cam,
            n,
            p.refine,
            max_candidates,
            &mut ev,
        )?;
        let crown = finish_wheel(
            &st,
            Wheel::Crown,
            sr.crown,
            n,
            p.refine,
            max_candidates,
            &mut ev,
        )?;
        (cam, crown, ev)
    } else {
        (
            WheelMaxResult::zero(Wheel::Cam),
            WheelMaxResult::zero(Wheel::Crown),
            0,
        )
    };
    for m in [&cam, &crown] {
        let at = m.phi.map(f64::to_degrees);
        finite("sigma", m.sigma, at)?;
        finite("F", m.f, at)?;
        finite("b", m.b, at)?;
    }
    let curves = curves_stride.map(|stride| curves(&st, p.n_intervals, stride.max(1)));
    if let Some(c) = &curves
        && !(c.f.iter().chain(&c.sigma_cam).chain(&c.sigma_crown)).all(|v| v.is_finite())
    {
        return Err(IrefcError::NonFinite {
            quantity: "curves",
            phi_deg: None,
        });
    }
    Ok(DesignResult {
        geometry: g,
        t_cam,
        t_crown,
        t_in,
        e_star: p.e_star,
        lb,
        forces,
        cam,
        crown,
        evaluations,
        n_intervals: n,
        curves,
    })
}

fn finite(quantity: &'static str, v: f64, phi_deg: Option<f64>) -> Result<(), IrefcError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(IrefcError::NonFinite { quantity, phi_deg })
    }
}

/// Sample the curves every `stride` grid points plus the last one.
fn curves(st: &Stresser<'_>, n: usize, stride: usize) -> CurveData {
    let mut c = CurveData::default();
    let mut push = |j: usize| {
        let phi = grid_phi(j, n);
        let (s, a) = st.state_at(phi);
        c.phi.push(phi);
        c.f.push(s.f);
        c.sigma_cam.push(s.s2_cam.max(0.0).sqrt());
        c.sigma_crown.push(s.s2_crown.max(0.0).sqrt());
        c.rho_cam.push(a.rho(Wheel::Cam));
        c.rho_crown.push(a.rho(Wheel::Crown));
    };
    let mut j = 0;
    while j < n {
        push(j);
        j += stride;
    }
    push(n);
    c
}

/// Outcome of one sweep combination.
#[derive(Debug, Clone, PartialEq)]
pub enum ComboOutcome {
    /// Computed.
    Valid(Box<DesignResult>),
    /// Infeasible or failed: code, message, geometry (for the min profile radius).
    Invalid {
        /// Spec code.
        code: &'static str,
        /// Message.
        message: String,
        /// Geometry of the combination.
        geometry: Geometry,
    },
    /// Not evaluated: the budget ran out first.
    NotEvaluated,
}

/// Result of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepResult {
    /// One outcome per combination, in [`SweepInput::design`] order.
    pub outcomes: Vec<ComboOutcome>,
    /// How the sweep stopped.
    pub stop_reason: StopReason,
    /// Combinations evaluated.
    pub evaluated: u64,
    /// Worker threads.
    pub threads: u32,
}

/// Run every combination of the sweep (spec "Sweep") on the job's threads
/// ([`Budget::threads`], through [`par_map_while`]).
///
/// Work is claimed one combination at a time; results land at their index, so the order is
/// deterministic. Before each combination the budget is checked: on a deadline, or once the
/// evaluation cap (counted in combinations) is reached, the remaining combinations are
/// `NotEvaluated`.
///
/// Only the combinations `items` (global indices, see [`crate::calc::common::Shard`]) are run;
/// outcome `k` is combination `items.start + k`, computed exactly as in the whole sweep.
#[must_use]
pub fn compute_sweep(
    input: &SweepInput,
    items: std::ops::Range<usize>,
    budget: &Budget,
) -> SweepResult {
    let items = items.start.min(input.len())..items.end.min(input.len());
    let total = items.len();
    let p = input.params;
    let n = p.n_intervals;
    let table = (n < TRIG_TABLE_MAX_POINTS).then(|| TrigTable::new(n));
    let grid = table.as_ref().map_or(GridTrig::OnTheFly, GridTrig::Table);
    let threads = budget.threads().min(total).max(1);
    let evaluated = AtomicU64::new(0);
    let stop_reason = Mutex::new(None::<StopReason>);
    let record = |r: StopReason| {
        if let Ok(mut g) = stop_reason.lock() {
            g.get_or_insert(r);
        }
    };
    let combos: Vec<usize> = items.collect();
    let results = par_map_while(threads, &combos, |k, &i| {
        if let Some(r) = budget.check(k as u64) {
            record(r);
            return None;
        }
        let d = input.design(i);
        let outcome = match compute_design(&d, &p, grid, None, Some(budget)) {
            Ok(r) => ComboOutcome::Valid(Box::new(r)),
            Err(IrefcError::Deadline { .. }) => {
                record(StopReason::Deadline);
                return None;
            }
            Err(e) => ComboOutcome::Invalid {
                code: e.code(),
                message: e.to_string(),
                geometry: Geometry::new_unchecked(d.r2, d.z2, d.chi, d.rb),
            },
        };
        let done = evaluated.fetch_add(1, Ordering::Relaxed) + 1;
        // Combination counts are far below 2^53: exact in f64.
        budget.progress(done as f64 / total as f64, None);
        Some(outcome)
    });
    let outcomes: Vec<ComboOutcome> = results
        .into_iter()
        .map(|o| o.unwrap_or(ComboOutcome::NotEvaluated))
        .collect();
    let stop = stop_reason
        .into_inner()
        .ok()
        .flatten()
        .unwrap_or(StopReason::Completed);
    SweepResult {
        outcomes,
        stop_reason: stop,
        evaluated: evaluated.load(Ordering::Relaxed),
        threads: u32::try_from(threads).unwrap_or(u32::MAX),
    }
}
