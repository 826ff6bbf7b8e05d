//! Pure compute modules, one folder per paper method. Nothing here knows about HTTP or async:
//! each module exposes `compute(input, budget) -> Result<Output, Error>` and its wire types.

pub mod bus_fuel_economy;
pub mod cam_law;
pub mod cam_law_fit;
pub mod cognates;
pub mod component_importance;
pub mod continuum_workspace;
pub mod irefc;
pub mod problem;

pub use problem::{CalcFailure, FieldIssue, ProblemClass, Validator};
