//! Service configuration: command-line flags, each with an environment-variable fallback.

use std::net::SocketAddr;
use std::time::Duration;

use clap::Parser;

// A flag whose text names a unit in brackets carries an explicit `help`: rustdoc needs the
// brackets escaped in the doc comment, and clap would print the escapes.
/// mechcalc HTTP service configuration. Every flag can also be set through its environment
/// variable; flags win.
#[derive(Debug, Clone, Parser)]
#[command(
    name = "mechcalc",
    version,
    about = "Machine-design calculations over HTTP/JSON",
    long_about = "Machine-design calculations over HTTP/JSON. Every flag can also be set through \
                  its environment variable (shown with each flag); a flag wins over its variable."
)]
pub struct ServiceConfig {
    /// Address and port to listen on.
    #[arg(long = "bind", env = "MECHCALC_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,

    /// Maximum number of compute jobs running at once (0 = number of CPU cores).
    #[arg(
        long = "compute-slots",
        env = "MECHCALC_COMPUTE_SLOTS",
        default_value_t = 0
    )]
    pub compute_slots: usize,

    /// Threads of the compute pool that runs every calculation (0 = number of CPU cores). All
    /// jobs and their parallel parts share these threads, so they bound the service's CPU.
    #[arg(
        long = "compute-threads",
        env = "MECHCALC_COMPUTE_THREADS",
        default_value_t = 0
    )]
    pub compute_threads: usize,

    /// Threads one job may use for its parallel parts (sweeps, multi-starts, folds; 0 = every
    /// compute thread). Results do not depend on it.
    #[arg(
        long = "threads-per-job",
        env = "MECHCALC_THREADS_PER_JOB",
        default_value_t = 0
    )]
    pub threads_per_job: usize,

    /// Maximum number of compute jobs waiting for a slot before requests get 503.
    #[arg(
        long = "queue-depth",
        env = "MECHCALC_QUEUE_DEPTH",
        default_value_t = 16
    )]
    pub queue_depth: usize,

    /// Maximum request body size in bytes.
    #[arg(long = "max-body-bytes", env = "MECHCALC_MAX_BODY_BYTES", default_value_t = 16 * 1024 * 1024)]
    pub max_body_bytes: usize,

    /// Upper bound on any request's time budget, in milliseconds; requests may ask for less.
    #[arg(
        long = "max-time-budget-ms",
        env = "MECHCALC_MAX_TIME_BUDGET_MS",
        default_value_t = 600_000
    )]
    pub max_time_budget_ms: u64,

    /// Time a client has to send a complete request head, and the longest an idle keep-alive
    /// connection is kept open \[ms\].
    #[arg(
        help = "Time a client has to send a complete request head, and the longest an idle keep-alive connection is kept open [ms]",
        long = "header-timeout-ms",
        env = "MECHCALC_HEADER_TIMEOUT_MS",
        default_value_t = 10_000
    )]
    pub header_timeout_ms: u64,

    /// Time a client has to send the whole request body \[ms\] (408 after it).
    #[arg(
        help = "Time a client has to send the whole request body [ms] (408 after it)",
        long = "body-timeout-ms",
        env = "MECHCALC_BODY_TIMEOUT_MS",
        default_value_t = 30_000
    )]
    pub body_timeout_ms: u64,

    /// Longest a single write of a response may stall on a client that does not read \[ms\]; the
    /// connection is closed after it.
    #[arg(
        help = "Longest a single write of a response may stall on a client that does not read [ms]; the connection is closed after it",
        long = "write-timeout-ms",
        env = "MECHCALC_WRITE_TIMEOUT_MS",
        default_value_t = 30_000
    )]
    pub write_timeout_ms: u64,

    /// Open connections at most (0 = from the process's file-descriptor limit); beyond it a new
    /// connection gets an immediate 503 and is closed.
    #[arg(
        long = "max-connections",
        env = "MECHCALC_MAX_CONNECTIONS",
        default_value_t = 0
    )]
    pub max_connections: usize,

    /// After SIGTERM/SIGINT, time in-flight requests get to finish \[ms\]; then running jobs are
    /// cancelled and the process exits.
    #[arg(
        help = "After SIGTERM/SIGINT, time in-flight requests get to finish [ms]; then running jobs are cancelled and the process exits",
        long = "shutdown-grace-ms",
        env = "MECHCALC_SHUTDOWN_GRACE_MS",
        default_value_t = 20_000
    )]
    pub shutdown_grace_ms: u64,

    /// Largest response body \[bytes\]; a request whose answer would be larger is refused with a
    /// 422 naming the option to change (before computing where the size is known in advance).
    #[arg(
        help = "Largest response body [bytes]; a request whose answer would be larger is refused with a 422 naming the option to change (before computing where the size is known in advance)",
        long = "max-response-bytes",
        env = "MECHCALC_MAX_RESPONSE_BYTES",
        default_value_t = 64 * 1024 * 1024
    )]
    pub max_response_bytes: usize,

    /// Browser origins allowed to call the API (comma-separated, `*` for any); CORS is off when
    /// empty.
    #[arg(
        long = "cors-origins",
        env = "MECHCALC_CORS_ORIGINS",
        value_delimiter = ',',
        default_value = ""
    )]
    pub cors_origins: Vec<String>,

    /// File of API keys, one a line: `<key id> <sha256 hex of the token> [<requests per
    /// minute>]`, `#` starts a comment. With keys, every route but `/healthz`, the page and the
    /// docs needs `Authorization: Bearer <token>`; the file is read again on SIGHUP. Without it
    /// the service is open to whoever reaches the port.
    #[arg(
        help = "File of API keys, one a line: `<key id> <sha256 hex of the token> [<requests per minute>]`, `#` starts a comment. With keys, every route but /healthz, the page and the docs needs `Authorization: Bearer <token>`; the file is read again on SIGHUP. Without it the service is open to whoever reaches the port",
        long = "api-keys-file",
        env = "MECHCALC_API_KEYS_FILE"
    )]
    pub api_keys_file: Option<std::path::PathBuf>,

    /// Heavy jobs one client (API key, or remote address without keys) may have waiting at once
    /// (0 = half of `--queue-depth`, at least 1); beyond it that client gets 429. Waiting jobs
    /// start in round-robin order over the clients.
    #[arg(
        long = "client-queue-depth",
        env = "MECHCALC_CLIENT_QUEUE_DEPTH",
        default_value_t = 0
    )]
    pub client_queue_depth: usize,

    /// Extra address serving only `/metrics` and `/healthz`, never behind API keys (for a
    /// scraper that a network policy admits to this port alone); off when unset.
    #[arg(long = "metrics-bind", env = "MECHCALC_METRICS_BIND")]
    pub metrics_bind: Option<SocketAddr>,

    /// Nice value of the compute threads (0 to 19; 0 = the process's own priority): sweeps yield
    /// the CPU to the threads that serve connections and cheap requests.
    #[arg(
        long = "compute-nice",
        env = "MECHCALC_COMPUTE_NICE",
        default_value_t = 10,
        value_parser = clap::value_parser!(i32).range(0..=19)
    )]
    pub compute_nice: i32,

    /// Log format: `text` or `json`.
    #[arg(
        long = "log-format",
        env = "MECHCALC_LOG_FORMAT",
        default_value = "text"
    )]
    pub log_format: String,
}

impl Default for ServiceConfig {
    fn default() -> Self {
        Self {
            bind: SocketAddr::from(([127, 0, 0, 1], 8080)),
            compute_slots: 0,
            compute_threads: 0,
            threads_per_job: 0,
            queue_depth: 16,
            max_body_bytes: 16 * 1024 * 1024,
            max_time_budget_ms: 600_000,
            header_timeout_ms: 10_000,
            body_timeout_ms: 30_000,
            write_timeout_ms: 30_000,
            max_connections: 0,
            shutdown_grace_ms: 20_000,
            max_response_bytes: 64 * 1024 * 1024,
            cors_origins: Vec::new(),
            api_keys_file: None,
            client_queue_depth: 0,
            metrics_bind: None,
            compute_nice: 10,
            log_format: "text".to_owned(),
        }
    }
}

impl ServiceConfig {
    /// Effective number of concurrent compute jobs (at most the compute threads: a job beyond
    /// them could only wait inside the pool).
    #[must_use]
    pub fn effective_compute_slots(&self) -> usize {
        let slots = if self.compute_slots > 0 {
            self.compute_slots
        } else {
            cores()
        };
        slots.min(self.effective_compute_threads())
    }

    /// Effective size of the compute pool.
    #[must_use]
    pub fn effective_compute_threads(&self) -> usize {
        if self.compute_threads > 0 {
            self.compute_threads
        } else {
            cores()
        }
    }

    /// Effective threads per job.
    #[must_use]
    pub fn effective_threads_per_job(&self) -> usize {
        let all = self.effective_compute_threads();
        if self.threads_per_job > 0 {
            self.threads_per_job.min(all)
        } else {
            all
        }
    }

    /// Effective connection limit: the configured one, or what the file-descriptor limit allows
    /// (leaving room for the listener, logs and the process itself).
    #[must_use]
    pub fn effective_max_connections(&self, nofile: u64) -> usize {
        let from_fds = usize::try_from(nofile.saturating_sub(64))
            .unwrap_or(usize::MAX)
            .max(16);
        if self.max_connections > 0 {
            self.max_connections.min(from_fds)
        } else {
            from_fds.min(65_536)
        }
    }

    /// Effective per-client queue depth: the configured one, or half the queue (at least 1).
    #[must_use]
    pub fn effective_client_queue_depth(&self) -> usize {
        if self.client_queue_depth > 0 {
            self.client_queue_depth
        } else {
            (self.queue_depth / 2).max(1)
        }
    }

    /// The server-wide cap on a request's time budget.
    #[must_use]
    pub fn max_time_budget(&self) -> Duration {
        Duration::from_millis(self.max_time_budget_ms.max(1))
    }
}

/// CPU cores of this machine (2 when unknown).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(2, std::num::NonZeroUsize::get)
}
