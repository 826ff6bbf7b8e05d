//! Validation of an [`IrefcStressRequest`] into SI domain input, collecting every issue.

use super::wire::{IrefcStressRequest, LoadSharing, OutputLink, StressInclude, StressMode};
use crate::calc::CalcFailure;
use crate::calc::irefc::error::{BAD_RANGE, GRID_TOO_FINE, Issues, SWEEP_TOO_LARGE};
use crate::calc::irefc::wire::{
    MM, PROFILE_POINTS_DEFAULT, PROFILE_POINTS_MAX, PROFILE_POINTS_MIN, Warning, check_chi,
    check_r2, check_rb, check_z2, missing,
};

/// Default φ2 grid step [deg]: 1° + refinement is ≤ 1e-10 from the exact maximum and ~40× cheaper than the
/// paper's 0.02° grid (whose error is 1.8e-8); see `benches/RESULTS.md` (## irefc).
pub const STEP_DEG_DEFAULT: f64 = 1.0;
/// The paper's grid step [deg] (0.02°, no refinement).
pub const STEP_DEG_PAPER: f64 = 0.02;
/// Largest admitted grid step [deg] (spec).
pub const STEP_DEG_MAX: f64 = 10.0;
/// Largest number of grid intervals 180/step (spec: 180/step ≤ 2·10⁶).
pub const GRID_INTERVALS_MAX: f64 = 2e6;
/// Largest number of sweep combinations (spec).
pub const SWEEP_COMBINATIONS_MAX: u64 = 100_000;
/// Largest sweep work, combinations × grid points (spec).
pub const SWEEP_WORK_MAX: f64 = 5e8;
/// Tolerance on the last χ of a sweep range: χ_i = from + i·step is kept while ≤ to + this (spec).
pub const CHI_RANGE_TOL: f64 = 1e-12;
/// Largest output torque [N·m] (spec).
pub const TORQUE_MAX_NM: f64 = 1e7;
/// lb may be at most this multiple of r2 (spec).
pub const LB_MAX_OVER_R2: f64 = 100.0;

/// Scalar settings shared by every combination [SI].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StressParams {
    /// Output torque T_out [N·m].
    pub torque: f64,
    /// Output link.
    pub output_link: OutputLink,
    /// Contact length [m]; `None` = 2·rb of each design.
    pub lb: Option<f64>,
    /// Contact modulus E* [Pa].
    pub e_star: f64,
    /// Requested grid step [deg].
    pub step_deg: f64,
    /// Grid intervals N = round(180/step) (grid points N + 1).
    pub n_intervals: usize,
    /// Refine maxima.
    pub refine: bool,
    /// Load-sharing mode.
    pub load_sharing: LoadSharing,
    /// Report τ_max and its depth.
    pub subsurface: bool,
}

/// One design of the four initial parameters [SI].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Design {
    /// r2 [m].
    pub r2: f64,
    /// Z2.
    pub z2: u32,
    /// χ.
    pub chi: f64,
    /// rb [m].
    pub rb: f64,
}

/// Validated single-design input.
#[derive(Debug, Clone, PartialEq)]
pub struct SingleInput {
    /// The design.
    pub design: Design,
    /// Shared settings.
    pub params: StressParams,
    /// Output the element table.
    pub elements: bool,
    /// Output curves with this stride.
    pub curves_stride: Option<usize>,
    /// Output profiles with this many points per wheel.
    pub profile_points: Option<u32>,
}

/// Validated sweep input.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepInput {
    /// Z2 values, ascending.
    pub z2: Vec<u32>,
    /// χ values in order.
    pub chi: Vec<f64>,
    /// rb values [m].
    pub rb: Vec<f64>,
    /// r2 values [m].
    pub r2: Vec<f64>,
    /// Shared settings.
    pub params: StressParams,
    /// Request-level warnings (ignored fields).
    pub warnings: Vec<Warning>,
}

impl SweepInput {
    /// Number of combinations.
    #[must_use]
    pub fn len(&self) -> usize {
        self.z2.len() * self.chi.len() * self.rb.len() * self.r2.len()
    }

    /// Whether the sweep is empty (never, after validation).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The design of combination `i` (order: Z2, then χ, then rb, then r2 innermost).
    #[must_use]
    pub fn design(&self, i: usize) -> Design {
        let n_r2 = self.r2.len().max(1);
        let n_rb = self.rb.len().max(1);
        let n_chi = self.chi.len().max(1);
        let i_r2 = i % n_r2;
        let i_rb = (i / n_r2) % n_rb;
        let i_chi = (i / (n_r2 * n_rb)) % n_chi;
        let i_z2 = i / (n_r2 * n_rb * n_chi);
        Design {
            r2: self.r2.get(i_r2).copied().unwrap_or(f64::NAN),
            z2: self.z2.get(i_z2).copied().unwrap_or(0),
            chi: self.chi.get(i_chi).copied().unwrap_or(f64::NAN),
            rb: self.rb.get(i_rb).copied().unwrap_or(f64::NAN),
        }
    }
}

/// Validated input of `POST /v1/irefc-stress`.
#[derive(Debug, Clone, PartialEq)]
pub enum StressInput {
    /// One design.
    Single(SingleInput),
    /// The structured array.
    Sweep(SweepInput),
}

/// χ values from + i·step ≤ to (+ tolerance), clamped to `to`; `None` when there would be more than
/// `max` of them.
#[must_use]
pub fn chi_values(from: f64, to: f64, step: f64, max: u64) -> Option<Vec<f64>> {
    let approx = ((to - from + CHI_RANGE_TOL) / step).floor() + 1.0;
    // `max` ≤ 1e5 is exactly representable in f64.
    let maxf = max as f64;
    if !(approx.is_finite() && approx <= maxf + 1.0) {
        return None;
    }
    let mut v = Vec::new();
    for i in 0..=max {
        // i ≤ 1e5: exact in f64.
        let c = step.mul_add(i as f64, from);
        if c > to + CHI_RANGE_TOL {
            break;
        }
        if i == max {
            return None;
        }
        v.push(c.min(to));
    }
    Some(v)
}

impl StressInput {
    /// Validate a request (spec "Inputs"); every range problem is reported at once (`BAD_RANGE`,
    /// `MISSING_FIELD`), then grid/sweep size (`GRID_TOO_FINE`, `SWEEP_TOO_LARGE`). Feasibility (`UNDERCUT`,
    /// `ELEMENT_OVERLAP`) is checked on the geometry by the caller.
    pub fn try_from_request(req: &IrefcStressRequest) -> Result<Self, CalcFailure> {
        let mut is = Issues::new();
        let mut warnings = Vec::new();
        let mode = match (req.mode, req.sweep.is_some()) {
            (Some(m), _) => m,
            (None, true) => StressMode::Sweep,
            (None, false) => StressMode::Single,
        };
        if mode == StressMode::Single && req.sweep.is_some() {
            is.push(
                BAD_RANGE,
                "/sweep",
                "sweep is only allowed with mode \"sweep\"",
            );
        }

        is.range(
            "/torque_Nm",
            "output torque torque_Nm",
            req.torque_nm,
            0.0,
            TORQUE_MAX_NM,
        );
        let wm = req.wheel_material.unwrap_or_default();
        let rm = req.roller_material.unwrap_or_default();
        wm.validate(&mut is, "/wheel_material");
        rm.validate(&mut is, "/roller_material");

        let step_deg = req.step_deg.unwrap_or(STEP_DEG_DEFAULT);
        let mut n_intervals = 0usize;
        if is.range_open_lo(
            "/step_deg",
            "grid step step_deg",
            step_deg,
            0.0,
            STEP_DEG_MAX,
        ) {
            let n = (180.0 / step_deg).round();
            if 180.0 / step_deg > GRID_INTERVALS_MAX {
                is.push(
                    GRID_TOO_FINE,
                    "/step_deg",
                    format!("grid step {step_deg} deg gives 180/step = {} intervals > {GRID_INTERVALS_MAX}", 180.0 / step_deg),
                );
            } else {
                // 18 ≤ n ≤ 2e6 here: the conversion is exact.
                {
                    n_intervals = n as usize;
                }
            }
        }
        let include: StressInclude = req.include.unwrap_or_default();
        if let Some(s) = req.curves_stride {
            is.ensure(s >= 1, "/curves_stride", || {
                format!("curves_stride must be >= 1, got {s}")
            });
        }
        if let Some(n) = req.profile_points {
            is.ensure(
                (PROFILE_POINTS_MIN..=PROFILE_POINTS_MAX).contains(&n),
                "/profile_points",
                || format!("profile_points must be in [{PROFILE_POINTS_MIN}, {PROFILE_POINTS_MAX}], got {n}"),
            );
        }

        let r2 = req.r2_mm.and_then(|v| check_r2(&mut is, "/r2_mm", v));
        let rb = req.rb_mm.and_then(|v| check_rb(&mut is, "/rb_mm", v));
        let e_star = 1.0 / (wm.compliance() + rm.compliance());
        let refine = req.refine.unwrap_or(true);
        let load_sharing = req.load_sharing.unwrap_or_default();
        let subsurface = include.subsurface.unwrap_or(false);

        match mode {
            StressMode::Single => {
                if req.r2_mm.is_none() {
                    missing(&mut is, "/r2_mm", "r2_mm");
                }
                if req.rb_mm.is_none() {
                    missing(&mut is, "/rb_mm", "rb_mm");
                }
                let z2 = match req.z2 {
                    Some(v) => check_z2(&mut is, "/Z2", v),
                    None => {
                        missing(&mut is, "/Z2", "Z2 (mode \"single\")");
                        None
                    }
                };
                let chi = match req.chi {
                    Some(v) => check_chi(&mut is, "/chi", v),
                    None => {
                        missing(&mut is, "/chi", "chi (mode \"single\")");
                        None
                    }
                };
                let lb = check_lb(&mut is, req.lb_mm, r2.as_slice());
                is.finish()?;
                let (Some(r2), Some(z2), Some(chi), Some(rb)) = (r2, z2, chi, rb) else {
                    // Unreachable: each None recorded an issue and `finish` returned.
                    return Err(CalcFailure::general(
                        crate::calc::ProblemClass::InvalidInput,
                        BAD_RANGE,
                        "incomplete design",
                    ));
                };
                let params = StressParams {
                    torque: req.torque_nm,
                    output_link: req.output_link.unwrap_or_default(),
                    lb: lb.map(|v| v / MM),
                    e_star,
                    step_deg,
                    n_intervals,
                    refine,
                    load_sharing,
                    subsurface,
                };
                let curves_stride = include
                    .curves
                    .unwrap_or(false)
                    .then(|| usize::try_from(req.curves_stride.unwrap_or(1)).unwrap_or(usize::MAX));
                let profile_points = include
                    .profiles
                    .unwrap_or(false)
                    .then(|| req.profile_points.unwrap_or(PROFILE_POINTS_DEFAULT));
                Ok(Self::Single(SingleInput {
                    design: Design {
                        r2: r2 / MM,
                        z2,
                        chi,
                        rb: rb / MM,
                    },
                    params,
                    elements: include.elements.unwrap_or(true),
                    curves_stride,
                    profile_points,
                }))
            }
            StressMode::Sweep => {
                let Some(sw) = req.sweep.as_ref() else {
                    missing(&mut is, "/sweep", "sweep (mode \"sweep\")");
                    return Err(is.finish().err().unwrap_or_else(|| {
                        CalcFailure::general(
                            crate::calc::ProblemClass::InvalidInput,
                            BAD_RANGE,
                            "sweep missing",
                        )
                    }));
                };
                // Ignored, but still held to their documented ranges: a request the published
                // schema rejects is rejected here too.
                if let Some(v) = req.z2 {
                    check_z2(&mut is, "/Z2", v);
                }
                if let Some(v) = req.chi {
                    check_chi(&mut is, "/chi", v);
                }
                if req.z2.is_some() || req.chi.is_some() {
                    warnings.push(Warning::new(
                        "FIELD_IGNORED",
                        "scalar Z2/chi are ignored in mode \"sweep\" (the sweep ranges are used)",
                    ));
                }
                if include.elements == Some(true)
                    || include.curves == Some(true)
                    || include.profiles == Some(true)
                {
                    warnings.push(Warning::new(
                        "FIELD_IGNORED",
                        "include.elements/curves/profiles are forced off in mode \"sweep\"",
                    ));
                }
                // Z2 range
                let zf = check_z2(&mut is, "/sweep/Z2/from", sw.z2.from);
                let zt = check_z2(&mut is, "/sweep/Z2/to", sw.z2.to);
                let mut z2s = Vec::new();
                if let (Some(a), Some(b)) = (zf, zt) {
                    if a > b {
                        is.push(
                            BAD_RANGE,
                            "/sweep/Z2/to",
                            format!("Z2.to = {b} must be >= Z2.from = {a}"),
                        );
                    } else {
                        z2s = (a..=b).collect();
                    }
                }
                // chi range
                let cf = check_chi(&mut is, "/sweep/chi/from", sw.chi.from);
                let ct = check_chi(&mut is, "/sweep/chi/to", sw.chi.to);
                let step_ok = sw.chi.step.is_finite() && sw.chi.step > 0.0;
                if !step_ok {
                    is.push(
                        BAD_RANGE,
                        "/sweep/chi/step",
                        format!("chi.step must be a finite number > 0, got {}", sw.chi.step),
                    );
                }
                let mut chis = Vec::new();
                let mut chi_too_many = false;
                if let (Some(a), Some(b), true) = (cf, ct, step_ok) {
                    if a > b {
                        is.push(
                            BAD_RANGE,
                            "/sweep/chi/to",
                            format!("chi.to = {b} must be >= chi.from = {a}"),
                        );
                    } else if let Some(v) = chi_values(a, b, sw.chi.step, SWEEP_COMBINATIONS_MAX) {
                        chis = v;
                    } else {
                        chi_too_many = true;
                    }
                }
                // rb, r2 lists
                let rbs: Vec<f64> = match &sw.rb_mm {
                    Some(list) => {
                        if list.is_empty() {
                            is.push(BAD_RANGE, "/sweep/rb_mm", "rb_mm list must not be empty");
                        }
                        list.iter()
                            .enumerate()
                            .filter_map(|(i, &v)| {
                                check_rb(&mut is, &format!("/sweep/rb_mm/{i}"), v)
                            })
                            .collect()
                    }
                    None => {
                        if req.rb_mm.is_none() {
                            missing(&mut is, "/rb_mm", "rb_mm (or sweep.rb_mm)");
                        }
                        rb.into_iter().collect()
                    }
                };
                let r2s: Vec<f64> = match &sw.r2_mm {
                    Some(list) => {
                        if list.is_empty() {
                            is.push(BAD_RANGE, "/sweep/r2_mm", "r2_mm list must not be empty");
                        }
                        list.iter()
                            .enumerate()
                            .filter_map(|(i, &v)| {
                                check_r2(&mut is, &format!("/sweep/r2_mm/{i}"), v)
                            })
                            .collect()
                    }
                    None => {
                        if req.r2_mm.is_none() {
                            missing(&mut is, "/r2_mm", "r2_mm (or sweep.r2_mm)");
                        }
                        r2.into_iter().collect()
                    }
                };
                let lb = check_lb(&mut is, req.lb_mm, &r2s);
                if !is.is_empty() {
                    is.finish()?;
                }
                // Sizes (only once the ranges are valid).
                let combos = (z2s.len() as u64)
                    .saturating_mul(chis.len() as u64)
                    .saturating_mul(rbs.len() as u64)
                    .saturating_mul(r2s.len() as u64);
                if chi_too_many || combos > SWEEP_COMBINATIONS_MAX {
                    is.push(
                        SWEEP_TOO_LARGE,
                        "/sweep",
                        format!(
                            "the sweep has {} combinations > {SWEEP_COMBINATIONS_MAX}",
                            if chi_too_many {
                                "more than 100000".to_owned()
                            } else {
                                combos.to_string()
                            }
                        ),
                    );
                } else {
                    // combos ≤ 1e5, n_intervals ≤ 2e6: both exact in f64.
                    let work = combos as f64 * (n_intervals as f64 + 1.0);
                    if work > SWEEP_WORK_MAX {
                        is.push(
                            SWEEP_TOO_LARGE,
                            "/sweep",
                            format!(
                                "combinations x grid points = {combos} x {} = {work} > {SWEEP_WORK_MAX}; use a coarser step_deg",
                                n_intervals + 1
                            ),
                        );
                    }
                }
                is.finish()?;
                let params = StressParams {
                    torque: req.torque_nm,
                    output_link: req.output_link.unwrap_or_default(),
                    lb: lb.map(|v| v / MM),
                    e_star,
                    step_deg,
                    n_intervals,
                    refine,
                    load_sharing,
                    subsurface,
                };
                Ok(Self::Sweep(SweepInput {
                    z2: z2s,
                    chi: chis,
                    rb: rbs.into_iter().map(|v| v / MM).collect(),
                    r2: r2s.into_iter().map(|v| v / MM).collect(),
                    params,
                    warnings,
                }))
            }
        }
    }
}

/// Validate lb [mm] against 0 < lb ≤ 100·r2 for every r2 given; returns it when valid.
fn check_lb(is: &mut Issues, lb: Option<f64>, r2s_mm: &[f64]) -> Option<f64> {
    let v = lb?;
    let r2_min = r2s_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = if r2_min.is_finite() {
        LB_MAX_OVER_R2 * r2_min
    } else {
        f64::INFINITY
    };
    let ok = v.is_finite() && v > 0.0 && v <= hi;
    if !ok {
        is.push(
            BAD_RANGE,
            "/lb_mm",
            if hi.is_finite() {
                format!("contact length lb_mm must be in (0, 100*r2 = {hi}], got {v}")
            } else {
                format!("contact length lb_mm must be in (0, 100*r2], got {v}")
            },
        );
    }
    ok.then_some(v)
}
