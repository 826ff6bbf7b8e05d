//! The files engineers exchange, made from an answer: a calculation report (HTML), tables (CSV)
//! and geometry (DXF). Each is pure: the request and the JSON answer go in, bytes come out
//! ([`crate::http::formats`] negotiates them on the calculation endpoints; `mechcalc run --report`
//! writes a report).
//!
//! * [`report`]: `text/html`, every endpoint.
//! * [`table`]: `text/csv`, the endpoints with tables ([`table::TABLES`]; `?table=NAME`).
//! * [`dxf`]: `image/vnd.dxf`, the endpoints with geometry ([`dxf::ROUTES`]).

pub mod dxf;
pub mod report;
pub mod schema;
pub mod table;

use serde_json::{Value, json};

include!(concat!(env!("OUT_DIR"), "/module_docs.rs"));

/// Media type of the report.
pub const HTML: &str = "text/html";
/// Media type of a table.
pub const CSV: &str = "text/csv";
/// Media type of a drawing.
pub const DXF: &str = "image/vnd.dxf";

/// The calculation module (folder under `src/calc/`) behind each endpoint.
const MODULES: &[(&str, &str)] = &[
    ("/v1/cam-law/evaluate", "cam_law"),
    ("/v1/fit-cam-law", "cam_law_fit"),
    ("/v1/cognates", "cognates"),
    ("/v1/component-importance", "component_importance"),
    ("/v1/bus-fuel-economy", "bus_fuel_economy"),
    ("/v1/bus-fuel-economy/motor-map", "bus_fuel_economy"),
    ("/v1/irefc-stress", "irefc"),
    ("/v1/irefc-efficiency", "irefc"),
    ("/v1/continuum-workspace", "continuum_workspace"),
    ("/v1/machining-size/train", "machining_size"),
    ("/v1/machining-size/predict", "machining_size"),
    ("/v1/machining-size/analyze", "machining_size"),
    ("/v1/spatial-coupling", "spatial_coupling"),
    ("/v1/vibration-absorber", "vibration_absorber"),
    ("/v1/bezier-motion-law", "bezier_motion"),
];

/// The calculation module of `route`, if it is a calculation endpoint.
#[must_use]
pub fn module_of(route: &str) -> Option<&'static str> {
    MODULES.iter().find(|(r, _)| *r == route).map(|(_, m)| *m)
}

/// Every media type `POST route` can answer in, JSON first (for a 406's list).
#[must_use]
pub fn media_types(route: &str) -> Vec<&'static str> {
    let mut v = vec!["application/json", "text/event-stream"];
    if crate::plot::has_picture(route) {
        v.push("image/svg+xml");
    }
    if module_of(route).is_some() {
        v.push(HTML);
    }
    if !table::tables(route).is_empty() {
        v.push(CSV);
    }
    if dxf::has_drawing(route) {
        v.push(DXF);
    }
    v
}

/// Why a table cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// `?table=` names no table of the endpoint.
    #[error("{route} has no table `{name}`; its tables: {known}")]
    Unknown {
        /// The endpoint.
        route: String,
        /// The name asked for.
        name: String,
        /// The names it has.
        known: String,
    },
    /// The answer does not carry the table (or any table).
    #[error("{0}")]
    Absent(String),
    /// Writing failed (a bug).
    #[error("CSV writing failed: {0}")]
    Write(String),
}

/// The CSV of table `name` (default: the first table the answer carries) of `answer` at `route`.
///
/// # Errors
/// [`TableError::Unknown`] for a name the endpoint does not have, [`TableError::Absent`] when the
/// answer does not carry the table.
pub fn csv(
    route: &str,
    request: &Value,
    answer: &Value,
    doc: &Value,
    name: Option<&str>,
) -> Result<Vec<u8>, TableError> {
    let defs = table::tables(route);
    let schemas = schema::Schemas::of(doc, route);
    let ctx = table::Ctx {
        request,
        answer,
        schemas: &schemas,
    };
    let known = || defs.iter().map(|d| d.name).collect::<Vec<_>>().join(", ");
    let grid = match name {
        Some(n) => {
            let def = defs
                .iter()
                .find(|d| d.name == n)
                .ok_or_else(|| TableError::Unknown {
                    route: route.to_owned(),
                    name: n.to_owned(),
                    known: known(),
                })?;
            (def.build)(&ctx).ok_or_else(|| {
                TableError::Absent(format!(
                    "the answer does not carry the table `{n}` ({}); the request option in \
                     brackets turns it on",
                    def.doc
                ))
            })?
        }
        None => defs.iter().find_map(|d| (d.build)(&ctx)).ok_or_else(|| {
            TableError::Absent(format!(
                "the answer carries none of the tables of {route} ({}); the request \
                     options named in the OpenAPI document turn them on",
                known()
            ))
        })?,
    };
    table::to_csv(&grid).map_err(|e| TableError::Write(e.to_string()))
}

/// Document the report, tables and drawing of every POST operation in the 200 response's content
/// (called from the OpenAPI completion).
pub fn document_formats(doc: &mut Value) {
    let Some(paths) = doc.get_mut("paths").and_then(Value::as_object_mut) else {
        return;
    };
    for (route, item) in paths.iter_mut() {
        let Some(content) = item
            .pointer_mut("/post/responses/200/content")
            .and_then(Value::as_object_mut)
        else {
            continue;
        };
        if module_of(route).is_none() {
            continue;
        }
        content.insert(
            HTML.to_owned(),
            json!({"schema": {"type": "string", "description":
                "With `Accept: text/html`: the calculation report, one self-contained HTML file \
                 (prints on A4): inputs with units and meanings, method and references, results \
                 with units, the checks the answer carries, warnings, the solver report, the \
                 picture as inline SVG, and provenance (service, version, source commit, SHA-256 \
                 of the exact request bytes, time). The exact request and answer are embedded as \
                 `<script type=\"application/json\" id=\"request\">` and `id=\"answer\"` \
                 (`<` written `\\u003c`). CLI: `mechcalc run ENDPOINT FILE --report OUT.html`."}}),
        );
        let tables = table::tables(route);
        if !tables.is_empty() {
            let list: Vec<String> = tables
                .iter()
                .map(|t| format!("`{}`: {}", t.name, t.doc))
                .collect();
            content.insert(
                CSV.to_owned(),
                json!({"schema": {"type": "string", "description": format!(
                    "With `Accept: text/csv`: a table of the answer (RFC 4180, header `name [unit]`, \
                     numbers exactly as in the JSON answer). `?table=NAME` selects the table; \
                     without it, the first of these the answer carries: {}. A table the answer \
                     does not carry is a 406 (`NOTHING_TO_TABULATE`), an unknown name a 406 \
                     (`UNKNOWN_TABLE`).", list.join("; "))}}),
            );
        }
        if dxf::has_drawing(route) {
            content.insert(
                DXF.to_owned(),
                json!({"schema": {"type": "string", "description":
                    "With `Accept: image/vnd.dxf`: the geometry as a DXF drawing (AutoCAD 2000), \
                     one layer per part, `$INSUNITS` set from the request's length unit, curves as \
                     polylines. The request is first completed with the outputs the drawing needs \
                     (as for the picture); an answer with no geometry is a 406 \
                     (`NOTHING_TO_DRAW`)."}}),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_has_its_docs_embedded() {
        for (_, m) in MODULES {
            let doc = MODULE_DOCS.iter().find(|(n, _)| n == m).map(|(_, d)| *d);
            assert!(doc.is_some_and(|d| d.len() > 100), "{m}: no module docs");
        }
    }

    #[test]
    fn every_table_route_is_a_calculation() {
        for (r, _) in table::TABLES {
            assert!(module_of(r).is_some(), "{r}");
        }
        for r in dxf::ROUTES {
            assert!(module_of(r).is_some(), "{r}");
        }
    }
}
