//! Times a user PSF kernel applied by direct summation and by FFT
//! (`irsig::sensor::psf::{convolve_direct, convolve_fft}`) on square images
//! for square kernels, best of N, and prints the largest difference between
//! them; the crossover sets `psf::FFT_MIN_TAPS` (BENCHMARKS.md, "PSF:
//! direct against FFT").
//!
//! `cargo run --release --example psf_fft -- [sizes] [kernel sizes] [repeats] [max direct s]`,
//! e.g. `-- 512,2048 3,5,7,9,11,15,21,31,63 3 20`: the direct sum is not
//! timed again (nor at larger kernels of that image size) once one run
//! takes longer than `max direct s`.

use std::time::Instant;

use irsig::sensor::psf::{Kernel, convolve_direct, convolve_fft};

fn list(arg: Option<&String>, default: &str) -> Vec<usize> {
    arg.map_or(default, |s| s.as_str())
        .split(',')
        .map(|v| v.parse().expect("a comma-separated list of sizes"))
        .collect()
}

fn best_of(repeats: usize, f: impl Fn() -> Vec<f32>) -> (f64, Vec<f32>) {
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for _ in 0..repeats {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sizes = list(args.get(1), "512,2048");
    let kernels = list(args.get(2), "3,5,7,9,11,15,21,31,45,63");
    let repeats: usize = args.get(3).map_or(3, |s| s.parse().expect("repeats"));
    let max_direct_s: f64 = args.get(4).map_or(20.0, |s| s.parse().expect("seconds"));
    println!(
        "threads {}, best of {repeats}",
        rayon::current_num_threads()
    );
    println!("| image | kernel | taps | direct s | FFT s | direct / FFT | max diff / range |");
    println!("|---|---|---|---|---|---|---|");
    for &n in &sizes {
        // A smooth field with edges and a little texture, ~300 K-like levels.
        let img: Vec<f32> = (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f32, (i / n) as f32);
                let step = if (x as usize / 37 + y as usize / 53).is_multiple_of(2) {
                    1.0
                } else {
                    0.0
                };
                8.0 + 2.0 * step + 0.5 * (0.05 * x).sin() * (0.031 * y).cos()
            })
            .collect();
        let range = 3.0f64;
        let mut direct_ok = true;
        for &m in &kernels {
            let r = (m / 2) as f64;
            let w: Vec<f64> = (0..m * m)
                .map(|k| {
                    let (i, j) = ((k % m) as f64 - r, (k / m) as f64 - r);
                    (-(i * i + j * j) / (2.0 * (r / 2.0 + 0.5).powi(2))).exp()
                })
                .collect();
            let k = Kernel::new(m, m, w).expect("odd kernel");
            let (t_fft, fft) = best_of(repeats, || convolve_fft(&img, n, n, &k));
            let (direct, diff) = if direct_ok {
                let reps = if m * m * n * n > 50_000_000 {
                    1
                } else {
                    repeats
                };
                let (t, d) = best_of(reps, || convolve_direct(&img, n, n, &k));
                direct_ok = t <= max_direct_s;
                let diff = d
                    .iter()
                    .zip(&fft)
                    .map(|(a, b)| (a - b).abs() as f64)
                    .fold(0.0, f64::max);
                (
                    format!("{t:.3}"),
                    format!("{:.3} | {:.1e}", t / t_fft, diff / range),
                )
            } else {
                ("(not run)".into(), "| ".into())
            };
            println!(
                "| {n}² | {m}×{m} | {} | {direct} | {t_fft:.3} | {diff} |",
                m * m
            );
        }
    }
}
