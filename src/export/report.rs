//! The calculation report (`Accept: text/html`, `mechcalc run … --report OUT.html`): one
//! self-contained HTML file (no scripts, styles, fonts or images from anywhere else; prints on A4)
//! that can be filed with a part revision and re-run later.
//!
//! It holds the inputs with units and meanings (from the field docs of the OpenAPI document), the
//! method and its references (the module's documentation), the results with units, the checks the
//! answer carries (residuals, certificates, verification), the warnings, the solver report, the
//! picture inline as SVG, and provenance: service, version, source commit, the SHA-256 of the exact
//! request bytes and the time. The exact request and answer are embedded as
//! `<script type="application/json" id="request">` and `id="answer"`; the only change to their
//! bytes is that `<` (which JSON allows only inside strings) is written `\u003c`, the same JSON
//! value, so that no string can close the script element.

use std::fmt::Write as _;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::schema::{Schemas, unit_of};

/// Arrays up to this length are shown whole in the tables; longer ones are summarised (they are in
/// the embedded answer and the CSV tables).
const SHOWN_ARRAY: usize = 12;
/// Arrays of records up to this length are listed record by record.
const SHOWN_RECORDS: usize = 24;
/// Most rows of the inputs or results table (the embedded JSON holds everything).
const MAX_ROWS: usize = 1500;
/// Longest meaning shown in a table cell \[characters\].
const MEANING_CHARS: usize = 240;

/// Everything a report is made of.
pub struct ReportInput<'a> {
    /// The endpoint path (`/v1/cognates`).
    pub route: &'a str,
    /// The request body exactly as received.
    pub request_bytes: &'a [u8],
    /// The request, parsed.
    pub request: &'a Value,
    /// The JSON answer exactly as the service sent it.
    pub answer_bytes: &'a [u8],
    /// The answer, parsed.
    pub answer: &'a Value,
    /// The service's OpenAPI document (field docs, operation summary).
    pub doc: &'a Value,
    /// The time of the calculation (RFC 3339, UTC).
    pub time_utc: &'a str,
    /// The request id the service gave the calculation.
    pub request_id: Option<&'a str>,
}

/// The source commit of this build (`build.rs`).
pub const SOURCE_COMMIT: &str = env!("MECHCALC_GIT_COMMIT");

/// Lower-case hex SHA-256 of `bytes`.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .fold(String::with_capacity(64), |mut s, b| {
            let _ = write!(s, "{b:02x}");
            s
        })
}

/// HTML text escaping (element content and attribute values).
#[must_use]
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON text for a `<script type="application/json">` element: `<` written `\u003c`.
#[must_use]
pub fn script_json(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).replace('<', "\\u003c")
}

const STYLE: &str = "
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Helvetica,Arial,sans-serif;margin:2em auto;max-width:60em;color:#111;line-height:1.35;padding:0 1em}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.2em;border-bottom:1px solid #999;margin-top:1.6em}
h3{font-size:1em;margin-bottom:.3em}
table{border-collapse:collapse;width:100%;font-size:.85em;margin:.5em 0}
th,td{border:1px solid #bbb;padding:.15em .4em;text-align:left;vertical-align:top}
th{background:#eee}td.v{font-family:ui-monospace,Menlo,Consolas,monospace;word-break:break-all}
code{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:.95em}
.sub{color:#444}.warn{background:#fff4d6}.ok{color:#075}.bad{color:#a00}
figure{margin:1em 0}figure svg{max-width:100%;height:auto;border:1px solid #ddd}
@page{size:A4;margin:15mm}
@media print{body{margin:0;max-width:none;font-size:10pt}h2{break-after:avoid}tr,figure{break-inside:avoid}}
";

/// The report as one HTML document.
#[must_use]
pub fn render(r: &ReportInput<'_>) -> String {
    let schemas = Schemas::of(r.doc, r.route);
    let op = r.doc.pointer(&format!(
        "/paths/{}/post",
        r.route.replace('~', "~0").replace('/', "~1")
    ));
    let summary = op
        .and_then(|o| o.get("summary"))
        .and_then(Value::as_str)
        .unwrap_or(r.route);
    let mut h = String::with_capacity(64 * 1024);
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width,initial-scale=1\">\
         <title>mechcalc report: {}</title><style>{STYLE}</style></head><body>",
        escape(r.route)
    );
    let _ = writeln!(
        h,
        "<h1>Calculation report: {}</h1><p class=\"sub\"><code>POST {}</code> · mechcalc {} · {}</p>",
        escape(summary),
        escape(r.route),
        escape(env!("CARGO_PKG_VERSION")),
        escape(r.time_utc)
    );
    provenance(&mut h, r);
    method(&mut h, r, op);
    h.push_str("<h2 id=\"inputs\">Inputs</h2>\n");
    let mut rows = Vec::new();
    leaves(r.request, &mut Vec::new(), &mut rows);
    field_table(&mut h, &rows, |p| schemas.request_doc(p));
    results(&mut h, r, &schemas);
    picture(&mut h, r);
    h.push_str("<h2 id=\"record\">Request and answer (machine-readable)</h2>\n<p>The exact request and answer are embedded in this file as JSON (elements <code>script#request</code> and <code>script#answer</code>). To re-run: save the request as <code>request.json</code> and <code>curl -sS -H 'Content-Type: application/json' --data-binary @request.json http://HOST");
    h.push_str(&escape(r.route));
    h.push_str("</code>, or <code>mechcalc run ");
    h.push_str(&escape(r.route));
    h.push_str(" request.json</code>; the answer of the same version and commit is identical (deterministic calculations; fields measuring time differ).</p>\n");
    let _ = writeln!(
        h,
        "<script type=\"application/json\" id=\"request\">{}</script>\n\
         <script type=\"application/json\" id=\"answer\">{}</script>\n</body></html>",
        script_json(r.request_bytes),
        script_json(r.answer_bytes)
    );
    h
}

fn provenance(h: &mut String, r: &ReportInput<'_>) {
    h.push_str("<h2 id=\"provenance\">Provenance</h2>\n<table>");
    let mut row = |k: &str, v: &str| {
        let _ = write!(
            h,
            "<tr><th>{}</th><td class=\"v\">{}</td></tr>",
            escape(k),
            escape(v)
        );
    };
    row("service", "mechcalc");
    row("version", env!("CARGO_PKG_VERSION"));
    row("source commit", SOURCE_COMMIT);
    row("endpoint", &format!("POST {}", r.route));
    row("request SHA-256", &sha256_hex(r.request_bytes));
    row("request bytes", &r.request_bytes.len().to_string());
    row("answer SHA-256", &sha256_hex(r.answer_bytes));
    row("time (UTC)", r.time_utc);
    if let Some(id) = r.request_id {
        row("request id", id);
    }
    h.push_str("</table>\n");
}

/// Minimal rendering of a module's `//!` documentation: `#` headings, `*`/`-` list items,
/// paragraphs; `` `code` `` kept as code.
fn doc_html(h: &mut String, text: &str) {
    let mut in_list = false;
    let mut para = String::new();
    let flush = |h: &mut String, para: &mut String| {
        if !para.trim().is_empty() {
            let _ = writeln!(h, "<p>{}</p>", inline(para.trim()));
        }
        para.clear();
    };
    for line in text.lines() {
        let t = line.trim();
        if let Some(head) = t.strip_prefix('#') {
            flush(h, &mut para);
            if in_list {
                h.push_str("</ul>\n");
                in_list = false;
            }
            let _ = writeln!(
                h,
                "<h3>{}</h3>",
                inline(head.trim_start_matches('#').trim())
            );
        } else if let Some(item) = t.strip_prefix("* ").or_else(|| t.strip_prefix("- ")) {
            flush(h, &mut para);
            if !in_list {
                h.push_str("<ul>\n");
                in_list = true;
            }
            let _ = write!(h, "<li>{}", inline(item));
        } else if t.is_empty() {
            flush(h, &mut para);
            if in_list {
                h.push_str("</ul>\n");
                in_list = false;
            }
        } else if in_list {
            let _ = write!(h, " {}", inline(t));
        } else {
            para.push_str(t);
            para.push(' ');
        }
    }
    flush(h, &mut para);
    if in_list {
        h.push_str("</ul>\n");
    }
}

/// Escaped text with `` `code` `` spans; rustdoc's escaped brackets `\[` `\]` unescaped.
fn inline(s: &str) -> String {
    let s = s.replace("\\[", "[").replace("\\]", "]");
    let mut out = String::new();
    for (i, part) in s.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{}</code>", escape(part));
        } else {
            out.push_str(&escape(part));
        }
    }
    out
}

fn method(h: &mut String, r: &ReportInput<'_>, op: Option<&Value>) {
    h.push_str("<h2 id=\"method\">Method and references</h2>\n");
    if let Some(d) = op
        .and_then(|o| o.get("description"))
        .and_then(Value::as_str)
    {
        doc_html(h, d);
    }
    if let Some(m) = super::module_of(r.route)
        && let Some((_, doc)) = super::MODULE_DOCS.iter().find(|(n, _)| *n == m)
    {
        let _ = writeln!(h, "<h3>Module <code>{}</code></h3>", escape(m));
        doc_html(h, doc);
    }
}

/// One row of a field table: JSON pointer, schema path, shown value.
struct Leaf {
    pointer: String,
    schema: Vec<String>,
    value: String,
}

fn show_scalar(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Null => "null".to_owned(),
        other => other.to_string(),
    }
}

/// The leaves of `v`: scalars, short arrays of scalars in one row, long arrays summarised.
fn leaves(v: &Value, path: &mut Vec<String>, out: &mut Vec<Leaf>) {
    let pointer = || {
        path.iter()
            .map(|s| format!("/{}", s.replace('~', "~0").replace('/', "~1")))
            .collect::<String>()
    };
    let schema = |path: &[String]| -> Vec<String> {
        path.iter()
            .map(|s| {
                if s.parse::<usize>().is_ok() {
                    "*".to_owned()
                } else {
                    s.clone()
                }
            })
            .collect()
    };
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                path.push(k.clone());
                leaves(x, path, out);
                path.pop();
            }
        }
        Value::Array(a) if a.iter().all(|x| !x.is_object() && !x.is_array()) => {
            let value = if a.len() <= SHOWN_ARRAY {
                format!(
                    "[{}]",
                    a.iter().map(show_scalar).collect::<Vec<_>>().join(", ")
                )
            } else {
                let nums: Vec<f64> = a.iter().filter_map(Value::as_f64).collect();
                let lo = nums.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = nums.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                if nums.len() == a.len() {
                    format!(
                        "{} values from {lo} to {hi} (min … max; all in the embedded JSON)",
                        a.len()
                    )
                } else {
                    format!("{} values (all in the embedded JSON)", a.len())
                }
            };
            out.push(Leaf {
                pointer: pointer(),
                schema: schema(path),
                value,
            });
        }
        Value::Array(a) if a.len() <= SHOWN_RECORDS => {
            for (i, x) in a.iter().enumerate() {
                path.push(i.to_string());
                leaves(x, path, out);
                path.pop();
            }
        }
        Value::Array(a) => out.push(Leaf {
            pointer: pointer(),
            schema: schema(path),
            value: format!(
                "{} entries (all in the embedded JSON and the CSV tables)",
                a.len()
            ),
        }),
        scalar => out.push(Leaf {
            pointer: pointer(),
            schema: schema(path),
            value: show_scalar(scalar),
        }),
    }
}

fn shorten(s: &str) -> String {
    let s = s.replace("\\[", "[").replace("\\]", "]");
    if s.chars().count() <= MEANING_CHARS {
        return s;
    }
    let mut t: String = s.chars().take(MEANING_CHARS).collect();
    t.push('…');
    t
}

fn field_table<'d>(h: &mut String, rows: &[Leaf], doc: impl Fn(&[&str]) -> Option<&'d str>) {
    h.push_str("<table><tr><th>field</th><th>value</th><th>unit</th><th>meaning</th></tr>\n");
    for l in rows.iter().take(MAX_ROWS) {
        let p: Vec<&str> = l.schema.iter().map(String::as_str).collect();
        let d = doc(&p).unwrap_or("");
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td class=\"v\">{}</td><td>{}</td><td>{}</td></tr>",
            escape(&l.pointer),
            escape(&l.value),
            escape(unit_of(d).unwrap_or("")),
            escape(&shorten(d))
        );
    }
    if rows.len() > MAX_ROWS {
        let _ = writeln!(
            h,
            "<tr><td colspan=\"4\">… {} more fields in the embedded JSON</td></tr>",
            rows.len() - MAX_ROWS
        );
    }
    h.push_str("</table>\n");
}

/// Whether an answer field is a check of the answer (residual, certificate, verification).
fn is_check(pointer: &str) -> bool {
    const WORDS: &[&str] = &[
        "residual",
        "verification",
        "certificate",
        "local_accuracy",
        "passed",
        "max_dev",
        "stability",
        "exact_zero",
        "at_numerical_floor",
        "closure",
        "check",
    ];
    let p = pointer.to_ascii_lowercase();
    WORDS.iter().any(|w| p.contains(w))
}

fn results(h: &mut String, r: &ReportInput<'_>, schemas: &Schemas<'_>) {
    let mut rows = Vec::new();
    leaves(r.answer, &mut Vec::new(), &mut rows);
    let (warnings, rest): (Vec<Leaf>, Vec<Leaf>) = rows
        .into_iter()
        .partition(|l| l.pointer.starts_with("/warnings"));
    let (solver, rest): (Vec<Leaf>, Vec<Leaf>) = rest.into_iter().partition(|l| {
        l.pointer.starts_with("/report/")
            || l.pointer.starts_with("/meta/solver/")
            || l.pointer.starts_with("/optimizer_report/")
    });
    let checks: Vec<&Leaf> = rest.iter().filter(|l| is_check(&l.pointer)).collect();
    h.push_str("<h2 id=\"results\">Results</h2>\n");
    field_table(h, &rest, |p| schemas.answer_doc(p));
    h.push_str("<h2 id=\"checks\">Checks the answer carries</h2>\n");
    if checks.is_empty() {
        h.push_str("<p>This answer carries no residual, certificate or verification field.</p>\n");
    } else {
        let owned: Vec<Leaf> = checks
            .iter()
            .map(|l| Leaf {
                pointer: l.pointer.clone(),
                schema: l.schema.clone(),
                value: l.value.clone(),
            })
            .collect();
        field_table(h, &owned, |p| schemas.answer_doc(p));
    }
    h.push_str("<h2 id=\"warnings\">Warnings</h2>\n");
    let list = r.answer.get("warnings").and_then(Value::as_array);
    match list {
        Some(w) if !w.is_empty() => {
            h.push_str("<table><tr><th>code</th><th>message</th><th>field</th></tr>\n");
            for x in w {
                let s = |k: &str| x.get(k).map(show_scalar).unwrap_or_default();
                let _ = writeln!(
                    h,
                    "<tr class=\"warn\"><td><code>{}</code></td><td>{}</td><td><code>{}</code></td></tr>",
                    escape(&s("code")),
                    escape(&s("message")),
                    escape(&s("pointer"))
                );
            }
            h.push_str("</table>\n");
        }
        _ if !warnings.is_empty() => field_table(h, &warnings, |p| schemas.answer_doc(p)),
        _ => h.push_str("<p>None.</p>\n"),
    }
    h.push_str("<h2 id=\"solver\">Solver report</h2>\n");
    if solver.is_empty() {
        h.push_str("<p>This calculation is closed-form or reports no solver run.</p>\n");
    } else {
        field_table(h, &solver, |p| schemas.answer_doc(p));
    }
}

fn picture(h: &mut String, r: &ReportInput<'_>) {
    h.push_str("<h2 id=\"picture\">Picture</h2>\n");
    match crate::plot::render(r.route, r.request, r.answer) {
        Some(Ok(svg)) => {
            let body = svg.find("<svg").map_or(svg.as_str(), |i| &svg[i..]);
            let _ = writeln!(
                h,
                "<figure>{body}<figcaption>The answer's picture (as <code>Accept: image/svg+xml</code> draws it).</figcaption></figure>"
            );
        }
        Some(Err(e)) => {
            let _ = writeln!(
                h,
                "<p>No picture of this answer: {}. The picture endpoint (<code>Accept: image/svg+xml</code>) turns on the outputs it needs.</p>",
                escape(&e.to_string())
            );
        }
        None => h.push_str("<p>This endpoint has no picture.</p>\n"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_abc() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn script_json_cannot_close_the_element() {
        let s = script_json(br#"{"a":"</script><b>"}"#);
        assert!(!s.contains('<'));
        let v: Value = serde_json::from_str(&s).expect("still JSON");
        assert_eq!(v["a"], "</script><b>");
    }
}
