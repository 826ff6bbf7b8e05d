//! Cam motion laws: the general 7-segment modified-trapezoidal law with arbitrary end rates
//! (Tiboni, Amici, Bussola, "Cam Mechanisms Reverse Engineering Based on Evolutionary Algorithms",
//! Electronics 2021, 10, 3073, Appendix A), the classic laws of the spec's Appendix A, and the
//! `/v1/cam-law/evaluate` computation. Spec: `shared/specs/cam_law_fit.md`.

pub mod catalogue;
pub mod law;
