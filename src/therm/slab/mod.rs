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
//! sample time, where the linearly interpolated forcing has a kink, or a
//! sun/shadow switch). With `tol_k = None` the step is fixed at `step_s`
//! (cut at breakpoints).
//!
//! **Forcing between samples.** Each scalar field of
//! [`Forcing`] is interpolated linearly in time; the sun vector is
//! interpolated linearly and renormalised. Before the first / after the last
//! sample the end values are held. A backward-Euler step ending at `t`
//! evaluates the forcing at `t` and the sun/shadow flag at the step's
//! midpoint (steps never straddle a flag switch, so this is the flag in
//! force over the whole step).
//!
//! **Spin-up.** The march starts from a steady state ([`SpinUpStart`]): by
//! default the steady state under the *time-mean* surface drive of the whole
//! forcing series (the pixel's sun/shadow history included); optionally, as
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

pub use grid::Mesh;
pub use history::{SunHistory, sun_fraction};
pub use interp::{forcing_at, validate_forcing};
pub use march::{SlabModel, StepRecord, ThermSolution, solve_surface, update_store_mm};
pub use material::{BackBoundary, SlabMaterial};
pub use settings::{SpinUpStart, ThermError, ThermSettings};
