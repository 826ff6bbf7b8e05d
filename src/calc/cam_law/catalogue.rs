//! Classic motion laws (spec Appendix A) and the Table-3 catalogue of 7-segment vectors (spec §5.3).
//!
//! Normalized forms: `x = (t − t_a)/Δt ∈ [0, 1]`, unit rise, zero end rates. Physical values:
//! `s = s_a + Δs·S`, `v = Δs/Δt·V`, `a = Δs/Δt²·A`, `j = Δs/Δt³·J`. At an acceleration jump the
//! closed forms follow the law's convention (right-continuous inside, left-continuous at `x = 1`).

// Closed-form polynomials read best in their printed (Appendix A) form.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::law::Sample;

/// A named classic motion law of Appendix A.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law::NamedLaw)]
#[serde(rename_all = "snake_case")]
pub enum NamedLaw {
    /// Constant velocity `S = x` (infinite acceleration at the ends; outside the 7-segment class).
    ConstantVelocity,
    /// Constant acceleration (parabolic), Table-3 L2.
    ConstantAcceleration,
    /// Simple harmonic `S = (1 − cos πx)/2`, Table-3 L4.
    SimpleHarmonic,
    /// Cycloidal `S = x − sin(2πx)/(2π)`, Table-3 L8.
    Cycloidal,
    /// Cubic (3-2 polynomial) `S = 3x² − 2x³` (outside the class).
    Cubic,
    /// Polynomial 3-4-5 (outside the class).
    #[serde(rename = "polynomial_345")]
    Polynomial345,
    /// Polynomial 4-5-6-7 (outside the class).
    #[serde(rename = "polynomial_4567")]
    Polynomial4567,
    /// Polynomial 5-6-7-8-9 (outside the class).
    #[serde(rename = "polynomial_56789")]
    Polynomial56789,
    /// Double harmonic (rise of a rise–return without dwell; outside the class).
    DoubleHarmonic,
    /// Modified trapezoid (MT), `ĉ = [⅛,¼,⅛,0,⅛,¼,⅛]`, Table-3 L5.
    ModifiedTrapezoid,
    /// Modified sine (MS), `ĉ = [⅛,0,⅜,0,⅜,0,⅛]`, Table-3 L1.
    ModifiedSine,
}

/// Dimensionless peak factors of a normalized law: `max|V|`, `max|A|`, `max|J|` (J excluding
/// impulses at jumps). `None` means infinite (spec Appendix A table).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::PeakFactors)]
pub struct PeakFactors {
    /// `Cv = max|V|`.
    pub cv: f64,
    /// `Ca = max|A|`; absent when infinite (constant velocity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ca: Option<f64>,
    /// `Cj = max|J|`; absent when infinite (constant velocity, constant acceleration).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cj: Option<f64>,
}

/// MT peak acceleration `Ca = 8π/(π+2)`.
fn ca_mt() -> f64 {
    8.0 * PI / (PI + 2.0)
}

/// MS peak acceleration `Ca = 4π²/(π+4)`.
fn ca_ms() -> f64 {
    4.0 * PI * PI / (PI + 4.0)
}

impl NamedLaw {
    /// Every named law, in the order of the Appendix A table.
    pub const ALL: [Self; 11] = [
        Self::ConstantVelocity,
        Self::ConstantAcceleration,
        Self::SimpleHarmonic,
        Self::Cycloidal,
        Self::Cubic,
        Self::Polynomial345,
        Self::Polynomial4567,
        Self::Polynomial56789,
        Self::DoubleHarmonic,
        Self::ModifiedTrapezoid,
        Self::ModifiedSine,
    ];

    /// The wire name (snake case).
    #[must_use]
    pub fn wire_name(self) -> &'static str {
        match self {
            Self::ConstantVelocity => "constant_velocity",
            Self::ConstantAcceleration => "constant_acceleration",
            Self::SimpleHarmonic => "simple_harmonic",
            Self::Cycloidal => "cycloidal",
            Self::Cubic => "cubic",
            Self::Polynomial345 => "polynomial_345",
            Self::Polynomial4567 => "polynomial_4567",
            Self::Polynomial56789 => "polynomial_56789",
            Self::DoubleHarmonic => "double_harmonic",
            Self::ModifiedTrapezoid => "modified_trapezoid",
            Self::ModifiedSine => "modified_sine",
        }
    }

    /// The 7-segment coefficients when the law belongs to the class (spec A.2), else `None`.
    #[must_use]
    pub fn seven_segment_coefficients(self) -> Option<[f64; 7]> {
        match self {
            Self::ConstantAcceleration => Some(TABLE3[1].coefficients),
            Self::SimpleHarmonic => Some(TABLE3[3].coefficients),
            Self::Cycloidal => Some(TABLE3[7].coefficients),
            Self::ModifiedTrapezoid => Some(TABLE3[4].coefficients),
            Self::ModifiedSine => Some(TABLE3[0].coefficients),
            Self::ConstantVelocity
            | Self::Cubic
            | Self::Polynomial345
            | Self::Polynomial4567
            | Self::Polynomial56789
            | Self::DoubleHarmonic => None,
        }
    }

    /// Peak factors `Cv, Ca, Cj` (exact closed forms; the Appendix A table prints 4–5 digits).
    #[must_use]
    pub fn peak_factors(self) -> PeakFactors {
        let pf = |cv: f64, ca: Option<f64>, cj: Option<f64>| PeakFactors { cv, ca, cj };
        match self {
            Self::ConstantVelocity => pf(1.0, None, None),
            Self::ConstantAcceleration => pf(2.0, Some(4.0), None),
            Self::SimpleHarmonic => pf(PI / 2.0, Some(PI * PI / 2.0), Some(PI * PI * PI / 2.0)),
            Self::Cycloidal => pf(2.0, Some(2.0 * PI), Some(4.0 * PI * PI)),
            Self::Cubic => pf(1.5, Some(6.0), Some(12.0)),
            Self::Polynomial345 => pf(1.875, Some(10.0 / 3f64.sqrt()), Some(60.0)),
            Self::Polynomial4567 => {
                // A = 420x²(1−x)²(1−2x) peaks where 5x² − 5x + 1 = 0.
                let x = (5.0 - 5f64.sqrt()) / 10.0;
                let ca = 420.0 * x * x * (1.0 - x) * (1.0 - x) * (1.0 - 2.0 * x);
                pf(2.1875, Some(ca), Some(52.5))
            }
            Self::Polynomial56789 => {
                // A = 2520x³(1−x)³(1−2x) peaks where 14x² − 14x + 3 = 0.
                let x = 0.5 - 28f64.sqrt() / 28.0;
                let ca = 2520.0 * (x * (1.0 - x)).powi(3) * (1.0 - 2.0 * x);
                pf(630.0 / 256.0, Some(ca), Some(78.75))
            }
            Self::DoubleHarmonic => {
                // Cv at x = 2/3; Cj where 8c² − c − 4 = 0 with c = cos πx < 0.
                let cv = (PI / 2.0) * (3.0 * 3f64.sqrt() / 4.0);
                let c = (1.0 - 129f64.sqrt()) / 16.0;
                let sn = (1.0 - c * c).sqrt();
                let cj = (PI * PI * PI / 2.0) * (sn - 4.0 * sn * c);
                pf(cv, Some(PI * PI), Some(cj))
            }
            Self::ModifiedTrapezoid => pf(2.0, Some(ca_mt()), Some(4.0 * PI * ca_mt())),
            Self::ModifiedSine => {
                // V peaks at x = ½ (A changes sign there): V(½) = Ca[1/(4π) + 3/(4π)].
                let ca = ca_ms();
                pf(ca / PI, Some(ca), Some(4.0 * PI * ca))
            }
        }
    }

    /// Normalized abscissa of the first maximum of |V|.
    #[must_use]
    pub fn x_at_v_max(self) -> f64 {
        match self {
            Self::ConstantVelocity => 0.0,
            Self::DoubleHarmonic => 2.0 / 3.0,
            _ => 0.5,
        }
    }

    /// `S, V, A, J` of the normalized law at `x` (clamped to [0, 1]).
    #[must_use]
    pub fn eval_normalized(self, x: f64) -> Sample {
        let x = x.clamp(0.0, 1.0);
        match self {
            Self::ConstantVelocity => Sample {
                s: x,
                v: 1.0,
                a: 0.0,
                j: 0.0,
            },
            Self::ConstantAcceleration => {
                if x < 0.5 {
                    Sample {
                        s: 2.0 * x * x,
                        v: 4.0 * x,
                        a: 4.0,
                        j: 0.0,
                    }
                } else {
                    let u = 1.0 - x;
                    Sample {
                        s: 1.0 - 2.0 * u * u,
                        v: 4.0 * u,
                        a: -4.0,
                        j: 0.0,
                    }
                }
            }
            Self::SimpleHarmonic => {
                let (sn, cs) = (PI * x).sin_cos();
                Sample {
                    s: (1.0 - cs) / 2.0,
                    v: PI / 2.0 * sn,
                    a: PI * PI / 2.0 * cs,
                    j: -PI * PI * PI / 2.0 * sn,
                }
            }
            Self::Cycloidal => {
                let (sn, cs) = (2.0 * PI * x).sin_cos();
                Sample {
                    s: x - sn / (2.0 * PI),
                    v: 1.0 - cs,
                    a: 2.0 * PI * sn,
                    j: 4.0 * PI * PI * cs,
                }
            }
            Self::Cubic => Sample {
                s: x * x * (3.0 - 2.0 * x),
                v: 6.0 * x * (1.0 - x),
                a: 6.0 - 12.0 * x,
                j: -12.0,
            },
            Self::Polynomial345 => Sample {
                s: x * x * x * (10.0 + x * (-15.0 + 6.0 * x)),
                v: 30.0 * x * x * (1.0 - x) * (1.0 - x),
                a: x * (60.0 + x * (-180.0 + 120.0 * x)),
                j: 60.0 + x * (-360.0 + 360.0 * x),
            },
            Self::Polynomial4567 => {
                let x3 = x * x * x;
                Sample {
                    s: x3 * x * (35.0 + x * (-84.0 + x * (70.0 - 20.0 * x))),
                    v: 140.0 * x3 * (1.0 - x).powi(3),
                    a: 420.0 * x * x * (1.0 - x) * (1.0 - x) * (1.0 - 2.0 * x),
                    j: x * (840.0 + x * (-5040.0 + x * (8400.0 - 4200.0 * x))),
                }
            }
            Self::Polynomial56789 => {
                let x2 = x * x;
                let x4 = x2 * x2;
                Sample {
                    s: x4 * x * (126.0 + x * (-420.0 + x * (540.0 + x * (-315.0 + 70.0 * x)))),
                    v: 630.0 * x4 * (1.0 - x).powi(4),
                    a: 2520.0 * (x * (1.0 - x)).powi(3) * (1.0 - 2.0 * x),
                    j: x2
                        * (7560.0
                            + x * (-50400.0 + x * (113_400.0 + x * (-105_840.0 + 35_280.0 * x)))),
                }
            }
            Self::DoubleHarmonic => {
                let (s1, c1) = (PI * x).sin_cos();
                let (s2, c2) = (2.0 * PI * x).sin_cos();
                Sample {
                    s: 0.5 * ((1.0 - c1) - 0.25 * (1.0 - c2)),
                    v: PI / 2.0 * (s1 - 0.5 * s2),
                    a: PI * PI / 2.0 * (c1 - c2),
                    j: -PI * PI * PI / 2.0 * (s1 - 2.0 * s2),
                }
            }
            Self::ModifiedTrapezoid => mirror(x, mt_first_half),
            Self::ModifiedSine => mirror(x, ms_first_half),
        }
    }
}

/// Extend a symmetric rise law given on [0, ½] to [0, 1]: `S(x) = 1 − S(1−x)`, `V(x) = V(1−x)`,
/// `A(x) = −A(1−x)`, `J(x) = J(1−x)`.
fn mirror(x: f64, half: fn(f64) -> Sample) -> Sample {
    if x <= 0.5 {
        half(x)
    } else {
        let m = half(1.0 - x);
        Sample {
            s: 1.0 - m.s,
            v: m.v,
            a: -m.a,
            j: m.j,
        }
    }
}

/// The explicit MT pieces of spec A.1 on [0, ½].
fn mt_first_half(x: f64) -> Sample {
    let ca = ca_mt();
    let w = 4.0 * PI;
    let v1 = ca / w;
    let s1 = ca * (1.0 / (8.0 * w) - 1.0 / (w * w));
    if x <= 0.125 {
        let (sn, cs) = (w * x).sin_cos();
        Sample {
            s: ca * (x / w - sn / (w * w)),
            v: ca * (1.0 - cs) / w,
            a: ca * sn,
            j: ca * w * cs,
        }
    } else if x <= 0.375 {
        let u = x - 0.125;
        Sample {
            s: s1 + v1 * u + 0.5 * ca * u * u,
            v: v1 + ca * u,
            a: ca,
            j: 0.0,
        }
    } else {
        let v2 = v1 + 0.25 * ca;
        let s2 = s1 + 0.25 * v1 + ca / 32.0;
        let u = x - 0.375;
        let (sn, cs) = (w * u).sin_cos();
        Sample {
            s: s2 + v2 * u + ca * (1.0 - cs) / (w * w),
            v: v2 + ca * sn / w,
            a: ca * cs,
            j: -ca * w * sn,
        }
    }
}

/// The explicit MS pieces of spec A.1 on [0, ½].
fn ms_first_half(x: f64) -> Sample {
    let ca = ca_ms();
    let w = 4.0 * PI;
    if x <= 0.125 {
        let (sn, cs) = (w * x).sin_cos();
        Sample {
            s: ca * (x / w - sn / (w * w)),
            v: ca * (1.0 - cs) / w,
            a: ca * sn,
            j: ca * w * cs,
        }
    } else {
        let v1 = ca / w;
        let s1 = ca * (1.0 / (8.0 * w) - 1.0 / (w * w));
        let wm = w / 3.0;
        let u = x - 0.125;
        let (sn, cs) = (wm * u).sin_cos();
        Sample {
            s: s1 + v1 * u + ca * (1.0 - cs) / (wm * wm),
            v: v1 + ca * sn / wm,
            a: ca * cs,
            j: -ca * wm * sn,
        }
    }
}

/// One Table-3 vector of the paper (spec §5.3, §3.7 errata applied).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CatalogueEntry {
    /// Paper id `L1`..`L9`.
    pub id: &'static str,
    /// Descriptive name (corrected per spec §3.7).
    pub name: &'static str,
    /// Normalized coefficients `ĉ0..ĉ6`.
    pub coefficients: [f64; 7],
}

/// The nine Table-3 laws (spec §5.3). L6 uses the §3.7 erratum `ĉ3 = 0.25` (the paper prints
/// seven times 0.125, which sums to 0.875).
pub const TABLE3: [CatalogueEntry; 9] = [
    CatalogueEntry {
        id: "L1",
        name: "modified sine",
        coefficients: [0.125, 0.0, 0.375, 0.0, 0.375, 0.0, 0.125],
    },
    CatalogueEntry {
        id: "L2",
        name: "constant acceleration",
        coefficients: [0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.0],
    },
    CatalogueEntry {
        id: "L3",
        name: "trimmed constant acceleration",
        coefficients: [0.0, 0.25, 0.0, 0.5, 0.0, 0.25, 0.0],
    },
    CatalogueEntry {
        id: "L4",
        name: "simple harmonic",
        coefficients: [0.0, 0.0, 0.5, 0.0, 0.5, 0.0, 0.0],
    },
    CatalogueEntry {
        id: "L5",
        name: "modified trapezoid",
        coefficients: [0.125, 0.25, 0.125, 0.0, 0.125, 0.25, 0.125],
    },
    CatalogueEntry {
        id: "L6",
        name: "modified trapezoid with 25 % constant velocity",
        coefficients: [0.125, 0.125, 0.125, 0.25, 0.125, 0.125, 0.125],
    },
    CatalogueEntry {
        id: "L7",
        name: "trimmed trapezoid",
        coefficients: [0.0625, 0.125, 0.0625, 0.5, 0.0625, 0.125, 0.0625],
    },
    CatalogueEntry {
        id: "L8",
        name: "cycloidal",
        coefficients: [0.25, 0.0, 0.25, 0.0, 0.25, 0.0, 0.25],
    },
    CatalogueEntry {
        id: "L9",
        name: "asymmetric trapezoid",
        coefficients: [0.05, 0.2, 0.05, 0.0, 0.05, 0.6, 0.05],
    },
];

static TABLE3_STATIC: [CatalogueEntry; 9] = TABLE3;

/// The Table-3 entry nearest to `c` by `max_k |ĉ_k − c_ref,k|`, and that distance. `c` is
/// normalized to Σ = 1 first when its sum is positive and finite (spec §3.6 classification).
#[must_use]
pub fn nearest(c: &[f64; 7]) -> (&'static CatalogueEntry, f64) {
    let sum: f64 = c.iter().sum();
    let scale = if sum > 0.0 && sum.is_finite() {
        1.0 / sum
    } else {
        1.0
    };
    let mut best = (&TABLE3_STATIC[0], f64::INFINITY);
    for entry in &TABLE3_STATIC {
        let dist = entry
            .coefficients
            .iter()
            .zip(c)
            .map(|(r, x)| (x * scale - r).abs())
            .fold(0.0, f64::max);
        if dist < best.1 {
            best = (entry, dist);
        }
    }
    best
}
