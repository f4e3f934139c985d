//! Physical constants and unit conversions shared by every layer (the
//! ground floor: each is defined here once and imported where it is used).

/// Stefan–Boltzmann constant σ, W m⁻² K⁻⁴ (CODATA 2018, exact in SI since
/// 2019: σ = 2π⁵k⁴/(15h³c²)).
pub const STEFAN_BOLTZMANN_W_M2K4: f64 = 5.670_374_419e-8;

/// 0 °C in kelvin.
pub const ZERO_C_K: f64 = 273.15;
