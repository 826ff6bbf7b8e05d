//! The coupled beam–absorber–actuator model (spec §3.A–3.C): modal data, PD gains of Eq. (7)(8),
//! the state space `ṡ = A s + B p(t)` of every configuration and its output rows.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::beam::ModeShape;
use super::input::Config;

/// PD gains placing two fixed-base absorber roots at `±jω_c` (spec §3.B, paper Eq. (7)(8)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// `K_p` [V/m].
    pub kp: f64,
    /// `K_d` [V·s/m].
    pub kd: f64,
    /// Target `f_c` \[Hz\] (`None` for explicit gains).
    pub tuning_hz: Option<f64>,
    /// Third root `−(R/L_c + b_a/m_a)` [1/s] (exact only for tuned gains).
    pub third_pole: f64,
    /// Artificial stiffness `m_a ω_c² − k_a` [N/m] (tuned gains only).
    pub k_art: Option<f64>,
}

/// The absorber and actuator constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Device {
    /// `m_a` \[kg\].
    pub ma: f64,
    /// `k_a` [N/m].
    pub ka: f64,
    /// `b_a` [N·s/m].
    pub ba: f64,
    /// `R` \[Ω\].
    pub r: f64,
    /// `L_c` \[H\].
    pub lc: f64,
    /// `K_c` [N/A].
    pub kc: f64,
    /// `K_b` [V·s/m].
    pub kb: f64,
}

impl Device {
    /// Gains of Eq. (7)(8) for the target `f_c` \[Hz\]; `None` when `K_c = 0`.
    #[must_use]
    pub fn tuned_gains(&self, fc: f64) -> Option<Gains> {
        if self.kc == 0.0 {
            return None;
        }
        let w2 = (2.0 * std::f64::consts::PI * fc).powi(2);
        let k_art = self.ma * w2 - self.ka;
        Some(Gains {
            kp: (self.r * k_art + self.lc * self.ba * w2) / self.kc,
            kd: -(self.r * self.ba - self.lc * k_art + self.kb * self.kc) / self.kc,
            tuning_hz: Some(fc),
            third_pole: self.third_pole(),
            k_art: Some(k_art),
        })
    }

    /// `−(R/L_c + b_a/m_a)` [1/s].
    #[must_use]
    pub fn third_pole(&self) -> f64 {
        -(self.r / self.lc + self.ba / self.ma)
    }

    /// `D(s) = (m_a s² + b_a s + k_a)(L_c s + R) + K_b K_c s` at complex `s`.
    #[must_use]
    pub fn d_poly(&self, s: nalgebra::Complex<f64>) -> nalgebra::Complex<f64> {
        (s * s * self.ma + s * self.ba + self.ka) * (s * self.lc + self.r) + s * (self.kb * self.kc)
    }

    /// Fixed-base absorber with coil, state `[x, ẋ, i]`, input the coil voltage `e_c`.
    #[must_use]
    pub fn fixed_base(&self) -> (DMatrix<f64>, DVector<f64>) {
        let a = DMatrix::from_row_slice(
            3,
            3,
            &[
                0.0,
                1.0,
                0.0,
                -self.ka / self.ma,
                -self.ba / self.ma,
                self.kc / self.ma,
                0.0,
                -self.kb / self.lc,
                -self.r / self.lc,
            ],
        );
        (a, DVector::from_vec(vec![0.0, 0.0, 1.0 / self.lc]))
    }
}

/// The assembled model of one request.
#[derive(Debug, Clone)]
pub struct Model {
    /// Configuration (which states exist).
    pub config: Config,
    /// Beam length `L` \[m\].
    pub length: f64,
    /// Modal mass `m = ρAL` \[kg\] (every mode).
    pub modal_mass: f64,
    /// Bare-beam circular frequencies `ω_k` [rad/s].
    pub omega: Vec<f64>,
    /// Modal damping ratio ζ.
    pub zeta: f64,
    /// Mode shapes.
    pub shapes: Vec<ModeShape>,
    /// Absorber and actuator.
    pub dev: Device,
    /// PD gains in use (`0, 0` unless `active`).
    pub kp: f64,
    /// See `kp`.
    pub kd: f64,
    /// `φ_k(x_a)`.
    pub phi_a: Vec<f64>,
    /// `φ_k(x_p)`.
    pub phi_p: Vec<f64>,
}

impl Model {
    /// Number of modes kept.
    #[must_use]
    pub fn n(&self) -> usize {
        self.omega.len()
    }

    /// `[φ_k(x)]` at abscissa `x` \[m\].
    #[must_use]
    pub fn phi_at(&self, x: f64) -> Vec<f64> {
        let xi = (x / self.length).clamp(0.0, 1.0);
        self.shapes.iter().map(|m| m.phi(xi)).collect()
    }

    /// State size `N`: 2n (`none`), 2n+2 (`passive`), 2n+3 (`passive_shorted`, `active`).
    #[must_use]
    pub fn size(&self) -> usize {
        2 * self.n()
            + match self.config {
                Config::None => 0,
                Config::Passive => 2,
                Config::PassiveShorted | Config::Active => 3,
            }
    }

    /// Whether the coil current is a state.
    #[must_use]
    pub fn has_coil(&self) -> bool {
        matches!(self.config, Config::PassiveShorted | Config::Active)
    }

    /// `A` of spec §3.C (state `[q, q̇, z, ż, i]`, trailing states dropped by configuration).
    #[must_use]
    pub fn a_matrix(&self) -> DMatrix<f64> {
        let n = self.n();
        let big = self.size();
        let m = self.modal_mass;
        let mut a = DMatrix::zeros(big, big);
        for k in 0..n {
            a[(k, n + k)] = 1.0;
            a[(n + k, k)] = -self.omega[k] * self.omega[k];
            a[(n + k, n + k)] = -2.0 * self.zeta * self.omega[k];
        }
        if self.config == Config::None {
            return a;
        }
        let d = &self.dev;
        let (z, zd, i) = (2 * n, 2 * n + 1, 2 * n + 2);
        let pa = &self.phi_a;
        // Beam rows: + φ_a (k_a r + b_a ṙ − K_c i) / m, r = z − φ_aᵀq.
        for k in 0..n {
            for j in 0..n {
                a[(n + k, j)] -= pa[k] * d.ka * pa[j] / m;
                a[(n + k, n + j)] -= pa[k] * d.ba * pa[j] / m;
            }
            a[(n + k, z)] = pa[k] * d.ka / m;
            a[(n + k, zd)] = pa[k] * d.ba / m;
            if self.has_coil() {
                a[(n + k, i)] = -pa[k] * d.kc / m;
            }
        }
        // Absorber: m_a z̈ = −k_a r − b_a ṙ + K_c i.
        a[(z, zd)] = 1.0;
        for j in 0..n {
            a[(zd, j)] = d.ka * pa[j] / d.ma;
            a[(zd, n + j)] = d.ba * pa[j] / d.ma;
        }
        a[(zd, z)] = -d.ka / d.ma;
        a[(zd, zd)] = -d.ba / d.ma;
        if self.has_coil() {
            a[(zd, i)] = d.kc / d.ma;
            // Coil: L_c i̇ = −R i − (K_b + K_d) ṙ − K_p r.
            let (kr, krd) = (self.kp, d.kb + self.kd);
            for j in 0..n {
                a[(i, j)] = kr * pa[j] / d.lc;
                a[(i, n + j)] = krd * pa[j] / d.lc;
            }
            a[(i, z)] = -kr / d.lc;
            a[(i, zd)] = -krd / d.lc;
            a[(i, i)] = -d.r / d.lc;
        }
        a
    }

    /// `B` (unit force at `x_p`): `φ_p / m` in the `q̈` rows.
    #[must_use]
    pub fn b_vector(&self) -> DVector<f64> {
        let n = self.n();
        let mut b = DVector::zeros(self.size());
        for k in 0..n {
            b[n + k] = self.phi_p[k] / self.modal_mass;
        }
        b
    }

    /// Output row of the beam deflection `w(x)`.
    #[must_use]
    pub fn row_deflection(&self, x: f64) -> DVector<f64> {
        let mut c = DVector::zeros(self.size());
        for (k, p) in self.phi_at(x).into_iter().enumerate() {
            c[k] = p;
        }
        c
    }

    /// Output row of the stroke `r = z − φ_aᵀq` (or of `ṙ` with `rate`); `None` without absorber.
    #[must_use]
    pub fn row_stroke(&self, rate: bool) -> Option<DVector<f64>> {
        if self.config == Config::None {
            return None;
        }
        let n = self.n();
        let off = if rate { n } else { 0 };
        let mut c = DVector::zeros(self.size());
        for k in 0..n {
            c[off + k] = -self.phi_a[k];
        }
        c[2 * n + usize::from(rate)] = 1.0;
        Some(c)
    }

    /// Output row of the coil current scaled by `scale` (`1` for the current, `K_c` for the force
    /// `u = K_c i`); `None` without coil.
    #[must_use]
    pub fn row_current(&self, scale: f64) -> Option<DVector<f64>> {
        self.has_coil().then(|| {
            let mut c = DVector::zeros(self.size());
            c[2 * self.n() + 2] = scale;
            c
        })
    }

    /// Output row of the control voltage `e_c = −(K_p r + K_d ṙ)` (`active` only).
    #[must_use]
    pub fn row_voltage(&self) -> Option<DVector<f64>> {
        if self.config != Config::Active {
            return None;
        }
        let r = self.row_stroke(false)?;
        let rd = self.row_stroke(true)?;
        Some(-(r * self.kp + rd * self.kd))
    }

    /// Undamped natural frequencies \[Hz\] of the beam with the absorber's mass and spring only
    /// (spec §3.D.1): `K v = λ M v`, reduced with `M^{-1/2}`; ascending, n + 1 values.
    #[must_use]
    pub fn with_absorber_frequencies(&self) -> Vec<f64> {
        let n = self.n();
        let d = &self.dev;
        let mut k = DMatrix::zeros(n + 1, n + 1);
        let mut inv_sqrt_m = vec![1.0 / self.modal_mass.sqrt(); n];
        inv_sqrt_m.push(1.0 / d.ma.sqrt());
        for i in 0..n {
            for j in 0..n {
                k[(i, j)] = d.ka * self.phi_a[i] * self.phi_a[j];
            }
            k[(i, i)] += self.modal_mass * self.omega[i] * self.omega[i];
            k[(i, n)] = -d.ka * self.phi_a[i];
            k[(n, i)] = -d.ka * self.phi_a[i];
        }
        k[(n, n)] = d.ka;
        for i in 0..=n {
            for j in 0..=n {
                k[(i, j)] *= inv_sqrt_m[i] * inv_sqrt_m[j];
            }
        }
        let mut f: Vec<f64> = SymmetricEigen::new(k)
            .eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        f.sort_by(f64::total_cmp);
        f
    }

    /// Static compliance `Σ φ_k(x_o) φ_k(x_p) / (m ω_k²)` [m/N] of the truncated bare beam.
    #[must_use]
    pub fn static_compliance(&self, x_o: f64) -> f64 {
        let po = self.phi_at(x_o);
        (0..self.n())
            .map(|k| po[k] * self.phi_p[k] / (self.modal_mass * self.omega[k] * self.omega[k]))
            .sum()
    }
}
