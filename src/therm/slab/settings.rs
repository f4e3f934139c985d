//! The solver's numerical settings, its start rule and its errors.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::therm::balance::Convection;

/// The initial profile of a march started by [`SlabModel::solve`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpinUpStart {
    /// Steady state under the time-mean surface drive of the first 24 h of
    /// the forcing series (all of it when shorter), with the sun/shadow flag
    /// of each sample (see the module docs).
    #[default]
    MeanForcing,
    /// Steady state under the first forcing sample and its sun flag (the
    /// paper's THERM practice; needs a longer spin-up for deep slabs).
    FirstSample,
}

/// Numerical settings of the slab solver. The defaults were chosen on the
/// accuracy tests (`tests/therm_reference.rs`: < 0.1 K against a 500-node
/// stiff method-of-lines reference over 48 h of TMY3 weather).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThermSettings {
    /// Largest internal time step, s.
    pub step_s: f64,
    /// Local error tolerance per step, K; `None` = fixed steps of `step_s`.
    pub tol_k: Option<f64>,
    /// With `Some(τ)`, s: the tolerance of a step that ends `A` seconds
    /// before the last forcing sample is `tol_k·√(1 + A/τ)`
    /// ([`Self::tol_at`]); `None`: `tol_k` everywhere.
    pub tol_age_s: Option<f64>,
    /// Smallest adaptive step, s.
    pub min_step_s: f64,
    /// Hours of forcing before the image time that forcing builders should
    /// provide (the solver marches whatever forcing it is given).
    pub spin_up_h: f64,
    /// The initial profile of the march.
    pub spin_up_start: SpinUpStart,
    /// Minimum number of nodes through the slab.
    pub nodes: usize,
    /// Upper bound on the number of nodes.
    pub max_nodes: usize,
    /// Time scale that the first (surface) cell resolves: `d_0 = sqrt(κ·t)`, s.
    pub surface_time_s: f64,
    /// Largest ratio between neighbouring cell sizes.
    pub max_growth: f64,
    /// The convection model.
    pub convection: Convection,
    /// Sun/shadow between history samples: a linear ramp (true, the
    /// default) or the nearest sample's flag (THERM's step rule).
    pub shadow_ramp: bool,
}

impl Default for ThermSettings {
    fn default() -> Self {
        ThermSettings {
            step_s: 900.0,
            tol_k: Some(0.0005),
            tol_age_s: None,
            min_step_s: 0.05,
            spin_up_h: 24.0,
            spin_up_start: SpinUpStart::MeanForcing,
            nodes: 8,
            max_nodes: 200,
            surface_time_s: 30.0,
            max_growth: 1.06,
            convection: Convection::default(),
            shadow_ramp: true,
        }
    }
}

impl ThermSettings {
    /// The local error tolerance of a step that ends `age_s` seconds before
    /// the last forcing sample, K (`None`: fixed steps):
    /// `tol_k·√(1 + age/τ)` with `τ` = [`Self::tol_age_s`].
    ///
    /// Why: a march that is read only at its end (a render's image time)
    /// needs its early steps less accurate than its last ones. An error δ
    /// left in the surface cell at age A has spread into the slab by the
    /// end: on a semi-infinite solid the surface keeps about
    /// `δ·d₀/√(πκA)` of it (d₀ the surface cell, κ the diffusivity; Carslaw
    /// & Jaeger 1959 §2.2, an instantaneous plane source), i.e. it falls
    /// off as `1/√A`, and faster once the surface exchange takes over — so
    /// a tolerance growing as `√A` keeps each step's share of the end
    /// error about even. The same argument sets the render's history keys
    /// (`render::key_history`). τ was chosen on the accuracy curves
    /// (BENCHMARKS.md, "The default render").
    pub fn tol_at(&self, age_s: f64) -> Option<f64> {
        let tol = self.tol_k?;
        Some(match self.tol_age_s {
            Some(tau) if tau > 0.0 => tol * (1.0 + age_s.max(0.0) / tau).sqrt(),
            _ => tol,
        })
    }
}

/// Errors of the thermal solver (bad inputs; a non-converging step).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ThermError {
    #[error("bad material: {0}")]
    /// A material the solver cannot use (what is wrong).
    BadMaterial(String),
    #[error("bad thermal input: {0}")]
    /// Forcing or history the solver cannot use (what is wrong).
    BadInput(String),
    #[error("thermal solver failed at t = {t_s} s: {why}")]
    /// A step that would not converge.
    NoConvergence {
        /// Time of the step, s from the start of the forcing.
        t_s: f64,
        /// Why it failed.
        why: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The age rule: `tol_k` at the end, √2·tol_k one τ before it, 3·tol_k
    /// eight τ before it; uniform without τ; none with fixed steps.
    #[test]
    fn tolerance_grows_with_the_square_root_of_age() {
        let s = ThermSettings {
            tol_k: Some(0.1),
            tol_age_s: Some(900.0),
            ..ThermSettings::default()
        };
        let at = |a: f64| s.tol_at(a).unwrap();
        assert_eq!(at(0.0), 0.1);
        assert_eq!(at(-5.0), 0.1);
        assert!((at(900.0) - 0.1 * 2f64.sqrt()).abs() < 1e-15);
        assert!((at(8.0 * 900.0) - 0.3).abs() < 1e-15);
        let uniform = ThermSettings {
            tol_age_s: None,
            ..s
        };
        assert_eq!(uniform.tol_at(1e6), Some(0.1));
        let fixed = ThermSettings { tol_k: None, ..s };
        assert_eq!(fixed.tol_at(0.0), None);
    }
}
