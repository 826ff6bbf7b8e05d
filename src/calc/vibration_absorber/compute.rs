//! `compute`: builds the model of the validated input and runs the requested analyses.

use std::f64::consts::PI;

use nalgebra::{Complex, DMatrix, DVector};

#[path = "ava_step.rs"]
pub mod ava_step;
#[path = "schur_response.rs"]
pub mod schur_response;

use super::beam::ModeShape;
use super::error::VibrationAbsorberError as Error;
use super::input::{
    Config, Forcing, FreqRef, GainSource, Grid, TimeRequest, VibrationAbsorberInput,
};
use super::model::{Device, Gains, Model};
use super::response::{self, Eigen, StepMetrics, Stepper, TimeSeries};
use crate::numerics::linalg::BalancedSchur;
use crate::numerics::{Budget, SolverReport, StopReason};

/// Distance of `x_a` to a node of the tuned mode, relative to L, below which the mode is
/// (nearly) uncontrollable (spec §2 warning).
pub const NODE_WARN_REL: f64 = 1e-3;

/// A complex response per frequency; `None` where `jω` is (numerically) a pole.
pub type Response = Vec<Option<Complex<f64>>>;
/// Coupled FRF: frequencies \[Hz\], abscissae \[m\], one [`Response`] per abscissa.
pub type Frf = (Vec<f64>, Vec<f64>, Vec<Response>);

/// Everything `compute` found, in SI units.
#[derive(Debug, Clone)]
pub struct VibrationAbsorberOutput {
    /// The assembled model (configuration, modal data, gains in use).
    pub model: Model,
    /// `β_k L`.
    pub beta_l: Vec<f64>,
    /// Bare-beam `f_k` \[Hz\].
    pub freqs_hz: Vec<f64>,
    /// Beam mass \[kg\].
    pub beam_mass: f64,
    /// Static compliance at `x_p` [m/N].
    pub static_compliance: f64,
    /// Nodes of the tuned mode \[m\].
    pub tuned_nodes: Option<Vec<f64>>,
    /// Gains (active only).
    pub gains: Option<Gains>,
    /// Table-2 frequencies `(without, with)` \[Hz\].
    pub natural: Option<(Vec<f64>, Vec<f64>)>,
    /// Coupled eigen-analysis.
    pub eigen: Option<Eigen>,
    /// Absorber step responses `(G_ec, G_err)`.
    pub ava_step: Option<(StepMetrics, Option<StepMetrics>)>,
    /// Absorber closed-loop FRF `(f [Hz], G_cl)`.
    pub ava_frf: Option<(Vec<f64>, Response)>,
    /// Coupled FRF `(f [Hz], x_o, H[point][frequency])`.
    pub frf: Option<Frf>,
    /// Time response.
    pub time: Option<TimeOutput>,
    /// Mode shapes `(x [m], φ_k(x))`.
    pub mode_shapes: Option<(Vec<f64>, Vec<Vec<f64>>)>,
    /// Findings the caller should know about (turned into wire warnings by `output.rs`).
    pub warnings: Vec<Notice>,
    /// Cost.
    pub report: SolverReport,
}

/// Something the caller should know about an answer that is nevertheless returned (spec §2
/// warnings, §7 hazards), with the numbers that describe it.
#[derive(Debug, Clone, PartialEq)]
pub enum Notice {
    /// The absorber at `position` \[m\] is within [`NODE_WARN_REL`]·L of `node` \[m\] of the
    /// tuned mode: it cannot act on that mode.
    AbsorberAtNode {
        /// `x_a` \[m\].
        position: f64,
        /// The node \[m\].
        node: f64,
    },
    /// `K_p < 0` [V/m]: the actuator must act as a negative spring.
    NegativeKp {
        /// `K_p` [V/m].
        kp: f64,
    },
    /// An absorber step response does not settle (undamped or without spring).
    NoSettling,
    /// `count` grid frequencies coincide with an undamped eigenvalue (|H| null there).
    UndampedResonance {
        /// Null grid points.
        count: usize,
    },
    /// ζ = 0 with active control: the closed loop is marginal; `max_re` \[1/s\] when the
    /// eigenvalues were computed.
    MarginalStability {
        /// max Re λ \[1/s\].
        max_re: Option<f64>,
    },
    /// The coupled system is unstable.
    Unstable {
        /// max Re λ \[1/s\].
        max_re: f64,
    },
    /// Excitation near but not at the tuning frequency: beating, not cancellation (spec §4
    /// item 10).
    ExcitationOffTuning {
        /// Excitation frequency \[Hz\].
        excitation_hz: f64,
        /// Tuning frequency \[Hz\].
        tuning_hz: f64,
    },
}

/// Time response reductions with their channel layout.
#[derive(Debug, Clone)]
pub struct TimeOutput {
    /// Frequency of each harmonic component \[Hz\] (empty unless harmonic).
    pub excitation_hz: Vec<f64>,
    /// Whether the components were listed (`excitation.harmonics`).
    pub listed: bool,
    /// Samples.
    pub n_samples: usize,
    /// Output abscissae \[m\].
    pub points: Vec<f64>,
    /// Reductions; rows: points, then stroke, force, current, voltage as present.
    pub series: TimeSeries,
    /// Row of the stroke, force, current, voltage (if present).
    pub extra: [Option<usize>; 4],
}

/// Resolves a frequency reference [Hz] against the bare-beam frequencies.
fn hz(f: FreqRef, freqs: &[f64]) -> f64 {
    match f {
        FreqRef::Hz(x) => x,
        FreqRef::Mode(k) => freqs[k.clamp(1, freqs.len()) - 1],
    }
}

/// Frequency of each harmonic component \[Hz\] (empty unless harmonic), references resolved
/// against the bare-beam frequencies `freqs` \[Hz\].
#[must_use]
pub fn excitation_hz(input: &VibrationAbsorberInput, freqs: &[f64]) -> Vec<f64> {
    match &input.forcing {
        Forcing::Harmonic { components, .. } => {
            components.iter().map(|c| hz(c.freq, freqs)).collect()
        }
        _ => Vec::new(),
    }
}

/// Builds the model of spec §3.A–3.C.
#[must_use]
pub fn build_model(input: &VibrationAbsorberInput) -> (Model, Vec<f64>, Option<Gains>) {
    let b = &input.beam;
    let shapes: Vec<ModeShape> = (1..=b.n_modes).map(ModeShape::new).collect();
    let scale = (b.youngs * b.inertia / (b.density * b.area * b.length.powi(4))).sqrt();
    let omega: Vec<f64> = shapes.iter().map(|m| m.beta * m.beta * scale).collect();
    let freqs: Vec<f64> = omega.iter().map(|w| w / (2.0 * PI)).collect();
    let a = &input.absorber;
    let ka = a
        .stiffness
        .unwrap_or_else(|| a.mass * (2.0 * PI * hz(a.passive_tuning, &freqs)).powi(2));
    let act = &input.actuator;
    let dev = Device {
        ma: a.mass,
        ka,
        ba: a.damping,
        r: act.r,
        lc: act.lc,
        kc: act.kc,
        kb: act.kb,
    };
    let gains = (input.config == Config::Active)
        .then(|| match input.gains {
            GainSource::Tuning(f) => dev.tuned_gains(hz(f, &freqs)),
            GainSource::Explicit { kp, kd } => Some(Gains {
                kp,
                kd,
                tuning_hz: None,
                third_pole: dev.third_pole(),
                k_art: None,
            }),
        })
        .flatten();
    let (kp, kd) = gains.map_or((0.0, 0.0), |g| (g.kp, g.kd));
    let xi = |x: f64| (x / b.length).clamp(0.0, 1.0);
    let model = Model {
        config: input.config,
        length: b.length,
        modal_mass: b.density * b.area * b.length,
        zeta: b.zeta,
        phi_a: shapes.iter().map(|m| m.phi(xi(a.position))).collect(),
        phi_p: shapes
            .iter()
            .map(|m| m.phi(xi(input.force_position)))
            .collect(),
        omega,
        shapes,
        dev,
        kp,
        kd,
    };
    (model, freqs, gains)
}

/// Valid fields can still combine into a beam with no finite, positive natural frequency (e.g. a
/// subnormal thickness whose t³ underflows to 0, or E·I overflowing).
fn check_beam(input: &VibrationAbsorberInput, freqs: &[f64]) -> Result<(), Error> {
    match freqs.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        None => Ok(()),
        Some(f) => Err(Error::NonFinite {
            stage: "beam model",
            detail: format!(
                "natural frequency {f:e} Hz from E·I/(ρ·A·L⁴) = {:e}·{:e}/({:e}·{:e}·{:e}⁴)",
                input.beam.youngs,
                input.beam.inertia,
                input.beam.density,
                input.beam.area,
                input.beam.length
            ),
        }),
    }
}

/// The coupled state-space matrices are finite (else a 422, never a non-finite answer).
fn check_state_space(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<(), Error> {
    if a.iter().chain(b.iter()).all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFinite {
            stage: "coupled state-space model",
            detail: "a matrix entry overflows double precision at these unit scales".to_owned(),
        })
    }
}

/// Runs the requested analyses (spec §3.D).
///
/// # Errors
/// A [`Error`] when a result would not be finite, the eigen-iteration fails or the budget runs
/// out.
pub fn compute(
    input: &VibrationAbsorberInput,
    budget: &Budget,
) -> Result<VibrationAbsorberOutput, Error> {
    let (model, freqs, gains) = build_model(input);
    check_beam(input, &freqs)?;
    let mut warnings = Vec::new();
    let mut evaluations = 0_u64;
    let mut iterations = 0_u64;
    let o = &input.outputs;

    let tuned_nodes = design_warnings(&model, &freqs, gains.as_ref(), input, &mut warnings);

    let natural = o
        .natural_frequencies
        .then(|| (freqs.clone(), model.with_absorber_frequencies()));

    let a = model.a_matrix();
    let b = model.b_vector();
    check_state_space(&a, &b)?;
    let need_eig = o.eigenvalues || o.frf.is_some();
    let (eigen, schur) = if need_eig {
        evaluations += 1;
        let (e, s) = schur_response::decompose(&a)?;
        (Some(e), s)
    } else {
        (None, None)
    };
    stability_warning(&model, input.beam.zeta, eigen.as_ref(), &mut warnings);

    let ava_step = o
        .ava_step
        .then(|| ava_step::step_pair(&model.dev, gains.as_ref(), o.ava_step_series));
    if let Some((ec, err)) = &ava_step {
        evaluations += ec.expms + err.as_ref().map_or(0, |e| e.expms);
        if ec.settling.is_none() || err.as_ref().is_some_and(|e| e.settling.is_none()) {
            warnings.push(Notice::NoSettling);
        }
    }
    let ava_frf = o
        .ava_frf
        .as_ref()
        .map(|g| ava_frequency_response(&model.dev, gains.as_ref(), g));

    let frf = match &o.frf {
        Some((grid, points)) => {
            let eig = eigen
                .as_ref()
                .map(|e| e.values.as_slice())
                .unwrap_or_default();
            evaluations += grid.n() as u64;
            Some(coupled_frf(
                &model,
                (&a, &b),
                schur.as_ref(),
                grid,
                points,
                eig,
                budget,
                &mut warnings,
            )?)
        }
        None => None,
    };

    let excitation_hz = excitation_hz(input, &freqs);
    for fe in &excitation_hz {
        tuning_warning(gains.as_ref(), *fe, &mut warnings);
    }
    let time = match &o.time {
        Some(t) => {
            let out = time_response(&model, &a, &b, input, t, &excitation_hz, budget)?;
            evaluations += out.series.expms;
            iterations += t.steps as u64;
            Some(out)
        }
        None => None,
    };

    let mode_shapes = o.mode_shapes.map(|np| {
        let xi: Vec<f64> = (0..np).map(|i| i as f64 / (np - 1) as f64).collect();
        let shapes = model
            .shapes
            .iter()
            .map(|m| xi.iter().map(|x| m.phi(*x)).collect())
            .collect();
        (xi.iter().map(|x| x * model.length).collect(), shapes)
    });

    Ok(VibrationAbsorberOutput {
        beta_l: model.shapes.iter().map(|m| m.beta).collect(),
        beam_mass: model.modal_mass,
        static_compliance: model.static_compliance(input.force_position),
        model,
        freqs_hz: freqs,
        tuned_nodes,
        gains,
        natural,
        eigen,
        ava_step,
        ava_frf,
        frf,
        time,
        mode_shapes,
        warnings,
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations,
            evaluations,
            elapsed_ms: budget.elapsed_ms(),
        },
    })
}

/// Nodes of the tuned mode (the bare-beam mode nearest the tuning, active, or the passive
/// frequency) [m], with the design warnings: absorber at a node, negative K_p.
fn design_warnings(
    model: &Model,
    freqs: &[f64],
    gains: Option<&Gains>,
    input: &VibrationAbsorberInput,
    warnings: &mut Vec<Notice>,
) -> Option<Vec<f64>> {
    let has_absorber = model.config != Config::None;
    // Tuned mode and its nodes (where the absorber cannot act on it).
    let tuned_hz = match (gains, has_absorber) {
        (Some(g), _) => g.tuning_hz,
        (None, true) => Some((model.dev.ka / model.dev.ma).sqrt() / (2.0 * PI)),
        (None, false) => None,
    }
    .filter(|f| *f > 0.0);
    let tuned_nodes = tuned_hz.map(|f| {
        let k = nearest_mode(f, freqs);
        model.shapes[k]
            .nodes()
            .into_iter()
            .map(|x| x * model.length)
            .collect::<Vec<f64>>()
    });
    if let Some(nodes) = &tuned_nodes
        && let Some(x) = nodes
            .iter()
            .find(|x| (*x - input.absorber.position).abs() <= NODE_WARN_REL * model.length)
    {
        warnings.push(Notice::AbsorberAtNode {
            position: input.absorber.position,
            node: *x,
        });
    }
    if let Some(g) = gains
        && g.kp < 0.0
    {
        warnings.push(Notice::NegativeKp { kp: g.kp });
    }
    tuned_nodes
}

/// The coupled receptance on a grid at each abscissa, with the undamped-resonance warning: from
/// the kept Schur form of `A`, or by the dense complex LU per frequency without one.
#[expect(
    clippy::too_many_arguments,
    reason = "the model, its matrices and decomposition, the grid and the caller's collectors"
)]
fn coupled_frf(
    model: &Model,
    (a, b): (&DMatrix<f64>, &DVector<f64>),
    schur: Option<&BalancedSchur>,
    grid: &Grid,
    points: &[f64],
    eig: &[Complex<f64>],
    budget: &Budget,
    warnings: &mut Vec<Notice>,
) -> Result<Frf, Error> {
    let f = grid.frequencies();
    let w: Vec<f64> = f.iter().map(|f| 2.0 * PI * f).collect();
    let rows: Vec<DVector<f64>> = points.iter().map(|x| model.row_deflection(*x)).collect();
    let h = match schur {
        Some(s) => schur_response::frequency_response(s, b, &rows, &w, budget)?,
        None => response::frequency_response(a, b, &rows, &w, eig, budget)?,
    };
    let nulls = h.iter().filter(|r| r.iter().any(Option::is_none)).count();
    if nulls > 0 {
        warnings.push(Notice::UndampedResonance { count: nulls });
    }
    let per_point = (0..points.len())
        .map(|j| h.iter().map(|r| r[j]).collect())
        .collect();
    Ok((f, points.to_vec(), per_point))
}

/// The marginal-stability warning (ζ = 0 with active control, spec §7 item 1) or, otherwise, an
/// unstable label.
fn stability_warning(model: &Model, zeta: f64, eigen: Option<&Eigen>, warnings: &mut Vec<Notice>) {
    if model.config == Config::Active && zeta == 0.0 {
        warnings.push(Notice::MarginalStability {
            max_re: eigen.map(|e| e.max_re),
        });
    } else if let Some(e) = eigen
        && e.stability == response::Stab::Unstable
    {
        warnings.push(Notice::Unstable { max_re: e.max_re });
    }
}

/// Excitation near but not at the tuning frequency: beating, not cancellation (spec §4 item 10).
fn tuning_warning(gains: Option<&Gains>, fe: f64, warnings: &mut Vec<Notice>) {
    if let Some(g) = gains
        && let Some(fc) = g.tuning_hz
    {
        let rel = (fe - fc).abs() / fc;
        if rel > 1e-9 && rel < 0.02 {
            warnings.push(Notice::ExcitationOffTuning {
                excitation_hz: fe,
                tuning_hz: fc,
            });
        }
    }
}

/// Index (0-based) of the bare-beam mode nearest `f` on a log scale.
fn nearest_mode(f: f64, freqs: &[f64]) -> usize {
    let d = |g: f64| (f / g).ln().abs();
    (0..freqs.len())
        .min_by(|i, j| d(freqs[*i]).total_cmp(&d(freqs[*j])))
        .unwrap_or(0)
}

/// `G_cl(j2πf) = N/(D + N)`, `N = K_c(K_p + K_d s)`; `None` where `D + N` vanishes to rounding.
fn ava_frequency_response(
    dev: &Device,
    gains: Option<&Gains>,
    grid: &Grid,
) -> (Vec<f64>, Response) {
    let f = grid.frequencies();
    let (kp, kd) = gains.map_or((0.0, 0.0), |g| (g.kp, g.kd));
    let h = f
        .iter()
        .map(|f| {
            let s = Complex::new(0.0, 2.0 * PI * f);
            let num = (s * kd + kp) * dev.kc;
            let d = dev.d_poly(s);
            let den = d + num;
            let scale = d.norm() + num.norm();
            (den.norm() > 1e-13 * scale).then(|| num / den)
        })
        .collect();
    (f, h)
}

/// The augmented autonomous system of a time response (spec §3.D.4) and what to sample.
#[derive(Debug, Clone)]
pub struct AugmentedSystem {
    /// `A_aug`.
    pub a: DMatrix<f64>,
    /// `s_aug(0)`.
    pub s0: DVector<f64>,
    /// Output rows: the requested abscissae, then stroke, force, current, voltage as present.
    pub rows: Vec<DVector<f64>>,
    /// Row of the stroke, force, current, voltage (if present).
    pub extra: [Option<usize>; 4],
    /// First sample of the "last period" window.
    pub last_from: usize,
    /// Whether the harmonic components were listed (`excitation.harmonics`).
    pub listed: bool,
}

/// The augmented system of the exact time response: a harmonic force adds one 2×2 exosystem
/// block `[[0, Ω_j], [−Ω_j, 0]]` per component (state `[sin(Ω_j t + φ_j), cos(Ω_j t + φ_j)]`,
/// driving `A` through `P_j B`), a step one constant state, an impulse only the initial state
/// `P0 B`.
#[must_use]
pub fn augmented_system(
    model: &Model,
    (a, b): (&DMatrix<f64>, &DVector<f64>),
    input: &VibrationAbsorberInput,
    t: &TimeRequest,
    excitation_hz: &[f64],
) -> AugmentedSystem {
    let n = a.nrows();
    let p0 = input.amplitude;
    let (extra_states, listed) = match &input.forcing {
        Forcing::Harmonic { components, listed } => (2 * components.len(), *listed),
        Forcing::Step => (1, false),
        Forcing::Impulse | Forcing::None => (0, false),
    };
    let na = n + extra_states;
    let mut aug = DMatrix::zeros(na, na);
    aug.view_mut((0, 0), (n, n)).copy_from(a);
    let mut s0 = DVector::zeros(na);
    match &input.forcing {
        Forcing::Harmonic { components, .. } => {
            for (j, (c, f)) in components.iter().zip(excitation_hz).enumerate() {
                let (s, w) = (n + 2 * j, 2.0 * PI * f);
                aug.view_mut((0, s), (n, 1)).copy_from(&(b * c.amplitude));
                aug[(s, s + 1)] = w;
                aug[(s + 1, s)] = -w;
                s0[s] = c.phase.sin();
                s0[s + 1] = c.phase.cos();
            }
        }
        Forcing::Step => {
            aug.view_mut((0, n), (n, 1)).copy_from(&(b * p0));
            s0[n] = 1.0;
        }
        Forcing::Impulse => s0.rows_mut(0, n).copy_from(&(b * p0)),
        Forcing::None => {}
    }
    let pad = |c: DVector<f64>| {
        let mut r = DVector::zeros(na);
        r.rows_mut(0, n).copy_from(&c);
        r
    };
    let mut rows: Vec<DVector<f64>> = t
        .points
        .iter()
        .map(|x| pad(model.row_deflection(*x)))
        .collect();
    let mut extra = [None; 4];
    let candidates = [
        model.row_stroke(false),
        model.row_current(model.dev.kc),
        model.row_current(1.0),
        model.row_voltage(),
    ];
    for (slot, c) in extra.iter_mut().zip(candidates) {
        if let Some(c) = c {
            *slot = Some(rows.len());
            rows.push(pad(c));
        }
    }
    // "Last period": the longest component period (each component completes a period in it).
    let window = excitation_hz
        .iter()
        .copied()
        .filter(|f| *f > 0.0)
        .reduce(f64::min)
        .map_or(1.0, |f| 1.0 / f);
    let t_end = t.steps as f64 * t.dt;
    let last_from = ((t_end - window) / t.dt).ceil().max(0.0) as usize;
    AugmentedSystem {
        a: aug,
        s0,
        rows,
        extra,
        last_from: last_from.min(t.steps),
        listed,
    }
}

/// The exact time response (spec §3.D.4): the augmented autonomous system stepped with one
/// matrix exponential in the original coordinates ([`Stepper::run`]). Stepping in the Schur
/// coordinates ([`schur_response::time_response`]) was measured no faster on the api-like cases
/// (benches/RESULTS.md, issue 27) and is not used.
fn time_response(
    model: &Model,
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    input: &VibrationAbsorberInput,
    t: &TimeRequest,
    excitation_hz: &[f64],
    budget: &Budget,
) -> Result<TimeOutput, Error> {
    let sys = augmented_system(model, (a, b), input, t, excitation_hz);
    let stepper = Stepper {
        a: &sys.a,
        s0: &sys.s0,
        rows: &sys.rows,
        steps: t.steps,
        dt: t.dt,
        last_from: sys.last_from,
        decimate: t.series.then_some(t.decimate),
    };
    let series = stepper.run(budget)?;
    Ok(TimeOutput {
        excitation_hz: excitation_hz.to_vec(),
        listed: sys.listed,
        n_samples: t.steps + 1,
        points: t.points.clone(),
        series,
        extra: sys.extra,
    })
}
