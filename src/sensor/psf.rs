//! Point-spread-function blur: a separable Gaussian (two 1-D passes), or a
//! user kernel (normalised to unit sum), applied by direct convolution with
//! the image edge replicated (no energy lost at borders for a flat field);
//! rows in parallel, each output pixel summed in a fixed order.
//! The paper's sensor submodel (Schott & Salvaggio) degrades the radiance
//! image by convolution with such kernels to model optics, detector and
//! electronics MTF.

use rayon::prelude::*;

/// A normalised 2-D kernel, odd width and height, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub width: usize,
    pub height: usize,
    pub weights: Vec<f64>,
}

/// Errors in a user kernel.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum KernelError {
    #[error("kernel is {0}x{1}: width and height must be odd and at least 1")]
    Shape(usize, usize),
    #[error("kernel has {got} weights, expected {expected}")]
    Count { got: usize, expected: usize },
    #[error("kernel weights must be finite and sum to a positive number (sum = {0})")]
    Sum(f64),
    #[error("Gaussian sigma must be finite and > 0 pixels, got {0}")]
    Sigma(f64),
}

impl Kernel {
    /// A user kernel, normalised to unit sum.
    pub fn new(width: usize, height: usize, weights: Vec<f64>) -> Result<Self, KernelError> {
        if width.is_multiple_of(2) || height.is_multiple_of(2) {
            return Err(KernelError::Shape(width, height));
        }
        if weights.len() != width * height {
            return Err(KernelError::Count {
                got: weights.len(),
                expected: width * height,
            });
        }
        let sum: f64 = weights.iter().sum();
        if !sum.is_finite() || sum <= 0.0 || weights.iter().any(|w| !w.is_finite()) {
            return Err(KernelError::Sum(sum));
        }
        Ok(Kernel {
            width,
            height,
            weights: weights.iter().map(|w| w / sum).collect(),
        })
    }

    /// A sampled Gaussian exp(−r²/2σ²) truncated at ±ceil(4σ), normalised.
    pub fn gaussian(sigma_px: f64) -> Result<Self, KernelError> {
        let g = gaussian_taps(sigma_px)?;
        let n = g.len();
        let w = (0..n * n).map(|k| g[k / n] * g[k % n]).collect();
        Kernel::new(n, n, w)
    }

    /// The 1-D factor of [`Kernel::gaussian`] (normalised; the 2-D kernel
    /// is its outer product with itself).
    pub fn gaussian_1d(sigma_px: f64) -> Result<Vec<f64>, KernelError> {
        let g = gaussian_taps(sigma_px)?;
        let sum: f64 = g.iter().sum();
        Ok(g.iter().map(|v| v / sum).collect())
    }
}

/// The unnormalised taps exp(−i²/2σ²), i = −r..=r, r = max(ceil(4σ), 1).
fn gaussian_taps(sigma_px: f64) -> Result<Vec<f64>, KernelError> {
    if !(sigma_px.is_finite() && sigma_px > 0.0) {
        return Err(KernelError::Sigma(sigma_px));
    }
    let r = (4.0 * sigma_px).ceil().max(1.0) as i64;
    Ok((-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma_px * sigma_px)).exp())
        .collect())
}

/// Convolves `img` with the separable kernel kx(i)·ky(j) (odd lengths,
/// normalised), replicating edge pixels: a pass along rows, then along
/// columns, in f64 (one rounding to f32 at the end), rows in parallel.
pub fn convolve_separable(
    img: &[f32],
    width: usize,
    height: usize,
    kx: &[f64],
    ky: &[f64],
) -> Vec<f32> {
    let (rx, ry) = ((kx.len() / 2) as i64, (ky.len() / 2) as i64);
    let mut tmp = vec![0f64; img.len()];
    tmp.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            *out = (-rx..=rx)
                .map(|i| {
                    let xx = (x as i64 + i).clamp(0, width as i64 - 1) as usize;
                    kx[(i + rx) as usize] * img[y * width + xx] as f64
                })
                .sum();
        }
    });
    let mut out = vec![0f32; img.len()];
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let acc: f64 = (-ry..=ry)
                .map(|j| {
                    let yy = (y as i64 + j).clamp(0, height as i64 - 1) as usize;
                    ky[(j + ry) as usize] * tmp[yy * width + x]
                })
                .sum();
            *o = acc as f32;
        }
    });
    out
}

/// Convolves `img` (`width × height`, row-major) with `k`, replicating edge
/// pixels. Deterministic (fixed summation order).
pub fn convolve(img: &[f32], width: usize, height: usize, k: &Kernel) -> Vec<f32> {
    let (rx, ry) = ((k.width / 2) as i64, (k.height / 2) as i64);
    let mut out = vec![0f32; img.len()];
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let y = y as i64;
        for x in 0..width as i64 {
            let mut acc = 0f64;
            for j in -ry..=ry {
                let yy = (y + j).clamp(0, height as i64 - 1) as usize;
                for i in -rx..=rx {
                    let xx = (x + i).clamp(0, width as i64 - 1) as usize;
                    acc += k.weights[((j + ry) as usize) * k.width + (i + rx) as usize]
                        * img[yy * width + xx] as f64;
                }
            }
            row[x as usize] = acc as f32;
        }
    });
    out
}
