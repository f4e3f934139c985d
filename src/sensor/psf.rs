//! Point-spread-function blur: a separable Gaussian (two 1-D passes), or a
//! user kernel (normalised to unit sum), applied with the image edge
//! replicated (no energy lost at borders for a flat field): by direct
//! summation for small kernels, by FFT (rustfft) for kernels of at least
//! [`FFT_MIN_TAPS`] taps; rows in parallel, each output pixel computed in a
//! fixed order, so the result does not depend on the thread count.
//! The paper's sensor submodel (Schott & Salvaggio) degrades the radiance
//! image by convolution with such kernels to model optics, detector and
//! electronics MTF.

use rayon::prelude::*;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// A normalised 2-D kernel, odd width and height, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    /// Columns (odd).
    pub width: usize,
    /// Rows (odd).
    pub height: usize,
    /// Row-major weights, summing to 1.
    pub weights: Vec<f64>,
}

/// Errors in a user kernel.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum KernelError {
    /// Width or height (given) even or zero.
    #[error("kernel is {0}x{1}: width and height must be odd and at least 1")]
    Shape(usize, usize),
    /// Not width × height weights.
    #[error("kernel has {got} weights, expected {expected}")]
    Count {
        /// Weights given.
        got: usize,
        /// Width × height.
        expected: usize,
    },
    /// Weights not finite, or their sum (given) not positive.
    #[error("kernel weights must be finite and sum to a positive number (sum = {0})")]
    Sum(f64),
    /// A Gaussian's σ (given, pixels) not finite and positive.
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

/// User kernels with at least this many taps (width × height) are applied
/// by FFT, smaller ones by direct summation: the measured crossover on
/// 512² and 2048² images, 2 threads (BENCHMARKS.md, "PSF: direct against
/// FFT").
pub const FFT_MIN_TAPS: usize = 49;

/// Convolves `img` (`width × height`, row-major) with `k`, replicating edge
/// pixels: out(x, y) = Σ_ij k(i, j)·img(clamp(x + i − rx), clamp(y + j − ry)).
/// [`convolve_fft`] for kernels of at least [`FFT_MIN_TAPS`] taps on a
/// finite image (within 1e-6 of the image's range or one f32 rounding of
/// [`convolve_direct`]), [`convolve_direct`] otherwise. Deterministic.
pub fn convolve(img: &[f32], width: usize, height: usize, k: &Kernel) -> Vec<f32> {
    if k.width * k.height >= FFT_MIN_TAPS && img.iter().all(|v| v.is_finite()) {
        convolve_fft(img, width, height, k)
    } else {
        convolve_direct(img, width, height, k)
    }
}

/// [`convolve`] by direct summation in f64, in a fixed order (rows of the
/// kernel, then columns), one rounding to f32; rows in parallel.
pub fn convolve_direct(img: &[f32], width: usize, height: usize, k: &Kernel) -> Vec<f32> {
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

/// [`convolve`] by FFT: the image, padded by the kernel's radii with its
/// edge pixels replicated (so the borders are exactly those of the direct
/// definition) and shifted by the mid-range value c (the kernel sums to 1,
/// so c is added back after: the FFT's rounding then scales with the
/// image's range, not its level), is correlated with the kernel by the
/// correlation theorem, corr = F⁻¹(F(img) · conj(F(k))), over a 2-D
/// transform of 2·3·5-smooth sizes at least the padded size (no wrap-around
/// reaches the output pixels). f64 throughout, one rounding to f32. Rows
/// and columns are transformed in parallel, each by the same plan, so the
/// result does not depend on the thread count. Needs a finite image (a NaN
/// would spread over the whole transform).
pub fn convolve_fft(img: &[f32], width: usize, height: usize, k: &Kernel) -> Vec<f32> {
    if img.is_empty() {
        return Vec::new();
    }
    let (rx, ry) = (k.width / 2, k.height / 2);
    let (pw, ph) = (width + 2 * rx, height + 2 * ry);
    let (nx, ny) = (smooth_len(pw), smooth_len(ph));
    let (lo, hi) = img
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v as f64), hi.max(v as f64))
        });
    let c = if lo <= hi { 0.5 * (lo + hi) } else { 0.0 };
    let mut planner = FftPlanner::<f64>::new();
    let plans = Plans {
        nx,
        ny,
        fwd_x: planner.plan_fft_forward(nx),
        fwd_y: planner.plan_fft_forward(ny),
    };
    // Spectra are transposed (column x of the image is row x of the
    // spectrum). The kernel's first, so that its buffer is freed before
    // the image's are made.
    let mut kern = vec![Complex::new(0.0, 0.0); nx * k.height];
    for (j, row) in k.weights.chunks(k.width).enumerate() {
        for (i, &w) in row.iter().enumerate() {
            kern[j * nx + i] = Complex::new(w, 0.0);
        }
    }
    let kspec = plans.forward(&mut kern, k.height);
    drop(kern);
    // The padded image, rows 0..ph of nx (the rows below are zero).
    let mut a = vec![Complex::new(0.0, 0.0); nx * ph];
    a.par_chunks_mut(nx)
        .take(ph)
        .enumerate()
        .for_each(|(yp, row)| {
            let y = yp.saturating_sub(ry).min(height - 1);
            for (xp, v) in row[..pw].iter_mut().enumerate() {
                let x = xp.saturating_sub(rx).min(width - 1);
                *v = Complex::new(img[y * width + x] as f64 - c, 0.0);
            }
        });
    let mut spec = plans.forward(&mut a, ph);
    spec.par_iter_mut()
        .zip(kspec.par_iter())
        .for_each(|(s, k)| *s *= k.conj());
    drop(kspec);
    let inv_y = planner.plan_fft_inverse(ny);
    let inv_x = planner.plan_fft_inverse(nx);
    fft_rows(&mut spec, ny, &*inv_y);
    // Back to rows; only the output rows 0..height are transformed along x.
    a.par_chunks_mut(nx)
        .take(height)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                *v = spec[x * ny + y];
            }
        });
    drop(spec);
    let rows = &mut a[..height * nx];
    fft_rows(rows, nx, &*inv_x);
    let scale = 1.0 / (nx * ny) as f64;
    let mut out = vec![0f32; width * height];
    out.par_chunks_mut(width)
        .zip(rows.par_chunks(nx))
        .for_each(|(o, r)| {
            for (o, v) in o.iter_mut().zip(r) {
                *o = (v.re * scale + c) as f32;
            }
        });
    out
}

/// The forward plans of an `nx × ny` transform.
struct Plans {
    nx: usize,
    ny: usize,
    fwd_x: std::sync::Arc<dyn Fft<f64>>,
    fwd_y: std::sync::Arc<dyn Fft<f64>>,
}

impl Plans {
    /// The 2-D DFT of the `nx × ny` array whose first `rows` rows are `a`
    /// (rows of `nx`) and the others zero, transposed: row x of the result
    /// is the y-transform of column x. `a` is overwritten by its rows'
    /// x-transforms.
    fn forward(&self, a: &mut [Complex<f64>], rows: usize) -> Vec<Complex<f64>> {
        let (nx, ny) = (self.nx, self.ny);
        fft_rows(&mut a[..rows * nx], nx, &*self.fwd_x);
        let a = &*a;
        let mut t = vec![Complex::new(0.0, 0.0); nx * ny];
        t.par_chunks_mut(ny).enumerate().for_each(|(x, col)| {
            for (y, v) in col[..rows].iter_mut().enumerate() {
                *v = a[y * nx + x];
            }
        });
        fft_rows(&mut t, ny, &*self.fwd_y);
        t
    }
}

/// Transforms each row (length `n`) of `a` in place, rows in parallel.
fn fft_rows(a: &mut [Complex<f64>], n: usize, fft: &dyn Fft<f64>) {
    let scratch_len = fft.get_inplace_scratch_len();
    a.par_chunks_mut(n).for_each_init(
        || vec![Complex::new(0.0, 0.0); scratch_len],
        |scratch, row| fft.process_with_scratch(row, scratch),
    );
}

/// The smallest n' ≥ n whose prime factors are 2, 3 and 5 (fast FFT sizes).
fn smooth_len(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut m = m;
            for p in [2, 3, 5] {
                while m % p == 0 {
                    m /= p;
                }
            }
            m == 1
        })
        .expect("2-3-5-smooth numbers are unbounded")
}
