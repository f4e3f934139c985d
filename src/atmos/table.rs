//! Reading atmosphere tables (format IRSIG-ATMOS 1, docs/atmosphere-tables.md).

use std::io::Read;
use std::path::{Path, PathBuf};

use super::error::AtmosError;
use crate::bounds;

/// Current (and only) table format version.
pub const FORMAT_VERSION: u32 = 1;

/// One interpolation axis of a quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Axis name (altitude_km, view_zenith_deg, sky_zenith_deg, sun_zenith_deg, rel_azimuth_deg).
    pub name: String,
    /// Strictly ascending grid values.
    pub values: Vec<f64>,
}

/// A tabulated quantity: values on axes × wavenumber, row-major with the
/// wavenumber fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantity {
    /// Its name in the table (`tau_path`, `l_ue`, ...).
    pub name: String,
    /// Its unit, as the header gives it.
    pub unit: String,
    /// The axes before the wavenumber, outermost first.
    pub axes: Vec<Axis>,
    /// The values, row-major, wavenumber fastest.
    pub data: Vec<f64>,
    /// Number of wavenumber samples (length of the last dimension).
    pub n_wavenumber: usize,
}

impl Quantity {
    /// Number of spectra (product of the axis lengths).
    pub fn n_spectra(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// The spectrum at a grid node (one index per axis).
    pub fn spectrum(&self, index: &[usize]) -> &[f64] {
        let mut flat = 0;
        for (a, &i) in self.axes.iter().zip(index) {
            flat = flat * a.values.len() + i;
        }
        &self.data[flat * self.n_wavenumber..(flat + 1) * self.n_wavenumber]
    }
}

/// The quantities a table must hold, with their axes in order.
pub const REQUIRED: &[(&str, &[&str])] = &[
    ("tau_path", &["altitude_km", "view_zenith_deg"]),
    ("l_ue", &["altitude_km", "view_zenith_deg"]),
    (
        "l_us",
        &[
            "sun_zenith_deg",
            "rel_azimuth_deg",
            "altitude_km",
            "view_zenith_deg",
        ],
    ),
    ("l_de", &["sky_zenith_deg"]),
    (
        "l_ds",
        &["sun_zenith_deg", "rel_azimuth_deg", "sky_zenith_deg"],
    ),
    ("tau_sun", &["sun_zenith_deg"]),
    ("e_sun_exo", &[]),
];

/// A loaded atmosphere table, as stored.
#[derive(Clone, Debug, PartialEq)]
pub struct AtmosTable {
    /// The atmosphere's name (header `name`).
    pub name: String,
    /// What it is (header `description`).
    pub description: String,
    /// The command that generated the table (header `command`).
    pub command: String,
    /// All header lines as (key, rest).
    pub header: Vec<(String, String)>,
    /// Ascending wavenumbers, cm⁻¹.
    pub wavenumber_cm1: Vec<f64>,
    /// The tabulated quantities.
    pub quantities: Vec<Quantity>,
    /// Where it was loaded from.
    pub source: PathBuf,
}

impl AtmosTable {
    /// Loads a table file (gzip-compressed or plain).
    pub fn load(path: &Path) -> Result<Self, AtmosError> {
        let bytes =
            crate::files::read(path, crate::bounds::atmos_table::MAX_BYTES).map_err(|e| {
                AtmosError::Io {
                    path: path.display().to_string(),
                    source: e,
                }
            })?;
        let mut t = Self::from_bytes(&bytes, &path.display().to_string())?;
        t.source = path.to_path_buf();
        Ok(t)
    }

    /// Parses a table from its file bytes; `file` names it in errors.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<Self, AtmosError> {
        let raw = maybe_gunzip(bytes, file)?;
        let fmt = |line: usize, msg: String| AtmosError::Format {
            file: file.to_string(),
            line,
            msg,
        };
        // header: text lines up to and including the `data ...` line
        let mut pos = 0usize;
        let mut lines: Vec<String> = Vec::new();
        let data_kind;
        loop {
            let rest = &raw[pos..];
            let Some(nl) = rest.iter().position(|&b| b == b'\n') else {
                return Err(fmt(
                    lines.len() + 1,
                    "header ends before its 'data' line (truncated file?)".into(),
                ));
            };
            let line = std::str::from_utf8(&rest[..nl])
                .map_err(|_| fmt(lines.len() + 1, "header line is not UTF-8 text".into()))?
                .trim_end_matches('\r')
                .to_string();
            pos += nl + 1;
            if lines.is_empty() {
                let mut it = line.split_whitespace();
                if it.next() != Some("IRSIG-ATMOS") {
                    return Err(fmt(
                        1,
                        format!(
                            "expected 'IRSIG-ATMOS {FORMAT_VERSION}', found '{}'",
                            truncate(&line)
                        ),
                    ));
                }
                let v: u32 = it.next().and_then(|v| v.parse().ok()).ok_or_else(|| {
                    fmt(
                        1,
                        format!("expected a format version after IRSIG-ATMOS, found '{line}'"),
                    )
                })?;
                if v != FORMAT_VERSION {
                    return Err(fmt(
                        1,
                        format!(
                            "unsupported format version {v} (this irsig reads {FORMAT_VERSION})"
                        ),
                    ));
                }
            }
            if let Some(kind) = line.strip_prefix("data ") {
                data_kind = kind.trim().to_string();
                lines.push(line);
                break;
            }
            lines.push(line);
            if lines.len() > 10_000 {
                return Err(fmt(
                    lines.len(),
                    "no 'data' line in the first 10000 lines".into(),
                ));
            }
        }
        let mut header = Vec::new();
        let mut name = None;
        let mut description = String::new();
        let mut command = String::new();
        let mut wn: Option<Vec<f64>> = None;
        let mut quantities: Vec<(usize, Quantity)> = Vec::new();
        for (i, line) in lines.iter().enumerate().skip(1) {
            let ln = i + 1;
            let (key, rest) = line.split_once(' ').unwrap_or((line.as_str(), ""));
            header.push((key.to_string(), rest.to_string()));
            match key {
                "name" => name = Some(rest.trim().to_string()),
                "description" => description = rest.trim().to_string(),
                "command" => command = rest.trim().to_string(),
                "wavenumber_cm1" => wn = Some(parse_wavenumbers(rest).map_err(|m| fmt(ln, m))?),
                "quantity" => {
                    let q = parse_quantity(rest).map_err(|m| fmt(ln, m))?;
                    quantities.push((ln, q));
                }
                _ => {}
            }
        }
        let name = name.ok_or_else(|| fmt(0, "header has no 'name' line".into()))?;
        let wn = wn.ok_or_else(|| fmt(0, "header has no 'wavenumber_cm1' line".into()))?;
        let nwn = wn.len();
        for (_, q) in quantities.iter_mut() {
            q.n_wavenumber = nwn;
        }
        // required quantities and their axes
        for (req, axes) in REQUIRED {
            let Some((ln, q)) = quantities.iter().find(|(_, q)| q.name == *req) else {
                return Err(fmt(0, format!("missing quantity '{req}'")));
            };
            let names: Vec<&str> = q.axes.iter().map(|a| a.name.as_str()).collect();
            if names != *axes {
                return Err(fmt(
                    *ln,
                    format!("quantity '{req}' must have axes {axes:?}, found {names:?}"),
                ));
            }
        }
        // binary payload
        // checked: a header can describe more than usize holds (a fuzzed
        // axis of 10^6 values × 10^6 wavenumbers overflowed and panicked)
        let mut expected: usize = 0;
        for (ln, q) in &quantities {
            let bytes = nwn
                .checked_mul(4)
                .and_then(|n0| {
                    q.axes
                        .iter()
                        .try_fold(n0, |n, a| n.checked_mul(a.values.len()))
                })
                .and_then(|b| expected.checked_add(b))
                .filter(|&b| b as u64 <= bounds::atmos_table::MAX_BYTES);
            expected = bytes.ok_or_else(|| {
                let dims: Vec<String> = q.axes.iter().map(|a| a.values.len().to_string()).collect();
                fmt(
                    *ln,
                    format!(
                        "quantity '{}': {} spectra of {nwn} wavenumbers need more than the {} GiB \
                         a table may hold",
                        q.name,
                        dims.join(" × "),
                        bounds::atmos_table::MAX_BYTES >> 30
                    ),
                )
            })?;
        }
        let payload = &raw[pos..];
        if payload.len() < expected {
            return Err(AtmosError::Truncated {
                file: file.into(),
                expected,
                got: payload.len(),
            });
        }
        if payload.len() > expected {
            return Err(fmt(
                lines.len(),
                format!(
                    "{} bytes of data after the {expected} the header describes",
                    payload.len() - expected
                ),
            ));
        }
        let byteplanes = match data_kind.as_str() {
            "f32le" => false,
            "f32le-byteplanes" => true,
            other => {
                return Err(fmt(
                    lines.len(),
                    format!("unknown data encoding '{other}' (expected f32le or f32le-byteplanes)"),
                ));
            }
        };
        let mut off = 0;
        for (_, q) in quantities.iter_mut() {
            let n = q.n_spectra() * nwn;
            let chunk = &payload[off..off + 4 * n];
            off += 4 * n;
            q.data = (0..n)
                .map(|i| {
                    let b = if byteplanes {
                        [chunk[i], chunk[n + i], chunk[2 * n + i], chunk[3 * n + i]]
                    } else {
                        [
                            chunk[4 * i],
                            chunk[4 * i + 1],
                            chunk[4 * i + 2],
                            chunk[4 * i + 3],
                        ]
                    };
                    f32::from_le_bytes(b) as f64
                })
                .collect();
            if let Some(i) = q.data.iter().position(|v| !v.is_finite()) {
                return Err(AtmosError::NonFinite {
                    file: file.into(),
                    quantity: q.name.clone(),
                    spectrum: i / nwn,
                    wavenumber_cm1: wn[i % nwn],
                });
            }
        }
        for (ln, q) in &quantities {
            let Some(b) = bounds::atmos_table::range_of(&q.name) else {
                continue;
            };
            if let Some(i) = q.data.iter().position(|&v| !b.contains(v)) {
                return Err(fmt(
                    *ln,
                    format!(
                        "quantity '{}' at {} and {} cm⁻¹ (value {} of its data): {} = {} is out \
                         of range: expected {}",
                        q.name,
                        node_text(q, i / nwn),
                        bounds::num(wn[i % nwn]),
                        i,
                        q.name,
                        bounds::num(q.data[i]),
                        b.expected().replacen(b.key, &q.name, 1)
                    ),
                ));
            }
        }
        Ok(Self {
            name,
            description,
            command,
            header,
            wavenumber_cm1: wn,
            quantities: quantities.into_iter().map(|(_, q)| q).collect(),
            source: PathBuf::from(file),
        })
    }

    /// The quantity with this name.
    pub fn quantity(&self, name: &str) -> Option<&Quantity> {
        self.quantities.iter().find(|q| q.name == name)
    }
}

/// The axis values of spectrum `k` of `q` (`altitude_km=1, view_zenith_deg=60`).
fn node_text(q: &Quantity, mut k: usize) -> String {
    let mut parts = Vec::new();
    for a in q.axes.iter().rev() {
        let n = a.values.len().max(1);
        parts.push(format!("{}={}", a.name, bounds::num(a.values[k % n])));
        k /= n;
    }
    parts.reverse();
    if parts.is_empty() {
        "its single spectrum".into()
    } else {
        parts.join(", ")
    }
}

fn truncate(s: &str) -> String {
    s.chars().take(40).collect()
}

fn maybe_gunzip(bytes: &[u8], file: &str) -> Result<Vec<u8>, AtmosError> {
    if bytes.len() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b {
        let mut out = Vec::new();
        // The declared size (the gzip trailer's ISIZE, the size mod 2³²:
        // exact below 4 GiB) is checked before inflating, and the inflating
        // stops one byte past it (a bomb cannot inflate past what it says).
        let declared = bytes
            .len()
            .checked_sub(4)
            .map(|k| u32::from_le_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]))
            .map_or(0, u64::from);
        let max = bounds::atmos_table::MAX_BYTES;
        if declared > max {
            return Err(AtmosError::Format {
                file: file.into(),
                line: 0,
                msg: format!(
                    "the gzip stream declares {declared} bytes, more than the {} GiB a table \
                     may hold",
                    max >> 30
                ),
            });
        }
        let max = declared.max(1);
        flate2::read::GzDecoder::new(bytes)
            .take(max + 1)
            .read_to_end(&mut out)
            .map_err(|e| AtmosError::Format {
                file: file.into(),
                line: 0,
                msg: format!("gzip stream is corrupt or truncated: {e}"),
            })?;
        if out.len() as u64 > max {
            return Err(AtmosError::Format {
                file: file.into(),
                line: 0,
                msg: format!(
                    "decompresses to more than the {max} bytes its gzip trailer declares \
                     (a gzip bomb, or a multi-member stream: recompress it as one)"
                ),
            });
        }
        Ok(out)
    } else {
        Ok(bytes.to_vec())
    }
}

/// Reads only the header lines of a table file (for listings).
pub fn read_header(path: &Path) -> Result<Vec<(String, String)>, AtmosError> {
    let f = crate::files::check_regular(path, crate::bounds::atmos_table::MAX_BYTES)
        .and_then(|_| std::fs::File::open(path))
        .map_err(|e| AtmosError::Io {
            path: path.display().to_string(),
            source: e,
        })?;
    read_header_from(std::io::BufReader::new(f), &path.display().to_string())
}

/// Reads only the header lines of a table (gzip-compressed or plain) from
/// `f`; `file` names it in errors.
pub fn read_header_from(mut f: impl Read, file: &str) -> Result<Vec<(String, String)>, AtmosError> {
    let mut buf = Vec::new();
    let mut magic = [0u8; 2];
    f.read_exact(&mut magic).map_err(|e| AtmosError::Io {
        path: file.to_string(),
        source: e,
    })?;
    let rd: Box<dyn Read> = if magic == [0x1f, 0x8b] {
        Box::new(flate2::read::GzDecoder::new(
            std::io::Cursor::new(magic).chain(f),
        ))
    } else {
        Box::new(std::io::Cursor::new(magic).chain(f))
    };
    rd.take(64 * 1024).read_to_end(&mut buf).ok();
    let text = String::from_utf8_lossy(&buf);
    let mut out = Vec::new();
    for line in text.lines() {
        let (k, r) = line.split_once(' ').unwrap_or((line, ""));
        out.push((k.to_string(), r.to_string()));
        if k == "data" {
            return Ok(out);
        }
    }
    Err(AtmosError::Format {
        file: file.to_string(),
        line: 0,
        msg: "no 'data' line in the header".into(),
    })
}

fn parse_wavenumbers(rest: &str) -> Result<Vec<f64>, String> {
    let rest = rest.trim();
    let v: Vec<f64> = if let Some(list) = rest.strip_prefix("list=") {
        list.split(',')
            .map(|x| {
                x.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("bad wavenumber '{x}'"))
            })
            .collect::<Result<_, _>>()?
    } else {
        let f: Vec<&str> = rest.split_whitespace().collect();
        if f.len() != 3 {
            return Err(format!(
                "expected 'wavenumber_cm1 <start> <step> <count>' or 'wavenumber_cm1 list=...', got '{rest}'"
            ));
        }
        let start: f64 = f[0].parse().map_err(|_| format!("bad start '{}'", f[0]))?;
        let step: f64 = f[1].parse().map_err(|_| format!("bad step '{}'", f[1]))?;
        let count: usize = f[2].parse().map_err(|_| format!("bad count '{}'", f[2]))?;
        let max = bounds::atmos_table::WAVENUMBER_COUNT.hi;
        if !(step > 0.0) || count == 0 || count as f64 > max {
            return Err(format!(
                "wavenumber grid needs step > 0 and 0 < count <= {max}, got step {step}, count {count}"
            ));
        }
        (0..count).map(|i| start + step * i as f64).collect()
    };
    let b = bounds::atmos_table::WAVENUMBER;
    if let Some(x) = v.iter().find(|x| !b.contains(**x)) {
        return Err(b.check(*x).unwrap_err());
    }
    if v.is_empty() || v.len() as f64 > bounds::atmos_table::WAVENUMBER_COUNT.hi {
        return Err(format!(
            "{} wavenumbers: expected 1 to {}",
            v.len(),
            bounds::atmos_table::WAVENUMBER_COUNT.hi
        ));
    }
    if v.windows(2).any(|w| !(w[1] > w[0])) {
        return Err("wavenumbers must be strictly ascending".into());
    }
    Ok(v)
}

fn parse_quantity(rest: &str) -> Result<Quantity, String> {
    let mut it = rest.split_whitespace();
    let name = it.next().ok_or("quantity line without a name")?.to_string();
    let mut unit = String::new();
    let mut axes = Vec::new();
    for tok in it {
        let (k, v) = tok
            .split_once('=')
            .ok_or_else(|| format!("quantity {name}: expected key=value, got '{tok}'"))?;
        if k == "unit" {
            unit = v.replace('_', " ");
            continue;
        }
        let values: Vec<f64> = v
            .split(',')
            .map(|x| {
                x.parse::<f64>()
                    .map_err(|_| format!("quantity {name}: axis {k}: '{x}' is not a number"))
            })
            .collect::<Result<_, _>>()?;
        if values.iter().any(|x| !x.is_finite()) || values.windows(2).any(|w| !(w[1] > w[0])) {
            return Err(format!(
                "quantity {name}: axis {k} must be finite and strictly ascending"
            ));
        }
        axes.push(Axis {
            name: k.to_string(),
            values,
        });
    }
    Ok(Quantity {
        name,
        unit,
        axes,
        data: Vec::new(),
        n_wavenumber: 0,
    })
}
