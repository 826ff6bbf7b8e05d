//! Every endpoint's picture (`Accept: image/svg+xml`) for every `api/` example: well-formed SVG
//! with a non-empty data series and axis labels that carry units; and the JSON path unchanged.

use crate::common;
use crate::contract::examples;

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use mechcalc::config::ServiceConfig;
use mechcalc::{AppState, app};
use tower::ServiceExt;

/// Endpoints whose picture is still being drawn (transitional: the list must end empty).
const PENDING_PICTURES: &[&str] = &[];

async fn svg_of(endpoint: &str, body: &serde_json::Value) -> (u16, String, String) {
    let req = Request::builder()
        .method("POST")
        .uri(endpoint)
        .header("content-type", "application/json")
        .header("accept", "image/svg+xml")
        .body(Body::from(serde_json::to_vec(body).expect("JSON")))
        .expect("request");
    let resp = app(AppState::new(common::config()))
        .oneshot(req)
        .await
        .expect("infallible");
    let status = resp.status().as_u16();
    let ct = resp
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_owned();
    let bytes = resp.into_body().collect().await.expect("body").to_bytes();
    (status, ct, String::from_utf8_lossy(&bytes).into_owned())
}

/// Problems of an SVG document: not XML, no data series, no axis label with a unit.
pub fn svg_problems(svg: &str) -> Vec<String> {
    let mut out = Vec::new();
    let doc = match roxmltree::Document::parse(svg) {
        Ok(d) => d,
        Err(e) => return vec![format!("not well-formed XML: {e}")],
    };
    if doc.root_element().tag_name().name() != "svg" {
        out.push("the root element is not <svg>".to_owned());
    }
    let series = doc.descendants().any(|n| match n.tag_name().name() {
        "polyline" | "polygon" => n
            .attribute("points")
            .is_some_and(|p| p.split_whitespace().count() >= 2),
        "path" => n.attribute("d").is_some_and(|d| d.len() > 10),
        _ => false,
    });
    let bars = doc
        .descendants()
        .filter(|n| n.tag_name().name() == "rect")
        .count()
        > 3;
    if !series && !bars {
        out.push("no data series (polyline, path or bars)".to_owned());
    }
    let unit_label = doc
        .descendants()
        .filter(|n| n.tag_name().name() == "text")
        .any(|n| {
            let t: String = n.descendants().filter_map(|c| c.text()).collect();
            t.contains('[') && t.contains(']')
        });
    if !unit_label {
        out.push("no axis label with a unit in brackets".to_owned());
    }
    out
}

#[tokio::test]
async fn every_example_has_a_well_formed_picture() {
    let mut failures = Vec::new();
    let mut drawn = 0;
    for (file, endpoint, body) in examples() {
        let (status, ct, svg) = svg_of(&endpoint, &body).await;
        if PENDING_PICTURES.contains(&endpoint.as_str()) {
            assert_eq!(
                status, 406,
                "api/{file}: a pending picture must say 406, got {status}"
            );
            continue;
        }
        if status != 200 || ct != "image/svg+xml" {
            failures.push(format!(
                "api/{file}: {status} {ct}: {}",
                &svg[..svg.len().min(300)]
            ));
            continue;
        }
        for p in svg_problems(&svg) {
            failures.push(format!("api/{file}: {p}"));
        }
        drawn += 1;
    }
    assert!(drawn > 0);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[tokio::test]
async fn a_refused_request_keeps_its_problem_details() {
    let (status, ct, body) = svg_of("/v1/cognates", &serde_json::json!({"crank": -1})).await;
    assert_eq!(status, 422);
    assert_eq!(ct, "application/problem+json");
    assert!(body.contains("/problems/"));
}

#[tokio::test]
async fn json_answers_do_not_change_with_pictures_available() {
    // The JSON path is the default: no Accept header, or JSON first.
    for accept in [None, Some("application/json, image/svg+xml")] {
        let mut req = Request::builder()
            .method("POST")
            .uri("/v1/cam-law/evaluate")
            .header("content-type", "application/json");
        if let Some(a) = accept {
            req = req.header("accept", a);
        }
        let body = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/api/cam_law/evaluate_table1.json"
        ))
        .expect("example");
        let resp = app(AppState::new(ServiceConfig::default()))
            .oneshot(req.body(Body::from(body)).expect("request"))
            .await
            .expect("infallible");
        assert_eq!(resp.headers()["content-type"], "application/json");
    }
}

/// A valid answer with nothing to draw (here an empty shard of a single-wave sweep, and the
/// first shard that does hold the wave) is a 406 that says so, never a 500.
#[tokio::test]
async fn an_answer_with_nothing_to_draw_is_a_406_not_a_500() {
    let body = |index: u32| {
        serde_json::json!({"mode": "workspace", "design": {"preset": "keops_d1"},
            "workspace": {"grid": [3, 3], "stability_check": "none"},
            "shard": {"index": index, "count": 2}})
    };
    let (status, ct, problem) = svg_of("/v1/continuum-workspace", &body(1)).await;
    assert_eq!(status, 406, "{problem}");
    assert_eq!(ct, "application/problem+json");
    let p: serde_json::Value = serde_json::from_str(&problem).expect("problem+json");
    assert_eq!(p["type"], "/problems/not-acceptable");
    assert_eq!(p["code"], "NOTHING_TO_DRAW");
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("application/json"))
    );
    let (status, ct, svg) = svg_of("/v1/continuum-workspace", &body(0)).await;
    assert_eq!((status, ct.as_str()), (200, "image/svg+xml"), "{svg}");
    assert_eq!(svg_problems(&svg), Vec::<String>::new());
}
