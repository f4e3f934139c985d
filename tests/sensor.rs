//! Sensor model against analytic references.

use irsig::sensor::noise::{Direction, NoiseSpec, add_noise};
use irsig::sensor::psf::{
    FFT_MIN_TAPS, Kernel, KernelError, convolve, convolve_direct, convolve_fft, convolve_separable,
};
use irsig::sensor::quantise::Quantiser;

/// A delta blurred by a Gaussian PSF has second moment σ² per axis
/// (reference: the continuous Gaussian). The kernel is truncated at
/// ±ceil(4σ) px, which removes at most 8φ(4)/(1 − 2Φ(−4)) ≈ 1.07e-3 of the
/// variance (truncated-normal variance at ±4σ); sampling on integers changes
/// it by O(exp(−2π²σ²)), negligible for σ ≥ 1.5. Tolerance: 1.2e-3 relative,
/// and never more than σ².
#[test]
fn gaussian_psf_spreads_a_delta_by_sigma() {
    let (w, h) = (41usize, 41usize);
    for sigma in [1.5f64, 2.0, 3.0] {
        let mut img = vec![0f32; w * h];
        img[20 * w + 20] = 1.0;
        let out = convolve(&img, w, h, &Kernel::gaussian(sigma).unwrap());
        let sum: f64 = out.iter().map(|&v| v as f64).sum();
        assert!((sum - 1.0).abs() < 1e-6, "energy kept: {sum}");
        let var_x: f64 = out
            .iter()
            .enumerate()
            .map(|(i, &v)| v as f64 * ((i % w) as f64 - 20.0).powi(2))
            .sum();
        let rel = var_x / (sigma * sigma) - 1.0;
        assert!(
            rel.abs() < 1.2e-3 && rel < 1e-6,
            "σ={sigma}: variance {var_x}, relative error {rel}"
        );
    }
}

/// The separable Gaussian (two 1-D passes) equals the direct 2-D
/// convolution with the outer-product kernel (the reference: a sum over the
/// kernel's every weight) to float32 rounding, edges included.
#[test]
fn separable_gaussian_equals_the_direct_2d_convolution() {
    let (w, h) = (37, 23);
    let img: Vec<f32> = (0..w * h)
        .map(|k| ((k * 7919) % 101) as f32 * 0.37 + 5.0)
        .collect();
    for sigma in [0.4, 1.3, 3.0] {
        let direct = convolve_direct(&img, w, h, &Kernel::gaussian(sigma).unwrap());
        let g = Kernel::gaussian_1d(sigma).unwrap();
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let sep = convolve_separable(&img, w, h, &g, &g);
        let worst = direct
            .iter()
            .zip(&sep)
            .map(|(a, b)| ((a - b) / a).abs())
            .fold(0f32, f32::max);
        assert!(
            worst < 2e-7,
            "sigma {sigma}: worst relative difference {worst}"
        );
    }
}

/// A reproducible pseudo-random sequence in [0, 1) (xorshift64).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.max(1);
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A user kernel of random weights (some negative, as in a sharpening
/// kernel; the centre's raised so the sum is positive), `kw × kh`.
fn random_kernel(kw: usize, kh: usize, seed: u64) -> Kernel {
    let mut u = uniform(seed);
    let mut w: Vec<f64> = (0..kw * kh).map(|_| u() - 0.2).collect();
    w[kh / 2 * kw + kw / 2] += 1.0; // a positive sum

    Kernel::new(kw, kh, w).unwrap()
}

/// `a` and `b` agree to one f32 rounding: at most one unit in the last
/// place of the larger, or 1e-9 of the image's range near zero (where the
/// f32 spacing vanishes).
fn same_to_rounding(a: f32, b: f32, range: f64) -> bool {
    let ulp = |v: f32| (f32::from_bits(v.abs().to_bits() + 1) - v.abs()) as f64;
    ((a - b).abs() as f64) <= ulp(a).max(ulp(b)) + 1e-9 * range
}

/// The FFT path equals the direct sum (the definition: a sum over every
/// weight, clamp-to-edge) to one f32 rounding — the FFT's own error is
/// ~1e-15 of the image's range in f64 — for odd and even image sizes,
/// non-square images and kernels, kernels wider or taller than the image,
/// a high level with a small range (the FFT's rounding must scale with the
/// range, not the level) and negative weights.
#[test]
fn fft_psf_equals_the_direct_sum() {
    let mut u = uniform(7);
    for (w, h, level, amp) in [
        (37usize, 23usize, 300.0, 0.01),
        (64, 48, 8.0, 3.0),
        (20, 51, 0.0, 1.0),
        (9, 4, 1e3, 50.0),
    ] {
        let img: Vec<f32> = (0..w * h)
            .map(|i| (level + amp * (u() + if i % w < w / 3 { 1.0 } else { 0.0 })) as f32)
            .collect();
        let (lo, hi) = img
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        let range = (hi - lo) as f64;
        for (kw, kh) in [(1, 1), (3, 3), (5, 9), (11, 11), (15, 7), (1, 25), (31, 3)] {
            let k = random_kernel(kw, kh, (kw * 100 + kh) as u64);
            let direct = convolve_direct(&img, w, h, &k);
            let fft = convolve_fft(&img, w, h, &k);
            for (i, (&a, &b)) in direct.iter().zip(&fft).enumerate() {
                assert!(
                    same_to_rounding(a, b, range),
                    "{w}x{h} kernel {kw}x{kh} pixel ({}, {}): direct {a}, FFT {b}",
                    i % w,
                    i / w
                );
            }
        }
    }
}

/// An impulse reproduces the kernel (analytic): out(x, y) =
/// k(x0 − x + rx, y0 − y + ry) around the impulse at (x0, y0), zero
/// elsewhere; both paths, to f32 rounding of the weight (1e-12 absolute
/// where the weight is zero).
#[test]
fn psf_of_an_impulse_is_the_kernel() {
    let (w, h, x0, y0) = (40usize, 31usize, 17usize, 12usize);
    let mut img = vec![0f32; w * h];
    img[y0 * w + x0] = 1.0;
    let k = random_kernel(9, 13, 3);
    let (rx, ry) = (4i64, 6i64);
    for (path, out) in [
        ("direct", convolve_direct(&img, w, h, &k)),
        ("fft", convolve_fft(&img, w, h, &k)),
    ] {
        for (i, &v) in out.iter().enumerate() {
            let (i_k, j_k) = (
                x0 as i64 - (i % w) as i64 + rx,
                y0 as i64 - (i / w) as i64 + ry,
            );
            let want = if (0..9).contains(&i_k) && (0..13).contains(&j_k) {
                k.weights[j_k as usize * 9 + i_k as usize] as f32
            } else {
                0.0
            };
            assert!(
                same_to_rounding(v, want, 1e-3),
                "{path}: pixel {i}: {v}, kernel weight {want}"
            );
        }
    }
}

/// Clamp-to-edge borders (analytic): a ramp img(x, y) = x blurred by a
/// (2r+1)-tap box along x is the mean of clamp(x + i, 0, w − 1) over
/// i = −r..r; the FFT path (its padded, edge-replicated image) and the
/// direct one both give it, borders included.
#[test]
fn psf_borders_replicate_the_edge() {
    let (w, h, r) = (30usize, 5usize, 6i64);
    let img: Vec<f32> = (0..w * h).map(|i| (i % w) as f32).collect();
    let k = Kernel::new(2 * r as usize + 1, 3, vec![1.0; 3 * (2 * r as usize + 1)]).unwrap();
    for out in [
        convolve_direct(&img, w, h, &k),
        convolve_fft(&img, w, h, &k),
    ] {
        for (i, &v) in out.iter().enumerate() {
            let x = (i % w) as i64;
            let want = (-r..=r)
                .map(|d| (x + d).clamp(0, w as i64 - 1) as f64)
                .sum::<f64>()
                / (2 * r + 1) as f64;
            assert!(
                (v as f64 - want).abs() < 1e-5,
                "x = {x}: {v}, expected {want}"
            );
        }
    }
}

/// `convolve` takes the FFT path from [`FFT_MIN_TAPS`] taps on (finite
/// images only: a NaN stays local, as in the direct sum), and gives the
/// same bits with 1 and 2 threads.
#[test]
fn psf_path_choice_and_thread_count_independence() {
    let (w, h) = (61usize, 47usize);
    let mut u = uniform(11);
    let img: Vec<f32> = (0..w * h).map(|_| (5.0 + u()) as f32).collect();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let side = (FFT_MIN_TAPS as f64).sqrt().ceil() as usize | 1;
    let big = random_kernel(side, side, 5);
    let small = random_kernel(3, 3, 5);
    assert!(big.weights.len() >= FFT_MIN_TAPS && small.weights.len() < FFT_MIN_TAPS);
    let run = |threads: usize, k: &Kernel, img: &[f32]| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| convolve(img, w, h, k))
    };
    for k in [&big, &small] {
        let one = run(1, k, &img);
        assert_eq!(bits(&one), bits(&run(2, k, &img)));
        let path = if k.weights.len() >= FFT_MIN_TAPS {
            convolve_fft(&img, w, h, k)
        } else {
            convolve_direct(&img, w, h, k)
        };
        assert_eq!(bits(&one), bits(&path));
    }
    let mut holed = img.clone();
    holed[20 * w + 30] = f32::NAN;
    let out = run(2, &big, &holed);
    assert_eq!(bits(&out), bits(&convolve_direct(&holed, w, h, &big)));
    assert!(out[0].is_finite() && out[20 * w + 30].is_nan());
}

#[test]
fn psf_keeps_a_flat_field_and_rejects_bad_kernels() {
    let img = vec![3.25f32; 30 * 20];
    let out = convolve(&img, 30, 20, &Kernel::gaussian(2.5).unwrap());
    assert!(out.iter().all(|v| (v - 3.25).abs() < 1e-5));
    assert_eq!(
        Kernel::new(2, 3, vec![1.0; 6]),
        Err(KernelError::Shape(2, 3))
    );
    assert_eq!(
        Kernel::new(3, 3, vec![1.0; 8]),
        Err(KernelError::Count {
            got: 8,
            expected: 9
        })
    );
    assert_eq!(Kernel::new(1, 1, vec![0.0]), Err(KernelError::Sum(0.0)));
    assert_eq!(
        Kernel::gaussian(f64::NAN).unwrap_err().to_string(),
        "Gaussian sigma must be finite and > 0 pixels, got NaN"
    );
    let k = Kernel::new(3, 1, vec![1.0, 2.0, 1.0]).unwrap();
    assert_eq!(k.weights, vec![0.25, 0.5, 0.25]);
}

fn spec(sigma: f64, amp: f64, seed: u64) -> NoiseSpec {
    NoiseSpec {
        random_sigma: sigma,
        periodic_amplitude: amp,
        periodic_period_px: 8.0,
        periodic_direction: Direction::Columns,
        periodic_phase_deg: 0.0,
        seed,
    }
}

/// Random noise: sample std within 1 % of σ (its standard error is
/// σ/√(2N) ≈ 0.14 % for N = 262,144), mean within 0.01σ (SE 0.002σ);
/// reproducible for a seed, different across seeds.
#[test]
fn random_noise_has_the_stated_sigma_and_is_reproducible() {
    let n = 512 * 512;
    let mut a = vec![0f32; n];
    add_noise(&mut a, 512, &spec(0.5, 0.0, 42));
    let mean = a.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let sd = (a.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    assert!((sd / 0.5 - 1.0).abs() < 0.01, "sd {sd}");
    assert!(mean.abs() < 0.005, "mean {mean}");
    let mut b = vec![0f32; n];
    add_noise(&mut b, 512, &spec(0.5, 0.0, 42));
    assert_eq!(a, b);
    let mut c = vec![0f32; n];
    add_noise(&mut c, 512, &spec(0.5, 0.0, 43));
    assert_ne!(a, c);
}

#[test]
fn periodic_noise_is_the_stated_sinusoid() {
    let mut img = vec![1f32; 16 * 4];
    add_noise(&mut img, 16, &spec(0.0, 0.2, 0));
    for (i, v) in img.iter().enumerate() {
        let x = (i % 16) as f64;
        let want = 1.0 + 0.2 * (std::f64::consts::TAU * x / 8.0).sin();
        assert!((*v as f64 - want).abs() < 1e-6);
    }
}

#[test]
fn quantiser_matches_hand_computed_dns() {
    let q = Quantiser {
        bits: 8,
        gain: 10.0,
        offset: 5.0,
    };
    assert_eq!(q.max_dn(), 255.0);
    assert_eq!(q.dn(5.0), 0.0);
    assert_eq!(q.dn(10.04), 50.0); // 10·5.04 = 50.4 → 50
    assert_eq!(q.dn(10.06), 51.0);
    assert_eq!(q.dn(100.0), 255.0); // saturates
    assert_eq!(q.dn(-3.0), 0.0);
    assert_eq!(q.dn(f64::NAN), 0.0);
    let s = Quantiser::spanning(12, 2.0, 10.0);
    assert_eq!(s.dn(2.0), 0.0);
    assert_eq!(s.dn(10.0), 4095.0);
    assert!((s.value(s.dn(6.0)) - 6.0).abs() <= 0.5 / s.gain);
}
