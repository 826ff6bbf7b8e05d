//! The general 7-segment modified-trapezoidal law (spec §3.2).
