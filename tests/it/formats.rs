//! Reports, tables and drawings (`Accept: text/html`, `text/csv`, `image/vnd.dxf`) for every
//! `api/` example: the CSV's numbers are the JSON answer's numbers (same text), the report embeds
//! the exact request and the answer and loads nothing from elsewhere, every drawing reads back
//! with its units, layers and a geometry checked against the answer; 406 lists what an endpoint
//! offers; the OpenAPI document names each format per operation; `mechcalc run --report` writes
//! the report.

use crate::common;
use crate::contract::examples;

use std::collections::HashSet;

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use mechcalc::{AppState, app};
use serde_json::Value;
use sha2::{Digest, Sha256};
use tower::ServiceExt;

struct Got {
    status: u16,
    content_type: String,
    bytes: Vec<u8>,
}

async fn post(path: &str, accept: &str, body: &[u8]) -> Got {
    let req = Request::builder()
        .method("POST")
        .uri(path)
        .header("content-type", "application/json")
        .header("accept", accept)
        .body(Body::from(body.to_vec()))
        .expect("request");
    let resp = app(AppState::new(common::config()))
        .oneshot(req)
        .await
        .expect("infallible");
    let status = resp.status().as_u16();
    let content_type = resp
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_owned();
    let bytes = resp
        .into_body()
        .collect()
        .await
        .expect("body")
        .to_bytes()
        .to_vec();
    Got {
        status,
        content_type,
        bytes,
    }
}

/// Wall-clock fields differ between two runs of one request.
fn is_timing(name: &str) -> bool {
    [
        "elapsed_ms",
        "compute_ms",
        "compute_us",
        "timing_ms",
        "cpu_ms",
        "wall_ms",
        "threads",
    ]
    .iter()
    .any(|t| name.contains(t))
}

/// Every number token of a JSON text, as written.
fn number_tokens(v: &Value, out: &mut HashSet<String>) {
    match v {
        Value::Number(n) => {
            out.insert(n.to_string());
        }
        Value::Array(a) => a.iter().for_each(|x| number_tokens(x, out)),
        Value::Object(m) => m.values().for_each(|x| number_tokens(x, out)),
        _ => {}
    }
}

fn looks_numeric(s: &str) -> bool {
    s.parse::<f64>().is_ok() && !s.eq_ignore_ascii_case("nan") && !s.contains("inf")
}

/// (header, rows) of a CSV body.
fn read_csv(bytes: &[u8]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_reader(bytes);
    let header: Vec<String> = r
        .headers()
        .expect("header")
        .iter()
        .map(str::to_owned)
        .collect();
    let rows = r
        .records()
        .map(|rec| rec.expect("record").iter().map(str::to_owned).collect())
        .collect();
    (header, rows)
}

#[tokio::test]
async fn csv_numbers_are_the_json_answers_numbers() {
    let mut tables = 0;
    for (file, endpoint, body) in examples() {
        let bytes = serde_json::to_vec(&body).expect("JSON");
        let json = post(&endpoint, "application/json", &bytes).await;
        assert_eq!(json.status, 200, "{file}");
        let answer: Value = serde_json::from_slice(&json.bytes).expect("answer");
        let mut tokens = HashSet::new();
        number_tokens(&answer, &mut tokens);
        let got = post(&endpoint, "text/csv", &bytes).await;
        if got.status == 406 {
            // The answer carries none of the endpoint's tables: a problem saying so.
            let p: Value = serde_json::from_slice(&got.bytes).expect("problem");
            assert_eq!(p["code"], "NOTHING_TO_TABULATE", "{file}: {p}");
            continue;
        }
        assert_eq!(
            got.status,
            200,
            "{file}: {}",
            String::from_utf8_lossy(&got.bytes)
        );
        assert!(got.content_type.starts_with("text/csv"), "{file}");
        let (header, rows) = read_csv(&got.bytes);
        assert!(!rows.is_empty(), "{file}: no rows");
        tables += 1;
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), header.len(), "{file} row {i}");
            for (h, cell) in header.iter().zip(row) {
                if looks_numeric(cell) && !is_timing(h) {
                    // Index columns count rows; every other number is one of the answer's.
                    let index =
                        ["segment", "component", "row", "wave", "i", "j"].contains(&h.as_str());
                    assert!(
                        index || tokens.contains(cell),
                        "{file}: {h} = {cell} (row {i}) is not a number of the JSON answer"
                    );
                }
            }
        }
    }
    assert!(tables >= 20, "only {tables} examples gave a table");
}

#[tokio::test]
async fn csv_columns_follow_the_json_arrays_in_order() {
    // (example, JSON pointer of an array, CSV column header) pairs read both ways.
    let cases = [
        ("cam_law/evaluate_table1.json", "/curves/a", "a"),
        (
            "bezier_motion/optimize_paper.json",
            "/time_history/joint_torque_Nm",
            "joint_torque_Nm",
        ),
        (
            "vibration_absorber/frequency_sweep.json",
            "/frequency_response/frequencies_hz",
            "frequencies_hz",
        ),
        (
            "continuum_workspace/sweep_design1.json",
            "/nodes/px_m",
            "px_m",
        ),
    ];
    let all = examples();
    for (file, pointer, column) in cases {
        let (_, endpoint, body) = all.iter().find(|(f, _, _)| f == file).expect("example");
        let bytes = serde_json::to_vec(body).expect("JSON");
        let answer: Value =
            serde_json::from_slice(&post(endpoint, "application/json", &bytes).await.bytes)
                .expect("answer");
        let want: Vec<String> = answer
            .pointer(pointer)
            .and_then(Value::as_array)
            .expect("array")
            .iter()
            .map(|v| {
                if v.is_null() {
                    String::new()
                } else {
                    v.to_string()
                }
            })
            .collect();
        let (header, rows) = read_csv(&post(endpoint, "text/csv", &bytes).await.bytes);
        let c = header
            .iter()
            .position(|h| h == column || h.starts_with(&format!("{column} [")))
            .unwrap_or_else(|| panic!("{file}: no column {column} in {header:?}"));
        let got: Vec<String> = rows.iter().map(|r| r[c].clone()).collect();
        assert_eq!(got, want, "{file}: {column}");
        // The header names the unit from the field's doc.
        if pointer != "/nodes/px_m" || header[c].contains('[') {
            assert!(header[c].contains('['), "{file}: {} has no unit", header[c]);
        }
    }
}

#[tokio::test]
async fn table_parameter_selects_and_unknown_names_are_406() {
    let all = examples();
    let (_, endpoint, body) = all
        .iter()
        .find(|(f, _, _)| f == "irefc/stress_single.json")
        .expect("example");
    let mut body = body.clone();
    body["include"]["curves"] = Value::Bool(true);
    let bytes = serde_json::to_vec(&body).expect("JSON");
    let default = post(endpoint, "text/csv", &bytes).await;
    let (h, _) = read_csv(&default.bytes);
    assert_eq!(
        h.first().map(String::as_str),
        Some("k"),
        "main table: elements"
    );
    let curves = post(&format!("{endpoint}?table=curves"), "text/csv", &bytes).await;
    assert_eq!(curves.status, 200);
    let (h, rows) = read_csv(&curves.bytes);
    assert!(
        h.iter().any(|c| c.starts_with("sigma_cam_MPa [MPa]")),
        "{h:?}"
    );
    assert!(rows.len() > 100);
    let unknown = post(&format!("{endpoint}?table=nope"), "text/csv", &bytes).await;
    assert_eq!(unknown.status, 406);
    let p: Value = serde_json::from_slice(&unknown.bytes).expect("problem");
    assert_eq!(p["code"], "UNKNOWN_TABLE");
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("elements, curves")),
        "{p}"
    );
    assert!(unknown.content_type.starts_with("application/problem+json"));
}

#[tokio::test]
async fn a_format_an_endpoint_lacks_is_406_listing_what_it_offers() {
    let body = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cam_law/evaluate_table1.json"),
    )
    .expect("example");
    let got = post("/v1/cam-law/evaluate", "image/vnd.dxf", &body).await;
    assert_eq!(got.status, 406);
    let p: Value = serde_json::from_slice(&got.bytes).expect("problem");
    let detail = p["detail"].as_str().unwrap_or("");
    for t in [
        "application/json",
        "text/event-stream",
        "image/svg+xml",
        "text/html",
        "text/csv",
    ] {
        assert!(detail.contains(t), "{detail}");
    }
    assert!(!detail.contains("available: image/vnd.dxf"), "{detail}");
}

#[tokio::test]
async fn a_refused_request_answers_with_its_problem_in_every_format() {
    for accept in ["text/html", "text/csv", "image/vnd.dxf"] {
        let got = post("/v1/cognates", accept, br#"{"crank": -1}"#).await;
        assert_eq!(got.status, 422, "{accept}");
        assert!(
            got.content_type.starts_with("application/problem+json"),
            "{accept}"
        );
        let bad = post("/v1/cognates", accept, b"{not json").await;
        assert_eq!(bad.status, 400, "{accept}");
    }
}

/// The text of `<script type="application/json" id="ID">`.
fn script<'a>(html: &'a str, id: &str) -> &'a str {
    let open = format!("<script type=\"application/json\" id=\"{id}\">");
    let start = html
        .find(&open)
        .map(|i| i + open.len())
        .expect("script present");
    let len = html[start..].find("</script>").expect("closed");
    &html[start..start + len]
}

#[tokio::test]
async fn every_report_is_self_contained_and_embeds_the_exact_request_and_answer() {
    for (file, endpoint, body) in examples() {
        // The exact bytes as a client would send them (pretty-printed, as in the file).
        let bytes = serde_json::to_vec_pretty(&body).expect("JSON");
        let got = post(&endpoint, "text/html", &bytes).await;
        assert_eq!(
            got.status,
            200,
            "{file}: {}",
            String::from_utf8_lossy(&got.bytes)
        );
        assert!(got.content_type.starts_with("text/html"), "{file}");
        let html = String::from_utf8(got.bytes).expect("UTF-8");
        // Self-contained: nothing fetched from anywhere.
        for bad in [
            "<link", " src=", "@import", "url(", "<iframe", "<img", "<object",
        ] {
            assert!(!html.contains(bad), "{file}: {bad}");
        }
        assert_eq!(
            html.matches("<script").count(),
            2,
            "{file}: only the two JSON scripts"
        );
        // The exact request bytes, and their SHA-256 in the provenance.
        let req = script(&html, "request").replace("\\u003c", "<");
        assert_eq!(
            req.as_bytes(),
            bytes.as_slice(),
            "{file}: request not verbatim"
        );
        let sha: String = Sha256::digest(&bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert!(html.contains(&sha), "{file}: request SHA-256 missing");
        // The answer: the JSON answer to the same request (timings aside).
        let answer: Value = serde_json::from_str(script(&html, "answer")).expect("answer JSON");
        let json: Value =
            serde_json::from_slice(&post(&endpoint, "application/json", &bytes).await.bytes)
                .expect("JSON answer");
        let mut diffs = Vec::new();
        common::leaves_match(&json, &answer, "", 0.0, 0.0, &mut diffs);
        diffs.retain(|d| !is_timing(d));
        assert!(diffs.is_empty(), "{file}: {diffs:?}");
        for section in [
            "Provenance",
            "Inputs",
            "Results",
            "Method and references",
            "Warnings",
            "Solver report",
        ] {
            assert!(html.contains(section), "{file}: no {section}");
        }
        assert!(
            html.contains(mechcalc::export::report::SOURCE_COMMIT),
            "{file}"
        );
    }
}

#[tokio::test]
async fn report_shows_units_meanings_and_the_picture() {
    let body = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cognates/table1.json"),
    )
    .expect("example");
    let html =
        String::from_utf8(post("/v1/cognates", "text/html", &body).await.bytes).expect("UTF-8");
    // Input row: pointer, value, unit, meaning from the field doc.
    assert!(
        html.contains("<code>/input_angle_deg</code></td><td class=\"v\">30.0</td><td>deg</td>"),
        "input row"
    );
    assert!(html.contains("Roberts"), "module references");
    assert!(html.contains("<svg"), "inline picture");
    assert!(html.contains("/verification/sync/passed"), "checks");
}

fn dxf_of(bytes: &[u8]) -> dxf::Drawing {
    dxf::Drawing::load(&mut std::io::Cursor::new(bytes)).expect("DXF reads back")
}

fn layers(d: &dxf::Drawing) -> HashSet<String> {
    d.entities().map(|e| e.common.layer.clone()).collect()
}

#[tokio::test]
async fn every_drawing_reads_back_with_units_and_layers() {
    let mut drawn = 0;
    for (file, endpoint, body) in examples() {
        if !mechcalc::export::dxf::has_drawing(&endpoint) {
            continue;
        }
        let bytes = serde_json::to_vec(&body).expect("JSON");
        let got = post(&endpoint, "image/vnd.dxf", &bytes).await;
        if body["mode"] == "sweep" && endpoint == "/v1/irefc-stress" {
            assert_eq!(got.status, 406, "{file}: a sweep has no single geometry");
            continue;
        }
        if got.status == 406 {
            // Continuum modes without workspace nodes (fk, assembly modes) have nothing to draw.
            assert!(endpoint == "/v1/continuum-workspace", "{file}");
            continue;
        }
        assert_eq!(
            got.status,
            200,
            "{file}: {}",
            String::from_utf8_lossy(&got.bytes)
        );
        assert_eq!(got.content_type, "image/vnd.dxf");
        let d = dxf_of(&got.bytes);
        let units = d.header.default_drawing_units;
        let l = layers(&d);
        match endpoint.as_str() {
            "/v1/irefc-stress" | "/v1/irefc-efficiency" => {
                assert_eq!(units, dxf::enums::Units::Millimeters, "{file}");
                for want in [
                    "CAM_PROFILE",
                    "CROWN_PROFILE",
                    "ROLLING_ELEMENTS",
                    "PITCH_CIRCLES",
                ] {
                    assert!(l.contains(want), "{file}: {want}");
                }
            }
            "/v1/cognates" => {
                assert_eq!(units, dxf::enums::Units::Unitless, "{file}");
                for want in ["ORIGINAL_LINKS", "COGNATE1_COUPLER_CURVE", "COGNATE2_LINKS"] {
                    assert!(l.contains(want), "{file}: {want}");
                }
            }
            "/v1/continuum-workspace" => {
                assert_eq!(units, dxf::enums::Units::Meters, "{file}");
                assert!(
                    l.contains("WAVE_0_OUTLINE") && l.contains("WAVE_0_NODES"),
                    "{file}"
                );
            }
            "/v1/spatial-coupling" => {
                assert_eq!(units, dxf::enums::Units::Meters, "{file}");
                assert!(
                    l.contains("PATH_B_FRAME_1") && l.contains("PATH_B_FRAME_2"),
                    "{file}"
                );
            }
            other => panic!("{other} draws but is not checked"),
        }
        drawn += 1;
    }
    assert!(drawn >= 6, "{drawn}");
}

/// Distance from `p` to the closed polyline `poly` (segments, not only vertices).
fn distance_to(poly: &[(f64, f64)], p: (f64, f64)) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            (a.0 + t * dx - p.0).hypot(a.1 + t * dy - p.1)
        })
        .fold(f64::INFINITY, f64::min)
}

#[tokio::test]
async fn irefc_drawing_every_element_touches_both_profiles_and_the_radii_are_the_answers() {
    let body = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/irefc/stress_single.json"),
    )
    .expect("example");
    let answer: Value = serde_json::from_slice(
        &post("/v1/irefc-stress", "application/json", &body)
            .await
            .bytes,
    )
    .expect("answer");
    let d = dxf_of(&post("/v1/irefc-stress", "image/vnd.dxf", &body).await.bytes);
    let mut cam = Vec::new();
    let mut crown = Vec::new();
    let mut elements = Vec::new();
    let mut circles = Vec::new();
    for e in d.entities() {
        match &e.specific {
            dxf::entities::EntityType::LwPolyline(p) => {
                let pts: Vec<(f64, f64)> = p.vertices.iter().map(|v| (v.x, v.y)).collect();
                assert!(p.is_closed(), "profiles are closed");
                if e.common.layer == "CAM_PROFILE" {
                    cam = pts;
                } else {
                    crown = pts;
                }
            }
            dxf::entities::EntityType::Circle(c) if e.common.layer == "ROLLING_ELEMENTS" => {
                elements.push(((c.center.x, c.center.y), c.radius));
            }
            dxf::entities::EntityType::Circle(c) => circles.push(c.radius),
            _ => {}
        }
    }
    let g = &answer["geometry"];
    let z2 = usize::try_from(answer["geometry"]["Z1"].as_u64().expect("Z1") + 1).expect("small");
    assert_eq!(elements.len(), z2);
    // Pitch circles and the element-centre circle are the answer's radii.
    for key in ["r1_mm", "r3_mm", "rc_mm"] {
        let r = g[key].as_f64().expect("radius");
        assert!(circles.iter().any(|c| (c - r).abs() <= 1e-12 * r), "{key}");
    }
    // Tip and root radii of the cam are the extreme distances of its profile from its centre.
    let radii: Vec<f64> = cam.iter().map(|p| p.0.hypot(p.1)).collect();
    let (lo, hi) = radii
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(*r), b.max(*r)));
    assert!(
        (hi - g["cam_tip_mm"].as_f64().expect("tip")).abs() < 1e-6,
        "cam tip {hi}"
    );
    assert!(
        (lo - g["cam_root_mm"].as_f64().expect("root")).abs() < 1e-6,
        "cam root {lo}"
    );
    // Every element touches both profiles at the pose (distance to the polyline = rb, within the
    // chord tolerance), and none cuts into either.
    let tol = mechcalc::export::dxf::CHORD_TOLERANCE_MM;
    for (c, rb) in elements {
        let dc = distance_to(&cam, c) - rb;
        let dr = distance_to(&crown, c) - rb;
        assert!(dc.abs() <= tol, "cam gap {dc}");
        assert!(dr.abs() <= tol, "crown gap {dr}");
    }
}

#[test]
fn the_document_names_every_format_per_operation() {
    let doc = mechcalc::http::openapi::document();
    let content = |route: &str| {
        doc.pointer(&format!(
            "/paths/{}/post/responses/200/content",
            route.replace('/', "~1")
        ))
        .and_then(Value::as_object)
        .map(|m| m.keys().cloned().collect::<Vec<_>>())
        .unwrap_or_default()
    };
    let cognates = content("/v1/cognates");
    for t in ["application/json", "text/html", "text/csv", "image/vnd.dxf"] {
        assert!(cognates.iter().any(|k| k == t), "{t}: {cognates:?}");
    }
    let cam = content("/v1/cam-law/evaluate");
    assert!(cam.iter().any(|k| k == "text/csv") && !cam.iter().any(|k| k == "image/vnd.dxf"));
    let csv_doc = doc
        .pointer(
            "/paths/~1v1~1irefc-stress/post/responses/200/content/text~1csv/schema/description",
        )
        .and_then(Value::as_str)
        .unwrap_or("");
    for name in ["`records`", "`elements`", "`curves`"] {
        assert!(csv_doc.contains(name), "{csv_doc}");
    }
}

#[test]
fn cli_report_writes_the_report() {
    let out = std::env::temp_dir().join(format!("mechcalc-report-{}.html", std::process::id()));
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cognates/table1.json");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_mechcalc"))
        .args(["run", "cognates"])
        .arg(&file)
        .arg("--report")
        .arg(&out)
        .status()
        .expect("runs");
    assert!(status.success());
    let html = std::fs::read_to_string(&out).expect("report written");
    let _ = std::fs::remove_file(&out);
    let bytes = std::fs::read(&file).expect("example");
    assert_eq!(
        script(&html, "request").replace("\\u003c", "<").as_bytes(),
        bytes.as_slice()
    );
}
