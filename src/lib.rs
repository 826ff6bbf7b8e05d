//! mechcalc: research methods from machine design as fast, exact, validated calculations.
//!
//! * [`calc`]: pure compute modules, one per paper method (no HTTP, no async).
//! * [`numerics`]: shared numerical building blocks (budgets, solvers).
//! * [`http`]: the axum service around them; [`app`] builds the router (tests drive it with no
//!   socket).
//! * [`config`]: flags and environment variables of the binary.
//! * [`plot`]: SVG pictures of answers (`Accept: image/svg+xml`).
//! * [`cli`]: `mechcalc run`, one calculation from the command line without a server.

// Units are written in brackets in doc comments ("time [s]", "displacement [U]"), as the style
// guide asks; rustdoc would read them as intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod calc;
pub mod cli;
pub mod config;
pub mod http;
pub mod numerics;
pub mod plot;

pub use http::{AppState, app};
