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
#[allow(missing_docs)] // issue 31 item 6: its public items are not all documented yet
pub mod cli;
pub mod files;
pub mod output;
pub mod radiometry;
#[allow(missing_docs)] // issue 31 item 6: its public items are not all documented yet
pub mod render;
pub mod scene;
pub mod sensor;
pub mod sun;
#[allow(missing_docs)] // issue 31 item 6: its public items are not all documented yet
pub mod therm;
#[allow(missing_docs)] // issue 31 item 6: its public items are not all documented yet
pub mod trace;
pub mod units;
pub mod version;
#[allow(missing_docs)] // issue 31 item 6: its public items are not all documented yet
pub mod weather;
