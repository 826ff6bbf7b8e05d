//! Property (`props_<module>`, proptest; `PROPTEST_CASES` scales them) and numerical-stress
//! (`stress_<module>`) runs of every module, in one test crate.

#[path = "../support/mod.rs"]
mod support;

mod props_bezier_motion;
mod props_bus_fuel_economy;
mod props_cam_law;
mod props_cam_law_fit;
mod props_cognates;
mod props_component_importance;
mod props_continuum_workspace;
mod props_irefc;
mod props_machining_size;
mod props_spatial_coupling;
mod props_vibration_absorber;
mod stress_bezier_motion;
mod stress_bus_fuel_economy;
mod stress_cam_law;
mod stress_cam_law_fit;
mod stress_cognates;
mod stress_component_importance;
mod stress_continuum_workspace;
mod stress_irefc;
mod stress_machining_size;
mod stress_spatial_coupling;
mod stress_vibration_absorber;
