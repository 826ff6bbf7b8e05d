//! The process's metrics recorder (Prometheus exposition through `metrics-exporter-prometheus`),
//! installed once; every `metrics::counter!`/`gauge!`/`histogram!` in the service lands here.

use std::sync::OnceLock;

use metrics_exporter_prometheus::{Matcher, PrometheusBuilder, PrometheusHandle};

/// Latency buckets [s]: from 100 µs (closed-form answers) to 10 min (the largest budgets).
const BUCKETS_S: &[f64] = &[
    1e-4, 2.5e-4, 5e-4, 1e-3, 2.5e-3, 5e-3, 1e-2, 2.5e-2, 5e-2, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0,
    10.0, 30.0, 60.0, 300.0, 600.0,
];

fn handle() -> &'static PrometheusHandle {
    static HANDLE: OnceLock<PrometheusHandle> = OnceLock::new();
    HANDLE.get_or_init(|| {
        let builder = || {
            PrometheusBuilder::new()
                .set_buckets_for_metric(Matcher::Suffix("_seconds".to_owned()), BUCKETS_S)
                .unwrap_or_else(|_| PrometheusBuilder::new())
        };
        // Installing fails only when another recorder is already global (not in this binary);
        // then serve an empty, private registry rather than fail the endpoint.
        builder()
            .install_recorder()
            .unwrap_or_else(|_| builder().build_recorder().handle())
    })
}

/// How often histogram samples are folded into their buckets.
const UPKEEP: std::time::Duration = std::time::Duration::from_secs(5);

/// Install the recorder (idempotent); call before serving so early requests are counted. Starts
/// the recorder's upkeep: a recorder installed with `install_recorder` keeps every histogram
/// sample until the next render, so without a scrape memory grows with each request (the soak
/// showed +11 MiB in 15 min); the upkeep folds them into buckets every few seconds.
pub fn install() {
    static UPKEEP_STARTED: OnceLock<()> = OnceLock::new();
    let h = handle();
    UPKEEP_STARTED.get_or_init(|| {
        let h = h.clone();
        let _ = std::thread::Builder::new()
            .name("mechcalc-metrics-upkeep".to_owned())
            .spawn(move || {
                loop {
                    std::thread::sleep(UPKEEP);
                    h.run_upkeep();
                }
            });
    });
}

/// The current metrics in the Prometheus text format.
#[must_use]
pub fn render() -> String {
    handle().render()
}
