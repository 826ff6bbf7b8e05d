//! mechcalc: research methods from machine design as fast, exact, validated calculations.
//!
//! * [`calc`]: pure compute modules, one per paper method (no HTTP, no async).
//! * [`numerics`]: shared numerical building blocks (budgets, solvers).
//! * [`http`]: the axum service around them; [`app`] builds the router (tests drive it with no
//!   socket).
//! * [`config`]: flags and environment variables of the binary.
//! * [`plot`]: SVG pictures of answers (`Accept: image/svg+xml`).
//! * [`export`]: calculation reports (HTML), tables (CSV) and drawings (DXF) of answers.
//! * [`cli`]: `mechcalc run`, one calculation from the command line without a server.
//! * [`merge`]: the answers of a sweep's shards merged into the unsharded answer
//!   (`mechcalc merge`).

pub mod calc;
pub mod cli;
pub mod config;
pub mod export;
pub mod http;
pub mod merge;
pub mod numerics;
pub mod plot;

pub use http::{AppState, app};
