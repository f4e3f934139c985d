#!/usr/bin/env python3
"""Excerpts of real weather files and pvlib's reading of them, for
tests/weather_wild.rs.

Writes under tests/data/wild/weather/:
  tmy3_723170_yearend.csv      TMY3 Greensboro NC (pvlib/data/723170TYA.CSV): the two
                               header lines, 1-2 January (1988) and 30-31 December (1980)
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


tmy3_yearend()
print("ok")
