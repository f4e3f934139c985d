//! Ray tracing.
