"""Reference solar elevations (NREL SPA via pvlib) for the approximate
day/night test of `irsig check` (src/cli/check.rs). Writes
tests/data/sun_elevation_pvlib.csv: utc, latitude_deg, longitude_deg,
apparent-free elevation_deg (pvlib 'elevation', no refraction).
Run: tools/.venv/bin/python tools/sun_elevation_ref.py"""
import pathlib

import pandas as pd
import pvlib

cases = [
    ("2001-08-08T16:00:00", 43.1566, -77.6088),
    ("2001-08-08T11:00:00", 43.1566, -77.6088),
    ("2001-08-08T23:30:00", 43.1566, -77.6088),
    ("2001-08-09T03:00:00", 43.1566, -77.6088),
    ("2021-12-21T12:00:00", 51.48, 0.0),
    ("2021-03-20T06:00:00", 0.0, 90.0),
    ("2020-02-29T18:00:00", -33.87, 151.21),
    ("2019-06-21T20:00:00", 64.84, -147.72),
    ("2019-01-15T09:30:00", -77.85, 166.67),
    ("2024-10-01T14:45:00", 36.1, -79.95),
]
rows = []
for t, lat, lon in cases:
    ts = pd.DatetimeIndex([pd.Timestamp(t, tz="UTC")])
    sp = pvlib.solarposition.spa_python(ts, lat, lon, altitude=0, pressure=101325, temperature=12)
    rows.append(f"{t},{lat},{lon},{sp['elevation'].iloc[0]:.6f}")
out = pathlib.Path(__file__).resolve().parent.parent / "tests/data/sun_elevation_pvlib.csv"
out.write_text("utc,latitude_deg,longitude_deg,elevation_deg\n" + "\n".join(rows) + "\n")
print(out.read_text())
