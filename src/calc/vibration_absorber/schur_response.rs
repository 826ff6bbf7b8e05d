//! The coupled frequency and time responses (spec §3.D.3–4) from one real Schur decomposition.
//!
//! `A = D Q T Qᵀ D⁻¹` ([`BalancedSchur`]: the balancing and Schur form the eigen-analysis computes
//! anyway) is reused across every frequency and every sample:
//!
//! * FRF: `C (jωI − A)⁻¹ B = ĉ (jωI − T)⁻¹ b̂` with `b̂ = Qᵀ D⁻¹ B`, `ĉ = Qᵀ D cᵀ`: one
//!   quasi-triangular back substitution per frequency (`N²/2` products) instead of a complex LU
//!   (`N³/3`, plus a copy of the matrix);
//! * time response: the augmented system is stepped in the coordinates `u = Qᵀ D⁻¹ s` with
//!   `E = expm(T h)` (quasi-triangular as `T`), the outputs and the next state from one
//!   matrix-vector product with `[Ĉ; E]`.
//!
//! Neither forms eigenvectors, so both stay exact where `A` is defective or has repeated
//! eigenvalues (an undamped mode forced at its own frequency, where the exosystem's `±jΩ`
//! coincides with the beam's): `Q` is orthogonal whatever the eigenstructure. When the Schur
//! form is not available (the iteration fails, or `T` is not quasi-triangular) the callers use
//! the previous dense methods of [`response`], which remain the reference in the tests.

use nalgebra::{Complex, DMatrix, DVector};

use crate::calc::vibration_absorber::error::VibrationAbsorberError as Error;
use crate::calc::vibration_absorber::response::{
    self, Eigen, REANCHOR_ABOVE, REANCHOR_EVERY, SINGULAR_REL, STABILITY_REL, Stab, Stepper,
    TimeSeries,
};
use crate::numerics::linalg::{BalancedSchur, expm};
use crate::numerics::{Budget, par_map_while};

/// Frequencies solved per task of the parallel map (one work vector each).
const FRF_CHUNK: usize = 32;

/// Eigenvalues and stability label from the kept Schur form (the same numbers and label as
/// [`response::eigen`] computes from `A`).
#[must_use]
pub fn eigen(schur: &BalancedSchur) -> Eigen {
    let values = schur.values.clone();
    let max_re = values
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    let max_abs = values.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let tol = STABILITY_REL * max_abs;
    let stability = if max_re < -tol {
        Stab::Stable
    } else if max_re.abs() <= tol {
        Stab::Marginal
    } else {
        Stab::Unstable
    };
    Eigen {
        values,
        max_re,
        stability,
    }
}

/// `C (jωI − A)⁻¹ B` for each output row at each ω [rad/s] from the Schur form of `A`; `None`
/// where `jω` is (numerically) an eigenvalue (the test of [`response::frequency_response`]) or
/// the result is not finite. Indexed `[frequency][row]`.
///
/// # Errors
/// [`Error::Deadline`] when the budget runs out or the request is cancelled.
pub fn frequency_response(
    schur: &BalancedSchur,
    b: &DVector<f64>,
    rows: &[DVector<f64>],
    omegas: &[f64],
    budget: &Budget,
) -> Result<Vec<Vec<Option<Complex<f64>>>>, Error> {
    let n = schur.size();
    let eig = &schur.values;
    let max_abs = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let bh = schur.to_schur(b);
    let ch: Vec<DVector<f64>> = rows.iter().map(|c| schur.row_to_schur(c)).collect();
    let total = omegas.len();
    let chunks: Vec<&[f64]> = omegas.chunks(FRF_CHUNK).collect();
    let out = par_map_while(budget.threads(), &chunks, |i, chunk| {
        if budget.expired() || budget.cancelled() {
            return None;
        }
        budget.progress((i * FRF_CHUNK) as f64 / total as f64, None);
        let mut x = vec![Complex::new(0.0, 0.0); n];
        let per_freq: Vec<Vec<Option<Complex<f64>>>> = chunk
            .iter()
            .map(|&w| {
                let jw = Complex::new(0.0, w);
                let near = eig
                    .iter()
                    .map(|l| (jw - l).norm())
                    .fold(f64::INFINITY, f64::min);
                if near <= SINGULAR_REL * max_abs.max(w) {
                    return vec![None; rows.len()];
                }
                schur.solve_shifted(jw, bh.as_slice(), &mut x);
                ch.iter()
                    .map(|c| {
                        let h: Complex<f64> = c.iter().zip(&x).map(|(ci, xi)| xi * *ci).sum();
                        (h.re.is_finite() && h.im.is_finite()).then_some(h)
                    })
                    .collect()
            })
            .collect();
        Some(per_freq)
    });
    let done: usize = out.iter().flatten().map(Vec::len).sum();
    if done < total {
        return Err(Error::Deadline {
            stage: "frequency response",
            done: done as u64,
            total: total as u64,
        });
    }
    Ok(out.into_iter().flatten().flatten().collect())
}

/// The time response of [`Stepper`] stepped in Schur coordinates; falls back to
/// [`Stepper::run`] (dense `Φ` in the original coordinates) when `A_aug` has no usable Schur form.
///
/// # Errors
/// As [`Stepper::run`]: [`Error::NonFinite`] when the transition matrix or the state overflows,
/// [`Error::Deadline`] when the budget runs out (checked every 1024 steps).
pub fn time_response(stepper: &Stepper<'_>, budget: &Budget) -> Result<TimeSeries, Error> {
    match BalancedSchur::new(stepper.a) {
        Some(schur) => run_schur(stepper, &schur, budget),
        None => stepper.run(budget),
    }
}

/// `[Ĉ; E]` as one column-major matrix, so that one matrix-vector product gives the outputs
/// `y_k = Ĉ u_k` and the next state `u_{k+1} = E u_k` (the products vectorise along the
/// columns; separate row dot products would be latency-bound). The entries of `E` below `T`'s
/// block diagonal are zero in exact arithmetic and are set so.
fn fused(e: &DMatrix<f64>, ch: &[DVector<f64>], schur: &BalancedSchur) -> DMatrix<f64> {
    let n = e.nrows();
    let r = ch.len();
    let mut lim = vec![0; n];
    for &(start, size) in &schur.blocks {
        for l in &mut lim[start..start + size] {
            *l = start + size;
        }
    }
    DMatrix::from_fn(r + n, n, |i, j| {
        if i < r {
            ch[i][j]
        } else if i - r < lim[j] {
            e[(i - r, j)]
        } else {
            0.0
        }
    })
}

/// `u_{k+1} = E u_k`, `y_k = Ĉ u_k`, re-anchored with `u(t_k) = expm(T t_k) u(0)` as
/// [`Stepper::run`] does in the original coordinates.
fn run_schur(
    st: &Stepper<'_>,
    schur: &BalancedSchur,
    budget: &Budget,
) -> Result<TimeSeries, Error> {
    let t = &schur.t;
    let e = expm(&(t * st.dt)).ok_or_else(|| Error::NonFinite {
        stage: "transition matrix expm(A h)",
        detail: format!("‖A h‖ = {:.3e}", (st.a * st.dt).abs().max()),
    })?;
    let n = t.nrows();
    let ch: Vec<DVector<f64>> = st.rows.iter().map(|c| schur.row_to_schur(c)).collect();
    let nr = ch.len();
    let m = fused(&e, &ch, schur);
    let u0 = schur.to_schur(st.s0);
    let mut ts = TimeSeries {
        max_abs: vec![0.0; nr],
        max_last: vec![0.0; nr],
        rms: vec![0.0; nr],
        expms: 1,
        ..TimeSeries::default()
    };
    let keep = st.decimate.map(|d| d.max(1));
    let mut series: Option<Vec<Vec<f64>>> =
        keep.map(|d| vec![Vec::with_capacity(st.steps / d + 1); nr]);
    let mut times = keep.map(|d| Vec::with_capacity(st.steps / d + 1));
    let mut u = u0.clone();
    let mut out = DVector::zeros(nr + n);
    let reanchor = st.steps > REANCHOR_ABOVE;
    let mut sumsq = vec![0.0; nr];
    for k in 0..=st.steps {
        if k > 0 {
            if reanchor && k % REANCHOR_EVERY == 0 {
                let time = k as f64 * st.dt;
                let direct = expm(&(t * time)).ok_or_else(|| Error::NonFinite {
                    stage: "re-anchoring expm(A t)",
                    detail: format!("t = {time} s"),
                })?;
                ts.expms += 1;
                u = direct * &u0;
            } else {
                u.copy_from(&out.rows(nr, n));
            }
            if k % 1024 == 0 {
                if budget.check(ts.expms).is_some() {
                    return Err(Error::Deadline {
                        stage: "time response",
                        done: k as u64,
                        total: st.steps as u64,
                    });
                }
                budget.progress(k as f64 / st.steps as f64, None);
                if !u.iter().all(|x| x.is_finite()) {
                    return Err(Error::NonFinite {
                        stage: "time response",
                        detail: format!("state overflowed at t = {} s", k as f64 * st.dt),
                    });
                }
            }
        }
        out.gemv(1.0, &m, &u, 0.0);
        let last = k >= st.last_from;
        let sample = keep.is_some_and(|d| k % d == 0);
        for (j, &y) in out.as_slice()[..nr].iter().enumerate() {
            let ay = y.abs();
            ts.max_abs[j] = ts.max_abs[j].max(ay);
            if last {
                ts.max_last[j] = ts.max_last[j].max(ay);
            }
            sumsq[j] += y * y;
            if sample && let Some(ser) = series.as_mut() {
                ser[j].push(y);
            }
        }
        if sample && let Some(t) = times.as_mut() {
            t.push(k as f64 * st.dt);
        }
    }
    let count = (st.steps + 1) as f64;
    ts.rms = sumsq.iter().map(|s| (s / count).sqrt()).collect();
    ts.series = series;
    ts.t = times;
    let all = ts.max_abs.iter().chain(&ts.rms);
    if !all.clone().all(|x| x.is_finite()) {
        return Err(Error::NonFinite {
            stage: "time response",
            detail: "the response overflowed".to_owned(),
        });
    }
    Ok(ts)
}

/// The eigen-analysis and the FRF's decomposition of `A`: the kept Schur form, or `None` with the
/// eigenvalues of [`response::eigen`] when the form is not usable.
///
/// # Errors
/// [`Error::EigenNotConverged`] when the Schur iteration fails.
pub fn decompose(a: &DMatrix<f64>) -> Result<(Eigen, Option<BalancedSchur>), Error> {
    match BalancedSchur::new(a) {
        Some(s) => Ok((eigen(&s), Some(s))),
        None => Ok((response::eigen(a)?, None)),
    }
}
