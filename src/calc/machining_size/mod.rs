//! Gradient-boosted trees for machined dimensions (work in progress).

pub mod boost;
pub mod data;
pub mod model;
pub mod rng;
