//! The sensor submodel: camera geometry, supersampling (in the render),
//! PSF/MTF blur, detector noise and quantisation. [`apply`] runs the chain
//! on a rendered band-radiance image.

pub mod camera;
pub mod noise;
pub mod psf;
pub mod quantise;

use rayon::prelude::*;

use crate::scene::PsfKernel;
use crate::scene::spec::{NoiseDirection, Psf, SensorSpec};

/// What the sensor chain makes of a band-radiance image.
pub struct Sensed {
    /// The radiance after the PSF and the noise, W m⁻² sr⁻¹ µm⁻¹.
    pub radiance: Vec<f32>,
    /// The quantised counts (`sensor.quantisation`), if asked for.
    pub dn: Option<Vec<f32>>,
}

/// The sensor chain on a `width`×`height` row-major band-radiance image:
/// the PSF (the scene's kernel file `kernel`, or a separable Gaussian of
/// `sensor.psf`), then the noise (`sensor.noise`: random and periodic, a
/// function of the seed and the pixel), then the quantisation to counts
/// (`sensor.quantisation`: a given gain and offset, or spanning the finite
/// range of the image). Each stage is the pure function of its module.
pub fn apply(
    image: Vec<f32>,
    width: usize,
    height: usize,
    sensor: &SensorSpec,
    kernel: Option<&PsfKernel>,
) -> anyhow::Result<Sensed> {
    let mut sr = image;
    if let Some(k) = kernel {
        let kernel = psf::Kernel::new(k.size, k.size, k.weights.clone())?;
        sr = psf::convolve(&sr, width, height, &kernel);
    } else if let Psf::Gaussian { sigma_px } = sensor.psf {
        let g = psf::Kernel::gaussian_1d(sigma_px)?;
        sr = psf::convolve_separable(&sr, width, height, &g, &g);
    }
    let ns = &sensor.noise;
    let (amp, period, dir, phase) = match &ns.periodic {
        Some(pn) => (
            pn.amplitude_w_m2_sr_um,
            pn.period_px,
            match pn.direction {
                NoiseDirection::Rows => noise::Direction::Rows,
                NoiseDirection::Columns => noise::Direction::Columns,
            },
            pn.phase_deg,
        ),
        None => (0.0, 0.0, noise::Direction::Rows, 0.0),
    };
    noise::add_noise(
        &mut sr,
        width,
        &noise::NoiseSpec {
            random_sigma: ns.random_sigma_w_m2_sr_um,
            periodic_amplitude: amp,
            periodic_period_px: period,
            periodic_direction: dir,
            periodic_phase_deg: phase,
            seed: ns.seed,
        },
    );
    let dn = sensor.quantisation.as_ref().map(|q| {
        let quant = match (q.gain_counts_per_w_m2_sr_um, q.offset_counts) {
            (Some(g), off) => quantise::Quantiser {
                bits: q.bits,
                gain: g,
                offset: -off.unwrap_or(0.0) / g,
            },
            _ => {
                // (min and max do not depend on the order, up to the
                // sign of a zero, which + 0.0 makes +0: the same for any
                // thread count)
                let (lo, hi) = sr
                    .par_iter()
                    .filter(|v| v.is_finite())
                    .fold(
                        || (f32::INFINITY, f32::NEG_INFINITY),
                        |(lo, hi), &v| (lo.min(v), hi.max(v)),
                    )
                    .reduce(
                        || (f32::INFINITY, f32::NEG_INFINITY),
                        |a, b| (a.0.min(b.0), a.1.max(b.1)),
                    );
                let (lo, hi) = (lo as f64 + 0.0, hi as f64 + 0.0);
                let (lo, hi) = if lo.is_finite() && hi > lo {
                    (lo, hi)
                } else {
                    (0.0, 1.0)
                };
                quantise::Quantiser::spanning(q.bits, lo, hi)
            }
        };
        sr.par_iter().map(|&v| quant.dn(v as f64) as f32).collect()
    });
    Ok(Sensed { radiance: sr, dn })
}
