//! THERM-style transient 1-D heat flow per (material, orientation, sun/shadow
//! history), driven by weather and the sun ephemeris (docs/models.md, "Thermal model").
//!
//! Data flow: [`crate::weather::WeatherHistory`] + [`crate::sun`] →
//! [`forcing::Forcing`] (one per thermal time step, everything the surface
//! energy balance needs, in SI units) → the slab solver → surface temperature.

pub mod aero;
pub mod balance;
pub mod cache;
pub mod conditions;
pub mod forcing;
pub mod forcing_csv;
pub mod series;
pub mod slab;
pub mod surface;
