//! The validated request in SI units (spec §2): defaults filled in and the rules between fields
//! checked (the per-field rules are `#[rule]`s on the wire types, checked at the door).

use std::time::Duration;

use crate::calc::common::{RESPONSE_TOO_LARGE_RULE, TimeLimited};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Validator};

use super::error::{DEADLINE_RULE, EIGEN_NOT_CONVERGED_RULE, NON_FINITE_RULE};
use super::wire::{
    self, ExcitationIn, ExcitationType, GridIn, HarmonicIn, TimeResponseIn,
    VibrationAbsorberRequest,
};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/vibration-absorber` and the failures of its
    /// computation, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid SECTION_CONFLICT ["/beam/section", "/beam/area_m2", "/beam/second_moment_m4"]
        "beam.section and beam.area_m2 / beam.second_moment_m4 are not given together.";
    invalid SECTION_PAIR ["/beam/area_m2", "/beam/second_moment_m4"]
        "beam.area_m2 and beam.second_moment_m4 are given together or not at all.";
    invalid STIFFNESS_CONFLICT ["/absorber/stiffness_n_m", "/absorber/passive_tuning_hz",
        "/absorber/passive_tuning_mode"]
        "At most one of absorber.stiffness_n_m, passive_tuning_hz and passive_tuning_mode is given.";
    invalid MODE_OUT_OF_RANGE ["/beam/n_modes", "/absorber/passive_tuning_mode",
        "/control/tuning_mode", "/excitation/resonance_of_mode",
        "/excitation/harmonics/*/resonance_of_mode"]
        "Every mode reference (passive_tuning_mode, tuning_mode, resonance_of_mode) is at most \
         beam.n_modes (default 3).";
    invalid POSITION_OUT_OF_BEAM ["/beam/length_m", "/absorber/position_m",
        "/excitation/position_m", "/outputs/frequency_response/points_m/*",
        "/outputs/time_response/points_m/*"]
        "absorber.position_m, excitation.position_m and every output abscissa points_m are at most \
         beam.length_m (default 1 m).";
    invalid ZERO_FORCE_CONSTANT ["/actuator/force_constant_n_a", "/control/mode"]
        "With control.mode = active (the default), actuator.force_constant_n_a is not 0 (the gains \
         divide by K_c).";
    invalid TUNING_CONFLICT ["/control/tuning_hz", "/control/tuning_mode"]
        "At most one of control.tuning_hz and control.tuning_mode is given.";
    invalid GAIN_PAIR ["/control/kp_v_m", "/control/kd_v_s_m"]
        "control.kp_v_m and control.kd_v_s_m are given together or not at all.";
    invalid FREQUENCY_CONFLICT ["/excitation/frequency_hz", "/excitation/resonance_of_mode"]
        "At most one of excitation.frequency_hz and excitation.resonance_of_mode is given.";
    invalid HARMONICS_CONFLICT ["/excitation/harmonics", "/excitation/amplitude_n",
        "/excitation/frequency_hz", "/excitation/resonance_of_mode", "/excitation/phase_rad"]
        "With excitation.harmonics, the single harmonic's amplitude_n, frequency_hz, \
         resonance_of_mode and phase_rad are absent.";
    invalid HARMONICS_TYPE ["/excitation/harmonics", "/excitation/type"]
        "excitation.harmonics is given only with excitation.type = harmonic (the default).";
    invalid GRID_ORDER ["/outputs/ava_frequency_response/f_max_hz",
        "/outputs/frequency_response/f_max_hz"]
        "A frequency grid's f_max_hz is greater than its f_min_hz (equal only with n_points = 1).";
    too_large TOO_MANY_SAMPLES ["/outputs/time_response/t_end_s", "/outputs/time_response/dt_s"]
        "outputs.time_response.t_end_s / dt_s is at most 2e6 samples.";
    listed RESPONSE_TOO_LARGE_RULE;
    listed NON_FINITE_RULE;
    listed EIGEN_NOT_CONVERGED_RULE;
    listed DEADLINE_RULE;
}

/// Configuration (which states the model has): the request's `control.mode`.
pub use super::wire::ControlMode as Config;

/// A frequency given in Hz or as a bare-beam mode index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FreqRef {
    /// \[Hz\].
    Hz(f64),
    /// Mode k (1-based) of the bare beam.
    Mode(usize),
}

/// The beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// `L` \[m\].
    pub length: f64,
    /// `E` \[Pa\].
    pub youngs: f64,
    /// `ρ` [kg/m³].
    pub density: f64,
    /// `A` \[m²\].
    pub area: f64,
    /// `I` \[m⁴\].
    pub inertia: f64,
    /// `n`.
    pub n_modes: usize,
    /// `ζ`.
    pub zeta: f64,
}

/// The absorber.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Absorber {
    /// `m_a` \[kg\].
    pub mass: f64,
    /// Explicit `k_a` [N/m].
    pub stiffness: Option<f64>,
    /// Passive tuning (used when `stiffness` is `None`).
    pub passive_tuning: FreqRef,
    /// `b_a` [N·s/m].
    pub damping: f64,
    /// `x_a` \[m\].
    pub position: f64,
}

/// The actuator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuator {
    /// `R` \[Ω\].
    pub r: f64,
    /// `L_c` \[H\].
    pub lc: f64,
    /// `K_c` [N/A].
    pub kc: f64,
    /// `K_b` [V·s/m].
    pub kb: f64,
}

/// Where the PD gains come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GainSource {
    /// Eq. (7)(8) for a target frequency.
    Tuning(FreqRef),
    /// Explicit `K_p`, `K_d`.
    Explicit {
        /// [V/m].
        kp: f64,
        /// [V·s/m].
        kd: f64,
    },
}

/// One harmonic component `P sin(Ωt + φ)` of the force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// `P` \[N\].
    pub amplitude: f64,
    /// Ω/2π.
    pub freq: FreqRef,
    /// φ \[rad\].
    pub phase: f64,
}

/// Time law of the force.
#[derive(Debug, Clone, PartialEq)]
pub enum Forcing {
    /// `Σ_j P_j sin(Ω_j t + φ_j)`: one component for the single-harmonic form.
    Harmonic {
        /// The components (at least one).
        components: Vec<Harmonic>,
        /// Whether the request listed them (`excitation.harmonics`) rather than giving one.
        listed: bool,
    },
    /// Impulse `P0` [N·s] at t = 0.
    Impulse,
    /// Step `P0`.
    Step,
    /// None.
    None,
}

/// A frequency grid: the request's (its ranges checked at the door, its order here).
pub use super::wire::GridIn as Grid;

impl Grid {
    /// Points (at least 1 at the door).
    #[must_use]
    pub fn n(&self) -> usize {
        self.n_points.max(1) as usize
    }

    /// The frequencies \[Hz\].
    #[must_use]
    pub fn frequencies(&self) -> Vec<f64> {
        let (n, f_min, f_max) = (self.n(), self.f_min_hz, self.f_max_hz);
        if n == 1 {
            return vec![f_min];
        }
        let last = (n - 1) as f64;
        (0..n)
            .map(|i| {
                let t = i as f64 / last;
                if self.log {
                    f_min * (f_max / f_min).powf(t)
                } else {
                    f_min + (f_max - f_min) * t
                }
            })
            .collect()
    }
}

/// Time response request.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeRequest {
    /// Number of steps K (samples K + 1).
    pub steps: usize,
    /// Output step \[s\].
    pub dt: f64,
    /// Output abscissae \[m\].
    pub points: Vec<f64>,
    /// Return series.
    pub series: bool,
    /// Decimation.
    pub decimate: usize,
}

/// The analyses asked for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Outputs {
    /// Table-2 frequencies.
    pub natural_frequencies: bool,
    /// Eigenvalues.
    pub eigenvalues: bool,
    /// Absorber step responses.
    pub ava_step: bool,
    /// ... with series.
    pub ava_step_series: bool,
    /// Absorber closed-loop FRF.
    pub ava_frf: Option<Grid>,
    /// Coupled FRF: grid and abscissae.
    pub frf: Option<(Grid, Vec<f64>)>,
    /// Time response.
    pub time: Option<TimeRequest>,
    /// Mode-shape samples.
    pub mode_shapes: Option<usize>,
}

/// The validated request.
#[derive(Debug, Clone, PartialEq)]
pub struct VibrationAbsorberInput {
    /// Beam.
    pub beam: Beam,
    /// Absorber.
    pub absorber: Absorber,
    /// Actuator.
    pub actuator: Actuator,
    /// Configuration.
    pub config: Config,
    /// Gains (used with `active`).
    pub gains: GainSource,
    /// Force law.
    pub forcing: Forcing,
    /// `x_p` \[m\].
    pub force_position: f64,
    /// `P0` \[N\] or [N·s] of an impulse or a step (the single harmonic's amplitude too; the
    /// components carry their own).
    pub amplitude: f64,
    /// Analyses.
    pub outputs: Outputs,
}

impl TimeLimited for VibrationAbsorberRequest {
    fn time_limit(&self) -> Option<Duration> {
        self.time_limit_ms.map(Duration::from_millis)
    }
}

/// A mode reference `k` (already in `MODE_INDEX` at the door) against `beam.n_modes`.
fn mode_ref(v: &mut Validator, pointer: &str, name: &str, k: u32, n_modes: usize) -> usize {
    ensure_rule!(v, k as usize <= n_modes, MODE_OUT_OF_RANGE, pointer;
        "{name} must be ≤ beam.n_modes = {n_modes}, got {k}");
    (k as usize).clamp(1, n_modes.max(1))
}

/// A frequency given as `hz` or as mode `k`, at most one (`default` when neither).
fn freq_or_mode(
    v: &mut Validator,
    hz: Option<f64>,
    (mode, mode_pointer, mode_name): (Option<u32>, &str, &str),
    n_modes: usize,
    default: FreqRef,
) -> FreqRef {
    match (hz, mode) {
        (Some(f), _) => FreqRef::Hz(f),
        (None, Some(k)) => FreqRef::Mode(mode_ref(v, mode_pointer, mode_name, k, n_modes)),
        (None, None) => default,
    }
}

/// A position in (0, L] (the lower end and `LENGTH` are checked at the door).
fn position(v: &mut Validator, pointer: &str, x: Option<f64>, length: f64) -> f64 {
    let p = x.unwrap_or(length);
    ensure_rule!(v, p <= length, POSITION_OUT_OF_BEAM, pointer;
        "must be ≤ beam.length_m = {length} m, got {p}");
    p
}

/// Output abscissae in [0, L] (default: the tip; count and `ABSCISSA` checked at the door).
fn abscissae(v: &mut Validator, pointer: &str, xs: Option<&Vec<f64>>, length: f64) -> Vec<f64> {
    let Some(xs) = xs else {
        return vec![length];
    };
    for (i, x) in xs.iter().enumerate() {
        ensure_rule!(v, *x <= length, POSITION_OUT_OF_BEAM, format!("{pointer}/{i}");
            "points_m[{i}] [m] must be ≤ beam.length_m = {length} m, got {x}");
    }
    xs.clone()
}

/// A frequency grid: `f_min < f_max` (equal only with one point).
fn grid(v: &mut Validator, base: &str, g: &GridIn) -> Grid {
    let ok = g.f_max_hz > g.f_min_hz || (g.n_points == 1 && g.f_max_hz >= g.f_min_hz);
    ensure_rule!(v, ok, GRID_ORDER, format!("{base}/f_max_hz");
        "f_max_hz [Hz] must be > f_min_hz = {} Hz, got {}", g.f_min_hz, g.f_max_hz);
    g.clone()
}

fn time(v: &mut Validator, t: &TimeResponseIn, length: f64) -> TimeRequest {
    let base = "/outputs/time_response";
    let ratio = t.t_end_s / t.dt_s;
    ensure_rule!(v, ratio <= wire::MAX_SAMPLES, TOO_MANY_SAMPLES, format!("{base}/dt_s");
        "t_end_s / dt_s must be ≤ {:e} samples, got {ratio:.6e} (t_end_s = {} s, dt_s = {} s)",
        wire::MAX_SAMPLES, t.t_end_s, t.dt_s);
    let decimate = t.decimate.unwrap_or(1);
    // Steps: t_end/dt rounded (a ratio within 1e-9 of an integer is that integer).
    let steps = if ratio.is_finite() && ratio > 0.0 {
        (ratio - 1e-9 * ratio).ceil().max(1.0) as usize
    } else {
        1
    };
    TimeRequest {
        steps,
        dt: t.dt_s,
        points: abscissae(v, &format!("{base}/points_m"), t.points_m.as_ref(), length),
        series: t.return_series,
        decimate: decimate.max(1) as usize,
    }
}

/// The components of `excitation.harmonics` (spec §3.D.4 "several harmonics"; count, ranges and
/// "exactly one of `frequency_hz`, `resonance_of_mode`" are checked at the door).
fn harmonics(v: &mut Validator, list: &[HarmonicIn], n_modes: usize) -> Vec<Harmonic> {
    list.iter()
        .enumerate()
        .map(|(j, h)| Harmonic {
            amplitude: h.amplitude_n,
            freq: freq_or_mode(
                v,
                h.frequency_hz,
                (
                    h.resonance_of_mode,
                    &format!("/excitation/harmonics/{j}/resonance_of_mode"),
                    "resonance_of_mode",
                ),
                n_modes,
                FreqRef::Hz(1.0),
            ),
            phase: h.phase_rad.unwrap_or(0.0),
        })
        .collect()
}

/// The force law and its amplitude `P0` (impulse, step, single harmonic).
fn excitation(v: &mut Validator, e: &ExcitationIn, n_modes: usize) -> (Forcing, f64) {
    let amplitude = e.amplitude_n.unwrap_or(1.0);
    if let Some(list) = &e.harmonics {
        let single = [
            ("amplitude_n", e.amplitude_n.is_some()),
            ("frequency_hz", e.frequency_hz.is_some()),
            ("resonance_of_mode", e.resonance_of_mode.is_some()),
            ("phase_rad", e.phase_rad.is_some()),
        ];
        for (name, given) in single {
            ensure_rule!(v, !given, HARMONICS_CONFLICT, format!("/excitation/{name}");
                "give either excitation.harmonics or the single harmonic's {name}, not both");
        }
        ensure_rule!(v, e.kind == ExcitationType::Harmonic, HARMONICS_TYPE, "/excitation/harmonics";
            "harmonics needs excitation.type = harmonic");
        let components = harmonics(v, list, n_modes);
        return (
            Forcing::Harmonic {
                components,
                listed: true,
            },
            amplitude,
        );
    }
    ensure_rule!(v, e.frequency_hz.is_none() || e.resonance_of_mode.is_none(),
        FREQUENCY_CONFLICT, "/excitation/resonance_of_mode";
        "give at most one of frequency_hz and resonance_of_mode");
    let freq = freq_or_mode(
        v,
        e.frequency_hz,
        (
            e.resonance_of_mode,
            "/excitation/resonance_of_mode",
            "resonance_of_mode",
        ),
        n_modes,
        FreqRef::Mode(2.min(n_modes)),
    );
    let phase = e.phase_rad.unwrap_or(0.0);
    let forcing = match e.kind {
        ExcitationType::Harmonic => Forcing::Harmonic {
            components: vec![Harmonic {
                amplitude,
                freq,
                phase,
            }],
            listed: false,
        },
        ExcitationType::Impulse => Forcing::Impulse,
        ExcitationType::Step => Forcing::Step,
        ExcitationType::None => Forcing::None,
    };
    (forcing, amplitude)
}

impl TryFrom<VibrationAbsorberRequest> for VibrationAbsorberInput {
    type Error = CalcFailure;

    /// The rules between fields (the per-field rules passed at the door, `rules::check`), with
    /// the defaults of spec §2 filled in.
    #[expect(
        clippy::too_many_lines,
        reason = "one flat pass over the request's fields in wire order: splitting it would only \
                  scatter the defaults of spec §2"
    )]
    fn try_from(req: VibrationAbsorberRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let b = &req.beam;
        let length = b.length_m.unwrap_or(1.0);
        let youngs = b.youngs_modulus_pa.unwrap_or(210e9);
        let density = b.density_kg_m3.unwrap_or(7850.0);
        let (area, inertia) = match (&b.section, b.area_m2, b.second_moment_m4) {
            (Some(s), None, None) => (
                s.width_m * s.thickness_m,
                s.width_m * s.thickness_m.powi(3) / 12.0,
            ),
            (None, Some(a), Some(i)) => (a, i),
            (None, None, None) => (0.05 * 0.005, 0.05 * 0.005_f64.powi(3) / 12.0),
            (Some(_), _, _) => {
                rule!(v, SECTION_CONFLICT, "/beam/section";
                    "give either section or area_m2 + second_moment_m4, not both");
                (1.0, 1.0)
            }
            (None, a, _) => {
                let missing = if a.is_some() {
                    "/beam/second_moment_m4"
                } else {
                    "/beam/area_m2"
                };
                rule!(v, SECTION_PAIR, missing; "area_m2 and second_moment_m4 go together");
                (1.0, 1.0)
            }
        };
        let n_modes = (b.n_modes.unwrap_or(3) as usize).clamp(1, 50);
        let zeta = b.modal_damping_ratio.unwrap_or(0.0);

        let a = &req.absorber;
        let mass = a.mass_kg.unwrap_or(0.05);
        let given = [
            a.stiffness_n_m.is_some(),
            a.passive_tuning_hz.is_some(),
            a.passive_tuning_mode.is_some(),
        ];
        ensure_rule!(v, given.iter().filter(|g| **g).count() <= 1,
            STIFFNESS_CONFLICT, "/absorber/stiffness_n_m";
            "give at most one of stiffness_n_m, passive_tuning_hz, passive_tuning_mode");
        let stiffness = a.stiffness_n_m;
        let passive_tuning = freq_or_mode(
            &mut v,
            a.passive_tuning_hz,
            (
                a.passive_tuning_mode,
                "/absorber/passive_tuning_mode",
                "passive_tuning_mode",
            ),
            n_modes,
            FreqRef::Mode(1),
        );
        let damping = a.damping_n_s_m.unwrap_or(0.01);
        let xa = position(&mut v, "/absorber/position_m", a.position_m, length);

        let act = &req.actuator;
        let actuator = Actuator {
            r: act.resistance_ohm.unwrap_or(1.6),
            lc: act.inductance_h.unwrap_or(0.75e-3),
            kc: act.force_constant_n_a.unwrap_or(3.5),
            kb: act.back_emf_v_s_m.unwrap_or(3.5),
        };

        let c = &req.control;
        let config = c.mode;
        if config == Config::Active {
            ensure_rule!(v, actuator.kc != 0.0, ZERO_FORCE_CONSTANT, "/actuator/force_constant_n_a";
                "force_constant_n_a [N/A] must be ≠ 0 with control.mode = active (the gains \
                     divide by K_c)");
        }
        ensure_rule!(v, c.tuning_hz.is_none() || c.tuning_mode.is_none(),
            TUNING_CONFLICT, "/control/tuning_mode";
            "give at most one of tuning_hz and tuning_mode");
        ensure_rule!(v, c.kp_v_m.is_some() == c.kd_v_s_m.is_some(), GAIN_PAIR, "/control/kd_v_s_m";
            "kp_v_m and kd_v_s_m go together");
        let gains = match (c.kp_v_m, c.kd_v_s_m) {
            (Some(kp), Some(kd)) => GainSource::Explicit { kp, kd },
            _ => GainSource::Tuning(freq_or_mode(
                &mut v,
                c.tuning_hz,
                (c.tuning_mode, "/control/tuning_mode", "tuning_mode"),
                n_modes,
                FreqRef::Mode(2.min(n_modes)),
            )),
        };

        let e = &req.excitation;
        let force_position = position(&mut v, "/excitation/position_m", e.position_m, length);
        let (forcing, amplitude) = excitation(&mut v, e, n_modes);

        let o = &req.outputs;
        let outputs = Outputs {
            natural_frequencies: o.natural_frequencies,
            eigenvalues: o.eigenvalues,
            ava_step: o.ava_step,
            ava_step_series: o.ava_step_series,
            ava_frf: o
                .ava_frequency_response
                .as_ref()
                .map(|g| grid(&mut v, "/outputs/ava_frequency_response", g)),
            frf: o.frequency_response.as_ref().map(|f| {
                let base = "/outputs/frequency_response";
                let g = grid(
                    &mut v,
                    base,
                    &GridIn {
                        f_min_hz: f.f_min_hz,
                        f_max_hz: f.f_max_hz,
                        n_points: f.n_points,
                        log: f.log,
                    },
                );
                (
                    g,
                    abscissae(
                        &mut v,
                        &format!("{base}/points_m"),
                        f.points_m.as_ref(),
                        length,
                    ),
                )
            }),
            time: o.time_response.as_ref().map(|t| time(&mut v, t, length)),
            mode_shapes: o.mode_shapes.map(|m| m.n_points.max(2) as usize),
        };
        v.finish()?;
        Ok(Self {
            beam: Beam {
                length,
                youngs,
                density,
                area,
                inertia,
                n_modes,
                zeta,
            },
            absorber: Absorber {
                mass,
                stiffness,
                passive_tuning,
                damping,
                position: xa,
            },
            actuator,
            config,
            gains,
            forcing,
            force_position,
            amplitude,
            outputs,
        })
    }
}
