//! mechcalc: research methods from machine design as fast, exact, validated calculations.
//!
//! * [`calc`]: pure compute modules, one per paper method (no HTTP, no async).
//! * [`numerics`]: shared numerical building blocks (budgets, solvers).
//! * [`http`]: the axum service around them; [`app`] builds the router (tests drive it with no
//!   socket).
//! * [`config`]: flags and environment variables of the binary.

pub mod calc;
pub mod config;
pub mod http;
pub mod numerics;

pub use http::{AppState, app};
