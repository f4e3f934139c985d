//! The planes a render produces (band radiance, temperatures, truth,
//! radiometric terms): named, unit-annotated, row-major f32 images of one
//! size. Defined here, where they are made; `output` writes them.

const RADIANCE: &str = "W m-2 sr-1 um-1";

/// Every plane a render can produce with its unit, in render order (`dn`
/// only with the sensor's quantisation): the first [`PIXEL_PLANES`] are made
/// pixel by pixel, `dn` and `sensor_radiance` by the sensor model.
pub const PLANES: [(&str, &str); 21] = [
    ("band_radiance", RADIANCE),
    ("apparent_temperature", "K"),
    ("surface_temperature", "K"),
    ("material", "index (-1 none)"),
    ("facet", "triangle index (-1 none)"),
    ("sun_now", "fraction"),
    ("hours_sunlit", "h"),
    ("range", "m"),
    ("ground_x", "m"),
    ("ground_y", "m"),
    ("ground_z", "m"),
    ("view_angle", "deg"),
    ("case", "eq. 1-4 (0 outside)"),
    ("emitted", RADIANCE),
    ("reflected_solar", RADIANCE),
    ("reflected_sky", RADIANCE),
    ("reflected_background", RADIANCE),
    ("path_thermal", RADIANCE),
    ("path_scattered", RADIANCE),
    ("dn", "counts"),
    ("sensor_radiance", RADIANCE),
];

/// How many of [`PLANES`] are made pixel by pixel (before `dn`).
pub const PIXEL_PLANES: usize = 19;

/// The names of [`PLANES`]: what `--planes` chooses from.
pub const PLANE_NAMES: [&str; 21] = {
    let mut names = [""; 21];
    let mut i = 0;
    while i < names.len() {
        names[i] = PLANES[i].0;
        i += 1;
    }
    names
};

/// Where the radiometric term planes start in [`PLANES`].
pub const FIRST_TERM: usize = 13;

/// The radiometric terms of eqs. 1-4, as planes (W m⁻² sr⁻¹ µm⁻¹): the
/// six of [`PLANES`] from [`FIRST_TERM`].
pub const TERM_PLANES: [&str; 6] = {
    let mut names = [""; 6];
    let mut i = 0;
    while i < names.len() {
        names[i] = PLANES[FIRST_TERM + i].0;
        i += 1;
    }
    names
};

/// One image plane (an "AOV"): name, unit, row-major f32 samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// Plane name (`radiance`, `apparent_temp`, `material`, …).
    pub name: String,
    /// Its unit (`K`, `W/m²/sr/µm`, … or empty).
    pub unit: String,
    /// Row-major values, `width × height`.
    pub data: Vec<f32>,
}

/// A set of planes of the same size.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Planes {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// The planes, in output order.
    pub planes: Vec<Plane>,
}

impl Planes {
    /// No planes yet, of `width × height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        Planes {
            width,
            height,
            planes: Vec::new(),
        }
    }

    /// Adds a plane; `data.len()` must equal `width·height`.
    pub fn push(&mut self, name: &str, unit: &str, data: Vec<f32>) {
        assert_eq!(
            data.len(),
            self.width as usize * self.height as usize,
            "plane {name} has the wrong size"
        );
        self.planes.push(Plane {
            name: name.into(),
            unit: unit.into(),
            data,
        });
    }

    /// The plane named `name`, if any.
    pub fn get(&self, name: &str) -> Option<&Plane> {
        self.planes.iter().find(|p| p.name == name)
    }
}

impl Plane {
    /// Statistics of the plane's finite values.
    pub fn stats(&self) -> PlaneStats {
        plane_stats(&self.data)
    }
}

/// Summary statistics of the finite values of a plane (NaN, written as
/// JSON `null`, when there are none).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct PlaneStats {
    #[serde(deserialize_with = "nan_if_null")]
    /// Mean.
    pub mean: f64,
    #[serde(deserialize_with = "nan_if_null")]
    /// Smallest value.
    pub min: f64,
    #[serde(deserialize_with = "nan_if_null")]
    /// Largest value.
    pub max: f64,
    /// Population standard deviation.
    #[serde(deserialize_with = "nan_if_null")]
    pub std: f64,
    /// Number of finite values.
    pub count: usize,
}

/// A number, or NaN for JSON `null` (how serde_json writes NaN).
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Statistics of the finite values of `data` (NaN fields when none).
pub fn plane_stats(data: &[f32]) -> PlaneStats {
    let v: Vec<f64> = data
        .iter()
        .filter(|x| x.is_finite())
        .map(|&x| x as f64)
        .collect();
    if v.is_empty() {
        return PlaneStats {
            mean: f64::NAN,
            min: f64::NAN,
            max: f64::NAN,
            std: f64::NAN,
            count: 0,
        };
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    PlaneStats {
        mean,
        min: v.iter().copied().fold(f64::INFINITY, f64::min),
        max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        std: var.sqrt(),
        count: v.len(),
    }
}
