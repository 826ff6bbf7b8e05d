//! IREFC cycloid gear: gears with intermediate rolling elements and a free cage (a cam with Z2 − 1 lobes,
//! Z2 rolling elements in a free cage, a crown with Z2 + 1 lobes, driven by an eccentric carrier).
//!
//! * [`geometry`]: the ONE shared geometry (spec `irefc_geometry.md`): radii, eccentricity, the true contact
//!   angle (atan2 branch), the exact closed-form curvature of both wheel profiles, the undercut and
//!   element-overlap limits, the load-sharing element set and optional profile point sets.
//! * [`stress`]: `POST /v1/irefc-stress` (spec `irefc_stress.md`): element forces (rigid load sharing, paper
//!   or phase-exact), Hertz line-contact stresses at the cam and crown contacts, their maxima over φ2 by
//!   grid + Brent refinement, and the parallel "structured array" sweep over Z2 × χ (× rb × r2) with best and
//!   worst feasible designs. Entry point [`run_stress`].
//! * [`efficiency`]: `POST /v1/irefc-efficiency` (spec `irefc_efficiency.md`): slip speeds, friction power
//!   and mesh efficiency per element, in the paper's model (as printed, or with |Vs|) and in a rigid-body model
//!   (NOT in the paper, physically consistent speeds). Entry point [`run_efficiency`].
//!
//! # References
//! * "Development of an Algorithm for Computing the Force and Stress Parameters of a Cycloid Reducer",
//!   Mathematics 2023, 11, 993 (`shared/papers/irefc-force-stress.txt`), eqs 1–20.
//! * The companion paper on friction power and efficiency of a gear with intermediate rolling elements and
//!   a free cage, Mathematics 2024, 12, 873 (`shared/papers/irefc-efficiency.txt`), eqs 7–23 and Table 1.
//! * K. L. Johnson, *Contact Mechanics*, §4.2 (line-contact peak pressure, half-width, subsurface shear).
//!
//! Paper errata resolved as in the specs: efficiency eq. 7 (L) is misprinted; force eq. 14's arcsin gives
//! the wrong branch of α for cos φ > 1/χ (atan2 is used); eq. 20's Bobillier construction is replaced by the
//! exact closed-form curvature; efficiency eq. 23 is garbled (product and energy balance both reported).
//!
//! # Validity and accuracy
//! * Input range: 0 < r2 ≤ 10 000 mm, 3 ≤ Z2 ≤ 1000, 1 < χ ≤ 5, 0 < rb < min(rb_overlap, rb_undercut);
//!   torque 0…1e7 N·m; E 1e3…1e7 MPa, 0 ≤ ν < 0.5. Outside: `BAD_RANGE` (every field at once), `UNDERCUT`,
//!   `ELEMENT_OVERLAP`; a sweep marks such combinations `valid: false` with the reason instead.
//! * Geometry: closed forms, f64 round-off only (the Table 1 pitch distances of the efficiency paper are
//!   reproduced to the printed 6 decimals; curvature agrees with the Bobillier and Euler–Savary forms to
//!   1e-10 and with finite differences of the generated profile to the FD truncation error).
//! * Maximum contact stress: with `refine: true` and the default step of 1° the maxima are within 2e-15
//!   (relative) of a 0.001° + refine reference on the spec's designs and near-undercut designs; the paper's
//!   0.02° grid without refinement is within 1.8e-8 (7e-8 near the undercut). Hertz σ equals the textbook
//!   line-contact p0 and the paper's eq. 18 to 1e-9 (property test) and an independent implementation to
//!   1e-15. Measured error-vs-time tables: `benches/RESULTS.md` (## irefc).
//! * Near the undercut limit (sharpest convex profile radius < 0.25·rb) σ is legitimately huge and finite
//!   (`NEAR_UNDERCUT` warning); at the limit within round-off the result is `UNDERCUT`, never NaN. Results
//!   that overflow f64 at absurd scales (e.g. lb = 1e-300 mm) give `NON_FINITE`, never NaN/Inf in JSON.
//! * Efficiency: "paper_table" reproduces the paper's Table 1 (LA, LB, Vs, NS, R) to its printed digits and
//!   η = 0.93; its NSA/NSB columns are not reproducible from its equations (see the spec). "rigid_body"
//!   gives η ≤ 1 for every μ, f_s ≥ 0; with the paper's μ = 1 mm it predicts η ≈ 0.37, so the paper's
//!   η = 0.93 depends on its reduced relative speeds.

pub mod efficiency;
pub mod error;
pub mod geometry;
pub mod input;
pub mod output;
pub mod stress;
pub mod wire;

pub use efficiency::run_efficiency;
pub use efficiency::wire::{IrefcEfficiencyRequest, IrefcEfficiencyResponse};
pub use error::IrefcError;
pub use stress::run_stress;
pub use stress::wire::{IrefcStressRequest, IrefcStressResponse};
