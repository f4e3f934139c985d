//! In-process fuzzing of every parser (issue 17, item 3): mutated seed
//! inputs (the sample files) through each entry point. Nothing may panic or
//! abort; every refusal must be an error that names its file; every accepted
//! input must hold only finite, in-range values (crate::bounds), and
//! accepted scenes render finite planes.
//!
//! The mutations are proptest strategies run by a `TestRunner` with a fixed
//! seed, so CI is reproducible. CI runs `IRSIG_FUZZ_CASES` cases per target
//! (default 10 000); `scripts/fuzz.sh` runs a longer campaign (see
//! docs/reliability.md for the inputs run and the bugs found). Each target
//! prints `fuzz <target>: <cases> cases, <accepted> accepted, <refused>
//! refused`.
//!
//! `cargo fuzz` (libFuzzer) needs nightly Rust, which a fresh Debian CI does
//! not have; these proptest suites cover the same entry points there.

mod args;
mod mutate;
mod targets;
