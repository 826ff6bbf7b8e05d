//! The one place that builds the wire response from the computed output.

use std::f64::consts::PI;

use nalgebra::Complex;

use super::compute::{NODE_WARN_REL, Notice, TimeOutput, VibrationAbsorberOutput};
use super::input::VibrationAbsorberInput;
use super::response::{Eigen, Stab, StepMetrics};
use super::wire::{
    AbsorberOut, AvaFrfOut, AvaStepOut, BeamOut, ClosedLoopOut, EigenvalueOut, FrfOut, FrfPointOut,
    GainsOut, ModeShapesOut, NaturalFrequenciesOut, Stability, StepOut, TimeOut, TimePointOut,
    VibrationAbsorberResponse,
};
use crate::calc::common::{ResponseSize, Warning};
use crate::numerics::Budget;

/// Upper estimate of the answer's size from the validated request (checked before computing):
/// fixed fields and per-mode tables, then each requested series: absorber step responses
/// (2 responses × 2 series × 5001 samples), frequency grids (frequency, magnitude and phase per
/// point and abscissa), the time response (per kept sample: time, w per abscissa, stroke and
/// force) and mode shapes (per sample: x and one value per mode).
#[must_use]
pub fn response_size(input: &VibrationAbsorberInput) -> ResponseSize {
    let o = &input.outputs;
    let modes = input.beam.n_modes as u64;
    let mut size = ResponseSize::fixed(16 * 1024 + modes * 1024);
    if o.ava_step_series {
        let samples = super::response::SETTLING_SAMPLES as u64 + 1;
        size = size.numbers("/outputs/ava_step_series", 4 * samples);
    }
    if let Some(g) = &o.ava_frf {
        size = size.numbers("/outputs/ava_frequency_response/n_points", 3 * g.n() as u64);
    }
    if let Some((g, points)) = &o.frf {
        let per_point = 1 + 2 * points.len() as u64;
        size = size
            .numbers(
                "/outputs/frequency_response/n_points",
                per_point * g.n() as u64,
            )
            .bytes(
                "/outputs/frequency_response/n_points",
                100 * points.len() as u64,
            );
    }
    if let Some(t) = &o.time {
        let p = t.points.len() as u64;
        size = size.bytes("/outputs/time_response/points_m", p * (4 * 25 + 100));
        if t.series {
            let kept = (t.steps / t.decimate.max(1)) as u64 + 2;
            size = size.numbers("/outputs/time_response/decimate", kept * (p + 3));
        }
    }
    if let Some(n) = o.mode_shapes {
        size = size.numbers("/outputs/mode_shapes/n_points", n as u64 * (modes + 1));
    }
    size
}

impl From<&Notice> for Warning {
    fn from(n: &Notice) -> Self {
        match n {
            Notice::AbsorberAtNode { position, node } => Self::at(
                "ABSORBER_AT_NODE",
                "/absorber/position_m",
                format!(
                    "the absorber at {position} m is within {NODE_WARN_REL}·L of the node {node:.6} m of the tuned mode: it cannot act on that mode"
                ),
            ),
            Notice::NegativeKp { kp } => Self::at(
                "NEGATIVE_KP",
                "/control",
                format!("K_p = {kp:.6e} V/m < 0: the actuator must act as a negative spring"),
            ),
            Notice::NoSettling => Self::new(
                "NO_SETTLING",
                "an absorber step response does not settle (undamped or without spring): no settling time",
            ),
            Notice::UndampedResonance { count } => Self::at(
                "UNDAMPED_RESONANCE",
                "/outputs/frequency_response",
                format!(
                    "{count} grid frequencies coincide with an undamped eigenvalue: |H| is null there"
                ),
            ),
            Notice::MarginalStability { max_re } => {
                let rate = max_re.map_or(String::new(), |m| format!(" (max Re λ = {m:+.3e} 1/s)"));
                Self::at(
                    "MARGINAL_STABILITY",
                    "/beam/modal_damping_ratio",
                    format!(
                        "modal_damping_ratio = 0 with active control: the closed loop is marginal{rate}; any ζ ≥ 1e-4 makes it stable"
                    ),
                )
            }
            Notice::Unstable { max_re } => Self::new(
                "UNSTABLE",
                format!("the coupled system is unstable: max Re λ = {max_re:+.3e} 1/s"),
            ),
            Notice::ExcitationOffTuning {
                excitation_hz,
                tuning_hz,
            } => Self::at(
                "EXCITATION_OFF_TUNING",
                "/excitation",
                format!(
                    "excitation at {excitation_hz:.6} Hz, tuning at {tuning_hz:.6} Hz: the response beats instead of being cancelled (tune by mode index to use the model's own frequency)"
                ),
            ),
        }
    }
}

/// Magnitude and phase [deg] of optional complex values.
fn mag_phase(h: &[Option<Complex<f64>>]) -> (Vec<Option<f64>>, Vec<Option<f64>>) {
    h.iter()
        .map(|z| (z.map(|z| z.norm()), z.map(|z| z.arg().to_degrees())))
        .unzip()
}

fn step_out(s: &StepMetrics) -> StepOut {
    StepOut {
        settling_time_s: s.settling,
        overshoot_pct: s.overshoot_pct,
        dc_gain: s.dc,
        t_s: s.series.as_ref().map(|(t, _)| t.clone()),
        y: s.series.as_ref().map(|(_, y)| y.clone()),
    }
}

fn closed_loop_out(e: &Eigen, size: usize) -> ClosedLoopOut {
    let mut ev: Vec<EigenvalueOut> = e
        .values
        .iter()
        .filter(|z| z.im >= 0.0)
        .map(|z| EigenvalueOut {
            re_1_s: z.re,
            im_hz: z.im / (2.0 * PI),
        })
        .collect();
    ev.sort_by(|a, b| {
        a.im_hz
            .total_cmp(&b.im_hz)
            .then(a.re_1_s.total_cmp(&b.re_1_s))
    });
    ClosedLoopOut {
        eigenvalues: ev,
        max_real_part_1_s: e.max_re,
        stability: match e.stability {
            Stab::Stable => Stability::Stable,
            Stab::Marginal => Stability::Marginal,
            Stab::Unstable => Stability::Unstable,
        },
        state_size: size,
    }
}

fn time_out(t: &TimeOutput) -> TimeOut {
    let s = &t.series;
    let row = |i: Option<usize>, v: &Vec<f64>| i.map(|i| v[i]);
    // Series of the stroke, force, current, voltage channels (when asked and present).
    let channel = |c: usize| {
        s.series
            .as_ref()
            .and_then(|ser| t.extra[c].map(|i| ser[i].clone()))
    };
    TimeOut {
        method: "expm-exosystem".to_owned(),
        excitation_frequency_hz: (!t.listed)
            .then(|| t.excitation_hz.first().copied())
            .flatten(),
        excitation_frequencies_hz: t.listed.then(|| t.excitation_hz.clone()),
        n_samples: t.n_samples,
        points: t
            .points
            .iter()
            .enumerate()
            .map(|(j, x)| TimePointOut {
                x_m: *x,
                max_abs_m: s.max_abs[j],
                max_abs_last_period_m: s.max_last[j],
                rms_m: s.rms[j],
                w_m: s.series.as_ref().map(|ser| ser[j].clone()),
            })
            .collect(),
        stroke_max_m: row(t.extra[0], &s.max_abs),
        force_max_n: row(t.extra[1], &s.max_abs),
        current_max_a: row(t.extra[2], &s.max_abs),
        voltage_max_v: row(t.extra[3], &s.max_abs),
        t_s: s.t.clone(),
        stroke_m: channel(0),
        force_n: channel(1),
        current_a: channel(2),
        voltage_v: channel(3),
    }
}

/// Builds the response.
#[must_use]
pub fn respond(
    input: &VibrationAbsorberInput,
    out: &VibrationAbsorberOutput,
    budget: &Budget,
) -> VibrationAbsorberResponse {
    let m = &out.model;
    let dev = &m.dev;
    let closed_loop = out
        .eigen
        .as_ref()
        .filter(|_| input.outputs.eigenvalues)
        .map(|e| closed_loop_out(e, m.size()));
    let time_response = out.time.as_ref().map(time_out);
    let mut report = out.report.clone();
    report.elapsed_ms = budget.elapsed_ms();
    VibrationAbsorberResponse {
        beam: BeamOut {
            beta_l: out.beta_l.clone(),
            natural_frequencies_hz: out.freqs_hz.clone(),
            modal_mass_kg: m.modal_mass,
            mass_kg: out.beam_mass,
            static_compliance_m_per_n: out.static_compliance,
            tuned_mode_nodes_m: out.tuned_nodes.clone(),
        },
        absorber: AbsorberOut {
            stiffness_n_m: dev.ka,
            passive_frequency_hz: (dev.ka / dev.ma).sqrt() / (2.0 * PI),
            mass_ratio: dev.ma / m.modal_mass,
        },
        gains: out.gains.map(|g| GainsOut {
            kp_v_m: g.kp,
            kd_v_s_m: g.kd,
            tuning_frequency_hz: g.tuning_hz,
            third_pole_1_s: g.third_pole,
            artificial_stiffness_n_m: g.k_art,
        }),
        natural_frequencies: out.natural.as_ref().map(|(a, b)| NaturalFrequenciesOut {
            without_absorber_hz: a.clone(),
            with_passive_absorber_hz: b.clone(),
        }),
        closed_loop,
        ava_step: out.ava_step.as_ref().map(|(ec, err)| AvaStepOut {
            xa_over_ec: step_out(ec),
            xa_over_err: err.as_ref().map(step_out),
        }),
        ava_frequency_response: out.ava_frf.as_ref().map(|(f, h)| {
            let (magnitude, phase_deg) = mag_phase(h);
            let peak = f
                .iter()
                .zip(&magnitude)
                .filter_map(|(f, m)| m.map(|m| (*f, m)))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(f, _)| f);
            AvaFrfOut {
                frequencies_hz: f.clone(),
                magnitude,
                phase_deg,
                peak_frequency_hz: peak,
            }
        }),
        frequency_response: out.frf.as_ref().map(|(f, xs, h)| FrfOut {
            frequencies_hz: f.clone(),
            points: xs
                .iter()
                .zip(h)
                .map(|(x, h)| {
                    let (magnitude_m_per_n, phase_deg) = mag_phase(h);
                    FrfPointOut {
                        x_m: *x,
                        magnitude_m_per_n,
                        phase_deg,
                    }
                })
                .collect(),
        }),
        time_response,
        mode_shapes: out.mode_shapes.as_ref().map(|(x, s)| ModeShapesOut {
            x_m: x.clone(),
            shapes: s.clone(),
        }),
        warnings: out.warnings.iter().map(Warning::from).collect(),
        report,
    }
}
