//! Memory follows the request, not a copy of it: the release binary on loopback receives a
//! machining-size training body of B bytes (rows × 20 features, one shallow tree, so the model
//! work is small and what is measured is the reading), and the service's peak RSS (`VmHWM`) rise
//! is compared with 5·B + 32 MiB; its RSS 2 s after the answer shows whether the memory went back.
//! Prints a table for benches/RESULTS.md.
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

fn post(port: u16, body: &[u8]) -> u16 {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
    let head = format!(
        "POST /v1/machining-size/train HTTP/1.1\r\nhost: x\r\ncontent-type: application/json\r\n\
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

fn main() {
    let bin = std::env::var("MECHCALC_BOUNDARY_BIN").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/target/release/mechcalc").to_owned()
    });
    println!("binary: {bin}\n");
    println!(
        "| rows × 20 | body MiB | idle RSS MiB | peak rise MiB | limit 5·B + 32 MiB | RSS 2 s after MiB | status |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for rows in [20_000usize, 40_000, 100_000] {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map(|a| a.port())
            .expect("a free port");
        let mut child = start(&bin, port);
        let pid = child.id();
        let b = body(rows);
        std::thread::sleep(Duration::from_millis(300));
        let idle = status_kib(pid, "VmRSS:");
        let hwm0 = status_kib(pid, "VmHWM:");
        let status = post(port, &b);
        let peak = status_kib(pid, "VmHWM:");
        std::thread::sleep(Duration::from_secs(2));
        let after = status_kib(pid, "VmRSS:");
        let mib = |k: u64| k as f64 / 1024.0;
        let b_mib = b.len() as f64 / 1048576.0;
        println!(
            "| {rows} | {b_mib:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {status} |",
            mib(idle),
            mib(peak.saturating_sub(hwm0.max(idle))),
            5.0 * b_mib + 32.0,
            mib(after)
        );
        child.kill().ok();
        child.wait().ok();
    }
}
