//! One proptest configuration for every property file: `cases` unless `PROPTEST_CASES` says
//! otherwise (CI fixes `PROPTEST_RNG_SEED`, so a run is reproducible).

use proptest::test_runner::Config;

/// A configuration running `default` cases, or `PROPTEST_CASES` when it is set.
#[must_use]
pub fn cases(default: u32) -> Config {
    Config {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(default),
        ..Config::default()
    }
}
