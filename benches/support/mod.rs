//! Timing helpers shared by every benchmark's accuracy-vs-cost tables (criterion measures the
//! headline numbers; these tables need a median and a worst time per knob value next to an error).
//! Each bench includes this file with `#[path = "support/mod.rs"] mod support;`.
#![allow(dead_code, reason = "shared by several bench crates; each uses a part")]

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Median and worst wall time of repeated runs, and the mean on-CPU time of the calling thread
/// per run when the kernel exposes it (the machines are shared: wall time includes waiting for a
/// core, CPU time does not).
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// Median wall time of one run [s].
    pub median_s: f64,
    /// Worst wall time of one run [s].
    pub worst_s: f64,
    /// Mean on-CPU time of the calling thread per run [s], if available.
    pub cpu_s: Option<f64>,
    /// Runs timed.
    pub runs: usize,
}

impl Timing {
    /// Median in milliseconds.
    #[must_use]
    pub fn median_ms(&self) -> f64 {
        self.median_s * 1e3
    }
    /// Worst in milliseconds.
    #[must_use]
    pub fn worst_ms(&self) -> f64 {
        self.worst_s * 1e3
    }
    /// Median in microseconds.
    #[must_use]
    pub fn median_us(&self) -> f64 {
        self.median_s * 1e6
    }
    /// Worst in microseconds.
    #[must_use]
    pub fn worst_us(&self) -> f64 {
        self.worst_s * 1e6
    }
}

/// On-CPU time of the calling thread [ns], if the kernel exposes it.
#[must_use]
pub fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Process CPU time (user + system, all threads) [ms], from /proc (10 ms resolution).
#[must_use]
pub fn process_cpu_ms() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let Some(rest) = stat.rsplit(')').next() else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        f.get(i)
            .and_then(|s| s.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (ticks(11) + ticks(12)) * 10.0
}

/// Time `f` `runs` times after one warm-up run; returns the timing and the last result.
pub fn time_runs<T>(runs: usize, mut f: impl FnMut() -> T) -> (Timing, T) {
    let mut last = black_box(f());
    let runs = runs.max(1);
    let mut v = Vec::with_capacity(runs);
    let cpu0 = thread_cpu_ns();
    for _ in 0..runs {
        let t = Instant::now();
        last = black_box(f());
        v.push(t.elapsed().as_secs_f64());
    }
    let cpu = cpu0
        .zip(thread_cpu_ns())
        .map(|(a, b)| (b.saturating_sub(a)) as f64 / 1e9 / runs as f64);
    v.sort_by(f64::total_cmp);
    (
        Timing {
            median_s: v[v.len() / 2],
            worst_s: v[v.len() - 1],
            cpu_s: cpu,
            runs,
        },
        last,
    )
}

/// Time `f` for about `target` of wall time (at least 3 and at most `max_runs` runs, sized from
/// the warm-up run); returns the timing and the last result.
pub fn time_for<T>(target: Duration, max_runs: usize, mut f: impl FnMut() -> T) -> (Timing, T) {
    let t0 = Instant::now();
    let _ = black_box(f());
    let first = t0.elapsed().as_secs_f64().max(1e-9);
    let runs = ((target.as_secs_f64() / first) as usize).clamp(3, max_runs.max(3));
    time_runs(runs, f)
}

/// Median and worst of `reps` timings of `f` after one warm-up run, in µs.
pub fn time_us(reps: usize, f: impl FnMut()) -> (f64, f64) {
    let (t, ()) = time_runs(reps, f);
    (t.median_us(), t.worst_us())
}

/// The name filters of a `cargo bench` run (its arguments that do not start with `-`), or `None`
/// when the minutes-long accuracy-vs-cost sweeps are not to run: when the benches run as tests
/// (no `--bench`), or when there are filters and none contains `word` (`cargo bench --bench
/// <name> sweep` runs the sweeps alone).
#[must_use]
pub fn sweep_filters(word: &str) -> Option<Vec<String>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if !args.iter().any(|a| a == "--bench") {
        return None;
    }
    let filters: Vec<String> = args.into_iter().filter(|a| !a.starts_with('-')).collect();
    (filters.is_empty() || filters.iter().any(|f| f.contains(word))).then_some(filters)
}

/// Every `api/` example as (file, endpoint, body bytes), in the order of `api/examples.json`.
#[must_use]
pub fn api_examples() -> Vec<(String, String, Vec<u8>)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api");
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("examples.json")).expect("api/examples.json"),
    )
    .expect("JSON");
    index["examples"]
        .as_array()
        .expect("examples")
        .iter()
        .map(|e| {
            let file = e["file"].as_str().expect("file").to_owned();
            let endpoint = e["endpoint"].as_str().expect("endpoint").to_owned();
            let body = std::fs::read(dir.join(&file)).expect("example");
            (file, endpoint, body)
        })
        .collect()
}
