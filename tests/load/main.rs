//! Load and fault tests against the real binary on loopback: idle and slowloris connections, a
//! flood of heavy requests with cheap ones mixed in, client disconnects, slow readers and SIGTERM
//! during work. Every scenario is bounded in count and time and stops by itself.
//!
//! `MECHCALC_LOAD_SCALE` (default 1) multiplies the connection and request counts for a longer run.

mod client;
mod keys_and_fairness;

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use client::{Server, cpu_seconds, get, post, rss_kib, status_field, thread_count};
use serde_json::{Value, json};

/// The scenarios run one at a time: each starts its own server and floods it, and two floods at
/// once on a 2-core machine would measure each other.
static SERIAL: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

fn scale() -> usize {
    std::env::var("MECHCALC_LOAD_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

/// A heavy request: a workspace sweep that runs until its time limit.
fn heavy(time_limit_ms: u64) -> Value {
    let mut v: Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/api/continuum_workspace/sweep_design1.json"
        ))
        .expect("example"),
    )
    .expect("JSON");
    v["workspace"]["grid"] = json!([201, 201]);
    v["time_limit_ms"] = json!(time_limit_ms);
    v
}

/// A cheap request: the cam-law evaluation of the spec's Table-1 law at five points.
fn cheap() -> Value {
    serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/api/cam_law/evaluate_table1.json"
        ))
        .expect("example"),
    )
    .expect("JSON")
}

/// Every heavy request of a flood is answered: computed or turned away, never a failure.
async fn heavy_answers(tasks: Vec<tokio::task::JoinHandle<std::io::Result<client::Reply>>>) {
    for t in tasks {
        let r = t.await.expect("join").expect("answers");
        assert!(
            r.status == 200 || r.status == 503,
            "heavy answered {}",
            r.status
        );
    }
}

async fn healthz_ms(server: &Server) -> f64 {
    let t = Instant::now();
    let r = get(server.addr, "/healthz").await.expect("healthz answers");
    assert_eq!(r.status, 200);
    t.elapsed().as_secs_f64() * 1e3
}

fn metric(text: &str, name_and_labels: &str) -> f64 {
    text.lines()
        .filter(|l| l.starts_with(name_and_labels))
        .filter_map(|l| l.rsplit(' ').next()?.parse::<f64>().ok())
        .sum()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn idle_and_slowloris_connections_cannot_take_the_service_down() {
    let _serial = SERIAL.lock().await;
    client::raise_fd_limit();
    let server = Server::start(&[("MECHCALC_HEADER_TIMEOUT_MS", "1500")]).await;
    let n_idle = 2000 * scale();
    let mut idle = Vec::with_capacity(n_idle);
    for _ in 0..n_idle {
        match tokio::net::TcpStream::connect(server.addr).await {
            Ok(s) => idle.push(s),
            Err(e) => panic!("connect #{} failed: {e}", idle.len()),
        }
    }
    // Slowloris: half a request head, one byte at a time.
    let slow: Vec<_> = (0..50)
        .map(|_| {
            tokio::spawn(client::slowloris(
                server.addr,
                Duration::from_millis(200),
                40,
            ))
        })
        .collect();
    let mut worst = 0.0f64;
    for _ in 0..10 {
        worst = worst.max(healthz_ms(&server).await);
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(
        worst < 50.0,
        "/healthz took {worst:.1} ms with {n_idle} idle connections"
    );
    // Every slowloris connection is closed by the server before it finishes its head.
    for s in slow {
        let closed_early = s.await.expect("join");
        assert!(closed_early, "a slowloris connection was kept open");
    }
    // The idle connections are closed by the header timeout.
    tokio::time::sleep(Duration::from_millis(1000)).await;
    let mut closed = 0;
    for s in &mut idle {
        if client::is_closed(s).await {
            closed += 1;
        }
    }
    assert_eq!(
        closed, n_idle,
        "idle connections outlive the header timeout"
    );
    drop(idle);
    assert!(healthz_ms(&server).await < 50.0);
    server.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn cheap_requests_are_served_during_a_flood_of_sweeps() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_QUEUE_DEPTH", "64")]).await;
    // Teach the pool what the cheap route costs.
    for _ in 0..5 {
        assert_eq!(
            post(server.addr, "/v1/cam-law/evaluate", &cheap())
                .await
                .expect("ok")
                .status,
            200
        );
    }
    let heavy_tasks: Vec<_> = (0..(8 * scale()))
        .map(|_| {
            let addr = server.addr;
            tokio::spawn(async move { post(addr, "/v1/continuum-workspace", &heavy(3000)).await })
        })
        .collect();
    tokio::time::sleep(Duration::from_millis(200)).await;
    // 64 concurrent cheap clients, 5 requests each, while the sweeps hold every compute slot.
    let cheap_tasks: Vec<_> = (0..64)
        .map(|_| {
            let addr = server.addr;
            tokio::spawn(async move {
                let mut statuses = Vec::new();
                for _ in 0..5 {
                    let r = post(addr, "/v1/cam-law/evaluate", &cheap())
                        .await
                        .expect("answers");
                    statuses.push(r.status);
                }
                statuses
            })
        })
        .collect();
    let mut worst = 0.0f64;
    for _ in 0..10 {
        worst = worst.max(healthz_ms(&server).await);
        tokio::time::sleep(Duration::from_millis(30)).await;
    }
    let mut refused = 0;
    let mut total = 0;
    for t in cheap_tasks {
        for s in t.await.expect("join") {
            total += 1;
            if s != 200 {
                refused += 1;
            }
        }
    }
    assert_eq!(
        refused, 0,
        "{refused} of {total} cheap requests were not served"
    );
    assert!(worst < 50.0, "/healthz took {worst:.1} ms during the flood");
    heavy_answers(heavy_tasks).await;
    server.stop().await;
}

/// The compute pool bounds the CPU: with one compute thread, a flood of parallel sweeps (each of
/// which would use every core it were given) keeps the process at about one core, and the
/// process does not grow a thread per job.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_flood_of_sweeps_stays_within_the_configured_compute_threads() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[
        ("MECHCALC_COMPUTE_THREADS", "1"),
        ("MECHCALC_COMPUTE_SLOTS", "4"),
        ("MECHCALC_QUEUE_DEPTH", "64"),
    ])
    .await;
    let pid = server.pid();
    let threads_idle = thread_count(pid);
    let heavy_tasks: Vec<_> = (0..(6 * scale()))
        .map(|_| {
            let addr = server.addr;
            tokio::spawn(async move { post(addr, "/v1/continuum-workspace", &heavy(2500)).await })
        })
        .collect();
    tokio::time::sleep(Duration::from_millis(300)).await;
    let (cpu0, t0) = (cpu_seconds(pid), Instant::now());
    let mut threads_busy = 0;
    for _ in 0..15 {
        tokio::time::sleep(Duration::from_millis(100)).await;
        threads_busy = threads_busy.max(thread_count(pid));
    }
    let cores = (cpu_seconds(pid) - cpu0) / t0.elapsed().as_secs_f64();
    eprintln!(
        "one compute thread, 6 sweeps: {cores:.2} cores, threads {threads_idle} idle / {threads_busy} busy"
    );
    // One compute thread plus the async layer's decoding and bookkeeping; an unbounded sweep
    // on this 2-core machine would show close to 2.
    assert!(
        cores < 1.35,
        "the process used {cores:.2} cores with one compute thread"
    );
    assert!(
        threads_busy <= threads_idle + 4,
        "threads grew from {threads_idle} to {threads_busy} under the flood"
    );
    heavy_answers(heavy_tasks).await;
    server.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_disconnected_client_frees_its_slot() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[]).await;
    let slots = get(server.addr, "/healthz").await.expect("ok").json()["compute_slots_free"]
        .as_u64()
        .expect("slots");
    // Heavy requests with a long budget whose clients leave after 300 ms.
    let n = 4;
    let tasks: Vec<_> = (0..n)
        .map(|_| {
            let addr = server.addr;
            tokio::spawn(async move {
                let _ = tokio::time::timeout(
                    Duration::from_millis(300),
                    post(addr, "/v1/continuum-workspace", &heavy(60_000)),
                )
                .await;
            })
        })
        .collect();
    for t in tasks {
        t.await.expect("join");
    }
    // Each job stops at its next budget check: the slots are free again within a second.
    let t = Instant::now();
    loop {
        let free = get(server.addr, "/healthz").await.expect("ok").json()["compute_slots_free"]
            .as_u64()
            .unwrap_or(0);
        if free == slots {
            break;
        }
        assert!(
            t.elapsed() < Duration::from_secs(2),
            "slots still busy {:?} after the clients left",
            t.elapsed()
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let m = get(server.addr, "/metrics").await.expect("metrics").text();
    assert!(
        metric(&m, "mechcalc_jobs_cancelled_total{cause=\"client_gone\"}") >= 1.0,
        "no cancelled job counted:\n{m}"
    );
    assert!(server.log().contains("request aborted by the client"));
    server.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn slow_readers_are_dropped_and_memory_returns() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_WRITE_TIMEOUT_MS", "1000")]).await;
    let big = json!({"law": "modified_sine", "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0},
        "abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 200_000}}, "quantities": ["s", "v", "a", "j"]});
    let base = rss_kib(server.pid());
    let readers: Vec<_> = (0..8)
        .map(|_| {
            tokio::spawn(client::post_and_never_read(
                server.addr,
                "/v1/cam-law/evaluate",
                big.clone(),
            ))
        })
        .collect();
    tokio::time::sleep(Duration::from_millis(500)).await;
    let peak = rss_kib(server.pid());
    // After the write timeout the server closes them.
    for r in readers {
        let closed = r.await.expect("join");
        assert!(closed, "a slow reader was kept open past the write timeout");
    }
    tokio::time::sleep(Duration::from_millis(300)).await;
    let after = rss_kib(server.pid());
    assert!(healthz_ms(&server).await < 50.0);
    // Memory returns near the baseline (allocator caches allowed: within 64 MiB).
    assert!(
        after < base + 64 * 1024,
        "RSS {after} KiB after the slow readers left (baseline {base}, peak {peak})"
    );
    server.stop().await;
}

/// A machining-size training body of `rows` × 20 features (one shallow tree: the reading, not
/// the model, is what the memory follows).
fn training_body(rows: usize) -> Vec<u8> {
    training_body_with(
        rows,
        &json!({"n_estimators": 1, "max_depth": 2, "tree_method": "hist"}),
        &json!({"test_fraction": 0.2}),
    )
}

/// A machining-size training body of `rows` × 20 features with these params and validation
/// (values with four decimals, about 8 bytes of JSON per value).
fn training_body_with(rows: usize, params: &Value, validation: &Value) -> Vec<u8> {
    let mut rng = 7_u64;
    let mut next = || {
        // xorshift: a fixed, dependency-free stream of numbers in [0, 100).
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng % 1_000_000) as f64 / 1e4
    };
    let x: Vec<Vec<f64>> = (0..rows)
        .map(|_| (0..20).map(|_| next()).collect())
        .collect();
    let y: Vec<f64> = x
        .iter()
        .map(|r| r.iter().enumerate().map(|(j, v)| v * (j + 1) as f64).sum())
        .collect();
    serde_json::to_vec(&json!({
        "feature_names": (0..20).map(|j| format!("f{j}")).collect::<Vec<_>>(),
        "rows": x, "target": y,
        "params": params, "validation": validation, "time_limit_ms": 60_000
    }))
    .expect("serializes")
}

/// Issue 26 item 7: a request body of B bytes raises peak RSS by at most 5·B + 32 MiB, and the
/// memory goes back to the system after the answer (the binary's allocator purges freed pages
/// in the background; glibc's kept tens of MiB).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn memory_follows_a_large_body_and_goes_back() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_MAX_BODY_BYTES", "33554432")]).await;
    let pid = server.pid();
    let body = training_body(40_000);
    let b_mib = body.len() / (1 << 20);
    tokio::time::sleep(Duration::from_millis(300)).await;
    let idle = rss_kib(pid);
    within_memory_limit(&server, "/v1/machining-size/train", &body, "training").await;
    // Up to 4 s for the background purge (1-s decay).
    let mut after = rss_kib(pid);
    for _ in 0..40 {
        if after <= idle + 16 * 1024 {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
        after = rss_kib(pid);
    }
    assert!(
        after <= idle + 16 * 1024,
        "RSS {after} KiB 4 s after a {b_mib} MiB body; idle was {idle} KiB"
    );
    server.stop().await;
}

/// The trainers' own memory stays within the limit too: k-fold training runs two models at
/// once, each with its working columns (exact) or histograms (hist, deep trees). The values
/// carry ten significant digits (about 13 bytes of JSON each, as measured data written by a
/// program); with fewer digits the body is smaller than the data in memory (8 bytes per f64 plus
/// the models' columns), and the model work alone is above 5·B.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn memory_of_k_fold_training_stays_within_the_limit() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_MAX_BODY_BYTES", "33554432")]).await;
    for params in [
        json!({"n_estimators": 3, "max_depth": 6, "tree_method": "exact"}),
        json!({"n_estimators": 3, "max_depth": 12, "tree_method": "hist"}),
    ] {
        let mut body: Value =
            serde_json::from_slice(&training_body_with(40_000, &params, &json!({"k_fold": 5})))
                .expect("json");
        let mut k = 0u64;
        for row in body["rows"].as_array_mut().expect("rows") {
            for v in row.as_array_mut().expect("row") {
                k = k.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                *v = json!(v.as_f64().unwrap_or(0.0) + (k >> 44) as f64 * 1e-10);
            }
        }
        let body = serde_json::to_vec(&body).expect("json");
        within_memory_limit(
            &server,
            "/v1/machining-size/train",
            &body,
            &params.to_string(),
        )
        .await;
    }
    server.stop().await;
}

/// Posts `body` to `path` on a running `server`, expects 200, and asserts that the peak RSS
/// rose by at most 5·B + 32 MiB for the body's B MiB.
async fn within_memory_limit(server: &Server, path: &str, body: &[u8], what: &str) {
    let pid = server.pid();
    let b_mib = body.len() / (1 << 20);
    tokio::time::sleep(Duration::from_millis(300)).await;
    let hwm0 = status_field(pid, "VmHWM:").max(rss_kib(pid));
    let r = client::send(server.addr, client::request_bytes_raw("POST", path, body))
        .await
        .expect("answers");
    assert_eq!(r.status, 200, "{}", r.text());
    let rise_mib = (status_field(pid, "VmHWM:") - hwm0) / 1024;
    assert!(
        rise_mib as usize <= 5 * b_mib + 32,
        "{what}: peak RSS rose {rise_mib} MiB for a {b_mib} MiB body (limit 5·B + 32 MiB)"
    );
}

/// A `/predict` body whose XGBoost model has `trees` complete trees of depth 8 (511 nodes) over
/// 20 features, with 10 rows.
fn model_body(trees: usize) -> Vec<u8> {
    const NODES: usize = 511;
    let inner = |i: usize| i < NODES / 2;
    let tree = |t: usize| {
        let ints = |f: &dyn Fn(usize) -> i64| (0..NODES).map(f).collect::<Vec<i64>>();
        let floats = |f: &dyn Fn(usize) -> f64| (0..NODES).map(f).collect::<Vec<f64>>();
        json!({
            "base_weights": floats(&|i| (i as f64 + 0.5) * 1e-3),
            "default_left": ints(&|i| i64::from(i % 2 == 0)),
            "id": t,
            "left_children": ints(&|i| if inner(i) { 2 * i as i64 + 1 } else { -1 }),
            "loss_changes": floats(&|i| 1.0 / (i as f64 + 1.0)),
            "parents": ints(&|i| if i == 0 { 2_147_483_647 } else { (i as i64 - 1) / 2 }),
            "right_children": ints(&|i| if inner(i) { 2 * i as i64 + 2 } else { -1 }),
            "split_conditions": floats(&|i| 100.0 * ((i * 37 + t) % 101) as f64 / 101.0 + 1e-3),
            "split_indices": ints(&|i| if inner(i) { ((i + t) % 20) as i64 } else { 0 }),
            "split_type": ints(&|_| 0),
            "sum_hessian": floats(&|i| 1e4 / (i as f64 + 1.0).log2().floor().exp2()),
            "tree_param": {"num_deleted": "0", "num_feature": "20", "num_nodes": "511",
                           "size_leaf_vector": "1"}
        })
    };
    let body = json!({
        "model": {"xgboost_json": {"learner": {
            "gradient_booster": {"name": "gbtree", "model": {
                "tree_info": vec![0; trees], "trees": (0..trees).map(tree).collect::<Vec<_>>()}},
            "learner_model_param": {"base_score": "[5E1]", "num_class": "0",
                                    "num_feature": "20", "num_target": "1"},
            "objective": {"name": "reg:squarederror"}}, "version": [3, 2, 0]}},
        "rows": (0..10).map(|r| (0..20).map(|j| ((r * 7 + j * 13) % 100) as f64).collect::<Vec<_>>())
            .collect::<Vec<_>>()
    });
    serde_json::to_vec(&body).expect("json")
}

/// A large model document is read into a compact tree, not a `serde_json::Value` (which took
/// 4.3 times the memory of this 8 MiB body, above the 5·B + 32 MiB limit).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn memory_follows_a_large_model() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_MAX_BODY_BYTES", "33554432")]).await;
    let body = model_body(300);
    assert!(body.len() >= 6 << 20, "{} bytes", body.len());
    within_memory_limit(
        &server,
        "/v1/machining-size/predict",
        &body,
        "300-tree model",
    )
    .await;
    server.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn sigterm_during_work_exits_within_the_deadline() {
    let _serial = SERIAL.lock().await;
    let server = Server::start(&[("MECHCALC_SHUTDOWN_GRACE_MS", "1000")]).await;
    let addr = server.addr;
    let work =
        tokio::spawn(async move { post(addr, "/v1/continuum-workspace", &heavy(60_000)).await });
    // A client holding a half-sent request.
    let half = tokio::spawn(client::slowloris(addr, Duration::from_millis(500), 1000));
    tokio::time::sleep(Duration::from_millis(300)).await;
    let t = Instant::now();
    let status = server.terminate_and_wait(Duration::from_secs(10)).await;
    let took = t.elapsed();
    assert!(
        status.is_some(),
        "the process did not exit within 10 s of SIGTERM"
    );
    assert!(
        took < Duration::from_millis(3000),
        "exit took {took:?} with a 1 s grace period"
    );
    let _ = work.await;
    half.abort();
}

/// Keep the child from outliving a failed test.
impl Drop for Server {
    fn drop(&mut self) {
        if let Some(c) = self.child.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Start the binary on a free loopback port with test-friendly limits plus `env`.
pub fn spawn(port: u16, env: &[(&str, &str)]) -> Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_mechcalc"));
    cmd.env("MECHCALC_BIND", format!("127.0.0.1:{port}"))
        .env("MECHCALC_LOG", "info")
        .env("MECHCALC_COMPUTE_SLOTS", "2")
        .stdout(Stdio::piped())
        .stderr(Stdio::null());
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.spawn().expect("the service binary starts")
}
