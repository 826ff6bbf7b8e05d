//! Battery models of spec §5.6: constant efficiency, or a two-RC equivalent circuit
//! (discharge-positive current; the paper's eq. 7-10 use the opposite sign).

// Plain products instead of `mul_add`: without FMA hardware in the target (the default x86-64
// baseline) `mul_add` is a libm call, ~10x slower in these per-interval loops, and plain
// arithmetic follows the rounding of the spec's reference implementation.

use crate::numerics::grid::interp_clamped;

/// Battery model in SI units.
#[derive(Debug, Clone)]
pub enum Battery {
    /// P_in = P_dc/η if P_dc ≥ 0 else P_dc·η.
    Constant {
        /// η_Bat.
        eta: f64,
    },
    /// Two-RC equivalent circuit.
    Ecm(Ecm),
}

/// Two-RC equivalent-circuit battery with constant R/C.
#[derive(Debug, Clone)]
pub struct Ecm {
    /// SOC points of the OCV table (strictly increasing in [0, 1]).
    pub ocv_soc: Vec<f64>,
    /// OCV at `ocv_soc` \[V\].
    pub ocv_v: Vec<f64>,
    /// Series resistance R0 \[Ω\] (> 0).
    pub r0: f64,
    /// R1 \[Ω\].
    pub r1: f64,
    /// C1 \[F\].
    pub c1: f64,
    /// R2 \[Ω\].
    pub r2: f64,
    /// C2 \[F\].
    pub c2: f64,
    /// Initial SOC.
    pub soc0: f64,
    /// Charge capacity Q = capacity_kwh·3.6e6/nominal_voltage \[C\].
    pub q_coulomb: f64,
}

/// State of the 2RC battery along a cycle.
#[derive(Debug, Clone, Copy)]
pub struct EcmState {
    /// State of charge.
    pub soc: f64,
    /// Voltage over the first RC branch \[V\].
    pub v1: f64,
    /// Voltage over the second RC branch \[V\].
    pub v2: f64,
    /// Intervals whose power exceeded e²/(4 R0) (clamped to the maximum-power current).
    pub n_power_infeasible: u64,
    /// The SOC left [0, 1] at some point.
    pub soc_out_of_range: bool,
}

impl Ecm {
    /// Initial state (relaxed RC branches).
    #[must_use]
    pub fn initial(&self) -> EcmState {
        EcmState {
            soc: self.soc0,
            v1: 0.0,
            v2: 0.0,
            n_power_infeasible: 0,
            soc_out_of_range: false,
        }
    }

    /// Advance one interval of length `dt` at DC power `p_dc` \[W\]; returns the internal
    /// (chemical) power P_in = OCV·i \[W\].
    pub fn step(&self, st: &mut EcmState, p_dc: f64, dt: f64) -> f64 {
        let ocv = interp_clamped(&self.ocv_soc, &self.ocv_v, st.soc);
        let e = ocv - st.v1 - st.v2;
        let mut disc = e * e - 4.0 * self.r0 * p_dc;
        let clamped = disc < 0.0;
        if clamped {
            st.n_power_infeasible += 1;
            disc = 0.0;
        }
        let sq = disc.sqrt();
        // Smaller root of R0 i² − e i + P = 0; the product form avoids cancellation when e > 0.
        let i = if clamped || e <= 0.0 {
            (e - sq) / (2.0 * self.r0)
        } else {
            2.0 * p_dc / (e + sq)
        };
        let p_in = ocv * i;
        for (v, r, c) in [
            (&mut st.v1, self.r1, self.c1),
            (&mut st.v2, self.r2, self.c2),
        ] {
            let decay = (-dt / (r * c)).exp();
            *v = *v * decay + r * i * (1.0 - decay);
        }
        st.soc -= i * dt / self.q_coulomb;
        if !(0.0..=1.0).contains(&st.soc) {
            st.soc_out_of_range = true;
        }
        p_in
    }
}
