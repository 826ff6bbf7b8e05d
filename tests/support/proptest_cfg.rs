//! Case counts: one proptest configuration for every property file (`cases` unless
//! `PROPTEST_CASES` says otherwise; CI fixes `PROPTEST_RNG_SEED`, so a run is reproducible) and
//! the size of the seeded stress sweeps (`STRESS_CASES`).

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

/// Cases of a seeded random stress sweep: `default`, or `STRESS_CASES` when it is set.
#[must_use]
pub fn stress_cases(default: usize) -> usize {
    std::env::var("STRESS_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}
