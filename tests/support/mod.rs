//! Support shared by the integration-test crates (`tests/it`, `tests/slow`) and, through `#[path]`,
//! the benches: the HTTP driver, spec fixtures, the finite-number check of a JSON answer and the
//! `PROPTEST_CASES` configuration. Each crate uses a part of it, so unused items are expected.
#![allow(
    dead_code,
    reason = "shared by several test crates; each crate uses a different part"
)]

pub mod bezier_ode;
pub mod bus_demo_motor;
pub mod cam_law_strategies;
pub mod cam_table1;
pub mod component_importance;
pub mod finite;
pub mod http;
pub mod machining_size;
pub mod proptest_cfg;
pub mod spatial_coupling;
