//! Identification of a 7-segment cam motion law from sampled motion (work in progress).

pub mod objective;
pub mod optim;
pub mod prep;
