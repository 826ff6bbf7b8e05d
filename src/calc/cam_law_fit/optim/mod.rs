//! Optimizers of the fit (spec §3.5), generic over a [`CurveModel`] through the evaluation
//! context [`Ctx`].
//!
//! Every optimizer works on the *free* genes only (`fixed_zero` and zero-snapped genes are held at
//! exactly 0), checks the budget before every evaluation and once per iteration, and leaves its
//! best-so-far in the context, so a budget stop returns the best point found.

pub mod cmaes;
pub mod de;
pub mod ga;
pub mod lsq;

use super::objective::{Ctx, CurveModel};
use crate::numerics::StopReason;

/// Indices of the genes an optimizer may change; the others are held at 0.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FreeGenes(pub Vec<usize>);

impl FreeGenes {
    /// All genes not flagged in `fixed_zero`.
    #[must_use]
    pub fn from_mask(fixed_zero: &[bool; 7]) -> Self {
        Self((0..7).filter(|&k| !fixed_zero[k]).collect())
    }

    /// Number of free genes.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether no gene is free.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The 7 genes with the free ones taken from `y` (others 0).
    #[must_use]
    pub fn expand(&self, y: &[f64]) -> [f64; 7] {
        let mut g = [0.0; 7];
        for (&k, &v) in self.0.iter().zip(y) {
            g[k] = v;
        }
        g
    }

    /// The free genes of `g`.
    #[must_use]
    pub fn project(&self, g: &[f64; 7]) -> Vec<f64> {
        self.0.iter().map(|&k| g[k]).collect()
    }
}

/// Normalize genes to `ĉ = g/Σg` (unchanged when the sum is not positive).
#[must_use]
pub fn normalized(g: &[f64; 7]) -> [f64; 7] {
    let s: f64 = g.iter().sum();
    if s > 0.0 && s.is_finite() {
        g.map(|v| v / s)
    } else {
        *g
    }
}

/// How one optimizer run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunEnd {
    /// Why it stopped.
    pub stop: StopReason,
    /// Best objective of the run (under the context's metric, or EN for least squares).
    pub f: f64,
    /// Best genes of the run.
    pub g: [f64; 7],
}

pub use crate::numerics::rng::normal;

/// Evaluate `g`, returning `None` when the budget refuses.
pub(crate) fn eval<M: CurveModel>(ctx: &mut Ctx<'_, M>, g: &[f64; 7]) -> Option<f64> {
    ctx.value(g).ok()
}

#[cfg(test)]
pub(crate) mod testmodel {
    //! A smooth toy model for optimizer unit tests (the cam law lives in `cam_law`): the curve is
    //! a normalized mixture of 7 bumps, so `ĉ` is identifiable from the curve.
    use super::super::objective::CurveModel;

    pub struct Bumps {
        pub xs: Vec<f64>,
    }

    impl CurveModel for Bumps {
        fn curve(&self, g: &[f64; 7], out: &mut [f64]) -> bool {
            let s: f64 = g.iter().sum();
            if s <= 0.0 || g[0] + g[1] + g[2] <= 0.0 || g[4] + g[5] + g[6] <= 0.0 {
                return false;
            }
            for (o, x) in out.iter_mut().zip(&self.xs) {
                *o = g
                    .iter()
                    .enumerate()
                    .map(|(k, gk)| {
                        let c = (k as f64 + 0.5) / 7.0;
                        gk / s * (-(x - c) * (x - c) * 60.0).exp() * (1.0 + k as f64)
                    })
                    .sum();
            }
            true
        }
    }

    pub fn setup(truth: &[f64; 7]) -> (Bumps, Vec<f64>) {
        let xs: Vec<f64> = (0..120).map(|k| f64::from(k) / 119.0).collect();
        let m = Bumps { xs };
        let mut y = vec![0.0; 120];
        assert!(m.curve(truth, &mut y));
        (m, y)
    }

    /// Largest absolute difference between the normalized coefficients of `g` and `truth`.
    pub fn coefficient_error(g: &[f64; 7], truth: &[f64; 7]) -> f64 {
        super::normalized(g)
            .iter()
            .zip(truth)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }
}
