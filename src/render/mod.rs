//! The render: the paper's Fig. 11 as a data flow. Per block of pixels
//! (rayon over blocks, 4x4 tiles of 16-wide packets inside):
//!
//! 1. primary rays → facet, point, normal, range;
//! 2. specular-bounce rays for specular materials → sky direction or a
//!    background facet;
//! 3. solar-history rays from every surface point (primary and background),
//!    one packet per tile and sun sample, skipped with the sun below the
//!    horizon or behind the facet → the pixel's sun/shadow history;
//! 4. temperatures from the memoised thermal model, keyed by (material,
//!    orientation, history);
//! 5. radiometry by the paper's four cases, bin by bin over the band, then
//!    the sensor (supersampling, PSF, noise, quantisation).
//!
//! Everything is deterministic: results depend on pixel, key and seed only,
//! never on thread scheduling.

pub mod adaptive;
pub mod assemble;
pub mod atmosphere;
pub mod blocks;
pub mod cancel;
pub mod frame;
pub mod image;
pub mod memory;
pub mod pixel;
pub mod planes;
pub mod plausible;
pub mod prepare;
pub mod probe;
pub mod run;
pub mod sample;
pub mod sequence;
pub mod sunflags;
pub mod thermal;
pub mod tracing;
pub mod weather;

pub use blocks::band_samples;
pub use frame::{Frame, Progress, ProgressFn, Stage, StageTimes, Stats};
pub use image::{Rendered, render_at, render_conditions, render_scene};
pub use prepare::{
    Conditions, Reused, Static, derive_static, drop_in_background, prepare_conditions,
    prepare_static,
};
pub use run::{
    output_pixel_samples, render, render_with, thread_pool, trace_frame, trace_frame_with,
    trace_samples,
};
pub use sample::{Sample, Surface, angle_deg, azimuth_deg, zenith_deg};
pub use thermal::{key_history, thermal_solution};
pub use tracing::sample_camera;
