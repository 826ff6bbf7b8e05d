//! Pictures of answers: every endpoint's natural plot as SVG, drawn with `plotters` (SVG backend:
//! text stays text, no fonts or native libraries at run time).
//!
//! A picture is drawn from the request and the JSON answer the endpoint gives (never from the
//! module's internals), so the JSON path pays nothing for it. [`prepare`] first turns on the
//! outputs a picture needs (curves, a dense sample grid) in the request; [`render`] then draws.
//! Axes carry quantity and unit; colours come from the Okabe–Ito palette, which stays
//! distinguishable for colour-blind readers, and series also differ by marker or dash.

mod bezier_motion;
mod bus_fuel_economy;
mod cam_law;
mod cam_law_fit;
mod cognates;
mod component_importance;
mod continuum_workspace;
mod irefc;
mod machining_size;
mod spatial_coupling;
pub mod style;
mod vibration_absorber;

use serde_json::Value;

/// A picture could not be drawn (the answer lacks what the picture needs).
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A field the picture needs is missing from the answer.
    #[error("the answer has no `{0}` to draw")]
    Missing(&'static str),
    /// The drawing backend failed.
    #[error("drawing failed: {0}")]
    Draw(String),
}

impl<E: std::error::Error + Send + Sync> From<plotters::drawing::DrawingAreaErrorKind<E>>
    for PlotError
{
    fn from(e: plotters::drawing::DrawingAreaErrorKind<E>) -> Self {
        Self::Draw(e.to_string())
    }
}

/// One endpoint's picture: how to prepare its request and how to draw its answer.
struct Picture {
    route: &'static str,
    prepare: fn(&mut Value),
    render: fn(&Value, &Value) -> Result<String, PlotError>,
}

const PICTURES: &[Picture] = &[
    Picture {
        route: "/v1/bezier-motion-law",
        prepare: bezier_motion::prepare,
        render: bezier_motion::render,
    },
    Picture {
        route: "/v1/cam-law/evaluate",
        prepare: cam_law::prepare,
        render: cam_law::render,
    },
    Picture {
        route: "/v1/fit-cam-law",
        prepare: cam_law_fit::prepare,
        render: cam_law_fit::render,
    },
    Picture {
        route: "/v1/cognates",
        prepare: cognates::prepare,
        render: cognates::render,
    },
    Picture {
        route: "/v1/component-importance",
        prepare: component_importance::prepare,
        render: component_importance::render,
    },
    Picture {
        route: "/v1/bus-fuel-economy",
        prepare: bus_fuel_economy::prepare,
        render: bus_fuel_economy::render,
    },
    Picture {
        route: "/v1/bus-fuel-economy/motor-map",
        prepare: bus_fuel_economy::prepare_map,
        render: bus_fuel_economy::render_map,
    },
    Picture {
        route: "/v1/irefc-stress",
        prepare: irefc::prepare_stress,
        render: irefc::render_stress,
    },
    Picture {
        route: "/v1/irefc-efficiency",
        prepare: irefc::prepare_efficiency,
        render: irefc::render_efficiency,
    },
    Picture {
        route: "/v1/continuum-workspace",
        prepare: continuum_workspace::prepare,
        render: continuum_workspace::render,
    },
    Picture {
        route: "/v1/machining-size/train",
        prepare: machining_size::prepare_train,
        render: machining_size::render_train,
    },
    Picture {
        route: "/v1/machining-size/predict",
        prepare: machining_size::prepare_predict,
        render: machining_size::render_predict,
    },
    Picture {
        route: "/v1/machining-size/analyze",
        prepare: machining_size::prepare_analyze,
        render: machining_size::render_analyze,
    },
    Picture {
        route: "/v1/spatial-coupling",
        prepare: spatial_coupling::prepare,
        render: spatial_coupling::render,
    },
    Picture {
        route: "/v1/vibration-absorber",
        prepare: vibration_absorber::prepare,
        render: vibration_absorber::render,
    },
];

fn find(route: &str) -> Option<&'static Picture> {
    PICTURES.iter().find(|p| p.route == route)
}

/// Whether the endpoint at `route` has a picture.
#[must_use]
pub fn has_picture(route: &str) -> bool {
    find(route).is_some()
}

/// Turn on in `request` what the picture of `route` needs.
pub fn prepare(route: &str, request: &mut Value) {
    if let Some(p) = find(route) {
        (p.prepare)(request);
    }
}

/// The picture of `answer` (to `request`) at `route`, if the endpoint has one.
#[must_use]
pub fn render(route: &str, request: &Value, answer: &Value) -> Option<Result<String, PlotError>> {
    find(route).map(|p| (p.render)(request, answer))
}

/// Numbers of a JSON array (non-numbers are skipped).
pub(crate) fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

/// `[x, y]` pairs of a JSON array of 2-arrays.
pub(crate) fn points(v: &Value) -> Vec<(f64, f64)> {
    v.as_array()
        .map(|a| {
            a.iter()
                .filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?)))
                .collect()
        })
        .unwrap_or_default()
}
