//! Pure compute modules, one folder per paper method. Nothing here knows about HTTP or async:
//! each module exposes `compute(input, budget) -> Result<Output, Error>` and its wire types.

pub mod cam_law;
pub mod cognates;
pub mod continuum_workspace;
pub mod problem;

pub use problem::{CalcFailure, FieldIssue, ProblemClass, Validator};
