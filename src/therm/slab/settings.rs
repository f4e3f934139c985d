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

/// Errors of the thermal solver (bad inputs; a non-converging step).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ThermError {
    #[error("bad material: {0}")]
    BadMaterial(String),
    #[error("bad thermal input: {0}")]
    BadInput(String),
    #[error("thermal solver failed at t = {t_s} s: {why}")]
    NoConvergence { t_s: f64, why: String },
}
