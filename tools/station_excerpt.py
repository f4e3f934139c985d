#!/usr/bin/env python3
"""Writes the station-day excerpts under tests/data/stations/: measured
forcing in irsig's plain weather CSV (docs/weather-format.md) plus the
measured radiation and the skin temperature derived from it (`x_` columns,
ignored by the weather reader). See tests/data/stations/README.md for the
sources and docs/validation-stations.md for the method.

Station-days (UTC):

  bon-19950510      NOAA SURFRAD Bondville, IL, grass, late spring
                    (overcast, wet). QCrad file, 3-min means -> 15-min.
                    One day only: the 24-h spin-up repeats that day
                    (x_spinup = 1 rows, measurement columns blank).
  slv-20160101      NOAA SURFRAD Alamosa, CO, winter, snow-free. 1-min
                    means -> 15-min. One day only: same repeated-day
                    spin-up (the measured 2015-12-31, slv15365.dat, is
                    a file of a repository reserved for independent
                    checking, issue #30, and is not used).

Raw inputs: tools/data/stations-raw/ holds the Bondville file (small). The
Alamosa file (340 kB) is not committed; pass --surfrad-dir DIR with
slv16001.dat (source in the README) to rewrite slv-20160101.csv, otherwise
its committed excerpt is kept. (The ARM SGP E39 day once written here was
removed: its files are ARM-DOE/ACT's test data, reserved for independent
checking.)

Skin temperature from the measured longwave (e.g. Wang & Liang 2009,
Remote Sens. Environ. 113, 1556):
    LWup = eps*sigma*Ts^4 + (1 - eps)*LWdn
    Ts   = ((LWup - (1 - eps)*LWdn) / (eps*sigma))^(1/4)

Standard library only.
Run:
    python3 tools/station_excerpt.py [--surfrad-dir DIR]
"""
import argparse
import datetime as dt
import hashlib
import math
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
RAW = ROOT / "tools/data/stations-raw"
OUT = ROOT / "tests/data/stations"
SIGMA = 5.670374419e-8  # W m-2 K-4 (CODATA 2018)
UTC = dt.timezone.utc

# SHA-256 of the raw inputs the committed excerpts were written from.
RAW_SHA256 = {
    "bon_19950510.qdat": "64fc9c1cb3cc80f33863802d032f5b71bcbb48848d07091b6de6f7f3c0c8c10b",
    "slv16001.dat": "8d681d07c9161812db4f82d0c43d24f002234cf5c9bbba147b39cb038c550f83",
}


def check_raw(path):
    """Warns when a raw input differs from the one the excerpts were written from."""
    path = pathlib.Path(path)
    h = hashlib.sha256(path.read_bytes()).hexdigest()
    want = RAW_SHA256.get(path.name)
    if want and h != want:
        print(f"warning: {path}: sha256 {h} differs from the recorded {want}", file=sys.stderr)
    return path

# ---------------------------------------------------------------------------
# Records: dicts with 'end' (UTC end of the averaging interval), 'span'
# (averaging length) and float-or-None fields
#   ghi dni dhi sw_up lw_dn lw_up t_air_c rh wind p_hpa
# ---------------------------------------------------------------------------
def read_surfrad_dat(path):
    """NOAA SURFRAD daily file (README: times are the END of 1- or 3-min
    averages; missing = -9999.9 with qc 1; qc 2 = questionable)."""
    lines = check_raw(path).read_text().splitlines()
    meta = {"name": lines[0].strip()}
    lat, lon, elev = lines[1].split()[:3]
    # The header gives west longitudes as positive numbers.
    meta.update(lat=float(lat), lon=-abs(float(lon)), elev=float(elev))
    cols = ["ghi", "sw_up", "dni", "dhi", "lw_dn", "dw_case", "dw_dome", "lw_up",
            "uw_case", "uw_dome", "uvb", "par", "netsolar", "netir", "totalnet",
            "t_air_c", "rh", "wind", "wdir", "p_hpa"]
    recs, questionable = [], 0
    for ln in lines[2:]:
        f = ln.split()
        if len(f) < 48:
            continue
        y, _, mo, d, h, mi = (int(x) for x in f[:6])
        r = {"end": dt.datetime(y, mo, d, h, mi, tzinfo=UTC),
             "span": dt.timedelta(minutes=1 if y >= 2009 else 3)}
        for i, c in enumerate(cols):
            v, qc = float(f[8 + 2 * i]), int(f[9 + 2 * i])
            bad = qc == 1 or v <= -9999.0
            questionable += qc == 2 and c in ("ghi", "dni", "dhi", "sw_up", "lw_dn", "lw_up", "t_air_c", "rh", "wind", "p_hpa")
            r[c] = None if bad else v
        recs.append(r)
    return meta, recs, questionable


def read_qcrad(path):
    """SURFRAD QCrad file (bon_19950510.qdat): header row of names, 3-min
    averages; Time is HMM UTC, taken as the END of the average like the
    SURFRAD daily files. Ta in K; pressure missing (-9999.9) in 1995.
    Flags (hagne/SURFRAD data/SURFRAD_QCrad_metadata.txt): qc1 GSW, qc3 DIR,
    qc4 SWup, qc5 LWdn, qc6 LWup thresholds; qc10-18 longwave consistency;
    qc19 Ta; 0 = no known issue, -1 = test not possible. DIF is not used:
    its flag (qc2) is 10 on nearly every record, a value the metadata does
    not define, so the diffuse is derived by irsig from GHI and DNI."""
    lines = check_raw(path).read_text().splitlines()
    names = lines[0].split()
    recs = []
    for ln in lines[1:]:
        f = ln.split()
        if len(f) != len(names):
            continue
        v = dict(zip(names, f))
        date, hm = v["Date"], int(v["Time"])
        t = dt.datetime(int(date[:4]), int(date[4:6]), int(date[6:]), hm // 100, hm % 100, tzinfo=UTC)
        num = lambda k: None if float(v[k]) <= -9999.0 else float(v[k])
        ok = lambda *q: all(int(v[x]) in (0, -1) for x in q)
        lw_ok = ok("qc10", "qc11", "qc12", "qc13", "qc14", "qc15", "qc16", "qc17", "qc18")
        r = {"end": t, "span": dt.timedelta(minutes=3),
             "ghi": num("GSW") if ok("qc1") else None,
             "dni": num("DIR") if ok("qc3") else None,
             "dhi": None,
             "sw_up": num("SWup") if ok("qc4") else None,
             "lw_dn": num("LWdn") if ok("qc5") and lw_ok else None,
             "lw_up": num("LWup") if ok("qc6") and lw_ok else None,
             "t_air_c": num("Ta") - 273.15 if ok("qc19") and num("Ta") is not None else None,
             "rh": num("RH"), "wind": num("WindSp"), "p_hpa": num("Prs")}
        recs.append(r)
    return recs


# ---------------------------------------------------------------------------
FIELDS = ["ghi", "dni", "dhi", "sw_up", "lw_dn", "lw_up", "t_air_c", "rh", "wind", "p_hpa"]


def resample(recs, minutes):
    """Means over `minutes` bins; a bin [end - minutes, end] holds the records
    whose averaging interval ends in (end - minutes, end]. A field's bin mean
    needs at least half the bin's records valid. Returns rows stamped at the
    bin centre."""
    span = recs[0]["span"]
    per_bin = dt.timedelta(minutes=minutes) // span
    step = dt.timedelta(minutes=minutes)
    bins = {}
    for r in recs:
        epoch = (r["end"] - dt.datetime(1970, 1, 1, tzinfo=UTC)).total_seconds()
        k = math.ceil(epoch / step.total_seconds())
        bins.setdefault(k, []).append(r)
    rows = []
    for k in sorted(bins):
        end = dt.datetime(1970, 1, 1, tzinfo=UTC) + k * step
        rs = bins[k]
        row = {"time": end - step / 2}
        for f in FIELDS:
            vals = [r[f] for r in rs if r[f] is not None]
            row[f] = sum(vals) / len(vals) if len(vals) * 2 >= per_bin else None
        row["n"] = len(rs)
        if len(rs) * 2 >= per_bin:
            rows.append(row)
    return rows


def fill_required(rows, keys=("t_air_c", "rh", "wind")):
    """Linear interpolation in time over gaps of required fields (at most
    1 h); returns how many values were filled."""
    filled = 0
    for k in keys:
        idx = [i for i, r in enumerate(rows) if r[k] is not None]
        if not idx:
            raise ValueError(f"no valid {k}")
        for i, r in enumerate(rows):
            if r[k] is not None:
                continue
            lo = max((j for j in idx if j < i), default=None)
            hi = min((j for j in idx if j > i), default=None)
            if lo is None or hi is None or (rows[hi]["time"] - rows[lo]["time"]) > dt.timedelta(hours=1):
                raise ValueError(f"{k} missing at {r['time']} with no neighbours within 1 h")
            w = (r["time"] - rows[lo]["time"]) / (rows[hi]["time"] - rows[lo]["time"])
            r[k] = rows[lo][k] + w * (rows[hi][k] - rows[lo][k])
            filled += 1
    return filled


def skin_temp_c(lw_up, lw_dn, eps):
    return ((lw_up - (1.0 - eps) * lw_dn) / (eps * SIGMA)) ** 0.25 - 273.15


def solar_time_h(t, lon):
    """Local apparent solar time in hours (NOAA equation of time, ~1 min)."""
    doy = t.timetuple().tm_yday
    g = 2 * math.pi / 365 * (doy - 1 + (t.hour - 12) / 24)
    eot = 229.18 * (0.000075 + 0.001868 * math.cos(g) - 0.032077 * math.sin(g)
                    - 0.014615 * math.cos(2 * g) - 0.040849 * math.sin(2 * g))
    return (t.hour + t.minute / 60 + t.second / 3600 + lon / 15 + eot / 60) % 24


def midday_albedo(rows, lon):
    """Sum(SWup)/Sum(SWdn) over 10:00-14:00 local solar time, GHI > 50 W/m2."""
    up = dn = 0.0
    for r in rows:
        if r["ghi"] is None or r["sw_up"] is None or r["ghi"] <= 50:
            continue
        if 10.0 <= solar_time_h(r["time"], lon) <= 14.0:
            up += r["sw_up"]
            dn += r["ghi"]
    return up / dn if dn > 0 else float("nan")


def fmt(v, nd=2):
    return "" if v is None else f"{v:.{nd}f}"


def iso(t):
    return t.strftime("%Y-%m-%dT%H:%M:%SZ")


def write_station(name, rows, meta, eps, eps_note, source_lines, notes, spinup=None):
    """rows: the measured rows of the compared day (sorted). spinup: the
    measured rows before it, or None to repeat the compared day 24 h
    earlier as the spin-up (x_ measurement columns blank there)."""
    filled = fill_required(rows)
    repeat_day = spinup is None
    compare_from, compare_to = rows[0]["time"], rows[-1]["time"]
    out_rows = []
    if repeat_day:
        for r in rows:
            c = dict(r, time=r["time"] - dt.timedelta(hours=24))
            out_rows.append((c, True))
    else:
        filled += fill_required(spinup)
        out_rows += [(r, True) for r in spinup]
    out_rows += [(r, False) for r in rows]
    spin_from = out_rows[0][0]["time"]
    spin_up_h = (compare_from - spin_from).total_seconds() / 3600
    albedo = midday_albedo(rows, meta["lon"])
    for r, _ in out_rows:
        if r["lw_up"] is not None and r["lw_dn"] is not None:
            r["skin"] = skin_temp_c(r["lw_up"], r["lw_dn"], eps)
            # sensitivity of the derived skin temperature to eps +/- 0.01
            r["dts"] = abs(skin_temp_c(r["lw_up"], r["lw_dn"], eps + 0.01) - r["skin"])
        else:
            r["skin"] = r["dts"] = None
    measured = [r for r, copy in out_rows if not copy and r["skin"] is not None]
    dts_mean = sum(r["dts"] for r in measured) / len(measured)
    dts_max = max(r["dts"] for r in measured)
    has_p = any(r["p_hpa"] is not None for r in rows)
    cols = ["time", "air_temp_c", "rh_percent", "wind_m_s"] + (["pressure_hpa"] if has_p else []) + [
        "cloud_fraction", "ghi_w_m2", "dni_w_m2", "dhi_w_m2", "sky_temp_c", "precip_mm_h",
        "x_lw_up_w_m2", "x_lw_dn_w_m2", "x_sw_up_w_m2", "x_skin_temp_c", "x_spinup"]
    hdr = [
        f"# {name}: irsig plain weather CSV (docs/weather-format.md) written by tools/station_excerpt.py",
        *[f"# {s}" for s in source_lines],
        f"# lat: {meta['lat']:.5f}",
        f"# lon: {meta['lon']:.5f}",
        f"# elevation_m: {meta['elev']:.0f}",
        f"# compare_from: {iso(compare_from)}",
        f"# compare_to: {iso(compare_to)}",
        f"# spin_up_h: {spin_up_h:g}",
        f"# emissivity: {eps}  ({eps_note})",
        f"# midday_albedo: {albedo:.3f}  (sum SWup / sum SWdn, 10-14 h local solar time, GHI > 50 W/m2)",
        f"# skin_temp_sensitivity_k_per_0.01_emissivity: mean {dts_mean:.2f}, max {dts_max:.2f}",
        "# Times: UTC, centre of each averaging interval. Irradiances and longwave are interval means.",
        "# sky_temp_c = (LWdn/sigma)^(1/4) - 273.15 (effective sky temperature of the measured LWdn).",
        "# x_skin_temp_c = ((LWup - (1-eps)*LWdn)/(eps*sigma))^(1/4) - 273.15, sigma = 5.670374419e-8.",
        "# cloud_fraction: required by the reader today; unused (0) because sky_temp_c and the irradiances are measured.",
        "# precip_mm_h: 0 (not used by the surface model).",
        "# x_ columns are ignored by the weather reader; x_spinup = 1 marks spin-up rows (not compared).",
        *[f"# note: {n}" for n in notes],
    ]
    if filled:
        hdr.append(f"# note: {filled} value(s) of air temperature/RH/wind linearly interpolated over short gaps")
    if repeat_day:
        hdr.append("# note: one measured day only; the spin-up day is that day repeated 24 h earlier (documented fallback)")
    lines = hdr + [",".join(cols)]
    for r, copy in out_rows:
        sky = None if r["lw_dn"] is None else (r["lw_dn"] / SIGMA) ** 0.25 - 273.15
        clip = lambda v: None if v is None else max(v, 0.0)
        cells = [iso(r["time"]), fmt(r["t_air_c"]), fmt(min(r["rh"], 100.0), 1), fmt(r["wind"])]
        if has_p:
            cells.append(fmt(r["p_hpa"], 1))
        cells += ["0", fmt(clip(r["ghi"]), 1), fmt(clip(r["dni"]), 1), fmt(clip(r["dhi"]), 1),
                  fmt(sky), "0"]
        if copy and repeat_day:
            cells += ["", "", "", "", "1"]
        else:
            cells += [fmt(r["lw_up"], 1), fmt(r["lw_dn"], 1), fmt(clip(r["sw_up"]), 1), fmt(r["skin"]),
                      "1" if copy else "0"]
        lines.append(",".join(cells))
    OUT.mkdir(parents=True, exist_ok=True)
    p = OUT / f"{name}.csv"
    p.write_text("\n".join(lines) + "\n")
    print(f"{p.relative_to(ROOT)}: {len(out_rows)} rows, compare {iso(compare_from)} .. {iso(compare_to)}, "
          f"spin-up {spin_up_h:g} h, albedo {albedo:.3f}, dTs/0.01eps mean {dts_mean:.2f} K max {dts_max:.2f} K")
    return {"albedo": albedo, "dts_mean": dts_mean, "dts_max": dts_max}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--surfrad-dir", type=pathlib.Path,
                    help="directory with slv16001.dat (SURFRAD Alamosa)")
    a = ap.parse_args()

    # --- SURFRAD Bondville, 1995-05-10 (late spring, grass) ---
    recs = read_qcrad(RAW / "bon_19950510.qdat")
    rows = resample(recs, 15)
    # Site: NOAA's station metadata (as in hagne/SURFRAD's Bondville netCDF
    # files and gml.noaa.gov/grad/surfrad): 40.05192 N, 88.37309 W, 230 m
    # (Augustine et al. 2000 list 213 m). 1995: no barometer yet (SURFRAD
    # README); standard atmosphere at 230 m.
    p_est = 1013.25 * (1 - 2.25577e-5 * 230) ** 5.25588
    for r in rows:
        r["p_hpa"] = p_est
    write_station(
        "bon-19950510", rows, {"lat": 40.05192, "lon": -88.37309, "elev": 230}, 0.98,
        "grass, typical broadband value; see docs/validation-stations.md",
        ["source: NOAA SURFRAD Bondville, IL (bon), QCrad file bon_19950510.qdat (3-min means),",
         "        via github.com/hagne/SURFRAD data/bon_19950510.qdat (see tests/data/stations/README.md)",
         "data: NOAA Global Monitoring Laboratory, U.S. Government work (public domain)"],
        [f"pressure not measured in 1995: {p_est:.1f} hPa = standard atmosphere at 230 m",
         "diffuse not used (undocumented QC flag); irsig derives DHI from GHI and DNI",
         "overcast and humid all day: LWdn within a few W/m2 of LWup, small diurnal cycle"],
        spinup=None)

    # --- SURFRAD Alamosa, 2016-01-01 (winter, snow-free), repeated-day spin-up ---
    if not a.surfrad_dir:
        print("tests/data/stations/slv-20160101.csv: kept (no --surfrad-dir)")
        return 0
    meta, recs, q = read_surfrad_dat(a.surfrad_dir / "slv16001.dat")
    split = dt.datetime(2016, 1, 1, tzinfo=UTC)
    day = [r for r in resample(recs, 15) if split <= r["time"] < split + dt.timedelta(days=1)]
    write_station(
        "slv-20160101", day, meta, 0.95,
        "snow-free sparse dry grass on sandy soil, typical broadband value; see docs/validation-stations.md",
        ["source: NOAA SURFRAD Alamosa, CO (slv), daily file slv16001.dat (1-min means),",
         "        via github.com/pvlib/pvlib-python tests/data/surfrad-slv16001.dat (see tests/data/stations/README.md)",
         "data: NOAA Global Monitoring Laboratory, U.S. Government work (public domain)"],
        [f"{q} 1-min values carry SURFRAD qc 2 (questionable) and were kept",
         "clear sky; the file header gives the west longitude 105.92 as a positive number"],
        spinup=None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
