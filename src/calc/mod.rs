//! Pure compute modules, one folder per paper method. Nothing here knows about HTTP or async.
//!
//! Every module has the same five files with the same roles (ARCHITECTURE.md): `wire.rs` (serde +
//! OpenAPI types, bounds), `input.rs` (the validated SI domain input), `compute.rs` (the pure
//! `compute(&Input, &Budget) -> Result<Output, Error>`), `output.rs` (the one place that builds the
//! response) and `mod.rs` (docs and `run`, which chains them). Shared here: the validator and
//! failure types ([`problem`]), the bounds table ([`bounds`]) and the wire types every endpoint
//! uses the same way ([`common`]).

pub mod bezier_motion;
pub mod bounds;
pub mod bus_fuel_economy;
pub mod cam_law;
pub mod cam_law_fit;
pub mod cognates;
pub mod common;
pub mod component_importance;
pub mod continuum_workspace;
pub mod irefc;
pub mod machining_size;
pub mod problem;
pub mod rules;
pub mod spatial_coupling;
pub mod vibration_absorber;

pub use bounds::Range;
pub use problem::{CalcFailure, FieldIssue, INVALID_INPUT, ProblemClass, Validator};
pub use rules::{CrossRule, Rules};

/// The per-field rules of every request type (`#[rule(...)]`, see [`rules`]), for the OpenAPI
/// document.
#[must_use]
pub fn document_rules() -> rules::DocRules {
    rules::DocRules::default()
        .of::<bezier_motion::BezierMotionRequest>()
        .of::<bus_fuel_economy::BusFuelEconomyRequest>()
        .of::<bus_fuel_economy::MotorMapRequest>()
        .of::<cam_law::EvaluateRequest>()
        .of::<cam_law_fit::FitCamLawRequest>()
        .of::<cognates::CognatesRequest>()
        .of::<component_importance::ComponentImportanceRequest>()
        .of::<continuum_workspace::ContinuumWorkspaceRequest>()
        .of::<irefc::IrefcStressRequest>()
        .of::<irefc::IrefcEfficiencyRequest>()
        .of::<machining_size::TrainRequest>()
        .of::<machining_size::PredictRequest>()
        .of::<machining_size::AnalyzeRequest>()
        .of::<machining_size::wire::GbdtModel>()
        .of::<spatial_coupling::SpatialCouplingRequest>()
        .of::<vibration_absorber::VibrationAbsorberRequest>()
}
