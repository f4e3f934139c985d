//! Spectral grids, sensor relative spectral response and band integration.
//!
//! Band radiance is L_band = ∫ L(λ) R(λ) dλ / ∫ R(λ) dλ (docs/models.md, "Radiometry"). Spectra
//! are sampled on a wavenumber grid (the atmosphere tables' grid); each sample
//! stands for the bin [ν − Δν⁻/2, ν + Δν⁺/2] around it. A [`Band`] keeps only the
//! bins where the response is non-zero, with quadrature weights
//! wᵢ = ∫_binᵢ R(λ) dλ / ∫ R dλ (exact for the piecewise-linear R), so band integration is Σ wᵢ Lᵢ.

use std::path::Path;

use super::RadiometryError;
use super::planck::{brightness_temp_k, planck_dt_w_m2_sr_um_k, planck_radiance_w_m2_sr_um};

/// Ascending wavenumber samples, cm⁻¹.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralGrid {
    /// The samples, cm⁻¹, ascending.
    pub wavenumber_cm1: Vec<f64>,
}

impl SpectralGrid {
    /// Uniform grid start, start + step, ... (count samples).
    pub fn uniform(start_cm1: f64, step_cm1: f64, count: usize) -> Self {
        Self {
            wavenumber_cm1: (0..count)
                .map(|i| start_cm1 + step_cm1 * i as f64)
                .collect(),
        }
    }

    /// Validates a grid: at least one sample, finite, positive, strictly ascending.
    pub fn new(wavenumber_cm1: Vec<f64>) -> Result<Self, RadiometryError> {
        if wavenumber_cm1.is_empty() {
            return Err(RadiometryError::Grid("empty wavenumber grid".into()));
        }
        for w in wavenumber_cm1.windows(2) {
            if !(w[1] > w[0]) {
                return Err(RadiometryError::Grid(format!(
                    "wavenumbers not strictly ascending at {} cm-1",
                    w[0]
                )));
            }
        }
        if wavenumber_cm1.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(RadiometryError::Grid(
                "wavenumbers must be finite and positive".into(),
            ));
        }
        Ok(Self { wavenumber_cm1 })
    }

    /// Bin edges (cm⁻¹): midpoints between samples, half a step beyond the ends.
    pub fn bin_edges_cm1(&self) -> Vec<f64> {
        let v = &self.wavenumber_cm1;
        let n = v.len();
        let mut e = Vec::with_capacity(n + 1);
        if n == 1 {
            return vec![v[0], v[0]];
        }
        e.push(v[0] - 0.5 * (v[1] - v[0]));
        for i in 0..n - 1 {
            e.push(0.5 * (v[i] + v[i + 1]));
        }
        e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
        e
    }
}

/// Sensor relative spectral response R(λ), piecewise linear between samples and
/// zero outside them. The one spectral-response type: a scene's sensor band
/// ([`crate::scene::LoadedScene::response`]) is one.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SpectralResponse {
    /// Ascending wavelengths, µm.
    pub wavelength_um: Vec<f64>,
    /// Relative response (≥ 0) at each wavelength.
    pub response: Vec<f64>,
    /// Where it came from (file name or "ideal 8-14 um").
    pub label: String,
}

impl SpectralResponse {
    /// Ideal rectangular band: R = 1 on [lo, hi] µm, 0 elsewhere.
    pub fn ideal(lo_um: f64, hi_um: f64) -> Result<Self, RadiometryError> {
        let wl = crate::bounds::data::WAVELENGTH_UM;
        if !(wl.contains(lo_um) && wl.contains(hi_um) && hi_um > lo_um) {
            return Err(RadiometryError::Grid(format!(
                "ideal band needs {} <= lo < hi <= {} um, got {lo_um}-{hi_um} um",
                wl.lo, wl.hi
            )));
        }
        // a tiny ramp (1e-9 µm) keeps the piecewise-linear form exact for a box
        let eps = 1e-9;
        Ok(Self {
            wavelength_um: vec![lo_um - eps, lo_um, hi_um, hi_um + eps],
            response: vec![0.0, 1.0, 1.0, 0.0],
            label: format!("ideal {lo_um}-{hi_um} um"),
        })
    }

    /// Built-in ideal mid-wave band, 3-5 µm.
    pub fn mwir() -> Self {
        Self::ideal(3.0, 5.0).expect("valid band")
    }

    /// Built-in ideal long-wave band, 8-14 µm.
    pub fn lwir() -> Self {
        Self::ideal(8.0, 14.0).expect("valid band")
    }

    /// Parses "3-5", "8-14", "8.5-12.25" (µm) into an ideal band.
    pub fn parse_band(spec: &str) -> Result<Self, RadiometryError> {
        let (a, b) = spec.split_once('-').ok_or_else(|| {
            RadiometryError::Grid(format!(
                "band '{spec}': expected <lo>-<hi> in um, e.g. 8-14"
            ))
        })?;
        let lo: f64 = a
            .trim()
            .parse()
            .map_err(|_| RadiometryError::Grid(format!("band '{spec}': '{a}' is not a number")))?;
        let hi: f64 = b
            .trim()
            .parse()
            .map_err(|_| RadiometryError::Grid(format!("band '{spec}': '{b}' is not a number")))?;
        Self::ideal(lo, hi)
    }

    /// Reads a CSV of `wavelength_um,response` rows. Blank lines and lines starting
    /// with '#' are skipped; a first line that does not parse as numbers is taken as
    /// a header. Wavelengths must be strictly ascending and positive, responses
    /// finite and ≥ 0, and at least one response > 0.
    pub fn from_csv(path: &Path) -> Result<Self, RadiometryError> {
        let text = crate::files::read_text(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES)
            .map_err(|e| RadiometryError::Io {
                path: path.display().to_string(),
                source: e,
            })?;
        Self::from_csv_str(&text, &path.display().to_string())
    }

    /// As [`Self::from_csv`], from text; `file` names the source in errors.
    pub fn from_csv_str(text: &str, file: &str) -> Result<Self, RadiometryError> {
        let mut wl = Vec::new();
        let mut r = Vec::new();
        let mut seen_data = false;
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = line.split([',', ';', '\t']).map(str::trim).collect();
            let bad = |what: &str| RadiometryError::Csv {
                file: file.to_string(),
                line: line_no,
                msg: what.to_string(),
            };
            if fields.len() < 2 {
                return Err(bad(&format!(
                    "expected 'wavelength_um,response', got '{line}'"
                )));
            }
            let (a, b) = (fields[0].parse::<f64>(), fields[1].parse::<f64>());
            let (a, b) = match (a, b) {
                (Ok(a), Ok(b)) => (a, b),
                _ if !seen_data && wl.is_empty() && fields[0].parse::<f64>().is_err() => {
                    seen_data = true; // header line
                    continue;
                }
                _ => {
                    return Err(bad(&format!(
                        "expected two numbers 'wavelength_um,response', got '{line}'"
                    )));
                }
            };
            seen_data = true;
            crate::bounds::data::WAVELENGTH_UM
                .check(a)
                .map_err(|m| bad(&m))?;
            crate::bounds::data::RESPONSE
                .check(b)
                .map_err(|m| bad(&m))?;
            if let Some(&prev) = wl.last()
                && a <= prev
            {
                return Err(bad(&format!(
                    "wavelengths must be strictly ascending ({a} after {prev})"
                )));
            }
            wl.push(a);
            r.push(b);
        }
        if wl.len() < 2 {
            return Err(RadiometryError::Csv {
                file: file.into(),
                line: 0,
                msg: "need at least two data rows".into(),
            });
        }
        if r.iter().all(|&x| x == 0.0) {
            return Err(RadiometryError::Csv {
                file: file.into(),
                line: 0,
                msg: "response is zero everywhere".into(),
            });
        }
        Ok(Self {
            wavelength_um: wl,
            response: r,
            label: file.to_string(),
        })
    }

    /// R(λ), piecewise linear, 0 outside the tabulated range.
    pub fn at(&self, wavelength_um: f64) -> f64 {
        let w = &self.wavelength_um;
        if wavelength_um < w[0] || wavelength_um > w[w.len() - 1] {
            return 0.0;
        }
        let i = w
            .partition_point(|&x| x <= wavelength_um)
            .clamp(1, w.len() - 1);
        let t = (wavelength_um - w[i - 1]) / (w[i] - w[i - 1]);
        self.response[i - 1] + t * (self.response[i] - self.response[i - 1])
    }

    /// ∫_{a}^{b} R(λ) dλ, µm, exact for the piecewise-linear R.
    pub fn integral_um(&self, a_um: f64, b_um: f64) -> f64 {
        let w = &self.wavelength_um;
        let (a, b) = (a_um.max(w[0]), b_um.min(w[w.len() - 1]));
        if !(b > a) {
            return 0.0;
        }
        // breakpoints inside (a, b) plus the ends; R is linear between them
        let mut xs = vec![a];
        xs.extend(w.iter().copied().filter(|&x| x > a && x < b));
        xs.push(b);
        xs.windows(2)
            .map(|p| 0.5 * (p[1] - p[0]) * (self.at(p[0]) + self.at(p[1])))
            .sum()
    }

    /// The response-weighted centre wavelength, µm:
    /// λ̄ = ∫ λ R(λ) dλ / ∫ R(λ) dλ, exact for the piecewise-linear R (on a
    /// segment [x0, x1] where R runs from r0 to r1,
    /// ∫ λ R dλ = (x1 − x0)/6 · (x0 (2 r0 + r1) + x1 (r0 + 2 r1))). For an
    /// ideal band the midpoint.
    pub fn centroid_um(&self) -> f64 {
        let (w, r) = (&self.wavelength_um, &self.response);
        let (mut m0, mut m1) = (0.0, 0.0);
        for i in 0..w.len().saturating_sub(1) {
            let (x0, x1, r0, r1) = (w[i], w[i + 1], r[i], r[i + 1]);
            m0 += 0.5 * (x1 - x0) * (r0 + r1);
            m1 += (x1 - x0) / 6.0 * (x0 * (2.0 * r0 + r1) + x1 * (r0 + 2.0 * r1));
        }
        if m0 > 0.0 {
            m1 / m0
        } else {
            let (lo, hi) = self.support_um();
            0.5 * (lo + hi)
        }
    }

    /// The full width at half maximum, µm: the distance between the first
    /// and the last wavelengths where the piecewise-linear R crosses half
    /// its peak (linear interpolation; the outermost crossings, so a
    /// double-peaked response gets its whole width). For an ideal band its
    /// width.
    pub fn fwhm_um(&self) -> f64 {
        let (w, r) = (&self.wavelength_um, &self.response);
        let half = 0.5 * r.iter().copied().fold(0.0, f64::max);
        let peaked = half > 0.0;
        if !peaked || w.len() < 2 {
            return 0.0;
        }
        let cross = |i: usize| {
            let (x0, x1, r0, r1) = (w[i], w[i + 1], r[i], r[i + 1]);
            if r1 == r0 {
                x0
            } else {
                x0 + (half - r0) / (r1 - r0) * (x1 - x0)
            }
        };
        let n = w.len() - 1;
        let first = (0..n).find(|&i| r[i] < half && r[i + 1] >= half);
        let last = (0..n).rev().find(|&i| r[i] >= half && r[i + 1] < half);
        let lo = first.map_or(w[0], cross);
        let hi = last.map_or(w[n], cross);
        hi - lo
    }

    /// Wavelength range (µm) outside which R = 0.
    pub fn support_um(&self) -> (f64, f64) {
        let i0 = self.response.iter().position(|&x| x > 0.0).unwrap_or(0);
        let i1 = self
            .response
            .iter()
            .rposition(|&x| x > 0.0)
            .unwrap_or(self.response.len() - 1);
        (
            self.wavelength_um[i0.saturating_sub(1)],
            self.wavelength_um[(i1 + 1).min(self.wavelength_um.len() - 1)],
        )
    }
}

/// A sensor band sampled on a spectral grid: only the bins with non-zero
/// response, with normalised quadrature weights (Σ weights = 1).
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    /// Indices of the used bins in the parent grid.
    pub indices: Vec<usize>,
    /// Wavenumbers of the used bins, cm⁻¹ (ascending).
    pub wavenumber_cm1: Vec<f64>,
    /// Normalised weights wᵢ (Σ = 1): band value = Σ wᵢ Lᵢ for L per µm.
    pub weights: Vec<f64>,
    /// ∫ R(λ) dλ over the grid's bins, µm (the normalisation).
    pub response_integral_um: f64,
    /// The band's name as the outputs print it (`lwir 8-14 um`).
    pub label: String,
}

impl Band {
    /// Samples `response` on `grid`. Errors if the response does not overlap the grid.
    pub fn new(grid: &SpectralGrid, response: &SpectralResponse) -> Result<Self, RadiometryError> {
        let edges = grid.bin_edges_cm1();
        let (lo_um, hi_um) = response.support_um();
        let mut indices = Vec::new();
        let mut raw = Vec::new();
        for i in 0..grid.wavenumber_cm1.len() {
            let (a, b) = (edges[i], edges[i + 1]);
            // bin in wavelength: [1e4/b, 1e4/a]
            if 1.0e4 / b > hi_um || 1.0e4 / a.max(1e-30) < lo_um {
                continue;
            }
            let s = response.integral_um(1.0e4 / b, 1.0e4 / a.max(1e-30));
            if s > 0.0 {
                indices.push(i);
                raw.push(s);
            }
        }
        let total: f64 = raw.iter().sum();
        if indices.is_empty() || !(total > 0.0) {
            return Err(RadiometryError::Grid(format!(
                "response '{}' ({lo_um}-{hi_um} um) does not overlap the spectral grid {}-{} cm-1",
                response.label,
                grid.wavenumber_cm1[0],
                grid.wavenumber_cm1[grid.wavenumber_cm1.len() - 1]
            )));
        }
        Ok(Self {
            wavenumber_cm1: indices.iter().map(|&i| grid.wavenumber_cm1[i]).collect(),
            weights: raw.iter().map(|w| w / total).collect(),
            indices,
            response_integral_um: total,
            label: response.label.clone(),
        })
    }

    /// Number of used bins.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether no bin is used.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Σ wᵢ Lᵢ for a spectrum given on this band's bins (`spectrum.len() == self.len()`).
    pub fn integrate(&self, spectrum_on_band: &[f64]) -> f64 {
        debug_assert_eq!(spectrum_on_band.len(), self.weights.len());
        self.weights
            .iter()
            .zip(spectrum_on_band)
            .map(|(w, l)| w * l)
            .sum()
    }

    /// Σ wᵢ L_{indices[i]} for a spectrum given on the full parent grid.
    pub fn integrate_full(&self, spectrum_on_grid: &[f64]) -> f64 {
        self.weights
            .iter()
            .zip(&self.indices)
            .map(|(w, &i)| w * spectrum_on_grid[i])
            .sum()
    }

    /// Band-averaged blackbody radiance, W m⁻² sr⁻¹ µm⁻¹: Σ wᵢ L_λ(λᵢ, T).
    pub fn planck_w_m2_sr_um(&self, temp_k: f64) -> f64 {
        self.weights
            .iter()
            .zip(&self.wavenumber_cm1)
            .map(|(w, nu)| w * planck_radiance_w_m2_sr_um(1.0e4 / nu, temp_k))
            .sum()
    }

    /// dL/dT of the band-averaged Planck radiance, W m⁻² sr⁻¹ µm⁻¹ K⁻¹
    /// (the band weights applied to ∂B/∂T).
    pub fn planck_dt(&self, temp_k: f64) -> f64 {
        self.weights
            .iter()
            .zip(&self.wavenumber_cm1)
            .map(|(w, nu)| w * planck_dt_w_m2_sr_um_k(1.0e4 / nu, temp_k))
            .sum()
    }

    /// Band apparent temperature, K: the T whose band-averaged Planck radiance equals
    /// `radiance_w_m2_sr_um` (Newton's method on ln L_band(T) − ln L — nearly linear in
    /// 1/T in the Wien regime, where Newton on L itself crawls by T/x per step — with a
    /// bisection safeguard; converges to |ΔT| < 1e-9 K). `None` for a non-positive,
    /// non-finite radiance or one above the band radiance at 1e5 K.
    pub fn apparent_temp_k(&self, radiance_w_m2_sr_um: f64) -> Option<f64> {
        let l = radiance_w_m2_sr_um;
        if !(l > 0.0) || !l.is_finite() {
            return None;
        }
        let (mut lo, mut hi) = (1.0e-3_f64, 1.0e5_f64);
        if self.planck_w_m2_sr_um(hi) < l {
            return None;
        }
        // start from the brightness temperature at the weighted-mean wavelength
        let mean_nu: f64 = self
            .weights
            .iter()
            .zip(&self.wavenumber_cm1)
            .map(|(w, n)| w * n)
            .sum();
        let mut t = brightness_temp_k(1.0e4 / mean_nu, l)
            .unwrap_or(300.0)
            .clamp(lo, hi);
        for _ in 0..200 {
            let b = self.planck_w_m2_sr_um(t);
            if b > l {
                hi = t;
            } else {
                lo = t;
            }
            let d = self.planck_dt(t);
            // Newton on g(T) = ln B(T) − ln L, g' = B'/B
            let mut tn = if d > 0.0 && b > 0.0 {
                t - (b.ln() - l.ln()) * b / d
            } else {
                f64::NAN
            };
            if !(tn > lo && tn < hi) {
                tn = 0.5 * (lo + hi);
            }
            if (tn - t).abs() < 1e-10 * t.max(1.0) || hi - lo < 1e-12 * t {
                return Some(tn);
            }
            t = tn;
        }
        Some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (stress suite): in the Wien regime (1.1 K seen through a
    /// 0.25-20 µm band, x = c2/(λT) ≈ 650) Newton on the radiance itself moved
    /// by only T/x per step and stopped after 200 steps at 2.05 K. Reference:
    /// the band radiance of a blackbody at T must invert to T.
    #[test]
    fn apparent_temp_converges_deep_in_wien_regime() {
        let g = SpectralGrid::uniform(500.0, 20.0, 1976);
        for (lo, hi) in [(0.25, 20.0), (0.25, 0.3), (3.0, 5.0)] {
            let band = Band::new(&g, &SpectralResponse::ideal(lo, hi).unwrap()).unwrap();
            for t in [1.0, 1.102_684_164_171_709, 5.0, 20.0, 300.0, 6000.0] {
                let l = band.planck_w_m2_sr_um(t);
                if l > 1e-290 {
                    let ta = band.apparent_temp_k(l).unwrap();
                    assert!((ta / t - 1.0).abs() < 1e-9, "{lo}-{hi} um {t} K: {ta}");
                }
            }
        }
    }

    #[test]
    fn ideal_band_weights_integrate_response() {
        let g = SpectralGrid::uniform(500.0, 20.0, 1976);
        let b = Band::new(&g, &SpectralResponse::lwir()).unwrap();
        // ∫R dλ = 6 µm for the 8-14 box (exact up to the 1e-9 µm edge ramps)
        assert!(
            (b.response_integral_um - 6.0).abs() < 1e-8,
            "{}",
            b.response_integral_um
        );
        assert!((b.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // only bins overlapping 714.3-1250 cm-1 are touched
        assert!(b.wavenumber_cm1.iter().all(|&n| n > 700.0 && n < 1265.0));
        assert_eq!(b.len(), 28);
    }

    #[test]
    fn csv_errors_name_file_and_line() {
        let e = SpectralResponse::from_csv_str("wl,r\n8,0.5\n9,x\n", "resp.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("resp.csv") && e.contains("line 3"), "{e}");
        let e = SpectralResponse::from_csv_str("8,0.5\n7,0.6\n", "r.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("ascending"), "{e}");
        let e = SpectralResponse::from_csv_str("8,-1\n9,1\n", "r.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1"), "{e}");
        let ok = SpectralResponse::from_csv_str(
            "# c\nwavelength_um,response\n8,0\n9,1\n10,0\n",
            "r.csv",
        )
        .unwrap();
        assert!((ok.at(8.5) - 0.5).abs() < 1e-12);
        assert_eq!(ok.at(11.0), 0.0);
    }

    #[test]
    fn parse_band_spec() {
        let b = SpectralResponse::parse_band("3-5").unwrap();
        assert_eq!(b.at(4.0), 1.0);
        assert!(SpectralResponse::parse_band("5-3").is_err());
        assert!(SpectralResponse::parse_band("abc").is_err());
    }
}
