//! Shared application state handed to every handler.

use std::sync::Arc;

use crate::config::ServiceConfig;

use super::pool::ComputePool;

/// Configuration plus the bounded compute pool.
#[derive(Clone)]
pub struct AppState {
    /// Service configuration (read-only).
    pub config: Arc<ServiceConfig>,
    /// The semaphore-bounded blocking pool every calculation runs on.
    pub pool: ComputePool,
}

impl AppState {
    /// Build the state from a configuration.
    #[must_use]
    pub fn new(config: ServiceConfig) -> Self {
        super::telemetry::install();
        let pool = ComputePool::new(
            config.effective_compute_slots(),
            config.queue_depth,
            config.max_time_budget(),
        )
        .with_threads_per_job(config.effective_threads_per_job());
        Self {
            config: Arc::new(config),
            pool,
        }
    }
}
