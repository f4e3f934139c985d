//! The THERM-style transient 1-D slab solver (docs/models.md, "Thermal model").
//!
//! **Model.** A slab of thickness `L` with constant density ρ, specific heat
//! c and conductivity k: `ρc ∂T/∂t = ∂/∂z(k ∂T/∂z)`, no lateral conduction.
//! The exposed face (z = 0) carries the surface energy balance of
//! [`super::balance`]; the back face (z = L) is insulated, exposed to
//! ambient air, or tied to a deep-ground temperature ([`BackBoundary`]).
//!
//! **Space.** Node-centred finite volumes: nodes at `z_0 = 0 < z_1 < … <
//! z_{N-1} = L`, half cells at both faces (so the surface node *is* the
//! surface temperature), conductance `k/(z_{i+1} − z_i)` between nodes. The
//! mesh is graded geometrically from the surface: first cell
//! `d_0 = sqrt(κ·t_res)` (κ = k/(ρc), `t_res` = [`ThermSettings::surface_time_s`])
//! growing by at most [`ThermSettings::max_growth`] per cell, at least
//! [`ThermSettings::nodes`] nodes; a slab thinner than that is meshed uniformly.
//!
//! **Time.** Backward Euler with the full nonlinear surface balance solved
//! by Newton's method each step (the σT⁴ term is linearised at the current
//! iterate and iterated to |δT| < 1e-9 K); the linear interior rows are
//! eliminated once per step, so Newton iterates on the surface temperature
//! alone (and the back face's, when it is exposed to air). Backward Euler applied to this
//! M-matrix system obeys the discrete maximum principle at any step size:
//! the solution stays within the bounds of the forcing and never
//! oscillates — it is the only (rational) scheme class that guarantees that
//! unconditionally (Bolley & Crouzeix 1978: unconditionally positive
//! schemes are at most first order). Accuracy comes from adaptive
//! steps instead: the local error `h²/2·|T''|` is estimated from successive
//! increments and kept below [`ThermSettings::tol_k`]; steps never exceed
//! [`ThermSettings::step_s`] and never straddle a breakpoint (a forcing
//! sample time, where the linearly interpolated forcing has a kink). With
//! `tol_k = None` the step is fixed at `step_s` (cut at breakpoints).
//! Newton starts each step from the linear extrapolation of the last
//! accepted step (same root, about 10 % fewer iterations).
//!
//! **Forcing between samples.** Each scalar field of
//! [`Forcing`] is interpolated linearly in time; the sun vector is
//! interpolated linearly and renormalised. Before the first / after the last
//! sample the end values are held. A backward-Euler step from `t` to `t'`
//! evaluates the forcing at `t'` and takes as its sunlit fraction the
//! history's exact mean over `[t, t']` ([`SunHistory::mean_fraction`]: the
//! ramp, or the nearest-sample staircase, integrated piece by piece in
//! closed form). The step's absorbed direct-beam energy is then the
//! history's, wherever the step ends: sun/shadow transitions are not
//! breakpoints (until issue 29 every ramp end was one, so a history with
//! many short transitions cost many short steps), and the step control
//! alone decides how finely a transition is resolved.
//!
//! **Spin-up.** The march starts from a steady state ([`SpinUpStart`]): by
//! default the steady state under the *time-mean* surface drive of the
//! first 24 h of the forcing (the whole series when it is shorter; the
//! pixel's sun/shadow history included); optionally, as
//! in THERM, under the first forcing sample. For a linear slab under
//! periodic forcing the mean of the periodic solution is exactly the steady
//! state under the mean forcing (the heat equation commutes with time
//! averaging), so the slow, deep part of the profile starts where a long
//! spin-up would leave it and only the diurnal wave (which forgets its
//! start within hours) must be marched in. The caller chooses how far before
//! the image time the forcing starts (`ThermSettings::spin_up_h`).

mod grid;
mod history;
mod interp;
mod march;
mod material;
mod settings;
mod store;

pub use grid::Mesh;
pub use history::{SunHistory, mean_sun_fraction, sun_fraction};
pub use interp::{forcing_at, validate_forcing};
pub use march::{
    MarchState, SPIN_UP_MEAN_WINDOW_S, SlabModel, StepRecord, ThermSolution, solve_surface,
};
pub use material::{BackBoundary, Layer, Layers, MAX_LAYERS, SlabMaterial, keys};
pub use settings::{SpinUpStart, ThermError, ThermSettings};
pub use store::update_store_mm;
pub(crate) use store::wet_drive;
