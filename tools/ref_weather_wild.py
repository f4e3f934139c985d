#!/usr/bin/env python3
"""Excerpts of real weather files and pvlib's reading of them, for
tests/weather_wild.rs.

Writes under tests/data/wild/weather/:
  tmy3_723170_yearend.csv      TMY3 Greensboro NC (pvlib/data/723170TYA.CSV): the two
                               header lines, 1-2 January (1988) and 30-31 December (1980)
  tmy2_12839_miami_jan1-3.tm2  TMY2 Miami FL (pvlib/data/12839.tm2): station line + 72 h
  psm3_401182_2017_jan1-3.csv  NSRDB PSM3 (sdist tests/data/test_read_psm3.csv): 3 header
                               lines + 144 half-hours
  pvgis_tmy_45N_8E_jan1-3.csv  PVGIS TMY CSV (sdist tmy_45.000_8.000_2005_2023.csv): its
                               header, 72 h and its legend
  pvgis_tmy_45N_8E_jan1-3.epw  PVGIS's EPW of the same TMY: 8 header lines + 72 h
  solaranywhere_tmy3_burlington_jan1-3.csv  SolarAnywhere "TMY3 format" (sdist): 2 header
                               lines + 72 h
  *_pvlib.csv                  each excerpt as read by pvlib.iotools (values and the UTC
                               time they belong to)

Sources: pvlib's installed data folder and the pvlib sdist's tests/data
(`pip download pvlib==0.16.1 --no-binary :all: --no-deps`, unpacked; give its
folder as PVLIB_SDIST). Run:
    PVLIB_SDIST=/tmp/pvsrc/pvlib-0.16.1 tools/.venv/bin/python tools/ref_weather_wild.py
"""
import os
import pathlib

import pandas as pd
import pvlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "data" / "wild" / "weather"
PVDATA = pathlib.Path(pvlib.__file__).parent / "data"
SDIST = pathlib.Path(os.environ.get("PVLIB_SDIST", "/tmp/pvsrc/pvlib-0.16.1")) / "tests" / "data"


def write_ref(path, times_utc, df, cols, note):
    """One row per record: the UTC time, then the named values."""
    with open(path, "w") as f:
        f.write(f"# pvlib {pvlib.__version__} {note}\n")
        f.write("time_utc," + ",".join(cols) + "\n")
        for i, t in enumerate(times_utc):
            vals = [df[c].iloc[i] for c in cols]
            f.write(t.strftime("%Y-%m-%dT%H:%M:%SZ") + "," + ",".join(repr(float(v)) for v in vals) + "\n")


def tmy3_yearend():
    lines = (PVDATA / "723170TYA.CSV").read_text().splitlines()
    head, rows = lines[:2], lines[2:]
    days = {"01/01/1988", "01/02/1988", "12/30/1980", "12/31/1980"}
    keep = [r for r in rows if r.split(",")[0] in days]
    assert len(keep) == 96, len(keep)
    p = OUT / "tmy3_723170_yearend.csv"
    p.write_text("\n".join(head + keep) + "\n")
    df, meta = pvlib.iotools.read_tmy3(p, map_variables=True)
    # pvlib stamps each record at its hour's end in local standard time with
    # the file's own year. irsig lays the typical year on 1990 and 1991: the
    # record labelled (month, day, hour) of the file belongs to that label in
    # each year (24:00 = midnight at the end of the labelled day).
    cols = ["temp_air", "temp_dew", "pressure", "wind_speed", "ghi", "dni", "dhi", "TotCld (tenths)"]
    times, frames = [], []
    for year in (1990, 1991):
        lab = df.index - pd.Timedelta(hours=1)
        t = [pd.Timestamp(x.replace(year=year, tzinfo=None)) + pd.Timedelta(hours=1) for x in lab]
        t = pd.DatetimeIndex(t).tz_localize("Etc/GMT+5").tz_convert("UTC")
        times.extend(t)
        frames.append(df)
    both = pd.concat(frames)
    order = sorted(range(len(times)), key=lambda i: times[i])
    write_ref(OUT / "tmy3_723170_yearend_pvlib.csv", [times[i] for i in order], both.iloc[order], cols,
              f"read_tmy3(map_variables=True), laid on 1990 and 1991; meta TZ={meta['TZ']}")


def end_utc(index, shift_h):
    """pvlib's index (tz-aware) + shift_h hours, in UTC."""
    return (index + pd.Timedelta(hours=shift_h)).tz_convert("UTC")


def excerpt(src, dst, n_head, n_rows, tail=None, encoding="utf-8"):
    """The first n_head header lines and the next n_rows records of src,
    byte-for-byte, plus the lines from `tail` (a line index) to the end."""
    raw = src.read_bytes().split(b"\n")
    keep = raw[: n_head + n_rows] + (raw[tail:] if tail is not None else [])
    dst.write_bytes(b"\n".join(keep) + (b"" if keep[-1] == b"" else b"\n"))
    return dst


def tmy2():
    p = excerpt(PVDATA / "12839.tm2", OUT / "tmy2_12839_miami_jan1-3.tm2", 1, 72)
    df, meta = pvlib.iotools.read_tmy2(str(p))
    df = df.assign(temp_air=df.DryBulb / 10, temp_dew=df.DewPoint / 10, wind_speed=df.Wspd / 10)
    # pvlib labels each record with the start of its hour (hour - 1).
    write_ref(OUT / "tmy2_12839_miami_pvlib.csv", end_utc(df.index, 1), df,
              ["temp_air", "temp_dew", "Pressure", "wind_speed", "GHI", "DNI", "DHI", "TotCld", "RHum"],
              f"read_tmy2(); time = end of the record's hour; meta TZ={meta['TZ']} "
              f"lat={meta['latitude']} lon={meta['longitude']} alt={meta['altitude']}")


def psm3():
    p = excerpt(SDIST / "test_read_psm3.csv", OUT / "psm3_401182_2017_jan1-3.csv", 3, 144)
    df, meta = pvlib.iotools.read_nsrdb_psm4(p, map_variables=True)
    write_ref(OUT / "psm3_401182_pvlib.csv", end_utc(df.index, 0), df,
              ["temp_air", "temp_dew", "pressure", "wind_speed", "ghi", "dni", "dhi", "relative_humidity"],
              f"read_nsrdb_psm4(map_variables=True); time = the record's stamp; meta TZ={meta['Time Zone']} "
              f"lat={meta['latitude']} lon={meta['longitude']} alt={meta['altitude']}")


def pvgis():
    src = SDIST / "tmy_45.000_8.000_2005_2023.csv"
    lines = src.read_bytes().split(b"\n")
    head = next(i for i, l in enumerate(lines) if l.startswith(b"time(UTC)")) + 1
    legend = next(i for i in range(head, len(lines)) if lines[i].strip() == b"")
    p = excerpt(src, OUT / "pvgis_tmy_45N_8E_jan1-3.csv", head, 72, tail=legend)
    # pvlib's PVGIS CSV parser reads exactly 8760 records: read the whole
    # source file and keep the excerpt's 72 (the same lines, byte for byte).
    df, meta = pvlib.iotools.read_pvgis_tmy(src, map_variables=True)[:2]
    df = df.iloc[:72]
    write_ref(OUT / "pvgis_tmy_45N_8E_pvlib.csv", end_utc(df.index, 0), df,
              ["temp_air", "relative_humidity", "pressure", "wind_speed", "ghi", "dni", "dhi", "IR(h)"],
              f"read_pvgis_tmy(map_variables=True) of the whole file, first 72 records; time = the record's "
              f"stamp (UTC); meta {meta['inputs']}")
    p = excerpt(SDIST / "tmy_45.000_8.000_2005_2023.epw", OUT / "pvgis_tmy_45N_8E_jan1-3.epw", 8, 72)
    df, meta = pvlib.iotools.read_epw(p)
    write_ref(OUT / "pvgis_epw_45N_8E_pvlib.csv", end_utc(df.index, 1), df,
              ["temp_air", "temp_dew", "atmospheric_pressure", "wind_speed", "ghi", "dni", "dhi", "ghi_infrared"],
              f"read_epw(); time = end of the record's hour; meta TZ={meta['TZ']} "
              f"lat={meta['latitude']} lon={meta['longitude']}")


def solaranywhere():
    src = SDIST / "Burlington, United States SolarAnywhere Time Series 2021 Lat_44_465 Lon_-73_205 TMY3 format.csv"
    p = excerpt(src, OUT / "solaranywhere_tmy3_burlington_jan1-3.csv", 2, 72)
    df, meta = pvlib.iotools.read_tmy3(p, map_variables=True, encoding="iso-8859-1")
    write_ref(OUT / "solaranywhere_tmy3_burlington_pvlib.csv", end_utc(df.index, 0), df,
              ["temp_air", "relative_humidity", "wind_speed", "ghi", "DNI (W/m^2))", "dhi"],
              f"read_tmy3(map_variables=True, encoding='iso-8859-1'); time = end of the record's hour; "
              f"meta TZ={meta['TZ']} lat={meta['latitude']} lon={meta['longitude']} alt={meta['altitude']}")


tmy3_yearend()
tmy2()
psm3()
pvgis()
solaranywhere()
print("ok")
