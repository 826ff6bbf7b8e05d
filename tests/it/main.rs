//! The fast integration tests in one crate (one link instead of one per file): the spec's
//! validation cases per module (`paper_<module>`), the HTTP contract per module (`http_<module>`),
//! the service-wide HTTP checks, the `api/` examples and the OpenAPI document.
//! Property and stress runs live in `tests/slow`.

#[path = "../support/mod.rs"]
mod support;
use support::http as common;

mod api_examples;
mod cli;
mod contract;
mod formats;
mod http_auth;
mod http_bezier_motion;
mod http_bus_fuel_economy;
mod http_cam_law;
mod http_cam_law_fit;
mod http_cognates;
mod http_component_importance;
mod http_continuum_workspace;
mod http_error_contract;
mod http_irefc;
mod http_machining_size;
mod http_mutated_examples;
mod http_service;
mod http_spatial_coupling;
mod http_vibration_absorber;
mod openapi;
mod paper_bezier_motion;
mod paper_bus_fuel_economy;
mod paper_cam_law;
mod paper_cam_law_fit;
mod paper_cognates;
mod paper_component_importance;
mod paper_continuum_workspace;
mod paper_irefc;
mod paper_machining_size;
mod paper_spatial_coupling;
mod paper_vibration_absorber;
mod pictures;
mod progress_stream;
mod response_size;
mod sharding;
mod sweep_cli;
