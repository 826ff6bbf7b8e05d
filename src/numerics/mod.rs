//! Shared numerics: solver budgets and stop reasons, and (as modules need them) roots, quadrature,
//! interpolation and seeded random numbers. Pure Rust: no I/O, no async runtime.

pub mod budget;
pub mod elliptic;

pub use budget::{Budget, SolverReport, StopReason};
