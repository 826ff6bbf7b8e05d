//! The mechcalc binary: configuration, logging, bind, serve, graceful shutdown.

use std::time::Duration;

use clap::Parser;
use mechcalc::config::ServiceConfig;
use mechcalc::{AppState, app};
use tracing_subscriber::EnvFilter;

/// jemalloc with a background purging thread (options in `.cargo/config.toml`): the memory a large
/// request used goes back to the system about a second after its answer; glibc's malloc kept
/// ~55 MiB above idle after a 28 MiB training body (benches/RESULTS.md, "Memory per body").
#[cfg(all(feature = "jemalloc", target_os = "linux"))]
#[global_allocator]
static ALLOCATOR: tikv_jemallocator::Jemalloc = tikv_jemallocator::Jemalloc;

#[derive(Debug, Parser)]
#[command(
    name = "mechcalc",
    version,
    about = "Machine-design calculations over HTTP/JSON"
)]
struct Cli {
    #[command(flatten)]
    config: ServiceConfig,
    /// Print the OpenAPI document (YAML) and exit.
    #[arg(long)]
    print_openapi: bool,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// Run one calculation (or an NDJSON batch) without a server: JSON request in (a file or
    /// standard input), JSON (or `--svg`) out; problem details on stderr and exit code 2 for a
    /// refused request. `--shard I/N` computes block I of N of a sweep.
    Run(mechcalc::cli::RunArgs),
    /// Merge the answers of shards 0..N of one sweep (`mechcalc run --shard I/N`) into the
    /// unsharded answer; missing, duplicated or mismatched shards are refused (exit code 2).
    Merge(mechcalc::cli::MergeArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    match &cli.command {
        Some(Command::Run(args)) => return mechcalc::cli::run(args, cli.config),
        Some(Command::Merge(args)) => return mechcalc::cli::merge(args),
        None => {}
    }
    if cli.print_openapi {
        return match mechcalc::http::openapi_yaml() {
            // `mechcalc --print-openapi | head`: a closed pipe ends the output quietly.
            Ok(y) => mechcalc::cli::write_stdout(y.as_bytes()),
            Err(e) => {
                eprintln!("could not render the OpenAPI document: {e}");
                std::process::ExitCode::FAILURE
            }
        };
    }
    match tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    {
        Ok(rt) => rt.block_on(serve(cli)),
        Err(e) => {
            eprintln!("cannot start the runtime: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

async fn serve(cli: Cli) -> std::process::ExitCode {
    let config = cli.config;
    let filter = EnvFilter::try_from_env("MECHCALC_LOG").unwrap_or_else(|_| EnvFilter::new("info"));
    if config.log_format == "json" {
        tracing_subscriber::fmt()
            .json()
            .with_env_filter(filter)
            .init();
    } else {
        let ansi = std::io::IsTerminal::is_terminal(&std::io::stdout());
        tracing_subscriber::fmt()
            .with_env_filter(filter)
            .with_ansi(ansi)
            .init();
    }

    // The one compute pool: every calculation and its parallel parts run on these threads.
    let nice = config.compute_nice;
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(config.effective_compute_threads())
        .thread_name(|i| format!("mechcalc-compute-{i}"))
        .start_handler(move |_| mechcalc::http::pool::lower_thread_priority(nice))
        .build_global()
    {
        tracing::error!(error = %e, "cannot start the compute pool");
        return std::process::ExitCode::FAILURE;
    }
    // Idle and slow connections each hold a descriptor: take the hard limit, size the
    // connection limit from it.
    let nofile = rlimit::increase_nofile_limit(u64::MAX).unwrap_or(1024);
    let limits = mechcalc::http::serve::ConnLimits {
        header_timeout: Duration::from_millis(config.header_timeout_ms.max(1)),
        write_timeout: Duration::from_millis(config.write_timeout_ms.max(1)),
        max_connections: config.effective_max_connections(nofile),
        shutdown_grace: Duration::from_millis(config.shutdown_grace_ms),
    };
    let listener = match tokio::net::TcpListener::bind(config.bind).await {
        Ok(l) => l,
        Err(e) => {
            tracing::error!(bind = %config.bind, error = %e, "cannot bind");
            return std::process::ExitCode::FAILURE;
        }
    };
    tracing::info!(
        bind = %config.bind,
        compute_slots = config.effective_compute_slots(),
        compute_threads = config.effective_compute_threads(),
        threads_per_job = config.effective_threads_per_job(),
        queue_depth = config.queue_depth,
        max_body_bytes = config.max_body_bytes,
        max_response_bytes = config.max_response_bytes,
        max_time_budget_ms = config.max_time_budget_ms,
        max_connections = limits.max_connections,
        header_timeout_ms = config.header_timeout_ms,
        body_timeout_ms = config.body_timeout_ms,
        write_timeout_ms = config.write_timeout_ms,
        shutdown_grace_ms = config.shutdown_grace_ms,
        "mechcalc listening"
    );
    let metrics_bind = config.metrics_bind;
    let state = match AppState::try_new(config) {
        Ok(s) => s,
        Err(e) => {
            tracing::error!(error = %e, "cannot start");
            return std::process::ExitCode::FAILURE;
        }
    };
    mechcalc::http::auth::reload_on_sighup(state.keys.clone());
    if let Some(addr) = metrics_bind {
        match tokio::net::TcpListener::bind(addr).await {
            Ok(l) => {
                tracing::info!(bind = %addr, "metrics listening");
                tokio::spawn(mechcalc::http::serve::serve_metrics(l, state.clone()));
            }
            Err(e) => {
                tracing::error!(bind = %addr, error = %e, "cannot bind the metrics address");
                return std::process::ExitCode::FAILURE;
            }
        }
    }
    let pool = state.pool.clone();
    mechcalc::http::serve::serve(listener, app(state), limits, pool, shutdown_signal()).await;
    tracing::info!("mechcalc stopped");
    std::process::ExitCode::SUCCESS
}

/// Resolves on SIGINT (Ctrl-C) or SIGTERM; in-flight requests then finish before exit.
async fn shutdown_signal() {
    let ctrl_c = async {
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {},
        () = term => {},
    }
    tracing::info!("shutdown signal received");
}
