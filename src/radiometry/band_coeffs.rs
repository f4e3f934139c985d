//! Band-integrated coefficients of eq. 1 (a diffuse surface) and a table of
//! the band-weighted Planck radiance in temperature, so that the band
//! radiance of a diffuse sample is a handful of multiply-adds and one table
//! lookup instead of a loop over the spectral bins.
//!
//! Eq. 1 (see [`super::equations::case1_diffuse`]), with the diffuse
//! facet's hemisphere split into sky F_sky and ground 1 − F_sky (a black
//! body at T_gnd), band-integrated over bins i with weights wᵢ:
//!
//! L = Σ wᵢ εᵢ τ₂ᵢ L(λᵢ, T)                      (emitted)
//!   + I·max(0, cos θ_S) · Σ wᵢ (E_Sᵢ/π) τ₁ᵢ (1 − εᵢ) τ₂ᵢ
//!   + F_sky · Σ wᵢ L_DEᵢ (1 − εᵢ) τ₂ᵢ + F_sky · Σ wᵢ L_DSᵢ (1 − εᵢ) τ₂ᵢ
//!   + (1 − F_sky) · Σ wᵢ L(λᵢ, T_gnd) (1 − εᵢ) τ₂ᵢ
//!   + Σ wᵢ L_UEᵢ + Σ wᵢ L_USᵢ.
//!
//! Every sum depends on the material (εᵢ = ε(0, λᵢ)), the target→sensor
//! path (τ₂, L_UE, L_US) and frame constants only: [`DiffuseCoeffs`] holds
//! them; a sample supplies I·max(0, cos θ_S), F_sky and T. The emitted sum
//! A(T) = Σ cᵢ L(λᵢ, T), cᵢ = wᵢ εᵢ τ₂ᵢ, is the cubic Hermite interpolant of
//! A on nodes every [`DT_K`] over [[`T_LO_K`], [`T_HI_K`]) with the exact
//! slopes A′(T_k) = Σ cᵢ ∂L/∂T(λᵢ, T_k) (Fritsch & Carlson 1980, SIAM J.
//! Numer. Anal. 17, the Hermite form). Hermite interpolation is linear in
//! its data, so this equals Σ cᵢ Hᵢ(T) with Hᵢ each bin's own interpolant,
//! whose error is at most h⁴/384·max|∂⁴L/∂T⁴| (h = 0.25 K): below 2e-8
//! relative from 150 K in MWIR and LWIR (3 µm at 150 K is the worst bin);
//! measured against direct Planck sums: 1.7e-9 in MWIR (at 150 K), 7e-12 in
//! LWIR, i.e. about 1e-8 K in apparent temperature. Outside the table the
//! sum is evaluated directly.
//!
//! The node values are built lazily per 8-K segment, once: a shared
//! per-bin table [`PlanckTable`] (L and h·∂L/∂T per bin and node) and, per
//! coefficient vector, its band sums ([`BandTable`]). A value depends on
//! its key only, so results do not depend on the order or the thread that
//! built them.

use std::hash::{BuildHasher, Hash};
use std::sync::{Arc, OnceLock, RwLock};

use rustc_hash::{FxBuildHasher, FxHashMap};

use super::equations::{PathRadiance, RadianceTerms, SkyRadiance, SunIllumination, case1_diffuse};
use super::planck::{planck_dt_w_m2_sr_um_k, planck_radiance_w_m2_sr_um};
use super::spectral::Band;

/// Lowest temperature of the table, K.
pub const T_LO_K: f64 = 150.0;
/// Node spacing, K.
pub const DT_K: f64 = 0.25;
/// Cells per lazily built segment (8 K).
const CELLS: usize = 32;
/// Segments: the table spans [T_LO_K, T_HI_K).
const SEGMENTS: usize = 32;
/// End of the table, K (406 K).
pub const T_HI_K: f64 = T_LO_K + DT_K * (CELLS * SEGMENTS) as f64;

/// The segment, the node within it and the fraction u ∈ [0, 1) of the cell
/// that holds `temp_k`; `None` outside the table (or NaN).
fn locate(temp_k: f64) -> Option<(usize, usize, f64)> {
    if !(T_LO_K..T_HI_K).contains(&temp_k) {
        return None;
    }
    let x = (temp_k - T_LO_K) / DT_K;
    let cell = (x.floor() as usize).min(CELLS * SEGMENTS - 1);
    Some((cell / CELLS, cell % CELLS, x - cell as f64))
}

/// Cubic Hermite basis h00, h10, h01, h11 at u ∈ [0, 1].
fn hermite_basis(u: f64) -> [f64; 4] {
    let (u2, u3) = (u * u, u * u * u);
    [
        2.0 * u3 - 3.0 * u2 + 1.0,
        u3 - 2.0 * u2 + u,
        3.0 * u2 - 2.0 * u3,
        u3 - u2,
    ]
}

/// Per-bin Planck radiance L(λᵢ, T_k) and tangent h·∂L/∂T(λᵢ, T_k) at the
/// table's nodes, W m⁻² sr⁻¹ µm⁻¹, for one band's bins (shared by a frame).
pub struct PlanckTable {
    wavelength_um: Vec<f64>,
    /// Per segment: node-major, for each node the n values L then the n
    /// tangents.
    segments: Vec<OnceLock<Box<[f64]>>>,
}

impl PlanckTable {
    /// A table over the wavelengths `wavelength_um` (its segments are
    /// filled on first use).
    pub fn new(wavelength_um: &[f64]) -> Self {
        PlanckTable {
            wavelength_um: wavelength_um.to_vec(),
            segments: (0..SEGMENTS).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Number of wavelengths.
    pub fn len(&self) -> usize {
        self.wavelength_um.len()
    }

    /// Whether there are no wavelengths.
    pub fn is_empty(&self) -> bool {
        self.wavelength_um.is_empty()
    }

    fn segment(&self, s: usize) -> &[f64] {
        self.segments[s].get_or_init(|| {
            let mut v = Vec::with_capacity((CELLS + 1) * 2 * self.len());
            for j in 0..=CELLS {
                let t = T_LO_K + DT_K * (s * CELLS + j) as f64;
                v.extend(
                    self.wavelength_um
                        .iter()
                        .map(|&wl| planck_radiance_w_m2_sr_um(wl, t)),
                );
                v.extend(
                    self.wavelength_um
                        .iter()
                        .map(|&wl| planck_dt_w_m2_sr_um_k(wl, t) * DT_K),
                );
            }
            v.into_boxed_slice()
        })
    }

    /// Σ cᵢ L(λᵢ, T) evaluated directly, bin by bin.
    pub fn direct(&self, coeffs: &[f64], temp_k: f64) -> f64 {
        coeffs
            .iter()
            .zip(&self.wavelength_um)
            .map(|(c, &wl)| c * planck_radiance_w_m2_sr_um(wl, temp_k))
            .sum()
    }
}

/// A(T) = Σ cᵢ L(λᵢ, T) for one coefficient vector c, by table (see the
/// module docs); segments built on first use.
pub struct BandTable {
    coeffs: Box<[f64]>,
    /// Per segment: A at its CELLS + 1 nodes, then the tangents h·A′.
    segments: [OnceLock<Box<[f64; 2 * (CELLS + 1)]>>; SEGMENTS],
}

impl BandTable {
    /// A table of the band integral with the per-bin coefficients
    /// `coeffs` (its segments are filled on first use).
    pub fn new(coeffs: Vec<f64>) -> Self {
        BandTable {
            coeffs: coeffs.into_boxed_slice(),
            segments: std::array::from_fn(|_| OnceLock::new()),
        }
    }

    /// Σ cᵢ L(λᵢ, T), W m⁻² sr⁻¹ µm⁻¹ when c carries the band weights.
    pub fn eval(&self, planck: &PlanckTable, temp_k: f64) -> f64 {
        let Some((s, j, u)) = locate(temp_k) else {
            return planck.direct(&self.coeffs, temp_k);
        };
        let a = self.segments[s].get_or_init(|| {
            let n = planck.len();
            let p = planck.segment(s);
            let mut a = Box::new([0.0; 2 * (CELLS + 1)]);
            for k in 0..=CELLS {
                let node = &p[k * 2 * n..(k + 1) * 2 * n];
                let dot = |x: &[f64]| self.coeffs.iter().zip(x).map(|(c, v)| c * v).sum();
                a[k] = dot(&node[..n]);
                a[CELLS + 1 + k] = dot(&node[n..]);
            }
            a
        });
        let [h00, h10, h01, h11] = hermite_basis(u);
        h00 * a[j] + h10 * a[CELLS + 1 + j] + h01 * a[j + 1] + h11 * a[CELLS + 2 + j]
    }
}

/// The spectra, on a band's bins, that eq. 1 needs for one material seen
/// along one path.
pub struct DiffuseSpectra<'a> {
    /// ε(0, λᵢ) of the material.
    pub emissivity: &'a [f64],
    /// E_S at the earth-sun distance, W m⁻² µm⁻¹.
    pub e_sun_exo_w_m2_um: &'a [f64],
    /// τ₁ of the sun→surface path.
    pub tau1: &'a [f64],
    /// Sky-dome L_DE, W m⁻² sr⁻¹ µm⁻¹.
    pub sky_dome_l_de: &'a [f64],
    /// Sky-dome L_DS, W m⁻² sr⁻¹ µm⁻¹.
    pub sky_dome_l_ds: &'a [f64],
    /// The target→sensor path τ₂.
    pub tau2: &'a [f64],
    /// The target→sensor path thermal radiance L_UE, W m⁻² sr⁻¹ µm⁻¹.
    pub l_ue_w_m2_sr_um: &'a [f64],
    /// The target→sensor path solar-scattered radiance L_US, W m⁻² sr⁻¹ µm⁻¹.
    pub l_us_w_m2_sr_um: &'a [f64],
    /// L(λᵢ, T_gnd) of the ground the facet sees, W m⁻² sr⁻¹ µm⁻¹.
    pub ground_blackbody: &'a [f64],
}

/// The band sums of eq. 1 for one (material, path): see the module docs.
pub struct DiffuseCoeffs {
    /// The terms for I·max(0, cos θ_S) = 1, F_sky = 1 (sky terms) and
    /// F_gnd = 1 (`reflected_background_emitted`), with `emitted` = 0.
    unit: RadianceTerms,
    /// The emitted sum A(T), cᵢ = wᵢ εᵢ τ₂ᵢ.
    emitted: BandTable,
    /// Σ wᵢ εᵢ: the band-averaged emissivity at normal view.
    pub emissivity: f64,
}

impl DiffuseCoeffs {
    /// The sums of eq. 1's per-bin terms ([`case1_diffuse`], the same
    /// function the spectral loop calls) over `band`.
    pub fn new(band: &Band, s: &DiffuseSpectra) -> Self {
        let mut unit = RadianceTerms::default();
        let mut c = Vec::with_capacity(band.len());
        let mut emissivity = 0.0;
        for (i, &w) in band.weights.iter().enumerate() {
            let e = s.emissivity[i];
            let path = PathRadiance {
                tau2: s.tau2[i],
                l_ue_w_m2_sr_um: s.l_ue_w_m2_sr_um[i],
                l_us_w_m2_sr_um: s.l_us_w_m2_sr_um[i],
            };
            let sun = SunIllumination {
                e_sun_exo_w_m2_um: s.e_sun_exo_w_m2_um[i],
                tau1: s.tau1[i],
                cos_incidence: 1.0,
                sun_flag: 1.0,
            };
            let sky = SkyRadiance {
                l_de_w_m2_sr_um: s.sky_dome_l_de[i],
                l_ds_w_m2_sr_um: s.sky_dome_l_ds[i],
            };
            // L_T = 1: `emitted` is then εᵢ τ₂ᵢ, the coefficient of L(λᵢ, T).
            let mut t = case1_diffuse(e, 1.0, &sun, &sky, &path);
            c.push(w * t.emitted);
            t.emitted = 0.0;
            t.reflected_background_emitted = s.ground_blackbody[i] * (1.0 - e) * path.tau2;
            unit.accumulate(&t, w);
            emissivity += w * e;
        }
        DiffuseCoeffs {
            unit,
            emitted: BandTable::new(c),
            emissivity,
        }
    }

    /// The band-integrated terms of a sample at temperature `temp_k` with
    /// `sun` = I·max(0, cos θ_S) and sky view factor `f_sky`.
    pub fn terms(&self, planck: &PlanckTable, temp_k: f64, sun: f64, f_sky: f64) -> RadianceTerms {
        let u = &self.unit;
        RadianceTerms {
            emitted: self.emitted.eval(planck, temp_k),
            reflected_solar: sun * u.reflected_solar,
            reflected_sky_thermal: f_sky * u.reflected_sky_thermal,
            reflected_sky_scattered: f_sky * u.reflected_sky_scattered,
            reflected_background_emitted: if f_sky < 1.0 {
                (1.0 - f_sky) * u.reflected_background_emitted
            } else {
                0.0
            },
            reflected_background_solar: 0.0,
            path_thermal: u.path_thermal,
            path_scattered: u.path_scattered,
        }
    }
}

/// Shards of a [`Memo`] (a power of two).
const SHARDS: usize = 64;

/// A concurrent memo: each value is computed once per key and depends on its
/// key only (so results do not depend on thread count or order). Lookups
/// take a read lock of one of [`SHARDS`] shards chosen by the key's hash;
/// two threads that build the same value at once keep the first inserted.
pub struct Memo<K, V> {
    shards: Vec<RwLock<FxHashMap<K, Arc<V>>>>,
}

impl<K: Hash + Eq, V> Default for Memo<K, V> {
    fn default() -> Self {
        Memo {
            shards: (0..SHARDS).map(|_| RwLock::default()).collect(),
        }
    }
}

impl<K: Hash + Eq, V> Memo<K, V> {
    /// The value of `key`, built by `build` on first use.
    pub fn get_or_try_insert<E>(
        &self,
        key: K,
        build: impl FnOnce(&K) -> Result<V, E>,
    ) -> Result<Arc<V>, E> {
        // Middle bits: hashbrown uses the low bits for the bucket and the
        // top 7 as tags, which must vary inside one shard.
        let shard = &self.shards[(FxBuildHasher.hash_one(&key) >> 32) as usize % SHARDS];
        if let Some(v) = shard.read().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return Ok(v.clone());
        }
        let v = Arc::new(build(&key)?);
        let mut map = shard.write().unwrap_or_else(|e| e.into_inner());
        Ok(map.entry(key).or_insert(v).clone())
    }

    /// Number of values held.
    pub fn len(&self) -> usize {
        self.shards
            .iter()
            .map(|s| s.read().unwrap_or_else(|e| e.into_inner()).len())
            .sum()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiometry::{SpectralGrid, SpectralResponse};

    fn bands() -> Vec<(Band, Vec<f64>)> {
        [SpectralResponse::mwir(), SpectralResponse::lwir()]
            .into_iter()
            .map(|r| {
                // The atmosphere tables' 20 cm⁻¹ grid, as the renders use.
                let grid = SpectralGrid::uniform(500.0, 20.0, 150);
                let band = Band::new(&grid, &r).unwrap();
                let wl = band.wavenumber_cm1.iter().map(|v| 1e4 / v).collect();
                (band, wl)
            })
            .collect()
    }

    /// The table interpolant against direct Planck band sums Σ cᵢ L(λᵢ, T)
    /// over 150-406 K (nodes and cell interiors), for the plain band
    /// weights and for weights times a spectrally varying εᵢτ₂ᵢ: within
    /// 2e-8 relative (the h⁴/384·max|L⁗| bound of the module docs, 0.25 K
    /// nodes). Outside the table the direct sum is used.
    #[test]
    fn t_table_matches_direct_planck_band_sums() {
        for (band, wl) in bands() {
            let planck = PlanckTable::new(&wl);
            let vectors = [
                band.weights.clone(),
                band.weights
                    .iter()
                    .enumerate()
                    .map(|(i, w)| w * (0.6 + 0.35 * (i as f64 * 0.7).sin()) * 0.8)
                    .collect::<Vec<_>>(),
            ];
            for c in vectors {
                let table = BandTable::new(c.clone());
                let mut worst = 0.0f64;
                let mut t = T_LO_K;
                while t < T_HI_K {
                    let direct: f64 = c
                        .iter()
                        .zip(&wl)
                        .map(|(c, &l)| c * planck_radiance_w_m2_sr_um(l, t))
                        .sum();
                    worst = worst.max((table.eval(&planck, t) / direct - 1.0).abs());
                    t += 0.0937;
                }
                assert!(
                    worst < 2e-8,
                    "{}: worst relative error {worst:e}",
                    band.label
                );
                // The plain weights reproduce the band's own Planck integral.
                for t in [120.0, 149.99, 406.0, 500.0, 1500.0] {
                    let d = planck.direct(&c, t);
                    assert_eq!(table.eval(&planck, t), d, "{t} K outside the table");
                }
            }
            let t = 287.3;
            let a = BandTable::new(band.weights.clone()).eval(&planck, t);
            assert!((a / band.planck_w_m2_sr_um(t) - 1.0).abs() < 2e-8);
        }
    }

    #[test]
    fn table_edges_and_nan() {
        assert_eq!(locate(T_LO_K), Some((0, 0, 0.0)));
        assert_eq!(locate(T_HI_K), None);
        assert_eq!(locate(f64::NAN), None);
        let (s, j, u) = locate(T_HI_K - 1e-9).unwrap();
        assert_eq!((s, j), (SEGMENTS - 1, CELLS - 1));
        assert!(u > 0.99 && u < 1.0);
    }

    /// The memo builds a key once and returns the same value to every
    /// caller; build errors are passed through and not stored.
    #[test]
    fn memo_builds_once() {
        let m: Memo<(i64, i64), f64> = Memo::default();
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let build = |k: &(i64, i64)| -> Result<f64, String> {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Ok((k.0 * 10 + k.1) as f64)
        };
        for _ in 0..3 {
            for k in 0..100 {
                assert_eq!(
                    *m.get_or_try_insert((k, 1), build).unwrap(),
                    (k * 10 + 1) as f64
                );
            }
        }
        assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 100);
        assert_eq!(m.len(), 100);
        assert!(m.get_or_try_insert((-1, 0), |_| Err("no")).is_err());
        assert_eq!(m.len(), 100);
    }
}
