//! Memory follows the request, not a copy of it: the release binary on loopback receives a
//! machining-size training body of B bytes (rows × 20 features, one shallow tree, so the model
//! work is small and what is measured is the reading), and the service's peak RSS (`VmHWM`) rise
//! is compared with 5·B + 32 MiB; its RSS 2 s after the answer shows whether the memory went back.
//! Then the same for `/predict` bodies that carry a large XGBoost model (trees × 511 nodes, the
//! model document read from its JSON tree into the model). Prints tables for benches/RESULTS.md.
//!
//! `cargo build --release && cargo bench --bench request_memory`
//! (`MECHCALC_BOUNDARY_BIN=/path/to/mechcalc` measures another build.)

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// `/proc/<pid>/status` field in KiB.
fn status_kib(pid: u32, field: &str) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .unwrap_or_default()
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// A training body of `rows` × 20 features with deterministic pseudo-random values.
fn body(rows: usize) -> Vec<u8> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        // 53 random bits → [0, 1): exact.
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut s = String::with_capacity(rows * 20 * 22);
    s.push_str("{\"feature_names\": [");
    for j in 0..20 {
        if j > 0 {
            s.push(',');
        }
        s.push_str(&format!("\"f{j}\""));
    }
    s.push_str("], \"rows\": [");
    let mut target = Vec::with_capacity(rows);
    for i in 0..rows {
        if i > 0 {
            s.push(',');
        }
        s.push('[');
        let mut y = 0.0;
        for j in 0..20 {
            let x = 100.0 * next();
            y += x * (j as f64 + 1.0);
            if j > 0 {
                s.push(',');
            }
            s.push_str(&format!("{x:.9}"));
        }
        s.push(']');
        target.push(y);
    }
    s.push_str("], \"target\": [");
    for (i, y) in target.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        s.push_str(&format!("{y:.6}"));
    }
    s.push_str(
        "], \"params\": {\"n_estimators\": 1, \"max_depth\": 2, \"tree_method\": \"hist\"}, \
         \"validation\": {\"test_fraction\": 0.2}, \"time_limit_ms\": 60000}",
    );
    s.into_bytes()
}

/// A `/predict` body: an XGBoost JSON model of `trees` complete trees of depth 8 (511 nodes)
/// over 20 features, and 100 rows.
fn predict_body(trees: usize) -> Vec<u8> {
    const NODES: usize = 511;
    let list =
        |f: &dyn Fn(usize) -> String| -> String { (0..NODES).map(f).collect::<Vec<_>>().join(",") };
    let inner = |i: usize| i < NODES / 2;
    let tree = |t: usize| -> String {
        format!(
            "{{\"base_weights\":[{bw}],\"default_left\":[{dl}],\"id\":{t},\"left_children\":[{lc}],\
             \"loss_changes\":[{lo}],\"parents\":[{pa}],\"right_children\":[{rc}],\
             \"split_conditions\":[{sc}],\"split_indices\":[{si}],\"split_type\":[{st}],\
             \"sum_hessian\":[{sh}],\"tree_param\":{{\"num_deleted\":\"0\",\"num_feature\":\"20\",\
             \"num_nodes\":\"{NODES}\",\"size_leaf_vector\":\"1\"}}}}",
            bw = list(&|i| format!("{:.7e}", (i as f64 + 0.5) * 1e-3)),
            dl = list(&|i| u8::from(i % 2 == 0).to_string()),
            lc = list(&|i| if inner(i) {
                (2 * i + 1).to_string()
            } else {
                "-1".into()
            }),
            lo = list(&|i| format!("{:.6}", 1.0 / (i as f64 + 1.0))),
            pa = list(&|i| if i == 0 {
                "2147483647".into()
            } else {
                ((i - 1) / 2).to_string()
            }),
            rc = list(&|i| if inner(i) {
                (2 * i + 2).to_string()
            } else {
                "-1".into()
            }),
            sc = list(&|i| format!("{:.6}", 100.0 * ((i * 37 + t) % 101) as f64 / 101.0)),
            si = list(&|i| if inner(i) {
                ((i + t) % 20).to_string()
            } else {
                "0".into()
            }),
            st = list(&|_| "0".into()),
            sh = list(&|i| format!(
                "{:.1}",
                1e4 / f64::from(1u32 << (usize::BITS - (i + 1).leading_zeros() - 1))
            )),
        )
    };
    let names = (0..20)
        .map(|j| format!("\"f{j}\""))
        .collect::<Vec<_>>()
        .join(",");
    let trees_json = (0..trees).map(tree).collect::<Vec<_>>().join(",");
    let rows = (0..100)
        .map(|r| {
            let row = (0..20)
                .map(|j| format!("{:.3}", ((r * 7 + j * 13) % 100) as f64))
                .collect::<Vec<_>>();
            format!("[{}]", row.join(","))
        })
        .collect::<Vec<_>>()
        .join(",");
    format!(
        "{{\"model\":{{\"xgboost_json\":{{\"learner\":{{\"feature_names\":[{names}],\
         \"gradient_booster\":{{\"model\":{{\"gbtree_model_param\":{{\"num_parallel_tree\":\"1\",\
         \"num_trees\":\"{trees}\"}},\"tree_info\":[{ti}],\"trees\":[{trees_json}]}},\"name\":\"gbtree\"}},\
         \"learner_model_param\":{{\"base_score\":\"[5E1]\",\"num_class\":\"0\",\"num_feature\":\"20\",\
         \"num_target\":\"1\"}},\"objective\":{{\"name\":\"reg:squarederror\"}}}},\"version\":[3,2,0]}}}},\
         \"rows\":[{rows}]}}",
        ti = vec!["0"; trees].join(","),
    )
    .into_bytes()
}

fn post(port: u16, path: &str, body: &[u8]) -> u16 {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
    let head = format!(
        "POST {path} HTTP/1.1\r\nhost: x\r\ncontent-type: application/json\r\n\
         content-length: {}\r\nconnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).expect("write");
    s.write_all(body).expect("write");
    let mut r = BufReader::new(s);
    let mut line = String::new();
    r.read_line(&mut line).expect("status");
    let status = line
        .split_whitespace()
        .nth(1)
        .and_then(|x| x.parse().ok())
        .unwrap_or(0);
    let mut rest = Vec::new();
    r.read_to_end(&mut rest).ok();
    status
}

fn start(bin: &str, port: u16) -> Child {
    let child = Command::new(bin)
        .env("MECHCALC_BIND", format!("127.0.0.1:{port}"))
        .env("MECHCALC_LOG", "error")
        .env("MECHCALC_MAX_BODY_BYTES", "33554432")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the release binary starts (cargo build --release first)");
    let t0 = Instant::now();
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "service did not start"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

/// One row of the table: a fresh service, its idle RSS, the peak rise over the request and the
/// RSS 2 s after the answer.
fn measure(bin: &str, label: &str, path: &str, b: &[u8]) {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port");
    let mut child = start(bin, port);
    let pid = child.id();
    std::thread::sleep(Duration::from_millis(300));
    let idle = status_kib(pid, "VmRSS:");
    let hwm0 = status_kib(pid, "VmHWM:");
    let status = post(port, path, b);
    let peak = status_kib(pid, "VmHWM:");
    std::thread::sleep(Duration::from_secs(2));
    let after = status_kib(pid, "VmRSS:");
    let mib = |k: u64| k as f64 / 1024.0;
    let b_mib = b.len() as f64 / 1048576.0;
    println!(
        "| {label} | {b_mib:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {status} |",
        mib(idle),
        mib(peak.saturating_sub(hwm0.max(idle))),
        5.0 * b_mib + 32.0,
        mib(after)
    );
    child.kill().ok();
    child.wait().ok();
}

fn main() {
    let bin = std::env::var("MECHCALC_BOUNDARY_BIN").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/target/release/mechcalc").to_owned()
    });
    println!("binary: {bin}\n");
    println!(
        "| body | body MiB | idle RSS MiB | peak rise MiB | limit 5·B + 32 MiB | RSS 2 s after MiB | status |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for rows in [20_000usize, 40_000, 100_000] {
        let label = format!("train, {rows} rows × 20");
        measure(&bin, &label, "/v1/machining-size/train", &body(rows));
    }
    for trees in [50usize, 150, 300] {
        let label = format!("predict, XGBoost model {trees} trees × 511 nodes");
        measure(
            &bin,
            &label,
            "/v1/machining-size/predict",
            &predict_body(trees),
        );
    }
}
