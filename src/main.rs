//! The mechcalc binary: configuration, logging, bind, serve, graceful shutdown.

use clap::Parser;
use mechcalc::config::ServiceConfig;
use mechcalc::{AppState, app};
use tracing_subscriber::EnvFilter;

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
}

#[tokio::main]
async fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    if cli.print_openapi {
        return match mechcalc::http::openapi().to_yaml() {
            Ok(y) => {
                print!("{y}");
                std::process::ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("could not render the OpenAPI document: {e}");
                std::process::ExitCode::FAILURE
            }
        };
    }
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
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(config.effective_compute_threads())
        .thread_name(|i| format!("mechcalc-compute-{i}"))
        .build_global()
    {
        tracing::error!(error = %e, "cannot start the compute pool");
        return std::process::ExitCode::FAILURE;
    }
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
        max_time_budget_ms = config.max_time_budget_ms,
        "mechcalc listening"
    );
    let app = app(AppState::new(config));
    if let Err(e) = axum::serve(listener, app)
        .with_graceful_shutdown(shutdown_signal())
        .await
    {
        tracing::error!(error = %e, "server error");
        return std::process::ExitCode::FAILURE;
    }
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
    tracing::info!("shutdown signal received; finishing in-flight requests");
}
