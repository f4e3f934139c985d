//! Radiometry submodel (docs/models.md, "Radiometry"): Planck's law and its inverse, spectral
//! grids and sensor responses with band integration, angular spectral
//! emissivity (tabulated and Fresnel), and the seed's equations 1-4 as pure
//! functions returning every term.

// Negated float comparisons (`!(x > 0.0)`) are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod band_coeffs;
pub mod emissivity;
pub mod equations;
pub mod planck;
pub mod spectral;

pub use emissivity::{Emissivity, EmissivityTable, fresnel_emissivity, fresnel_reflectance};
pub use equations::{
    Background, PathRadiance, RadianceTerms, SkyRadiance, SunIllumination, case1_diffuse,
    case2_specular_sky, case3_specular_background, case4_sky, integrate_terms,
};
pub use planck::{
    brightness_temp_k, planck_band_integral_w_m2_sr, planck_radiance_w_m2_sr_cm1,
    planck_radiance_w_m2_sr_um,
};
pub use spectral::{Band, SpectralGrid, SpectralResponse};

/// Errors from radiometry inputs (response files, grids, emissivity tables).
#[derive(Debug, thiserror::Error)]
pub enum RadiometryError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A CSV file (response, emissivity table) is malformed at a line.
    #[error("{file}: line {line}: {msg}")]
    Csv {
        /// The file.
        file: String,
        /// The 1-based line (0: the file as a whole).
        line: usize,
        /// What is wrong and what was expected.
        msg: String,
    },
    /// A spectral grid that cannot be built (empty, not ascending).
    #[error("spectral grid: {0}")]
    Grid(String),
    /// An emissivity table or value that is not valid.
    #[error("emissivity: {0}")]
    Emissivity(String),
}
