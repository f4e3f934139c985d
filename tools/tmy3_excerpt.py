"""Writes scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv: an
excerpt of the NREL TMY3 record for Greensboro Piedmont Triad Int'l, NC
(USAF 723170), as shipped in pvlib's data folder (pvlib/data/723170TYA.CSV).

The excerpt keeps the two TMY3 header lines unchanged and the hourly rows of
2001-08-04 01:00 to 2001-08-09 24:00 (local standard time, UTC-5): 144 rows,
a clear spell (total cloud 0.6/10 on Aug 7 and 8) that covers a 24-72 h
thermal spin-up before an image on 2001-08-08 and the whole image day.
Data: NREL National Solar Radiation Database, TMY3 (Wilcox & Marion 2008,
NREL/TP-581-43156), U.S. Government work, public. Run:
    tools/.venv/bin/python tools/tmy3_excerpt.py
"""
import os
import pathlib

import pvlib

src = pathlib.Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"
lines = src.read_text().splitlines()
header, rows = lines[:2], lines[2:]
days = {f"08/{d:02d}/2001" for d in range(4, 10)}
keep = [r for r in rows if r.split(",")[0] in days]
assert len(keep) == 144, len(keep)
out = pathlib.Path(__file__).resolve().parent.parent / "scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv"
out.parent.mkdir(parents=True, exist_ok=True)
out.write_text("\n".join(header + keep) + "\n")
print(out, len(keep), "rows")
