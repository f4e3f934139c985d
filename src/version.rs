//! What built this irsig: its version, the git commit of the source and
//! the Embree it was compiled against (recorded by `build.rs`), for
//! `irsig --version` and every JSON output.

use serde::Serialize;

/// irsig's version (Cargo.toml).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The git commit of the source tree, 12 hex digits ("unknown" when built
/// outside a git checkout).
pub const GIT_COMMIT: &str = env!("IRSIG_GIT_COMMIT");
/// Embree's version string from the headers irsig was compiled against.
pub const EMBREE_VERSION: &str = env!("IRSIG_EMBREE_VERSION");

/// `irsig --version`'s text: "0.1.0 (commit 0123456789ab, Embree 3.13.5)".
pub const LONG_VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("IRSIG_GIT_COMMIT"),
    ", Embree ",
    env!("IRSIG_EMBREE_VERSION"),
    ")"
);

/// What built this irsig, as recorded in the JSON outputs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BuildInfo {
    /// The crate version (`CARGO_PKG_VERSION`).
    pub irsig_version: &'static str,
    /// The git commit the build came from (`unknown` outside a checkout).
    pub git_commit: &'static str,
    /// The Embree version the ray tracer was built against.
    pub embree_version: &'static str,
}

/// This build's [`BuildInfo`].
pub fn build_info() -> BuildInfo {
    BuildInfo {
        irsig_version: VERSION,
        git_commit: GIT_COMMIT,
        embree_version: EMBREE_VERSION,
    }
}
