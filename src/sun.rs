//! Sun ephemeris (NREL SPA).
