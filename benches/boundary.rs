//! The boundary's own cost per request, measured as a client meets it: the release binary on
//! loopback, one keep-alive connection, every `api/` example sent 15 times. The boundary cost of
//! one answer is its round trip minus what the service reports in `Server-Timing` (queue +
//! compute + encode) minus the best `/healthz` round trip (the socket and HTTP cost every request
//! pays); the best of 15 is kept per example. Prints the per-endpoint table for
//! benches/RESULTS.md and the median and largest over the examples (goal: ≤ 50 µs, ≤ 150 µs).
//!
//! `cargo bench --bench boundary` (builds the release binary first: `cargo build --release`).
//! `MECHCALC_BOUNDARY_BIN=/path/to/mechcalc` measures another build (e.g. an older commit's).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

#[path = "support/mod.rs"]
mod support;

const REPEATS: usize = 15;

/// A keep-alive HTTP/1.1 connection.
struct Conn {
    reader: BufReader<TcpStream>,
    writer: TcpStream,
}

/// One answer: status, the sum of its `Server-Timing` durations [µs], body length.
struct Answer {
    status: u16,
    server_us: f64,
    /// The `door` metric (parse, rules, rules between fields) [µs]: part of the boundary.
    door_us: f64,
    bytes: usize,
}

impl Conn {
    fn open(port: u16) -> Self {
        let s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
        s.set_nodelay(true).expect("nodelay");
        Self {
            reader: BufReader::new(s.try_clone().expect("clone")),
            writer: s,
        }
    }

    fn request(&mut self, method: &str, path: &str, body: &[u8]) -> Answer {
        let head = format!(
            "{method} {path} HTTP/1.1\r\nhost: 127.0.0.1\r\ncontent-type: application/json\r\n\
             accept: application/json\r\ncontent-length: {}\r\n\r\n",
            body.len()
        );
        self.writer.write_all(head.as_bytes()).expect("write");
        self.writer.write_all(body).expect("write");
        let mut line = String::new();
        self.reader.read_line(&mut line).expect("status line");
        let status = line
            .split_whitespace()
            .nth(1)
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        let mut length = 0usize;
        let mut server_us = 0.0;
        let mut door_us = 0.0;
        loop {
            line.clear();
            self.reader.read_line(&mut line).expect("header");
            let l = line.trim_end();
            if l.is_empty() {
                break;
            }
            let lower = l.to_ascii_lowercase();
            if let Some(v) = lower.strip_prefix("content-length:") {
                length = v.trim().parse().expect("length");
            } else if let Some(v) = lower.strip_prefix("server-timing:") {
                // queue + compute + encode only: `door` and `handback` are part of the boundary.
                server_us = v
                    .split(',')
                    .filter(|m| {
                        let name = m.trim().split(';').next().unwrap_or("");
                        matches!(name, "queue" | "compute" | "encode")
                    })
                    .filter_map(|m| m.split("dur=").nth(1))
                    .filter_map(|d| d.trim().parse::<f64>().ok())
                    .sum::<f64>()
                    * 1e3;
                door_us = v
                    .split(',')
                    .find_map(|m| m.trim().strip_prefix("door;dur="))
                    .and_then(|d| d.trim().parse::<f64>().ok())
                    .unwrap_or(0.0)
                    * 1e3;
            }
        }
        let mut buf = vec![0u8; length];
        self.reader.read_exact(&mut buf).expect("body");
        Answer {
            status,
            server_us,
            door_us,
            bytes: length,
        }
    }
}

fn start(bin: &str, port: u16) -> Child {
    let child = Command::new(bin)
        .env("MECHCALC_BIND", format!("127.0.0.1:{port}"))
        .env("MECHCALC_LOG", "error")
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

/// The encoding of the cognates example answer (curves on, about 70 KB) in process: the finite-number guard (one
/// allocation-free pass) against writing the JSON, best of 200 each [µs].
fn encode_costs() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/api/cognates/table1.json");
    let Ok(text) = std::fs::read_to_string(file) else {
        println!("(no {file}: encode timing skipped)");
        return;
    };
    let req: mechcalc::calc::cognates::CognatesRequest =
        serde_json::from_str(&text).expect("the example decodes");
    let answer = mechcalc::calc::cognates::run(req, &mechcalc::numerics::Budget::unlimited())
        .expect("the example computes");
    let best = |f: &mut dyn FnMut()| {
        (0..200)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e6
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut bytes = 0;
    let guard = best(&mut || assert!(mechcalc::http::finite::all_finite(&answer)));
    let write = best(&mut || bytes = serde_json::to_vec(&answer).expect("encodes").len());
    let both = best(&mut || bytes = mechcalc::http::encode(&answer).expect("encodes").len());
    println!(
        "cognates answer, {bytes} bytes: finite guard {guard:.1} µs, JSON writing {write:.1} µs, \
         the service's encode (guard + pre-sized write) {both:.1} µs\n"
    );
}

fn main() {
    encode_costs();
    let bin = std::env::var("MECHCALC_BOUNDARY_BIN").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/target/release/mechcalc").to_owned()
    });
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port");
    let mut child = start(&bin, port);
    let mut conn = Conn::open(port);
    let mut health = f64::INFINITY;
    for _ in 0..50 {
        let t = Instant::now();
        let a = conn.request("GET", "/healthz", b"");
        assert_eq!(a.status, 200);
        health = health.min(t.elapsed().as_secs_f64() * 1e6);
    }
    println!("binary: {bin}");
    println!("/healthz round trip (best of 50): {health:.1} µs\n");
    println!(
        "| example | endpoint | answer bytes | round trip µs | server (queue+compute+encode) µs | of the boundary: door µs | boundary µs |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|");
    let mut costs = Vec::new();
    for (file, endpoint, body) in support::api_examples() {
        let mut best: Option<(f64, f64, f64, f64, usize)> = None;
        for _ in 0..REPEATS {
            let t = Instant::now();
            let a = conn.request("POST", &endpoint, &body);
            let rtt = t.elapsed().as_secs_f64() * 1e6;
            assert_eq!(a.status, 200, "api/{file} answered {}", a.status);
            let cost = rtt - a.server_us - health;
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, rtt, a.server_us, a.door_us, a.bytes));
            }
        }
        let (cost, rtt, server, door, bytes) = best.expect("measured");
        println!(
            "| {file} | {endpoint} | {bytes} | {rtt:.0} | {server:.0} | {door:.0} | {cost:.0} |"
        );
        costs.push(cost);
    }
    child.kill().ok();
    child.wait().ok();
    costs.sort_by(f64::total_cmp);
    let median = costs[costs.len() / 2];
    let largest = costs[costs.len() - 1];
    println!(
        "\nboundary cost over {} examples: median {median:.0} µs, largest {largest:.0} µs \
         (goal ≤ 50 µs, ≤ 150 µs)",
        costs.len()
    );
}
