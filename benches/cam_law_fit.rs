//! Benchmarks of the cam-law fit (placeholder).
fn main() {}
