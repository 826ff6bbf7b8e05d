//! mechcalc: research methods from machine design as fast, exact, validated calculations.
//!
//! * [`calc`]: pure compute modules, one per paper method (no HTTP, no async).
//! * [`numerics`]: shared numerical building blocks (budgets, solvers).

pub mod calc;
pub mod numerics;
