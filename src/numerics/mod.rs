//! Shared numerics: solver budgets and stop reasons, the one parallel map, angle conventions and
//! the building blocks more than one module needs (roots, small dense linear algebra, grids and
//! interpolation, seeded random numbers, elliptic integrals). Pure Rust: no I/O, no async runtime.

pub mod angles;
pub mod budget;
pub mod dense;
pub mod elliptic;
pub mod grid;
pub mod linalg;
pub mod parallel;
pub mod pchip;
pub mod quadrature;
pub mod rng;
pub mod roots;

pub use budget::{Budget, SolverReport, StopReason};
pub use parallel::{par_map, par_map_while};
