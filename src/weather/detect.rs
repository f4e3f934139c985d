//! Which weather format a file's text is, from its first lines.

use super::WeatherFormat;
use super::parse::split_csv;
use super::tmy2::tmy2_station;

/// The format of a weather file's text, from its first lines: EPW (a
/// `.epw` name or a `LOCATION,` first line); TMY3 (7 or more fields, then a
/// `Date (MM/DD/YYYY)` header); TMY2 (a whitespace station line ending
/// `N|S deg min E|W deg min elevation`); NSRDB PSM3/PSM4 (`Location ID` in
/// line 1, a `Year,Month,Day,Hour` header in line 3); PVGIS TMY CSV (a
/// `Latitude (decimal degrees):` line); the plain CSV (a header naming a
/// `time` column). Otherwise `Err((line, what it looks like))`.
pub fn detect_format(text: &str, epw_name: bool) -> Result<WeatherFormat, (usize, String)> {
    let lines: Vec<&str> = text.lines().take(40).collect();
    let l = |i: usize| lines.get(i).copied().unwrap_or("");
    if epw_name || text.starts_with("LOCATION,") {
        return Ok(WeatherFormat::Epw);
    }
    if l(1).trim_start().starts_with("Date (MM/DD/YYYY)") && split_csv(l(0)).len() >= 7 {
        return Ok(WeatherFormat::Tmy3);
    }
    if tmy2_station(l(0)).is_some() {
        return Ok(WeatherFormat::Tmy2);
    }
    let first4 = |s: &str| -> Vec<String> {
        split_csv(s)
            .iter()
            .take(4)
            .map(|x| x.trim().to_string())
            .collect()
    };
    if split_csv(l(0)).iter().any(|x| x.trim() == "Location ID")
        && first4(l(2)) == ["Year", "Month", "Day", "Hour"]
    {
        return Ok(WeatherFormat::Psm3);
    }
    if lines
        .iter()
        .any(|x| x.starts_with("Latitude (decimal degrees):"))
    {
        return Ok(WeatherFormat::Pvgis);
    }
    let t = text.trim_start();
    let looks = |what: &str| {
        Err((
            1,
            format!("this looks like {what}, not a weather format irsig reads"),
        ))
    };
    if t.starts_with('{') || t.starts_with('[') {
        return looks("a JSON file (e.g. PVGIS's JSON output: download its CSV or EPW instead)");
    }
    if t.starts_with("PK\u{3}\u{4}") {
        return looks("a ZIP archive or an Excel workbook (unpack it, or save the sheet as CSV)");
    }
    if t.starts_with("\u{1f}\u{fffd}") || t.starts_with("\u{1f}\u{8b}") {
        return looks("a gzip-compressed file (decompress it first)");
    }
    if l(1).starts_with("ObservationTime(LST)") {
        return looks("SolarAnywhere's own \"SA format\" (download its \"TMY3 format\" instead)");
    }
    // The plain CSV: the first line that is neither blank nor a comment
    // is its header.
    let Some((i, header)) = lines
        .iter()
        .enumerate()
        .find(|(_, x)| !x.trim().is_empty() && !x.trim_start().starts_with('#'))
    else {
        return Ok(WeatherFormat::Csv); // the reader reports "no header"
    };
    if split_csv(header)
        .iter()
        .any(|x| x.trim().eq_ignore_ascii_case("time"))
    {
        return Ok(WeatherFormat::Csv);
    }
    let shown: String = header.chars().take(60).collect();
    Err((
        i + 1,
        format!(
            "'{shown}{}' is not the start of a weather format irsig recognises (a plain CSV's header \
             names a `time` column)",
            if header.chars().count() > 60 {
                "…"
            } else {
                ""
            }
        ),
    ))
}
