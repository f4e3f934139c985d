//! The atmosphere module's error type, below the table reader and the
//! module root that both report it.

/// Errors from loading or querying atmosphere tables.
#[derive(Debug, thiserror::Error)]
pub enum AtmosError {
    /// A table file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A table's header is malformed at a line.
    #[error("{file}: header line {line}: {msg}")]
    Format {
        /// The file.
        file: String,
        /// The 1-based header line.
        line: usize,
        /// What is wrong and what was expected.
        msg: String,
    },
    /// A table has less data than its header describes.
    #[error("{file}: truncated: the header describes {expected} bytes of data, the file has {got}")]
    Truncated {
        /// The file.
        file: String,
        /// Bytes of data the header describes.
        expected: usize,
        /// Bytes of data the file has.
        got: usize,
    },
    /// A table holds NaN or infinity.
    #[error(
        "{file}: quantity {quantity}: non-finite value (NaN or inf) in spectrum {spectrum} at {wavenumber_cm1} cm-1"
    )]
    NonFinite {
        /// The file.
        file: String,
        /// The quantity (e.g. `tau_path`, `l_ue`).
        quantity: String,
        /// The spectrum's index in the table.
        spectrum: usize,
        /// Where in the spectrum, cm⁻¹.
        wavenumber_cm1: f64,
    },
    /// A query outside a table's axis (tables are not extrapolated).
    #[error(
        "atmosphere {atmosphere}: {quantity}: {axis} = {value} is outside the table ({min} .. {max}); no extrapolation"
    )]
    OutOfRange {
        /// The atmosphere's name.
        atmosphere: String,
        /// The quantity queried.
        quantity: String,
        /// The axis (e.g. `altitude_km`, `view_zenith_deg`).
        axis: String,
        /// The value asked for.
        value: f64,
        /// The axis's first value.
        min: f64,
        /// The axis's last value.
        max: f64,
    },
    /// No shipped or given atmosphere of that name.
    #[error("unknown atmosphere '{name}' (available: {available})")]
    Unknown {
        /// The name asked for.
        name: String,
        /// The names there are, comma-separated.
        available: String,
    },
}
