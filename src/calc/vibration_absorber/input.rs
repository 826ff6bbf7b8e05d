//! The validated request in SI units (spec §2): defaults filled in, every problem collected with
//! its JSON pointer.

use std::time::Duration;

use crate::calc::common::{TimeLimited, time_limit};
use crate::calc::{CalcFailure, Validator};

use super::wire::{
    self, ControlMode, ExcitationIn, ExcitationType, FrequencyResponseIn, GridIn, HarmonicIn,
    TimeResponseIn, VibrationAbsorberRequest,
};

/// Code of a `{mode: k}` reference beyond `beam.n_modes`.
pub const MODE_OUT_OF_RANGE: &str = "MODE_OUT_OF_RANGE";
/// Code of `K_c = 0` with `active`.
pub const ZERO_FORCE_CONSTANT: &str = "ZERO_FORCE_CONSTANT";
/// Code of a position outside (0, L].
pub const POSITION_OUT_OF_BEAM: &str = "POSITION_OUT_OF_BEAM";
/// Code of a time grid with more than 2e6 samples.
pub const TOO_MANY_SAMPLES: &str = "TOO_MANY_SAMPLES";
/// Code of `excitation.harmonics` given together with a single-harmonic member.
pub const HARMONICS_CONFLICT: &str = "HARMONICS_CONFLICT";

/// Configuration (which states the model has).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Config {
    /// No absorber.
    None,
    /// Coil open.
    Passive,
    /// Coil shorted.
    PassiveShorted,
    /// PD control.
    Active,
}

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

/// A frequency grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// \[Hz\].
    pub f_min: f64,
    /// \[Hz\].
    pub f_max: f64,
    /// Points.
    pub n: usize,
    /// Log spacing.
    pub log: bool,
}

impl Grid {
    /// The frequencies \[Hz\].
    #[must_use]
    pub fn frequencies(&self) -> Vec<f64> {
        if self.n == 1 {
            return vec![self.f_min];
        }
        let last = (self.n - 1) as f64;
        (0..self.n)
            .map(|i| {
                let t = i as f64 / last;
                if self.log {
                    self.f_min * (self.f_max / self.f_min).powf(t)
                } else {
                    self.f_min + (self.f_max - self.f_min) * t
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

/// A mode reference `k` checked against `1…n_modes` (the `MODE_INDEX` bound and the cross-field
/// rule `k ≤ beam.n_modes`).
fn mode_ref(v: &mut Validator, pointer: &str, name: &str, k: u32, n_modes: usize) -> usize {
    if v.uint(pointer, name, u64::from(k), wire::MODE_INDEX) {
        v.ensure_code(k as usize <= n_modes, MODE_OUT_OF_RANGE, pointer, || {
            format!("{name} must be ≤ beam.n_modes = {n_modes}, got {k}")
        });
    }
    (k as usize).clamp(1, n_modes.max(1))
}

/// One optional number with a default, checked against its range.
fn opt(
    v: &mut Validator,
    pointer: &str,
    x: Option<f64>,
    default: f64,
    r: crate::calc::Range,
) -> f64 {
    let name = pointer.rsplit('/').next().unwrap_or("");
    match x {
        Some(x) => {
            v.range(pointer, name, x, r);
            x
        }
        None => default,
    }
}

/// A position in (0, L].
fn position(v: &mut Validator, pointer: &str, x: Option<f64>, length: f64) -> f64 {
    let p = opt(v, pointer, x, length, wire::LENGTH);
    if wire::LENGTH.contains(p) && length.is_finite() {
        v.ensure_code(p <= length, POSITION_OUT_OF_BEAM, pointer, || {
            format!("must be ≤ beam.length_m = {length}, got {p}")
        });
    }
    p
}

/// Output abscissae in [0, L] (default: the tip).
fn abscissae(v: &mut Validator, pointer: &str, xs: Option<&Vec<f64>>, length: f64) -> Vec<f64> {
    let Some(xs) = xs else {
        return vec![length];
    };
    v.ensure(
        !xs.is_empty() && xs.len() <= wire::MAX_POINTS,
        pointer,
        || {
            format!(
                "must list 1…{} abscissae, got {}",
                wire::MAX_POINTS,
                xs.len()
            )
        },
    );
    if v.all_in(pointer, "points_m", xs, wire::ABSCISSA) {
        for (i, x) in xs.iter().enumerate() {
            v.ensure_code(
                *x <= length,
                POSITION_OUT_OF_BEAM,
                format!("{pointer}/{i}"),
                || format!("points_m[{i}] must be ≤ beam.length_m = {length}, got {x}"),
            );
        }
    }
    xs.clone()
}

/// A frequency grid: `f_min ≤ f_max` (strictly below unless one point).
fn grid(v: &mut Validator, base: &str, g: &GridIn) -> Grid {
    v.range(
        &format!("{base}/f_min_hz"),
        "f_min_hz",
        g.f_min_hz,
        wire::FREQUENCY,
    );
    let ok_max = v.range(
        &format!("{base}/f_max_hz"),
        "f_max_hz",
        g.f_max_hz,
        wire::FREQUENCY,
    );
    v.uint(
        &format!("{base}/n_points"),
        "n_points",
        u64::from(g.n_points),
        wire::FREQ_POINTS,
    );
    if ok_max && g.f_min_hz.is_finite() {
        let ok = g.f_max_hz > g.f_min_hz || (g.n_points == 1 && g.f_max_hz >= g.f_min_hz);
        v.ensure(ok, format!("{base}/f_max_hz"), || {
            format!(
                "f_max_hz must be > f_min_hz = {}, got {}",
                g.f_min_hz, g.f_max_hz
            )
        });
    }
    Grid {
        f_min: g.f_min_hz,
        f_max: g.f_max_hz,
        n: g.n_points.max(1) as usize,
        log: g.log,
    }
}

fn frf(v: &mut Validator, f: &FrequencyResponseIn, length: f64) -> (Grid, Vec<f64>) {
    let base = "/outputs/frequency_response";
    let g = grid(
        v,
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
        abscissae(v, &format!("{base}/points_m"), f.points_m.as_ref(), length),
    )
}

fn time(v: &mut Validator, t: &TimeResponseIn, length: f64) -> TimeRequest {
    let base = "/outputs/time_response";
    let ok_t = v.range(
        &format!("{base}/t_end_s"),
        "t_end_s",
        t.t_end_s,
        wire::T_END,
    );
    let ok_dt = v.range(&format!("{base}/dt_s"), "dt_s", t.dt_s, wire::DT);
    let ratio = t.t_end_s / t.dt_s;
    if ok_t && ok_dt {
        v.ensure_code(ratio <= wire::MAX_SAMPLES, TOO_MANY_SAMPLES, format!("{base}/dt_s"), || {
            format!(
                "t_end_s / dt_s must be ≤ {:e} samples, got {ratio:.6e} (t_end_s = {}, dt_s = {})",
                wire::MAX_SAMPLES,
                t.t_end_s,
                t.dt_s
            )
        });
    }
    let decimate = t.decimate.unwrap_or(1);
    v.uint(
        &format!("{base}/decimate"),
        "decimate",
        u64::from(decimate),
        wire::DECIMATE,
    );
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

/// A frequency given as `frequency_hz` or `resonance_of_mode` (at most one; `default` when
/// neither is given, `None` = required).
fn freq_ref(
    v: &mut Validator,
    base: &str,
    (hz, mode): (Option<f64>, Option<u32>),
    n_modes: usize,
    default: Option<FreqRef>,
) -> FreqRef {
    let both = hz.is_some() && mode.is_some();
    v.ensure(!both, format!("{base}/resonance_of_mode"), || {
        "give at most one of frequency_hz and resonance_of_mode".to_owned()
    });
    match (hz, mode, default) {
        (Some(f), _, _) => FreqRef::Hz(opt(
            v,
            &format!("{base}/frequency_hz"),
            Some(f),
            1.0,
            wire::FREQUENCY,
        )),
        (None, Some(k), _) => FreqRef::Mode(mode_ref(
            v,
            &format!("{base}/resonance_of_mode"),
            "resonance_of_mode",
            k,
            n_modes,
        )),
        (None, None, Some(d)) => d,
        (None, None, None) => {
            v.push(
                format!("{base}/frequency_hz"),
                "give frequency_hz or resonance_of_mode",
            );
            FreqRef::Hz(1.0)
        }
    }
}

/// The components of `excitation.harmonics` (spec §3.D.4 "several harmonics").
fn harmonics(v: &mut Validator, list: &[HarmonicIn], n_modes: usize) -> Vec<Harmonic> {
    let base = "/excitation/harmonics";
    v.ensure(
        !list.is_empty() && list.len() <= wire::MAX_HARMONICS,
        base,
        || {
            format!(
                "must list 1…{} components, got {}",
                wire::MAX_HARMONICS,
                list.len()
            )
        },
    );
    list.iter()
        .enumerate()
        .map(|(j, h)| {
            let at = format!("{base}/{j}");
            v.range(
                &format!("{at}/amplitude_n"),
                "amplitude_n",
                h.amplitude_n,
                wire::AMPLITUDE,
            );
            Harmonic {
                amplitude: h.amplitude_n,
                freq: freq_ref(v, &at, (h.frequency_hz, h.resonance_of_mode), n_modes, None),
                phase: opt(v, &format!("{at}/phase_rad"), h.phase_rad, 0.0, wire::PHASE),
            }
        })
        .collect()
}

/// The force law and its amplitude `P0` (impulse, step, single harmonic).
fn excitation(v: &mut Validator, e: &ExcitationIn, n_modes: usize) -> (Forcing, f64) {
    let amplitude = opt(
        v,
        "/excitation/amplitude_n",
        e.amplitude_n,
        1.0,
        wire::AMPLITUDE,
    );
    if let Some(list) = &e.harmonics {
        let single = [
            ("amplitude_n", e.amplitude_n.is_some()),
            ("frequency_hz", e.frequency_hz.is_some()),
            ("resonance_of_mode", e.resonance_of_mode.is_some()),
            ("phase_rad", e.phase_rad.is_some()),
        ];
        for (name, given) in single {
            v.ensure_code(
                !given,
                HARMONICS_CONFLICT,
                format!("/excitation/{name}"),
                || {
                    format!(
                        "give either excitation.harmonics or the single harmonic's {name}, not both"
                    )
                },
            );
        }
        v.ensure(
            e.kind == ExcitationType::Harmonic,
            "/excitation/harmonics",
            || "harmonics needs excitation.type = harmonic".to_owned(),
        );
        let components = harmonics(v, list, n_modes);
        return (
            Forcing::Harmonic {
                components,
                listed: true,
            },
            amplitude,
        );
    }
    let freq = freq_ref(
        v,
        "/excitation",
        (e.frequency_hz, e.resonance_of_mode),
        n_modes,
        Some(FreqRef::Mode(2.min(n_modes))),
    );
    let phase = opt(v, "/excitation/phase_rad", e.phase_rad, 0.0, wire::PHASE);
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

    #[expect(
        clippy::too_many_lines,
        reason = "one flat pass over the request's fields in wire order: splitting it would only \
                  scatter the defaults of spec §2"
    )]
    fn try_from(req: VibrationAbsorberRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        time_limit(&mut v, req.time_limit_ms);
        let b = &req.beam;
        let length = opt(&mut v, "/beam/length_m", b.length_m, 1.0, wire::LENGTH);
        let youngs = opt(
            &mut v,
            "/beam/youngs_modulus_pa",
            b.youngs_modulus_pa,
            210e9,
            wire::MODULUS,
        );
        let density = opt(
            &mut v,
            "/beam/density_kg_m3",
            b.density_kg_m3,
            7850.0,
            wire::DENSITY,
        );
        let (area, inertia) = match (&b.section, b.area_m2, b.second_moment_m4) {
            (Some(s), None, None) => {
                v.range("/beam/section/width_m", "width_m", s.width_m, wire::SECTION);
                v.range(
                    "/beam/section/thickness_m",
                    "thickness_m",
                    s.thickness_m,
                    wire::SECTION,
                );
                (
                    s.width_m * s.thickness_m,
                    s.width_m * s.thickness_m.powi(3) / 12.0,
                )
            }
            (None, Some(a), Some(i)) => {
                v.range("/beam/area_m2", "area_m2", a, wire::SECTION);
                v.range(
                    "/beam/second_moment_m4",
                    "second_moment_m4",
                    i,
                    wire::SECTION,
                );
                (a, i)
            }
            (None, None, None) => (0.05 * 0.005, 0.05 * 0.005_f64.powi(3) / 12.0),
            (Some(_), _, _) => {
                v.push(
                    "/beam/section",
                    "give either section or area_m2 + second_moment_m4, not both",
                );
                (1.0, 1.0)
            }
            (None, a, _) => {
                let missing = if a.is_some() {
                    "/beam/second_moment_m4"
                } else {
                    "/beam/area_m2"
                };
                v.push(missing, "area_m2 and second_moment_m4 go together");
                (1.0, 1.0)
            }
        };
        let n_modes = b.n_modes.unwrap_or(3);
        v.uint(
            "/beam/n_modes",
            "n_modes",
            u64::from(n_modes),
            wire::N_MODES,
        );
        let n_modes = (n_modes as usize).clamp(1, 50);
        let zeta = opt(
            &mut v,
            "/beam/modal_damping_ratio",
            b.modal_damping_ratio,
            0.0,
            wire::DAMPING_RATIO,
        );

        let a = &req.absorber;
        let mass = opt(&mut v, "/absorber/mass_kg", a.mass_kg, 0.05, wire::MASS);
        let given = [
            a.stiffness_n_m.is_some(),
            a.passive_tuning_hz.is_some(),
            a.passive_tuning_mode.is_some(),
        ];
        v.ensure(
            given.iter().filter(|g| **g).count() <= 1,
            "/absorber/stiffness_n_m",
            || {
                "give at most one of stiffness_n_m, passive_tuning_hz, passive_tuning_mode"
                    .to_owned()
            },
        );
        let stiffness = a.stiffness_n_m.map(|k| {
            opt(
                &mut v,
                "/absorber/stiffness_n_m",
                Some(k),
                0.0,
                wire::STIFFNESS,
            )
        });
        let passive_tuning = match (a.passive_tuning_hz, a.passive_tuning_mode) {
            (Some(f), _) => FreqRef::Hz(opt(
                &mut v,
                "/absorber/passive_tuning_hz",
                Some(f),
                1.0,
                wire::FREQUENCY,
            )),
            (None, Some(k)) => FreqRef::Mode(mode_ref(
                &mut v,
                "/absorber/passive_tuning_mode",
                "passive_tuning_mode",
                k,
                n_modes,
            )),
            (None, None) => FreqRef::Mode(1),
        };
        let damping = opt(
            &mut v,
            "/absorber/damping_n_s_m",
            a.damping_n_s_m,
            0.01,
            wire::DAMPING,
        );
        let xa = position(&mut v, "/absorber/position_m", a.position_m, length);

        let act = &req.actuator;
        let actuator = Actuator {
            r: opt(
                &mut v,
                "/actuator/resistance_ohm",
                act.resistance_ohm,
                1.6,
                wire::RESISTANCE,
            ),
            lc: opt(
                &mut v,
                "/actuator/inductance_h",
                act.inductance_h,
                0.75e-3,
                wire::INDUCTANCE,
            ),
            kc: opt(
                &mut v,
                "/actuator/force_constant_n_a",
                act.force_constant_n_a,
                3.5,
                wire::FORCE_CONSTANT,
            ),
            kb: opt(
                &mut v,
                "/actuator/back_emf_v_s_m",
                act.back_emf_v_s_m,
                3.5,
                wire::BACK_EMF,
            ),
        };

        let c = &req.control;
        let config = match c.mode {
            ControlMode::None => Config::None,
            ControlMode::Passive => Config::Passive,
            ControlMode::PassiveShorted => Config::PassiveShorted,
            ControlMode::Active => Config::Active,
        };
        if config == Config::Active {
            v.ensure_code(actuator.kc != 0.0, ZERO_FORCE_CONSTANT, "/actuator/force_constant_n_a", || {
                "force_constant_n_a must be ≠ 0 with control.mode = active (the gains divide by K_c)".to_owned()
            });
        }
        v.ensure(
            c.tuning_hz.is_none() || c.tuning_mode.is_none(),
            "/control/tuning_mode",
            || "give at most one of tuning_hz and tuning_mode".to_owned(),
        );
        v.ensure(
            c.kp_v_m.is_some() == c.kd_v_s_m.is_some(),
            "/control/kd_v_s_m",
            || "kp_v_m and kd_v_s_m go together".to_owned(),
        );
        let gains = match (c.kp_v_m, c.kd_v_s_m, c.tuning_hz, c.tuning_mode) {
            (Some(kp), Some(kd), _, _) => GainSource::Explicit {
                kp: opt(&mut v, "/control/kp_v_m", Some(kp), 0.0, wire::GAIN),
                kd: opt(&mut v, "/control/kd_v_s_m", Some(kd), 0.0, wire::GAIN),
            },
            (_, _, Some(f), _) => GainSource::Tuning(FreqRef::Hz(opt(
                &mut v,
                "/control/tuning_hz",
                Some(f),
                1.0,
                wire::FREQUENCY,
            ))),
            (_, _, None, Some(k)) => GainSource::Tuning(FreqRef::Mode(mode_ref(
                &mut v,
                "/control/tuning_mode",
                "tuning_mode",
                k,
                n_modes,
            ))),
            _ => GainSource::Tuning(FreqRef::Mode(2.min(n_modes))),
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
            frf: o
                .frequency_response
                .as_ref()
                .map(|f| frf(&mut v, f, length)),
            time: o.time_response.as_ref().map(|t| time(&mut v, t, length)),
            mode_shapes: o.mode_shapes.map(|m| {
                v.uint(
                    "/outputs/mode_shapes/n_points",
                    "n_points",
                    u64::from(m.n_points),
                    wire::SHAPE_POINTS,
                );
                m.n_points.max(2) as usize
            }),
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
