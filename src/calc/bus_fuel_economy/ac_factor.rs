//! AC resistance factor k_AC(f_e, T_w) of the stator winding (spec §5.5 item 4).
//!
//! Dowell's layer-averaged factor for the slot part, k_slot = F1(ξ) + ((m² − 1)/3)·F2(ξ), with
//! ξ = (h/δ)·√porosity and the skin depth δ = √(ρ(T_w)/(π f μ0)); the end winding is assumed free
//! of AC effect, k_AC = (k_slot L_stack + L_end)/(L_stack + L_end). F1/F2 are usually written φ/ψ.

// Plain products instead of `mul_add`: without FMA hardware in the target (the default x86-64
// baseline) `mul_add` is a libm call, ~10x slower in these per-interval loops, and plain
// arithmetic follows the rounding of the spec's reference implementation.

use std::f64::consts::PI;

use crate::numerics::grid::interp_clamped;

/// Copper resistivity at 20 °C [Ω·m] (spec §5.5).
pub const RHO_CU_20: f64 = 1.724e-8;
/// Temperature coefficient of copper resistance [1/K] (spec §5.5).
pub const ALPHA_CU: f64 = 0.00393;
/// Vacuum permeability μ0 = 4π·1e-7 [H/m] (the spec's value, not the 2019 SI measured one).
pub const MU0: f64 = 4.0 * PI * 1e-7;
/// Below this ξ the closed forms lose digits to cancellation: use the series (spec §5.5, §8 item 7).
pub const XI_SERIES_MAX: f64 = 0.3;
/// Above this ξ the closed forms equal the asymptotes to 1e-8 and cosh would overflow near 355.
pub const XI_ASYMPTOTE_MIN: f64 = 20.0;

/// Resistance temperature factor 1 + α (T_w − 20).
#[must_use]
pub fn temp_factor(temp_c: f64) -> f64 {
    1.0 + ALPHA_CU * (temp_c - 20.0)
}

/// Dowell F1(ξ) = ξ (sinh 2ξ + sin 2ξ)/(cosh 2ξ − cos 2ξ), closed form (ξ > 0).
#[must_use]
pub fn dowell_f1_closed(xi: f64) -> f64 {
    let x2 = 2.0 * xi;
    xi * (x2.sinh() + x2.sin()) / (x2.cosh() - x2.cos())
}

/// Dowell F2(ξ) = 2ξ (sinh ξ − sin ξ)/(cosh ξ + cos ξ), closed form.
#[must_use]
pub fn dowell_f2_closed(xi: f64) -> f64 {
    2.0 * xi * (xi.sinh() - xi.sin()) / (xi.cosh() + xi.cos())
}

/// Dowell F1(ξ) for ξ ≥ 0: series below 0.3, asymptote ξ above 20, closed form between.
///
/// The series carries one term more than the spec's (+88448ξ¹²/638512875): with two terms the
/// branches differ by 7e-11 at ξ = 0.3 for F1 and 3e-10 for F2, above the spec's own 1e-10
/// agreement requirement; with three they agree to 1e-15.
#[must_use]
pub fn dowell_f1(xi: f64) -> f64 {
    if xi < XI_SERIES_MAX {
        let x4 = xi.powi(4);
        1.0 + 4.0 * x4 / 45.0 - 16.0 * x4 * x4 / 4725.0 + 88448.0 * x4 * x4 * x4 / 638_512_875.0
    } else if xi > XI_ASYMPTOTE_MIN {
        xi
    } else {
        dowell_f1_closed(xi)
    }
}

/// Dowell F2(ξ) for ξ ≥ 0: series below 0.3, asymptote 2ξ above 20, closed form between.
/// Series ξ⁴/3 − 17ξ⁸/1260 + 691ξ¹²/1247400 (third term added, see [`dowell_f1`]).
#[must_use]
pub fn dowell_f2(xi: f64) -> f64 {
    if xi < XI_SERIES_MAX {
        let x4 = xi.powi(4);
        x4 / 3.0 - 17.0 * x4 * x4 / 1260.0 + 691.0 * x4 * x4 * x4 / 1_247_400.0
    } else if xi > XI_ASYMPTOTE_MIN {
        2.0 * xi
    } else {
        dowell_f2_closed(xi)
    }
}

/// Dowell parameters in SI units.
#[derive(Debug, Clone, Copy)]
pub struct Dowell {
    /// Conductor height h \[m\].
    pub conductor_height_m: f64,
    /// Layers m.
    pub layers: f64,
    /// Porosity factor.
    pub porosity: f64,
    /// Slot (active) length \[m\].
    pub stack_length_m: f64,
    /// End-winding length \[m\].
    pub end_length_m: f64,
}

/// The AC factor model of one motor.
#[derive(Debug, Clone)]
pub enum AcFactor {
    /// k_AC = 1.
    None,
    /// Table k_AC(f): linear in f, clamped at the ends.
    Table {
        /// Frequencies \[Hz\], strictly increasing.
        freq_hz: Vec<f64>,
        /// k_AC values.
        k_ac: Vec<f64>,
    },
    /// Dowell layer model.
    Dowell(Dowell),
}

impl AcFactor {
    /// k_AC at electrical frequency `f_hz` ≥ 0 and winding temperature `temp_c`.
    #[must_use]
    pub fn k_ac(&self, f_hz: f64, temp_c: f64) -> f64 {
        match self {
            Self::None => 1.0,
            Self::Table { freq_hz, k_ac } => interp_clamped(freq_hz, k_ac, f_hz),
            Self::Dowell(d) => {
                if f_hz <= 0.0 {
                    return 1.0;
                }
                let rho = RHO_CU_20 * temp_factor(temp_c);
                let delta = (rho / (PI * f_hz * MU0)).sqrt();
                let xi = d.conductor_height_m / delta * d.porosity.sqrt();
                let k_slot = dowell_f1(xi) + (d.layers * d.layers - 1.0) / 3.0 * dowell_f2(xi);
                let (ls, le) = (d.stack_length_m, d.end_length_m);
                (k_slot * ls + le) / (ls + le)
            }
        }
    }
}
