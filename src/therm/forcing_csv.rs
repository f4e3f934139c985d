//! Ready forcing CSVs (`tools/ref_therm.py` writes them): the columns
//! `t_s,air_temp_k,sky_temp_k,wind_speed_m_s,dni_w_m2,dhi_w_m2,ghi_w_m2,sun_e,sun_n,sun_u`
//! in any order, lines starting with `#` ignored; dry air at standard
//! pressure, no rain.

use std::path::Path;

use anyhow::Context;

use super::forcing::Forcing;

/// Reads a forcing CSV (columns in the module docs). Errors name the file,
/// the line and the column.
pub fn read_forcing_csv(path: &Path) -> anyhow::Result<Vec<Forcing>> {
    let text = crate::files::read_text(path, crate::bounds::sizes::MAX_WEATHER_FILE_BYTES)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse_forcing_csv(path, &text)
}

/// As [`read_forcing_csv`], from the file's text (`path` names it in errors).
pub fn parse_forcing_csv(path: &Path, text: &str) -> anyhow::Result<Vec<Forcing>> {
    let file = path.display();
    const COLS: [&str; 10] = [
        "t_s",
        "air_temp_k",
        "sky_temp_k",
        "wind_speed_m_s",
        "dni_w_m2",
        "dhi_w_m2",
        "ghi_w_m2",
        "sun_e",
        "sun_n",
        "sun_u",
    ];
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty());
    let (hl, header) = lines
        .next()
        .with_context(|| format!("{file}: empty file"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let idx: Vec<usize> = COLS
        .iter()
        .map(|c| {
            names.iter().position(|n| n == c).with_context(|| {
                format!(
                    "{file}:{}: header lacks column '{c}' (expected {})",
                    hl + 1,
                    COLS.join(",")
                )
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let mut out = Vec::new();
    for (ln, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut v = [0.0; 10];
        for (k, &j) in idx.iter().enumerate() {
            let s = fields
                .get(j)
                .with_context(|| format!("{file}:{}: missing column '{}'", ln + 1, COLS[k]))?;
            v[k] = s
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .with_context(|| {
                    format!(
                        "{file}:{}: column '{}': '{s}' is not a finite number",
                        ln + 1,
                        COLS[k]
                    )
                })?;
        }
        out.push(Forcing {
            t_s: v[0],
            air_temp_k: v[1],
            sky_temp_k: v[2],
            wind_speed_m_s: v[3],
            dni_w_m2: v[4],
            dhi_w_m2: v[5],
            ghi_w_m2: v[6],
            sun_dir_enu: [v[7], v[8], v[9]],
            dew_point_k: super::forcing::DRY_AIR_DEW_POINT_K,
            pressure_pa: 101_325.0,
            precip_mm_h: 0.0,
            ground_temp_k: None,
        });
    }
    super::slab::validate_forcing(&out).with_context(|| format!("{file}"))?;
    Ok(out)
}
