//! Angular spectral emissivity ε(θ, λ): tabulated, or from Fresnel's equations for
//! a specular surface with complex refractive index n + ik. Reflectance of an
//! opaque surface is ρ = 1 − ε (Kirchhoff), as in the seed's eqs. 1-4.

use super::RadiometryError;

/// Fresnel power reflectances of a smooth interface from a non-absorbing medium of
/// index 1 (air) into a medium of complex index N = n + ik, at incidence `incidence_deg`.
///
/// rₛ = (cos θ − N cos θₜ)/(cos θ + N cos θₜ), rₚ = (N cos θ − cos θₜ)/(N cos θ + cos θₜ),
/// with N cos θₜ = √(N² − sin²θ) (principal branch, Im ≥ 0) (Born & Wolf,
/// *Principles of Optics*, §1.5 and §14.2). Returns (Rₛ, Rₚ, (Rₛ+Rₚ)/2) — the last
/// is the unpolarised reflectance.
pub fn fresnel_reflectance(n: f64, k: f64, incidence_deg: f64) -> (f64, f64, f64) {
    let th = incidence_deg.clamp(0.0, 90.0).to_radians();
    let (s, c) = th.sin_cos();
    let nn = C::new(n, k);
    let n2 = nn.mul(nn);
    // N cos θt = sqrt(N² − sin²θ)
    let nct = n2.sub(C::new(s * s, 0.0)).sqrt();
    let ci = C::new(c, 0.0);
    let rs = ci.sub(nct).div(ci.add(nct));
    // rp = (N² cos θ − N cos θt) / (N² cos θ + N cos θt)
    let n2c = n2.mul(ci);
    let rp = n2c.sub(nct).div(n2c.add(nct));
    let (rs2, rp2) = (rs.norm2(), rp.norm2());
    (rs2, rp2, 0.5 * (rs2 + rp2))
}

/// Emissivity of an opaque specular surface from Fresnel: ε(θ) = 1 − R_unpolarised(θ).
pub fn fresnel_emissivity(n: f64, k: f64, incidence_deg: f64) -> f64 {
    1.0 - fresnel_reflectance(n, k, incidence_deg).2
}

#[derive(Clone, Copy, Debug)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root (Re ≥ 0).
    fn sqrt(self) -> Self {
        let r = self.norm2().sqrt();
        let re = ((r + self.re) * 0.5).max(0.0).sqrt();
        let im = ((r - self.re) * 0.5).max(0.0).sqrt().copysign(self.im);
        Self::new(re, im)
    }
}

/// How a material's emissivity depends on angle and wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Emissivity {
    /// Grey and Lambertian: ε independent of θ and λ.
    Constant(f64),
    /// Tabulated ε(θ, λ), bilinear.
    Table(EmissivityTable),
    /// Smooth dielectric/metal: ε(θ) = 1 − R_Fresnel(n, k, θ), grey in λ.
    Fresnel {
        /// Refractive index (real part).
        n: f64,
        /// Extinction coefficient (imaginary part of the index).
        k: f64,
    },
}

impl Emissivity {
    /// ε at view/incidence angle θ (deg from the surface normal) and wavelength λ (µm).
    pub fn at(&self, angle_deg: f64, wavelength_um: f64) -> f64 {
        match self {
            Emissivity::Constant(e) => *e,
            Emissivity::Table(t) => t.at(angle_deg, wavelength_um),
            Emissivity::Fresnel { n, k } => fresnel_emissivity(*n, *k, angle_deg),
        }
    }

    /// ε at one angle for every wavelength of `wavelength_um`, into `out`
    /// (same length): the values of [`Self::at`], bit for bit, with the
    /// angle's bracket or Fresnel factor computed once instead of per
    /// wavelength (the spectral loop of a specular pixel needs a spectrum
    /// at its view angle).
    pub fn spectrum_at(&self, angle_deg: f64, wavelength_um: &[f64], out: &mut [f64]) {
        debug_assert_eq!(wavelength_um.len(), out.len());
        match self {
            Emissivity::Constant(e) => out.fill(*e),
            Emissivity::Table(t) => {
                let (ia, ta) = bracket(&t.angles_deg, angle_deg);
                for (o, &wl) in out.iter_mut().zip(wavelength_um) {
                    *o = t.at_bracket(ia, ta, wl);
                }
            }
            Emissivity::Fresnel { n, k } => out.fill(fresnel_emissivity(*n, *k, angle_deg)),
        }
    }

    /// Reflectance ρ = 1 − ε (opaque surface, Kirchhoff).
    pub fn reflectance(&self, angle_deg: f64, wavelength_um: f64) -> f64 {
        1.0 - self.at(angle_deg, wavelength_um)
    }
}

/// ε(θ, λ) on a grid of angles (deg, ascending, within 0-90) and wavelengths (µm,
/// ascending). Bilinear interpolation; outside the grid the nearest edge value is
/// used (documented clamp: emissivity tables rarely reach 90° or every wavelength).
/// The one table type: a material's `emissivity = { table_file }` is read into one
/// ([`Self::from_csv_str`]) and the radiometry uses it as read.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EmissivityTable {
    /// Angles from the normal, degrees, ascending.
    pub angles_deg: Vec<f64>,
    /// Wavelengths, µm, ascending.
    pub wavelengths_um: Vec<f64>,
    /// Row-major: values[a * wavelengths.len() + w].
    pub values: Vec<f64>,
}

impl EmissivityTable {
    /// A table of `values` (row-major, angle by wavelength); errors for
    /// axes not finite and ascending, sizes that do not match or values
    /// outside [0, 1].
    pub fn new(
        angles_deg: Vec<f64>,
        wavelengths_um: Vec<f64>,
        values: Vec<f64>,
    ) -> Result<Self, RadiometryError> {
        let bad = |m: String| Err(RadiometryError::Emissivity(m));
        if angles_deg.is_empty() || wavelengths_um.is_empty() {
            return bad("emissivity table needs at least one angle and one wavelength".into());
        }
        if values.len() != angles_deg.len() * wavelengths_um.len() {
            return bad(format!(
                "emissivity table has {} values, expected {} angles x {} wavelengths",
                values.len(),
                angles_deg.len(),
                wavelengths_um.len()
            ));
        }
        for (name, ax) in [("angles", &angles_deg), ("wavelengths", &wavelengths_um)] {
            if ax.windows(2).any(|w| !(w[1] > w[0])) || ax.iter().any(|v| !v.is_finite()) {
                return bad(format!(
                    "emissivity table {name} must be finite and strictly ascending"
                ));
            }
        }
        if let Some(v) = values.iter().find(|v| !(**v >= 0.0 && **v <= 1.0)) {
            return bad(format!("emissivity {v} outside [0, 1]"));
        }
        Ok(Self {
            angles_deg,
            wavelengths_um,
            values,
        })
    }

    /// Reads an ε(θ, λ) table, the one reader (a material's
    /// `emissivity = { table_file }`): `#` comments and blank lines ignored;
    /// the first data line is `wavelength_um, θ1, θ2, ...` (angles from the
    /// normal, degrees, strictly increasing in [0, 90]); then one line per
    /// wavelength, strictly increasing: `λ, ε(θ1), ε(θ2), ...` with ε in
    /// [0, 1]. Comma-separated. Errors name `file`, the line (0: the file as a
    /// whole) and what was expected.
    pub fn from_csv_str(text: &str, file: &str) -> Result<Self, RadiometryError> {
        let data_err = |line: usize, msg: String| RadiometryError::Csv {
            file: file.to_string(),
            line,
            msg,
        };
        let mut angles: Option<Vec<f64>> = None;
        let mut wl = Vec::new();
        // rows by wavelength, as written; stored angle-major below
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let ln = i + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            match &angles {
                None => {
                    let mut it = line.split(',');
                    let first = it.next().unwrap_or("").trim();
                    if first != "wavelength_um" {
                        return Err(data_err(
                            ln,
                            format!(
                                "expected the header `wavelength_um, angle_deg, ...`, found `{first}`"
                            ),
                        ));
                    }
                    let rest: Vec<&str> = it.collect();
                    let a = crate::files::csv_numbers(&rest.join(",")).map_err(|(c, f)| {
                        data_err(
                            ln,
                            format!("column {}: `{f}` is not an angle in degrees", c + 1),
                        )
                    })?;
                    for x in &a {
                        crate::bounds::data::EMISSIVITY_ANGLE
                            .check(*x)
                            .map_err(|m| data_err(ln, m))?;
                    }
                    if a.is_empty() || a.windows(2).any(|w| w[1] <= w[0]) {
                        return Err(data_err(
                            ln,
                            "angles must be strictly increasing degrees in [0, 90]".to_string(),
                        ));
                    }
                    angles = Some(a);
                }
                Some(a) => {
                    let row = crate::files::csv_numbers(line).map_err(|(c, f)| {
                        data_err(ln, format!("column {c}: `{f}` is not a finite number"))
                    })?;
                    if row.len() != a.len() + 1 {
                        return Err(data_err(
                            ln,
                            format!(
                                "expected {} columns (wavelength + {} angles), found {}",
                                a.len() + 1,
                                a.len(),
                                row.len()
                            ),
                        ));
                    }
                    crate::bounds::data::WAVELENGTH_UM
                        .check(row[0])
                        .map_err(|m| data_err(ln, m))?;
                    if wl.last().is_some_and(|&l| row[0] <= l) {
                        return Err(data_err(
                            ln,
                            format!(
                                "wavelength {} µm: wavelengths must be strictly increasing",
                                row[0]
                            ),
                        ));
                    }
                    for e in &row[1..] {
                        crate::bounds::data::EMISSIVITY
                            .check(*e)
                            .map_err(|m| data_err(ln, m))?;
                    }
                    wl.push(row[0]);
                    rows.push(row[1..].to_vec());
                }
            }
        }
        let Some(angles) = angles else {
            return Err(data_err(
                0,
                "empty table: expected a header and at least one row".to_string(),
            ));
        };
        if wl.is_empty() {
            return Err(data_err(
                0,
                "no data rows: expected at least one wavelength row".to_string(),
            ));
        }
        let values = (0..angles.len())
            .flat_map(|a| rows.iter().map(move |r| r[a]))
            .collect();
        Self::new(angles, wl, values).map_err(|e| data_err(0, e.to_string()))
    }

    /// ε at `angle_deg` from the normal and `wavelength_um` (bilinear,
    /// clamped to the grid's edges).
    pub fn at(&self, angle_deg: f64, wavelength_um: f64) -> f64 {
        let (ia, ta) = bracket(&self.angles_deg, angle_deg);
        self.at_bracket(ia, ta, wavelength_um)
    }

    /// [`Self::at`] with the angle's bracket `(ia, ta)` given.
    fn at_bracket(&self, ia: usize, ta: f64, wavelength_um: f64) -> f64 {
        let (iw, tw) = bracket(&self.wavelengths_um, wavelength_um);
        let nw = self.wavelengths_um.len();
        let v = |a: usize, w: usize| self.values[a * nw + w];
        let a1 = (ia + 1).min(self.angles_deg.len() - 1);
        let w1 = (iw + 1).min(nw - 1);
        let lo = v(ia, iw) + tw * (v(ia, w1) - v(ia, iw));
        let hi = v(a1, iw) + tw * (v(a1, w1) - v(a1, iw));
        lo + ta * (hi - lo)
    }
}

/// Index i and fraction t in [0,1] with x ≈ xs[i] + t (xs[i+1] − xs[i]), clamped.
fn bracket(xs: &[f64], x: f64) -> (usize, f64) {
    let n = xs.len();
    if n == 1 || x <= xs[0] {
        return (0, 0.0);
    }
    if x >= xs[n - 1] {
        return (n - 1, 0.0);
    }
    let i = xs.partition_point(|&v| v <= x) - 1;
    (i, (x - xs[i]) / (xs[i + 1] - xs[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent closed forms for a real index n (Hecht, *Optics*, eqs. 4.42-4.43).
    fn hecht(n: f64, deg: f64) -> (f64, f64) {
        let t = deg.to_radians();
        let ct = t.cos();
        let root = (n * n - t.sin().powi(2)).sqrt();
        let rs = (ct - root) / (ct + root);
        let rp = (n * n * ct - root) / (n * n * ct + root);
        (rs * rs, rp * rp)
    }

    #[test]
    fn glass_n15_published_values() {
        // normal incidence: ((n-1)/(n+1))² = 0.04 exactly
        let (rs, rp, r) = fresnel_reflectance(1.5, 0.0, 0.0);
        assert!((r - 0.04).abs() < 1e-12 && (rs - rp).abs() < 1e-12);
        // 60° and 80°: Rs, Rp against the closed forms; published values
        // Rs(60)=0.1766, Rp(60)=0.0018, Rs(80)=0.5388, Rp(80)=0.2367 (4 d.p.)
        for &(deg, rs_pub, rp_pub) in &[(60.0, 0.1766, 0.0018), (80.0, 0.5388, 0.2367)] {
            let (rs, rp, r) = fresnel_reflectance(1.5, 0.0, deg);
            let (hs, hp) = hecht(1.5, deg);
            assert!((rs - hs).abs() < 1e-12 && (rp - hp).abs() < 1e-12, "{deg}");
            assert!(
                (rs - rs_pub).abs() < 6e-4 && (rp - rp_pub).abs() < 6e-4,
                "{deg}: {rs} {rp}"
            );
            assert!((r - 0.5 * (hs + hp)).abs() < 1e-12);
        }
        // Brewster angle atan(1.5): Rp = 0
        let (_, rp, _) = fresnel_reflectance(1.5, 0.0, 1.5f64.atan().to_degrees());
        assert!(rp < 1e-20);
        // grazing: R → 1
        assert!((fresnel_reflectance(1.5, 0.0, 90.0).2 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn absorbing_normal_incidence() {
        // R(0) = ((n−1)² + k²)/((n+1)² + k²)
        let (n, k) = (2.5, 3.0);
        let r = fresnel_reflectance(n, k, 0.0).2;
        let expect = ((n - 1.0f64).powi(2) + k * k) / ((n + 1.0f64).powi(2) + k * k);
        assert!((r - expect).abs() < 1e-12);
    }

    #[test]
    fn emissivity_plus_reflectance_is_one() {
        let table = EmissivityTable::new(
            vec![0.0, 60.0, 85.0],
            vec![8.0, 12.0],
            vec![0.95, 0.9, 0.9, 0.85, 0.6, 0.5],
        )
        .unwrap();
        let ms = [
            Emissivity::Constant(0.93),
            Emissivity::Table(table),
            Emissivity::Fresnel { n: 1.5, k: 0.0 },
        ];
        for m in &ms {
            for a in 0..=18 {
                for w in [3.0, 8.0, 10.0, 14.0] {
                    let (e, r) = (m.at(a as f64 * 5.0, w), m.reflectance(a as f64 * 5.0, w));
                    assert!((0.0..=1.0).contains(&e));
                    assert!((e + r - 1.0).abs() < 1e-15);
                }
            }
        }
    }

    #[test]
    fn table_from_csv() {
        let t = EmissivityTable::from_csv_str(
            "# glass-ish\nwavelength_um,0,60\n8,0.9,0.7\n12,0.8,0.6\n",
            "e.csv",
        )
        .unwrap();
        assert!((t.at(30.0, 10.0) - 0.75).abs() < 1e-12);
        let e = EmissivityTable::from_csv_str("wavelength_um,0,60\n8,0.9\n", "e.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("e.csv") && e.contains("line 2") && e.contains("columns"),
            "{e}"
        );
        let e = EmissivityTable::from_csv_str("wavelength_um,0,60\n8,0.9,1.3\n", "e.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("out of range"), "{e}");
    }

    #[test]
    fn table_bilinear_and_clamp() {
        let t = EmissivityTable::new(vec![0.0, 60.0], vec![8.0, 12.0], vec![0.9, 0.8, 0.7, 0.6])
            .unwrap();
        assert!((t.at(30.0, 10.0) - 0.75).abs() < 1e-12);
        assert!((t.at(90.0, 20.0) - 0.6).abs() < 1e-12);
        assert!(EmissivityTable::new(vec![0.0], vec![8.0], vec![1.2]).is_err());
    }

    #[test]
    fn spectrum_at_is_at_per_wavelength() {
        // Bilinear by hand at 30°: halfway between the 0° and 60° rows; at
        // 10 µm halfway between 8 and 12 µm, clamped outside the grid.
        let t = EmissivityTable::new(vec![0.0, 60.0], vec![8.0, 12.0], vec![0.9, 0.8, 0.7, 0.6])
            .unwrap();
        let wl = [7.0, 8.0, 10.0, 11.0, 12.0, 14.0];
        let by_hand = [0.8, 0.8, 0.75, 0.725, 0.7, 0.7];
        for e in [
            Emissivity::Table(t),
            Emissivity::Fresnel { n: 1.33, k: 0.1 },
            Emissivity::Constant(0.93),
        ] {
            let mut out = [0.0; 6];
            e.spectrum_at(30.0, &wl, &mut out);
            for (w, o) in wl.iter().zip(out) {
                assert_eq!(o.to_bits(), e.at(30.0, *w).to_bits(), "{e:?} at {w} µm");
            }
            if matches!(e, Emissivity::Table(_)) {
                for (o, h) in out.iter().zip(by_hand) {
                    assert!((o - h).abs() < 1e-12, "{o} against {h}");
                }
            }
        }
    }
}
