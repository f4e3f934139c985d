#![warn(missing_docs)]
//! irsig — a physics-based thermal-infrared synthetic image generator.
//!
//! The module tree mirrors the submodels of the DIRSIG model (Schott,
//! Raqueño, Salvaggio, Opt. Eng. 31(7), 1992): scene geometry, the ray
//! tracer, the sun ephemeris, the thermal model, the atmosphere, the
//! radiometry, the sensor, the render loop and the outputs.

pub mod atmos;
pub mod batch;
pub mod bench;
pub mod bounds;
pub mod cli;
pub mod files;
pub mod output;
pub mod radiometry;
pub mod render;
pub mod scene;
pub mod sensor;
pub mod sun;
pub mod therm;
pub mod trace;
pub mod units;
pub mod version;
pub mod weather;
