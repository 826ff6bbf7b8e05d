//! Gradient-boosted trees for machined dimensions (work in progress).

pub mod boost;
pub mod data;
pub mod document;
pub mod model;
pub mod rng;
pub mod shap;
pub mod gra;
pub mod pca;
pub mod smogn;
