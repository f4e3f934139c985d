#!/usr/bin/env python3
"""Runs `irsig therm` on a station-day excerpt (tests/data/stations/*.csv,
written by tools/station_excerpt.py) and compares the modelled surface
temperature with the skin temperature derived from the measured longwave
(x_skin_temp_c): RMS, bias (model - measured) and largest absolute error,
over the whole compared day and split into day (measured GHI > 10 W/m2)
and night. The site, window and spin-up come from the excerpt's `# key:`
header lines. Standard library only.

    python3 tools/station_compare.py tests/data/stations/slv-20160101.csv \
        --material grass [--materials scenes/materials.toml] \
        [--irsig target/release/irsig] [--hourly] [--out cmp.csv]

Prints one summary line per file (several files may be given; they all use
--material unless --material is given as FILE=NAME pairs, e.g.
--material bon-19950510=grass_irrigated).
"""
import argparse
import csv
import io
import math
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def read_excerpt(path):
    meta, lines = {}, []
    for ln in pathlib.Path(path).read_text().splitlines():
        if ln.startswith("#"):
            k, sep, v = ln[1:].partition(":")
            if sep and " " not in k.strip():
                meta.setdefault(k.strip(), v.strip().split()[0] if v.strip() else "")
        elif ln.strip():
            lines.append(ln)
    rows = list(csv.DictReader(io.StringIO("\n".join(lines))))
    return meta, rows


def run_irsig(irsig, materials, material, path, meta, step):
    cmd = [str(irsig), "therm", "--materials", str(materials), "--material", material,
           "--weather", str(path), "--lat", meta["lat"], "--lon", meta["lon"],
           "--elevation", meta["elevation_m"], "--from", meta["compare_from"],
           "--to", meta["compare_to"], "--step", str(step), "--spin-up-h", meta["spin_up_h"],
           # Measurement heights as tests/therm_stations.rs passes them: the
           # file's own (`wind_height_m`, `air_height_m`), else SURFRAD's
           # 10 m wind and 2 m air.
           "--wind-height-m", meta.get("wind_height_m", "10"),
           "--air-height-m", meta.get("air_height_m", "2"),
           "--csv"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)}\n{p.stderr}")
    return {r["time_utc"]: r for r in csv.DictReader(io.StringIO(p.stdout))}


def stats(errs):
    if not errs:
        return float("nan"), float("nan"), float("nan"), 0
    n = len(errs)
    return (math.sqrt(sum(e * e for e in errs) / n), sum(errs) / n, max(errs, key=abs), n)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", type=pathlib.Path)
    ap.add_argument("--material", action="append", required=True,
                    help="material name, or STATION=NAME (STATION = file stem)")
    ap.add_argument("--materials", type=pathlib.Path, default=ROOT / "scenes/materials.toml")
    ap.add_argument("--irsig", type=pathlib.Path, default=ROOT / "target/release/irsig")
    ap.add_argument("--step", type=float, default=15.0, help="irsig --step, minutes")
    ap.add_argument("--hourly", action="store_true", help="print measured and modelled values every hour")
    ap.add_argument("--out", type=pathlib.Path, help="write time,measured,model,air rows (one file only)")
    a = ap.parse_args()
    default = next((m for m in a.material if "=" not in m), None)
    per = dict(m.split("=", 1) for m in a.material if "=" in m)
    print(f"{'station-day':18} {'material':16} {'n':>4} {'RMS':>6} {'bias':>6} {'max':>7}"
          f" | {'day RMS':>7} {'bias':>6} {'max':>7} | {'night RMS':>9} {'bias':>6} {'max':>7}  (K, model - measured)")
    for f in a.files:
        mat = per.get(f.stem, default)
        if mat is None:
            sys.exit(f"no --material for {f.stem}")
        meta, rows = read_excerpt(f)
        model = run_irsig(a.irsig, a.materials, mat, f, meta, a.step)
        allv, day, night, pairs = [], [], [], []
        for r in rows:
            if r["x_spinup"] != "0" or not r["x_skin_temp_c"]:
                continue
            m = model.get(r["time"])
            if m is None:
                sys.exit(f"{f}: irsig printed no row at {r['time']} (use a --step that divides the record interval)")
            ts_model = float(m["surface_temp_k"]) - 273.15
            ts_meas = float(r["x_skin_temp_c"])
            e = ts_model - ts_meas
            allv.append(e)
            (day if float(r["ghi_w_m2"] or 0) > 10 else night).append(e)
            pairs.append((r["time"], ts_meas, ts_model, float(r["air_temp_c"])))
        s, d, n = stats(allv), stats(day), stats(night)
        print(f"{f.stem:18} {mat:16} {s[3]:4d} {s[0]:6.2f} {s[1]:+6.2f} {s[2]:+7.2f}"
              f" | {d[0]:7.2f} {d[1]:+6.2f} {d[2]:+7.2f} | {n[0]:9.2f} {n[1]:+6.2f} {n[2]:+7.2f}")
        if a.hourly:
            print(f"  {'time (UTC)':20} {'measured':>8} {'model':>8} {'air':>7}  (°C)")
            for t, ms, md, ta in pairs:
                if t[14:19] in ("07:30", "15:00"):
                    print(f"  {t:20} {ms:8.2f} {md:8.2f} {ta:7.2f}")
        if a.out:
            with open(a.out, "w") as fh:
                fh.write("time_utc,skin_measured_c,surface_model_c,air_c\n")
                for t, ms, md, ta in pairs:
                    fh.write(f"{t},{ms:.3f},{md:.3f},{ta:.2f}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
