//! Shared application state handed to every handler.

use std::sync::Arc;

use crate::config::ServiceConfig;

use super::auth::{KeyRing, KeysFileError};
use super::pool::ComputePool;

/// Configuration, the bounded compute pool and the API keys.
#[derive(Clone)]
pub struct AppState {
    /// Service configuration (read-only).
    pub config: Arc<ServiceConfig>,
    /// The semaphore-bounded blocking pool every calculation runs on.
    pub pool: ComputePool,
    /// The API keys (`--api-keys-file`); `None`: every request passes.
    pub keys: Option<Arc<KeyRing>>,
}

impl AppState {
    /// Build the state from a configuration. A keys file that cannot be read leaves the service
    /// closed (every request but the public ones is refused with 401) and is logged; use
    /// [`AppState::try_new`] to fail instead.
    #[must_use]
    pub fn new(config: ServiceConfig) -> Self {
        match Self::try_new(config.clone()) {
            Ok(s) => s,
            Err(e) => {
                tracing::error!(error = %e, "API keys not loaded: every request is refused");
                let path = config.api_keys_file.clone().unwrap_or_default();
                let mut s = Self::build(config, None);
                s.keys = Some(Arc::new(KeyRing::refusing(&path)));
                s
            }
        }
    }

    /// Build the state, reading the API keys file if one is configured. Warns when the service
    /// binds a non-loopback address without keys.
    ///
    /// # Errors
    /// The keys file cannot be read or has a bad line.
    pub fn try_new(config: ServiceConfig) -> Result<Self, KeysFileError> {
        let keys = match &config.api_keys_file {
            Some(path) => {
                let ring = KeyRing::load(path)?;
                tracing::info!(keys = ring.ids().len(), file = %path.display(), "API keys loaded");
                Some(Arc::new(ring))
            }
            None => None,
        };
        if keys.is_none() && !config.bind.ip().is_loopback() {
            tracing::warn!(bind = %config.bind,
                "no API keys (--api-keys-file) on a non-loopback address: anyone who reaches the port can start calculations");
        }
        Ok(Self::build(config, keys))
    }

    fn build(config: ServiceConfig, keys: Option<Arc<KeyRing>>) -> Self {
        super::telemetry::install();
        let pool = ComputePool::new(
            config.effective_compute_slots(),
            config.queue_depth,
            config.max_time_budget(),
        )
        .with_threads_per_job(config.effective_threads_per_job())
        .with_client_queue_depth(config.effective_client_queue_depth());
        Self {
            config: Arc::new(config),
            pool,
            keys,
        }
    }
}
