//! The error contract every POST endpoint shares (brief item 4), checked once for all of them:
//! each `api/` example is sent truncated (400 malformed-json), as text/plain and without a content
//! type (415), and with an unknown top-level member (422 with the member's pointer). A new
//! endpoint is covered as soon as its example is listed in `api/examples.json` (which
//! tests/api_examples.rs requires).

use crate::common;

use crate::contract::{api_dir, example_files};
use common::{post_json, send};
use serde_json::Value;

/// `(endpoint, example body)` for every example in `api/examples.json`.
fn examples() -> Vec<(String, String)> {
    example_files()
        .into_iter()
        .map(|(file, endpoint)| {
            let body = std::fs::read_to_string(api_dir().join(file)).expect("example file");
            (endpoint, body)
        })
        .collect()
}

#[tokio::test]
async fn truncated_json_is_400_malformed_json() {
    for (endpoint, body) in examples() {
        // Cut inside the document: still syntax, never a shape error.
        let cut = body.trim_end().len() / 2;
        let cut = (0..=cut)
            .rev()
            .find(|&i| body.is_char_boundary(i))
            .unwrap_or(0);
        let r = send(
            "POST",
            &endpoint,
            Some("application/json"),
            body.as_bytes()[..cut].to_vec(),
        )
        .await;
        let p = r.problem(400);
        assert_eq!(p["type"], "/problems/malformed-json", "{endpoint}: {p}");
        assert_eq!(p["code"], "MALFORMED_JSON", "{endpoint}: {p}");
    }
}

#[tokio::test]
async fn wrong_or_missing_content_type_is_415() {
    for (endpoint, body) in examples() {
        for ct in [
            Some("text/plain"),
            Some("application/x-www-form-urlencoded"),
            None,
        ] {
            let r = send("POST", &endpoint, ct, body.clone().into_bytes()).await;
            let p = r.problem(415);
            assert_eq!(
                p["type"], "/problems/unsupported-media-type",
                "{endpoint} with {ct:?}: {p}"
            );
        }
        // Parameters and a structured-syntax suffix are still JSON.
        let r = send(
            "POST",
            &endpoint,
            Some("application/json; charset=utf-8"),
            body.clone().into_bytes(),
        )
        .await;
        assert_ne!(
            r.status.as_u16(),
            415,
            "{endpoint}: charset parameter refused"
        );
    }
}

#[tokio::test]
async fn unknown_top_level_member_is_422_with_its_pointer() {
    for (endpoint, body) in examples() {
        let mut v: Value = serde_json::from_str(&body).expect("example is JSON");
        v.as_object_mut()
            .expect("example is an object")
            .insert("no_such_member".to_owned(), Value::Bool(true));
        let r = post_json(&endpoint, &v).await;
        let p = r.problem(422);
        assert_eq!(r.pointers(), vec!["/no_such_member"], "{endpoint}: {p}");
    }
}
