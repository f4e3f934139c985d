//! Numerical stress suite (issue 7, part 4): extreme but legal inputs to the
//! radiometry, atmosphere, tracer and sun/time code. Every output must be
//! finite and within its physical bounds, and nothing may panic; illegal
//! inputs must come back as errors. Deterministic (fixed grids, seeded
//! generators, proptest with a fixed case count) and bounded in time.
//!
//! Thermal extremes live next to the solver's own stability stress in
//! `tests/therm_properties.rs`.

mod geometry;
mod radiometry;
mod render_edges;
mod time;
