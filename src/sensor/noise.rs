//! Detector noise: random (zero-mean Gaussian, σ in the image's units) and
//! periodic (a sinusoidal pattern of amplitude A along rows, columns or a
//! diagonal — the striping and banding of scanning sensors). Seeded and
//! reproducible: the random field is drawn in pixel order from one ChaCha8
//! stream, independent of thread count.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

/// Direction along which periodic noise varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Varies with x (vertical stripes).
    Columns,
    /// Varies with y (horizontal bands).
    Rows,
    /// Varies with x + y (diagonal stripes).
    Diagonal,
}

/// Noise settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseSpec {
    /// σ of the random (white Gaussian) noise, image units; 0: none.
    pub random_sigma: f64,
    /// Amplitude of the periodic pattern, image units; 0: none.
    pub periodic_amplitude: f64,
    /// Period of the periodic pattern, pixels.
    pub periodic_period_px: f64,
    /// Direction along which the periodic pattern varies.
    pub periodic_direction: Direction,
    /// Phase of the periodic pattern at pixel 0, degrees.
    pub periodic_phase_deg: f64,
    /// Seed of the random field (same seed, same noise).
    pub seed: u64,
}

/// Adds the noise to `img` in place.
pub fn add_noise(img: &mut [f32], width: usize, spec: &NoiseSpec) {
    if spec.random_sigma > 0.0 && spec.random_sigma.is_finite() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed);
        let normal =
            Normal::new(0.0, spec.random_sigma).expect("sigma checked finite and positive");
        for v in img.iter_mut() {
            *v += normal.sample(&mut rng) as f32;
        }
    }
    if spec.periodic_amplitude != 0.0 && spec.periodic_period_px > 0.0 {
        let k = std::f64::consts::TAU / spec.periodic_period_px;
        for (i, v) in img.iter_mut().enumerate() {
            let (x, y) = ((i % width) as f64, (i / width) as f64);
            let s = match spec.periodic_direction {
                Direction::Columns => x,
                Direction::Rows => y,
                Direction::Diagonal => (x + y) / std::f64::consts::SQRT_2,
            };
            *v += (spec.periodic_amplitude * (k * s + spec.periodic_phase_deg.to_radians()).sin())
                as f32;
        }
    }
}
