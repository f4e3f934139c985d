//! Atmosphere submodel (docs/models.md, docs/atmosphere-tables.md): LOWTRAN-7 tables of τ₂, L_UE, L_US (vs
//! sensor altitude and view zenith), L_DE, L_DS (vs sky zenith), τ₁ (vs sun
//! zenith) and the exo-atmospheric solar irradiance, per wavenumber; reading
//! (format in docs/atmosphere-tables.md) and interpolation.
//!
//! Use: load once with [`Atmosphere::builtin`] or [`Atmosphere::load`], resample
//! once onto the band's wavenumber bins with [`Atmosphere::resample`]
//! (`band.wavenumber_cm1`), then ask the [`SpectralAtmosphere`] for spectra at
//! any geometry: each is a blend of 2-16 stored spectra written into a
//! caller-provided slice.
//!
//! ```no_run
//! use irsig::atmos::Atmosphere;
//! use irsig::radiometry::{self as rad, Band, SpectralGrid, SpectralResponse};
//! # fn main() -> anyhow::Result<()> {
//! let atm = Atmosphere::builtin("mls")?;                       // once
//! let grid = SpectralGrid::new(atm.wavenumber_cm1().to_vec())?;
//! let band = Band::new(&grid, &SpectralResponse::lwir())?;      // bins with R > 0
//! let sa = atm.resample(&band.wavenumber_cm1)?;                 // once per band
//! let path = sa.path(3.0, 30.0, 40.0, 90.0)?;                   // per view geometry (cacheable)
//! let dome_de = sa.sky_dome_l_de();
//! let dome_ds = sa.sky_dome_l_ds(40.0)?;                        // once per sun position
//! let mut tau1 = vec![0.0; sa.len()];
//! sa.tau_sun(40.0, &mut tau1)?;                                // τ₁(θ_sun)
//! let terms = rad::integrate_terms(&band, |i| {
//!     let lam_um = 1e4 / band.wavenumber_cm1[i];
//!     rad::case1_diffuse(
//!         0.95,
//!         rad::planck_radiance_w_m2_sr_um(lam_um, 300.0),
//!         &rad::SunIllumination { e_sun_exo_w_m2_um: sa.e_sun_exo()[i],
//!             tau1: tau1[i], cos_incidence: 0.7, sun_flag: 1.0 },
//!         &rad::SkyRadiance { l_de_w_m2_sr_um: dome_de[i], l_ds_w_m2_sr_um: dome_ds[i] },
//!         &rad::PathRadiance { tau2: path.tau2[i], l_ue_w_m2_sr_um: path.l_ue_w_m2_sr_um[i],
//!             l_us_w_m2_sr_um: path.l_us_w_m2_sr_um[i] },
//!     )
//! });
//! let t_app = band.apparent_temp_k(terms.total());
//! # Ok(()) }
//! ```
//!
//! Interpolation (per axis, multilinear):
//! * altitude_km: linear in u(h) = −(e^(−h/2 km) + e^(−h/8 km))/2, a proxy for the
//!   fraction of the absorber column (water vapour scale height ≈ 2 km, dry air
//!   ≈ 8 km) below h; outside the grid → [`AtmosError::OutOfRange`], except
//!   above the top of a table that reaches [`TOP_OF_ATMOSPHERE_KM`] (100 km,
//!   the top of LOWTRAN's model atmospheres and of the shipped tables): a
//!   sensor higher than that (a satellite) is given the top's values, the
//!   path through the whole atmosphere. Above 100 km the air holds about
//!   3·10⁻⁷ of the surface pressure (US 1976: 0.032 Pa), so the path from
//!   there to a satellite absorbs and emits nothing the tables resolve.
//! * transmissions (τ₂, τ₁) are interpolated in ln τ (Beer's law makes ln τ
//!   nearly linear in air mass and absorber column); radiances linearly.
//! * view_zenith_deg: linear in sec θ (optical air mass); 0 ≤ θ ≤ the last grid
//!   angle (85° in the shipped tables), otherwise an error.
//! * sky_zenith_deg: linear in sec θ; between the last grid angle (89°) and 90°
//!   the 89° value is used (documented clamp); above 90° is not sky → error.
//! * sun_zenith_deg: linear in sec θ up to the last grid angle; from there to
//!   90° the value ramps linearly to 0; at and beyond 90° (sun below the
//!   horizon) every sun-dependent term is 0.
//! * rel_azimuth_deg (sun azimuth − view azimuth): folded into [0°, 180°] by
//!   symmetry, linear.
//! * wavenumber: linear; requested wavenumbers outside the table → error.

// Negated float comparisons (`!(x > 0.0)`) are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adjust;
mod error;
pub mod standard;
pub mod table;
pub mod view;

use std::path::{Path, PathBuf};

pub use error::AtmosError;
pub use table::{AtmosTable, Axis, Quantity};

/// The shipped tables (`data/atmos/*.atm.gz`), embedded in the binary as
/// they are shipped (gzip), so that a copied or `cargo install`ed `irsig`
/// needs no data files: (name, gzip bytes).
const EMBEDDED: &[(&str, &[u8])] = &[
    ("mls", include_bytes!("../../data/atmos/mls.atm.gz")),
    (
        "mls_clear",
        include_bytes!("../../data/atmos/mls_clear.atm.gz"),
    ),
    ("mlw", include_bytes!("../../data/atmos/mlw.atm.gz")),
    ("sas", include_bytes!("../../data/atmos/sas.atm.gz")),
    ("saw", include_bytes!("../../data/atmos/saw.atm.gz")),
    (
        "tropical",
        include_bytes!("../../data/atmos/tropical.atm.gz"),
    ),
    ("us1976", include_bytes!("../../data/atmos/us1976.atm.gz")),
];

/// The environment variable naming a data folder that replaces the
/// embedded data: its `atmos/` folder holds the atmosphere tables.
pub const DATA_ENV: &str = "IRSIG_DATA";

/// The folder of atmosphere tables that add to (and, name for name,
/// replace) the embedded ones: `$IRSIG_DATA/atmos` when `IRSIG_DATA` is
/// set, else `None`.
pub fn atmos_dir() -> Option<PathBuf> {
    std::env::var_os(DATA_ENV).map(|d| PathBuf::from(d).join("atmos"))
}

/// Where a shipped table comes from.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TableSource {
    /// Embedded in the binary.
    Embedded,
    /// A file of the `$IRSIG_DATA/atmos` folder.
    File(PathBuf),
}

impl std::fmt::Display for TableSource {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            TableSource::Embedded => f.write_str("embedded in the irsig binary"),
            TableSource::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// The tables of `$IRSIG_DATA/atmos` (name, path), sorted by name; empty
/// when `IRSIG_DATA` is not set, an error when that folder cannot be read.
fn data_dir_tables() -> Result<Vec<(String, PathBuf)>, AtmosError> {
    let Some(dir) = atmos_dir() else {
        return Ok(Vec::new());
    };
    let rd = std::fs::read_dir(&dir).map_err(|e| AtmosError::Io {
        path: format!("{} (${DATA_ENV}/atmos)", dir.display()),
        source: e,
    })?;
    let mut out = Vec::new();
    for e in rd.flatten() {
        let p = e.path();
        let Some(fname) = p.file_name().and_then(|f| f.to_str()) else {
            continue;
        };
        if let Some(name) = fname
            .strip_suffix(".atm.gz")
            .or_else(|| fname.strip_suffix(".atm"))
        {
            out.push((name.to_string(), p));
        }
    }
    out.sort();
    Ok(out)
}

/// The shipped tables: (name, source, description), sorted by name: those
/// embedded in the binary, plus those of `$IRSIG_DATA/atmos` when
/// `IRSIG_DATA` is set (a file there replaces the embedded table of the
/// same name).
pub fn list_builtin() -> Result<Vec<(String, TableSource, String)>, AtmosError> {
    let description = |header: Vec<(String, String)>| {
        header
            .into_iter()
            .find(|(k, _)| k == "description")
            .map(|(_, v)| v)
            .unwrap_or_default()
    };
    let files = data_dir_tables()?;
    let mut out = Vec::new();
    for (name, bytes) in EMBEDDED {
        if !files.iter().any(|(n, _)| n == name) {
            let header = table::read_header_from(*bytes, &format!("embedded table {name}"))?;
            out.push((name.to_string(), TableSource::Embedded, description(header)));
        }
    }
    for (name, p) in files {
        let desc = description(table::read_header(&p)?);
        out.push((name, TableSource::File(p), desc));
    }
    out.sort();
    Ok(out)
}

/// A loaded atmosphere (the stored table).
#[derive(Clone, Debug)]
pub struct Atmosphere {
    /// The table as read.
    pub table: AtmosTable,
}

impl Atmosphere {
    /// Loads a table file.
    pub fn load(path: &Path) -> Result<Self, AtmosError> {
        Ok(Self {
            table: AtmosTable::load(path)?,
        })
    }

    /// Loads a shipped table by name (`mls`, `tropical`, ...): the file of
    /// `$IRSIG_DATA/atmos` when there is one, else the embedded table.
    pub fn builtin(name: &str) -> Result<Self, AtmosError> {
        if let Some((_, p)) = data_dir_tables()?.iter().find(|(n, _)| n == name) {
            return Self::load(p);
        }
        match EMBEDDED.iter().find(|(n, _)| *n == name) {
            Some((n, bytes)) => {
                let mut table = AtmosTable::from_bytes(bytes, &format!("embedded table {n}"))?;
                table.source = PathBuf::from(format!("embedded:{n}.atm.gz"));
                Ok(Self { table })
            }
            None => Err(AtmosError::Unknown {
                name: name.into(),
                available: list_builtin()?
                    .iter()
                    .map(|(n, _, _)| n.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }

    /// A shipped name, or else a path to a table file.
    pub fn by_name_or_path(spec: &str) -> Result<Self, AtmosError> {
        let p = Path::new(spec);
        if p.is_file() {
            Self::load(p)
        } else {
            Self::builtin(spec)
        }
    }

    /// The atmosphere's name (the table's `name`).
    pub fn name(&self) -> &str {
        &self.table.name
    }

    /// The table's own wavenumber grid, cm⁻¹.
    pub fn wavenumber_cm1(&self) -> &[f64] {
        &self.table.wavenumber_cm1
    }

    /// All quantities on the table's own wavenumbers (no spectral interpolation).
    pub fn full(&self) -> SpectralAtmosphere {
        self.resample(&self.table.wavenumber_cm1.clone())
            .expect("own grid is in range")
    }

    /// Interpolates every quantity (linearly in wavenumber) onto `wavenumber_cm1`
    /// (e.g. a band's bins). Wavenumbers outside the table give an error.
    pub fn resample(&self, wavenumber_cm1: &[f64]) -> Result<SpectralAtmosphere, AtmosError> {
        let src = &self.table.wavenumber_cm1;
        let (lo, hi) = (src[0], src[src.len() - 1]);
        let mut idx = Vec::with_capacity(wavenumber_cm1.len());
        for &w in wavenumber_cm1 {
            if !(w >= lo - 1e-9 && w <= hi + 1e-9) {
                return Err(AtmosError::OutOfRange {
                    atmosphere: self.table.name.clone(),
                    quantity: "all".into(),
                    axis: "wavenumber_cm1".into(),
                    value: w,
                    min: lo,
                    max: hi,
                });
            }
            let i = src
                .partition_point(|&x| x <= w)
                .clamp(1, src.len().max(2) - 1);
            if src.len() == 1 {
                idx.push((0, 0, 0.0));
            } else {
                let t = ((w - src[i - 1]) / (src[i] - src[i - 1])).clamp(0.0, 1.0);
                idx.push((i - 1, i, t));
            }
        }
        let field = |name: &str| -> Field {
            let q = self.table.quantity(name).expect("validated at load");
            let nw = idx.len();
            let mut data = Vec::with_capacity(q.n_spectra() * nw);
            for s in 0..q.n_spectra() {
                let spec = &q.data[s * q.n_wavenumber..(s + 1) * q.n_wavenumber];
                data.extend(
                    idx.iter()
                        .map(|&(a, b, t)| spec[a] + t * (spec[b] - spec[a])),
                );
            }
            let log = name.starts_with("tau");
            if log {
                data.iter_mut().for_each(|v| *v = v.max(TAU_FLOOR).ln());
            }
            Field {
                name: q.name.clone(),
                axes: q.axes.clone(),
                data,
                nw,
                log,
            }
        };
        let e_sun = field("e_sun_exo").data;
        let mut s = SpectralAtmosphere {
            name: self.table.name.clone(),
            wavenumber_cm1: wavenumber_cm1.to_vec(),
            tau_path: field("tau_path"),
            l_ue: field("l_ue"),
            l_us: field("l_us"),
            l_de: field("l_de"),
            l_ds: field("l_ds"),
            tau_sun: field("tau_sun"),
            e_sun_exo: e_sun,
            l_de_dome: Vec::new(),
        };
        s.l_de_dome = s.dome_average(|sa, z, _az, out| sa.l_de(z, out))?;
        Ok(s)
    }
}

/// Kinds of axis transform (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
enum AxisKind {
    Linear,
    ViewZenith,
    SkyZenith,
    SunZenith,
    RelAzimuth,
}

fn axis_kind(name: &str) -> AxisKind {
    match name {
        "view_zenith_deg" => AxisKind::ViewZenith,
        "sky_zenith_deg" => AxisKind::SkyZenith,
        "sun_zenith_deg" => AxisKind::SunZenith,
        "rel_azimuth_deg" => AxisKind::RelAzimuth,
        _ => AxisKind::Linear,
    }
}

/// Altitude coordinate for interpolation (see the module docs).
fn altitude_coord(h_km: f64) -> f64 {
    -0.5 * ((-h_km / 2.0).exp() + (-h_km / 8.0).exp())
}

/// The height (km) from which a table's top stands for the top of the
/// atmosphere: a query above the top of a table that reaches it takes the
/// top's values (see the module docs); a table ending lower refuses it.
pub const TOP_OF_ATMOSPHERE_KM: f64 = 100.0;

/// Floor for ln τ interpolation.
const TAU_FLOOR: f64 = 1e-30;

fn sec_deg(d: f64) -> f64 {
    1.0 / d.to_radians().cos()
}

/// A quantity resampled onto the working wavenumbers.
#[derive(Clone, Debug)]
struct Field {
    name: String,
    axes: Vec<Axis>,
    /// Values, or ln(max(value, TAU_FLOOR)) when `log`.
    data: Vec<f64>,
    nw: usize,
    /// Interpolate in logarithms (transmissions).
    log: bool,
}

/// (lower index, upper index, weight of upper) per axis, plus a global scale.
type Stencil = (Vec<(usize, usize, f64)>, f64);

impl Field {
    fn stencil(&self, atmosphere: &str, coords: &[f64]) -> Result<Stencil, AtmosError> {
        let mut st = Vec::with_capacity(self.axes.len());
        let mut scale = 1.0;
        for (ax, &x) in self.axes.iter().zip(coords) {
            let v = &ax.values;
            let (min, max) = (v[0], v[v.len() - 1]);
            let err = || AtmosError::OutOfRange {
                atmosphere: atmosphere.into(),
                quantity: self.name.clone(),
                axis: ax.name.clone(),
                value: x,
                min,
                max,
            };
            if !x.is_finite() {
                return Err(err());
            }
            let kind = axis_kind(&ax.name);
            let mut x = x;
            match kind {
                AxisKind::RelAzimuth => {
                    x = (x + 180.0).rem_euclid(360.0) - 180.0;
                    x = x.abs();
                    x = x.clamp(min, max);
                }
                AxisKind::SkyZenith => {
                    if !(0.0..=90.0).contains(&x) {
                        return Err(err());
                    }
                    x = x.min(max);
                }
                AxisKind::SunZenith => {
                    if x < min {
                        return Err(err());
                    }
                    if x >= 90.0 {
                        scale = 0.0;
                        x = max;
                    } else if x > max {
                        scale *= (90.0 - x) / (90.0 - max);
                        x = max;
                    }
                }
                AxisKind::Linear
                    if ax.name == "altitude_km" && x > max && max >= TOP_OF_ATMOSPHERE_KM =>
                {
                    // above the top of the atmosphere: the top's path
                    x = max;
                }
                AxisKind::ViewZenith | AxisKind::Linear => {
                    let tol = 1e-9 * (1.0 + max.abs());
                    if x < min - tol || x > max + tol {
                        return Err(err());
                    }
                    x = x.clamp(min, max);
                }
            }
            if v.len() == 1 {
                st.push((0, 0, 0.0));
                continue;
            }
            let i = v.partition_point(|&g| g <= x).clamp(1, v.len() - 1);
            let (a, b) = (v[i - 1], v[i]);
            let t = match kind {
                AxisKind::ViewZenith | AxisKind::SkyZenith | AxisKind::SunZenith if b < 90.0 => {
                    (sec_deg(x) - sec_deg(a)) / (sec_deg(b) - sec_deg(a))
                }
                AxisKind::Linear if ax.name == "altitude_km" => {
                    (altitude_coord(x) - altitude_coord(a))
                        / (altitude_coord(b) - altitude_coord(a))
                }
                _ => (x - a) / (b - a),
            };
            st.push((i - 1, i, t.clamp(0.0, 1.0)));
        }
        Ok((st, scale))
    }

    /// out = Σ corners weight · spectrum.
    fn eval(&self, atmosphere: &str, coords: &[f64], out: &mut [f64]) -> Result<(), AtmosError> {
        assert_eq!(
            coords.len(),
            self.axes.len(),
            "{}: wrong number of coordinates",
            self.name
        );
        assert_eq!(
            out.len(),
            self.nw,
            "{}: output slice has the wrong length",
            self.name
        );
        let (st, scale) = self.stencil(atmosphere, coords)?;
        out.iter_mut().for_each(|o| *o = 0.0);
        if scale == 0.0 {
            return Ok(());
        }
        let d = st.len();
        for corner in 0..(1usize << d) {
            let mut w = scale;
            let mut flat = 0;
            for (k, ax) in self.axes.iter().enumerate() {
                let (i0, i1, t) = st[k];
                let hi = (corner >> k) & 1 == 1;
                w *= if hi { t } else { 1.0 - t };
                flat = flat * ax.values.len() + if hi { i1 } else { i0 };
            }
            if w == 0.0 {
                continue;
            }
            let spec = &self.data[flat * self.nw..(flat + 1) * self.nw];
            for (o, s) in out.iter_mut().zip(spec) {
                *o += w * s;
            }
        }
        if self.log {
            // weights summed to `scale`; undo it before exponentiating
            out.iter_mut().for_each(|o| {
                let v = (*o / scale).exp();
                *o = if v <= TAU_FLOOR * 1.000_001 {
                    0.0
                } else {
                    (v * scale).min(1.0)
                };
            });
        }
        Ok(())
    }
}

/// Path spectra target→sensor on the working wavenumbers.
#[derive(Clone, Debug, PartialEq)]
pub struct PathSpectra {
    /// Transmittance τ₂.
    pub tau2: Vec<f64>,
    /// W m⁻² sr⁻¹ µm⁻¹
    pub l_ue_w_m2_sr_um: Vec<f64>,
    /// W m⁻² sr⁻¹ µm⁻¹
    pub l_us_w_m2_sr_um: Vec<f64>,
}

/// An atmosphere resampled onto working wavenumbers (e.g. a band's bins). All
/// radiances are W m⁻² sr⁻¹ µm⁻¹ and irradiances W m⁻² µm⁻¹ at each wavenumber.
/// Methods write `len()` values into `out` and fail only for geometry outside
/// the table (see the module docs for the rules).
#[derive(Clone, Debug)]
pub struct SpectralAtmosphere {
    /// The atmosphere's name.
    pub name: String,
    /// The working wavenumbers, cm⁻¹.
    pub wavenumber_cm1: Vec<f64>,
    tau_path: Field,
    l_ue: Field,
    l_us: Field,
    l_de: Field,
    l_ds: Field,
    tau_sun: Field,
    e_sun_exo: Vec<f64>,
    l_de_dome: Vec<f64>,
}

impl SpectralAtmosphere {
    /// Number of working wavenumbers.
    pub fn len(&self) -> usize {
        self.wavenumber_cm1.len()
    }

    /// Whether there are no working wavenumbers.
    pub fn is_empty(&self) -> bool {
        self.wavenumber_cm1.is_empty()
    }

    /// τ₂: transmission target→sensor for a sensor at `altitude_km` seen from the
    /// target at `view_zenith_deg` (zenith angle at the target, θ_E).
    pub fn tau_path(
        &self,
        altitude_km: f64,
        view_zenith_deg: f64,
        out: &mut [f64],
    ) -> Result<(), AtmosError> {
        self.tau_path
            .eval(&self.name, &[altitude_km, view_zenith_deg], out)
    }

    /// L_UE: path thermal radiance at the sensor.
    pub fn l_ue(
        &self,
        altitude_km: f64,
        view_zenith_deg: f64,
        out: &mut [f64],
    ) -> Result<(), AtmosError> {
        self.l_ue
            .eval(&self.name, &[altitude_km, view_zenith_deg], out)
    }

    /// L_US: path solar-scattered radiance at the sensor. `rel_azimuth_deg` is the
    /// sun's azimuth minus the azimuth of the sensor's line of sight (0 = the
    /// sensor looks toward the sun).
    pub fn l_us(
        &self,
        sun_zenith_deg: f64,
        rel_azimuth_deg: f64,
        altitude_km: f64,
        view_zenith_deg: f64,
        out: &mut [f64],
    ) -> Result<(), AtmosError> {
        self.l_us.eval(
            &self.name,
            &[
                sun_zenith_deg,
                rel_azimuth_deg,
                altitude_km,
                view_zenith_deg,
            ],
            out,
        )
    }

    /// τ₂, L_UE and L_US together.
    pub fn path(
        &self,
        altitude_km: f64,
        view_zenith_deg: f64,
        sun_zenith_deg: f64,
        rel_azimuth_deg: f64,
    ) -> Result<PathSpectra, AtmosError> {
        let n = self.len();
        let mut p = PathSpectra {
            tau2: vec![0.0; n],
            l_ue_w_m2_sr_um: vec![0.0; n],
            l_us_w_m2_sr_um: vec![0.0; n],
        };
        self.tau_path(altitude_km, view_zenith_deg, &mut p.tau2)?;
        self.l_ue(altitude_km, view_zenith_deg, &mut p.l_ue_w_m2_sr_um)?;
        self.l_us(
            sun_zenith_deg,
            rel_azimuth_deg,
            altitude_km,
            view_zenith_deg,
            &mut p.l_us_w_m2_sr_um,
        )?;
        Ok(p)
    }

    /// L_DE(θ_SK): sky thermal radiance arriving at the ground from sky zenith θ_SK.
    pub fn l_de(&self, sky_zenith_deg: f64, out: &mut [f64]) -> Result<(), AtmosError> {
        self.l_de.eval(&self.name, &[sky_zenith_deg], out)
    }

    /// L_DS(θ_SK): sky solar-scattered radiance from sky zenith θ_SK; `rel_azimuth_deg`
    /// = sun azimuth − azimuth of the sky direction.
    pub fn l_ds(
        &self,
        sun_zenith_deg: f64,
        rel_azimuth_deg: f64,
        sky_zenith_deg: f64,
        out: &mut [f64],
    ) -> Result<(), AtmosError> {
        self.l_ds.eval(
            &self.name,
            &[sun_zenith_deg, rel_azimuth_deg, sky_zenith_deg],
            out,
        )
    }

    /// τ₁: transmission sun→ground at sun zenith θ (0 when the sun is down).
    pub fn tau_sun(&self, sun_zenith_deg: f64, out: &mut [f64]) -> Result<(), AtmosError> {
        self.tau_sun.eval(&self.name, &[sun_zenith_deg], out)
    }

    /// E_S: exo-atmospheric solar spectral irradiance (mean earth-sun distance), W m⁻² µm⁻¹.
    pub fn e_sun_exo(&self) -> &[f64] {
        &self.e_sun_exo
    }

    /// τ₁ E_S: direct solar irradiance at the ground on a surface normal to the sun, W m⁻² µm⁻¹.
    pub fn sun_irradiance_ground(
        &self,
        sun_zenith_deg: f64,
        out: &mut [f64],
    ) -> Result<(), AtmosError> {
        self.tau_sun(sun_zenith_deg, out)?;
        for (o, e) in out.iter_mut().zip(&self.e_sun_exo) {
            *o *= e;
        }
        Ok(())
    }

    /// Sky-dome average of L_DE, the L_DE(λ) of eq. 1:
    /// (1/π) ∫∫ L_DE(θ) cos θ sin θ dθ dφ over the upper hemisphere.
    pub fn sky_dome_l_de(&self) -> &[f64] {
        &self.l_de_dome
    }

    /// Sky-dome average of L_DS (eq. 1's L_DS(λ)) for the sun at `sun_zenith_deg`.
    pub fn sky_dome_l_ds(&self, sun_zenith_deg: f64) -> Result<Vec<f64>, AtmosError> {
        self.dome_average(|sa, z, az, out| sa.l_ds(sun_zenith_deg, az, z, out))
    }

    /// (1/π) ∫₀^{2π} ∫₀^{π/2} L(θ, φ) cos θ sin θ dθ dφ by the midpoint rule in
    /// μ² = cos²θ (90 rings of equal weight) and 36 azimuths over [0, 180] (by symmetry).
    fn dome_average<F>(&self, f: F) -> Result<Vec<f64>, AtmosError>
    where
        F: Fn(&Self, f64, f64, &mut [f64]) -> Result<(), AtmosError>,
    {
        const RINGS: usize = 90;
        const AZ: usize = 36;
        let n = self.len();
        let mut acc = vec![0.0; n];
        let mut tmp = vec![0.0; n];
        // with s = μ², (1/π)∫∫ L μ dμ dφ = (1/2π) ∫ ds ∫ dφ L: equal-weight rings
        for r in 0..RINGS {
            let s = (r as f64 + 0.5) / RINGS as f64;
            let zen = s.sqrt().acos().to_degrees();
            for a in 0..AZ {
                let az = (a as f64 + 0.5) * 180.0 / AZ as f64;
                f(self, zen, az, &mut tmp)?;
                for (o, t) in acc.iter_mut().zip(&tmp) {
                    *o += t / (RINGS * AZ) as f64;
                }
            }
        }
        Ok(acc)
    }
}
