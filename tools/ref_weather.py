#!/usr/bin/env python3
"""Reference values from pvlib's weather-file readers for irsig's tests.

Reads the committed excerpts
  tests/data/tmy3_723170_greensboro_jun18-22.csv  (NREL TMY3, public data)
  tests/data/epw_amsterdam_iwec_jun18-22.epw      (IWEC via pvlib's test data)
with pvlib.iotools.read_tmy3 / read_epw and writes, per record, the UTC time
of the END of the record's hour and the values irsig must read:
  tests/data/tmy3_greensboro_pvlib.csv, tests/data/epw_amsterdam_pvlib.csv
pvlib labels TMY3 records by their hour-ending stamp and EPW records by the
hour's start (hour-1), so 1 h is added to the EPW index here.

Run: tools/.venv/bin/python tools/ref_weather.py
"""
import os
import pandas as pd
import pvlib

D = os.path.join(os.path.dirname(__file__), "..", "tests", "data")


def write(df, path, cols, shift_h, note):
    t = (df.index + pd.Timedelta(hours=shift_h)).tz_convert("UTC")
    with open(path, "w") as f:
        f.write(f"# pvlib {pvlib.__version__} {note}; time_end_utc = end of the record's hour\n")
        f.write("time_end_utc," + ",".join(cols) + "\n")
        for i in range(len(df)):
            vals = [df[c].iloc[i] for c in cols]
            f.write(t[i].strftime("%Y-%m-%dT%H:%M:%SZ") + "," + ",".join(repr(float(v)) for v in vals) + "\n")


tmy, meta = pvlib.iotools.read_tmy3(os.path.join(D, "tmy3_723170_greensboro_jun18-22.csv"), map_variables=True)
write(tmy, os.path.join(D, "tmy3_greensboro_pvlib.csv"),
      ["temp_air", "temp_dew", "relative_humidity", "pressure", "wind_speed", "ghi", "dni", "dhi",
       "Lprecip depth (mm)", "TotCld (tenths)"],
      0, f"read_tmy3(map_variables=True) meta TZ={meta['TZ']} lat={meta['latitude']} lon={meta['longitude']} alt={meta['altitude']}")

epw, meta = pvlib.iotools.read_epw(os.path.join(D, "epw_amsterdam_iwec_jun18-22.epw"))
write(epw, os.path.join(D, "epw_amsterdam_pvlib.csv"),
      ["temp_air", "temp_dew", "relative_humidity", "atmospheric_pressure", "wind_speed", "ghi", "dni", "dhi",
       "ghi_infrared", "total_sky_cover", "liquid_precipitation_depth"],
      1, f"read_epw() meta TZ={meta['TZ']} lat={meta['latitude']} lon={meta['longitude']} alt={meta['altitude']}")
print("ok")
