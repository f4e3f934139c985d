#!/usr/bin/env python3
"""Reference evapotranspiration (FAO-56 / ASCE-EWRI grass reference) for irsig's
latent-heat tests, from the airfield scene's weather record.

Writes
  tests/data/ref_et0_greensboro.csv        one row per hour of the window
  tests/data/ref_et0_greensboro_daily.csv  one row per local-standard-time day
  tests/data/ref_aero_fao56.csv            aerodynamic resistance of the FAO grass
See tests/data/ref_et0_README.md for what every column means.

Weather: scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv, read here
with a small parser of its own (not irsig's, not pvlib's). TMY3 (Wilcox & Marion
2008): line 1 = USAF id, name, state, UTC offset (h), latitude (deg N),
longitude (deg E, negative west), elevation (m); line 2 = column names; then one
row per hour, stamped at the END of the hour in local standard time (01:00 ...
24:00). Columns used:
  Date (MM/DD/YYYY), Time (HH:MM)  -> hour-ending stamp, LST (24:00 = next day 00:00)
  GHI (W/m^2)      mean global horizontal irradiance over the hour ending at the stamp
  Dry-bulb (C)     air temperature observed at the stamp
  Dew-point (C)    dew point observed at the stamp
  Wspd (m/s)       wind speed observed at the stamp, 10 m above ground
(Pressure (mbar) and TotCld (tenths) are copied to the output for information;
the standardized equations use the elevation-based pressure and Rs/Rso.)

Per hour h (the hour ending at stamp s_h, starting at s_{h-1}):
  T    = (T(s_{h-1}) + T(s_h)) / 2          hour-mean air temperature
  Td   = (Td(s_{h-1}) + Td(s_h)) / 2        hour-mean dew point
  u10  = (u(s_{h-1}) + u(s_h)) / 2          hour-mean wind at 10 m
  ea   = 0.6108 exp(17.27 Td / (Td + 237.3))  kPa   (FAO-56 eq. 14 = ASCE eq. 8)
  Rs   = GHI(s_h) * 0.0036                  MJ m-2 h-1 (W m-2 over 3600 s)
The two-stamp means are the exact hour means of the piecewise-linear
interpolation irsig applies between stamps (docs/weather-format.md), so a model
that integrates irsig's forcing over the hour sees these inputs.

Methods
  ASCE standardized hourly ETo (short/grass reference; Cn = 37; Cd = 0.24 and
    G = 0.1 Rn when Rn >= 0, Cd = 0.96 and G = 0.5 Rn when Rn < 0, refet's
    day/night test): refet.Hourly(...).eto(), method='asce' (ASCE-EWRI 2005).
    This is the reference.
  FAO-56 hourly ET0 (eq. 53: Cn = 37, Cd = 0.34 always, i.e. rs = 70 s/m,
    ra = 208/u2; G = 0.1 Rn day, 0.5 Rn night, eqs. 45-46, day = Rn > 0): pyet has no hourly
    variant (pm_fao56 hard-codes the daily 900 and daily net longwave), so
    pyet.pm_asce(..., rn=Rn, g=G, cn=37, cd=0.34) is used with the hourly Rn of
    refet's object above: pyet's combination equation, refet's radiation terms.
  Cross-checks only (never the reference):
    eto_asce_pyet_mm_h  pyet.pm_asce with refet's Rn and cd = 0.24/0.96
    et0_fao56_eq53_mm_h an implementation of FAO-56 eqs. 7, 8, 11, 13, 14,
                        24-33, 37-40, 45-47, 53 written here from the book, in
                        LOCAL STANDARD TIME (eq. 31 with Lz, Lm), to check
                        refet's UTC/longitude convention and units
  Daily (per LST day, hours ending 01:00 ... 24:00):
    sums of the hourly values, and the daily equations refet.Daily(method='asce')
    .eto() and pyet.pm_fao56 on the day's Tmax, Tmin (of the 24 stamps), mean ea
    (of the 24 stamps), summed Rs and mean wind (u2 by FAO-56 eq. 47).

Latent heat flux: LE = ET * lambda * rho_w / 3600 s with lambda = 2.45 MJ/kg
(FAO-56's fixed value, the 0.408 = 1/2.45 in eq. 6/53) and 1 mm = 1 kg m-2:
LE [W m-2] = ET [mm h-1] * 2.45e6 / 3600.

Run (from the repository root):
  python3 -m venv tools/.venv-et0
  tools/.venv-et0/bin/pip install refet==0.5.0 pyet==1.5.0 pandas numpy
  tools/.venv-et0/bin/python tools/ref_et0.py
"""
import csv
import datetime as dt
import math
import os
import sys
from importlib import metadata

import numpy as np
import pandas as pd
import pyet
import refet
import refet.calcs

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
WEATHER = os.path.join(ROOT, "scenes", "airfield", "weather", "greensboro-nc-tmy3-2001-08-04_09.csv")
OUT_H = os.path.join(ROOT, "tests", "data", "ref_et0_greensboro.csv")
OUT_D = os.path.join(ROOT, "tests", "data", "ref_et0_greensboro_daily.csv")
OUT_A = os.path.join(ROOT, "tests", "data", "ref_aero_fao56.csv")

# Window: four full local-standard-time days, Aug 6-9 2001 (the excerpt starts
# Aug 4 01:00; Aug 4-5 are left for a model's spin-up; Aug 6-9 are sunny,
# Aug 7-8 clear, and contain the scene's image time Aug 8 12:00 EDT).
WINDOW_FIRST_DAY = dt.date(2001, 8, 6)
WINDOW_DAYS = 4

ZW = 10.0          # m, TMY3 wind height
LAMBDA = 2.45      # MJ/kg, FAO-56
MJH_TO_WM2 = 1e6 / 3600.0
LE_PER_MM_H = LAMBDA * 1e6 / 3600.0   # W m-2 per mm h-1


def read_tmy3(path):
    """Return (station dict, list of records). Each record: dict with
    't_end_lst' (naive datetime, LST, hour END), ghi, t, td, u, p_mbar, cloud."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    h = rows[0]
    station = {"usaf": h[0], "name": h[1], "state": h[2], "utc_offset_h": float(h[3]),
               "lat": float(h[4]), "lon": float(h[5]), "elev": float(h[6])}
    cols = rows[1]
    ix = {name: cols.index(name) for name in
          ["Date (MM/DD/YYYY)", "Time (HH:MM)", "GHI (W/m^2)", "Dry-bulb (C)",
           "Dew-point (C)", "Wspd (m/s)", "Pressure (mbar)", "TotCld (tenths)"]}
    recs = []
    for r in rows[2:]:
        if not r:
            continue
        mo, dd, yy = (int(x) for x in r[ix["Date (MM/DD/YYYY)"]].split("/"))
        hh, mm = (int(x) for x in r[ix["Time (HH:MM)"]].split(":"))
        t_end = dt.datetime(yy, mo, dd) + dt.timedelta(hours=hh, minutes=mm)
        rec = {"t_end_lst": t_end,
               "ghi": float(r[ix["GHI (W/m^2)"]]),
               "t": float(r[ix["Dry-bulb (C)"]]),
               "td": float(r[ix["Dew-point (C)"]]),
               "u": float(r[ix["Wspd (m/s)"]]),
               "p_mbar": float(r[ix["Pressure (mbar)"]]),
               "cloud": float(r[ix["TotCld (tenths)"]])}
        for k in ("ghi", "t", "td", "u", "p_mbar", "cloud"):
            if rec[k] <= -9900:
                sys.exit(f"{path}: missing {k} at {t_end}")
        recs.append(rec)
    for a, b in zip(recs, recs[1:]):
        if b["t_end_lst"] - a["t_end_lst"] != dt.timedelta(hours=1):
            sys.exit(f"{path}: records not hourly at {b['t_end_lst']}")
    return station, recs


def e0(t):
    """FAO-56 eq. 11 / 14 (Tetens form), kPa."""
    return 0.6108 * np.exp(17.27 * np.asarray(t) / (np.asarray(t) + 237.3))


def rfc3339z(t):
    return t.strftime("%Y-%m-%dT%H:%M:%SZ")


def fao56_hourly_eq53(tmean, ea, rs, u2, elev, lat_deg, lon_deg, utc_offset_h, t_mid_lst, doy,
                      t_start_lst):
    """Cross-check: FAO-56 hourly ET0 (eq. 53) from the book, local standard time.
    Mirrors refet's two simplifications so that the comparison tests conventions,
    not choices: Rso = (0.75 + 2e-5 z) Ra on the hour; Rs/Rso taken as 1 (fcd = 1)
    when the solar elevation at the START of the hour is below 0.3 rad.
    Day/night for G: Rn > 0."""
    p = 101.3 * ((293.0 - 0.0065 * elev) / 293.0) ** 5.26                 # eq. 7
    gam = 0.665e-3 * p                                                     # eq. 8
    delta = 4098.0 * e0(tmean) / (tmean + 237.3) ** 2                      # eq. 13
    es = e0(tmean)                                                         # eq. 11
    phi = math.radians(lat_deg)
    lz = -utc_offset_h * 15.0          # deg WEST of Greenwich of the time-zone centre
    lm = -lon_deg                      # deg WEST of Greenwich of the site
    dr = 1 + 0.033 * np.cos(2 * np.pi * doy / 365)                         # eq. 23
    dec = 0.409 * np.sin(2 * np.pi * doy / 365 - 1.39)                     # eq. 24
    ws = np.arccos(-np.tan(phi) * np.tan(dec))                             # eq. 25
    b = 2 * np.pi * (doy - 81) / 364                                       # eq. 33
    sc = 0.1645 * np.sin(2 * b) - 0.1255 * np.cos(b) - 0.025 * np.sin(b)   # eq. 32

    def omega(t_lst):
        w = np.pi / 12 * ((t_lst + 0.06667 * (lz - lm) + sc) - 12)        # eq. 31
        return (w + np.pi) % (2 * np.pi) - np.pi

    w = omega(t_mid_lst)
    w1 = np.clip(w - np.pi / 24, -ws, ws)                                  # eq. 29
    w2 = np.clip(w + np.pi / 24, -ws, ws)                                  # eq. 30
    w1 = np.minimum(w1, w2)
    ra = 12 * 60 / np.pi * 0.0820 * dr * ((w2 - w1) * np.sin(phi) * np.sin(dec)
                                          + np.cos(phi) * np.cos(dec) * (np.sin(w2) - np.sin(w1)))  # eq. 28
    rso = (0.75 + 2e-5 * elev) * ra                                        # eq. 37
    ratio = np.divide(rs, rso, out=np.ones_like(rs), where=rso != 0)
    ratio = np.clip(ratio, 0.3, 1.0)
    beta0 = np.arcsin(np.sin(phi) * np.sin(dec) + np.cos(phi) * np.cos(dec) * np.cos(omega(t_start_lst)))
    f = 1.35 * ratio - 0.35
    f = np.where(beta0 < 0.3, 1.0, f)
    rnl = 2.042e-10 * f * (0.34 - 0.14 * np.sqrt(ea)) * (tmean + 273.16) ** 4  # eq. 39, hourly sigma
    rn = (1 - 0.23) * rs - rnl                                             # eqs. 38, 40
    g = np.where(rn > 0, 0.1, 0.5) * rn                                    # eqs. 45, 46
    et0 = (0.408 * delta * (rn - g) + gam * 37.0 / (tmean + 273) * u2 * (es - ea)) \
        / (delta + gam * (1 + 0.34 * u2))                                  # eq. 53
    return et0, ra, rn


def hourly_inputs(stamps, by_t, to_utc):
    """Hour-mean inputs for the hours ending at `stamps` (LST, naive)."""
    cur = [by_t[s] for s in stamps]
    prv = [by_t[s - dt.timedelta(hours=1)] for s in stamps]
    T = np.array([(a["t"] + b["t"]) / 2 for a, b in zip(prv, cur)])
    TD = np.array([(a["td"] + b["td"]) / 2 for a, b in zip(prv, cur)])
    U10 = np.array([(a["u"] + b["u"]) / 2 for a, b in zip(prv, cur)])
    GHI = np.array([b["ghi"] for b in cur])
    EA = e0(TD)
    RS = GHI * 0.0036
    t_end_utc = [s + to_utc for s in stamps]
    t_start_utc = [t - dt.timedelta(hours=1) for t in t_end_utc]
    t_mid_utc = [t + dt.timedelta(minutes=30) for t in t_start_utc]
    # refet 0.5.0: `time` = UTC hour at the START of the period (it adds 0.5
    # itself); `lon` in degrees EAST (negative west); doy of that same UTC date.
    HOUR_UTC = np.array([t.hour + t.minute / 60 for t in t_start_utc], dtype=float)
    DOY_UTC = np.array([t.timetuple().tm_yday for t in t_start_utc], dtype=float)
    return T, TD, U10, GHI, EA, RS, HOUR_UTC, DOY_UTC, t_end_utc, t_start_utc, t_mid_utc


def asce_night_fcd(stamps_ext, by_t, to_utc, zw, elev, lat, lon):
    """Sensitivity: ASCE-EWRI (2005) rule for fcd when the sun is low (beta < 0.3
    rad, i.e. night, dawn, dusk): carry forward fcd of the last hour with
    beta >= 0.3 (refet 0.5.0 uses fcd = 1 there, as its docstring warns).
    stamps_ext starts a day before the window so that the window's first night
    has a preceding afternoon; returns ETo for all of stamps_ext (NaN before
    the first hour with beta >= 0.3)."""
    T, TD, U10, GHI, EA, RS, HOUR_UTC, DOY_UTC, *_ = hourly_inputs(stamps_ext, by_t, to_utc)
    h = refet.Hourly(tmean=T, ea=EA, rs=RS, uz=U10, zw=zw, elev=elev, lat=lat, lon=lon,
                     doy=DOY_UTC, time=HOUR_UTC, method="asce")
    c = refet.calcs
    sc = c.seasonal_correction(DOY_UTC)
    dec = c.declination(DOY_UTC, "asce")
    om = c.solar_hour_angle(c.solar_time_rad(math.radians(lon), HOUR_UTC, sc))
    phi = math.radians(lat)
    beta = np.arcsin(np.sin(phi) * np.sin(dec) + np.cos(phi) * np.cos(dec) * np.cos(om))
    fcd = h.fcd.copy()
    last = np.nan
    for i in range(len(fcd)):
        if beta[i] >= 0.3:
            last = fcd[i]
        else:
            fcd[i] = last
    rnl = c.rnl_hourly(T, EA, fcd)
    rn = c.rn_hourly(RS, rnl)
    cd = np.where(rn < 0, 0.96, 0.24)
    g = np.where(rn < 0, 0.5, 0.1) * rn
    eto = c.etsz(rn=rn, g=g, tmean=T, u2=h.u2, vpd=h.es - EA, es_slope=h.es_slope, psy=h.psy, cn=37.0, cd=cd)
    return np.asarray(eto), fcd


def main():
    station, recs = read_tmy3(WEATHER)
    off = station["utc_offset_h"]
    lat, lon, elev = station["lat"], station["lon"], station["elev"]
    to_utc = dt.timedelta(hours=-off)          # LST - offset = UTC; off = -5 -> +5 h

    start = dt.datetime.combine(WINDOW_FIRST_DAY, dt.time(0))
    stamps = [start + dt.timedelta(hours=k) for k in range(1, 24 * WINDOW_DAYS + 1)]
    by_t = {r["t_end_lst"]: r for r in recs}
    if stamps[0] - dt.timedelta(hours=1) not in by_t or stamps[-1] not in by_t:
        sys.exit("window not covered by the excerpt")

    n = len(stamps)
    cur = [by_t[s] for s in stamps]
    T, TD, U10, GHI, EA, RS, HOUR_UTC, DOY_UTC, t_end_utc, t_start_utc, t_mid_utc = \
        hourly_inputs(stamps, by_t, to_utc)

    # ---- ASCE standardized hourly ETo (the reference) --------------------------
    # keyword arguments only: refet 0.5.0's positional order is
    # (tmean, rs, uz, zw, elev, lat, lon, doy, time, ea=, tdew=, method=, input_units=);
    # releases before 0.4 had ea second.
    h = refet.Hourly(tmean=T, ea=EA, rs=RS, uz=U10, zw=ZW, elev=elev, lat=lat, lon=lon,
                     doy=DOY_UTC, time=HOUR_UTC, method="asce")
    eto_asce = np.asarray(h.eto(), dtype=float)
    cd_asce = h.cd.copy()
    g_asce = h.g.copy()
    rn = h.rn.copy()
    u2 = h.u2.copy()

    # ---- FAO-56 hourly ET0 (eq. 53) with pyet's combination equation -----------
    idx = pd.DatetimeIndex(t_mid_utc)
    g_fao = np.where(rn > 0, 0.1, 0.5) * rn
    S = lambda a: pd.Series(np.asarray(a, dtype=float), index=idx)
    et0_fao = pyet.pm_asce(S(T), S(u2), rn=S(rn), g=S(g_fao), ea=S(EA), elevation=elev,
                           cn=37.0, cd=0.34, clip_zero=False).to_numpy()
    # cross-check of refet's ASCE with pyet's equation, same Rn, G and Cd
    eto_asce_pyet = pyet.pm_asce(S(T), S(u2), rn=S(rn), g=S(g_asce), ea=S(EA), elevation=elev,
                                 cn=37.0, cd=S(cd_asce), clip_zero=False).to_numpy()
    # cross-check: own FAO-56 implementation, local standard time
    t_start_lst = np.array([(s - dt.timedelta(hours=1)).hour for s in stamps], dtype=float)
    t_mid_lst = t_start_lst + 0.5
    doy_lst = np.array([(s - dt.timedelta(minutes=30)).timetuple().tm_yday for s in stamps], dtype=float)
    et0_eq53, ra_eq53, rn_eq53 = fao56_hourly_eq53(T, EA, RS, u2, elev, lat, lon, off, t_mid_lst,
                                                  doy_lst, t_start_lst)
    # sensitivity: refet with the local-standard-time doy instead of the UTC doy
    h_doylst = refet.Hourly(tmean=T, ea=EA, rs=RS, uz=U10, zw=ZW, elev=elev, lat=lat,
                            lon=lon, doy=doy_lst, time=HOUR_UTC, method="asce")
    eto_asce_doylst = np.asarray(h_doylst.eto())
    # sensitivity: wind floor u2 >= 0.5 m/s (not applied by refet or ASCE)
    u10_floor = 0.5 * math.log(67.8 * ZW - 5.42) / 4.87
    eto_asce_ufloor = np.asarray(refet.Hourly(tmean=T, ea=EA, rs=RS, uz=np.maximum(U10, u10_floor), zw=ZW,
                                              elev=elev, lat=lat, lon=lon, doy=DOY_UTC, time=HOUR_UTC,
                                              method="asce").eto())
    # sensitivity: hour-ending stamp values instead of two-stamp means
    T_end = np.array([b["t"] for b in cur]); TD_end = np.array([b["td"] for b in cur])
    U_end = np.array([b["u"] for b in cur])
    eto_asce_endval = np.asarray(refet.Hourly(tmean=T_end, ea=e0(TD_end), rs=RS, uz=U_end, zw=ZW, elev=elev,
                                              lat=lat, lon=lon, doy=DOY_UTC, time=HOUR_UTC,
                                              method="asce").eto())
    # sensitivity: the scene's own site (Rochester NY) instead of the station
    eto_asce_roc = np.asarray(refet.Hourly(tmean=T, ea=EA, rs=RS, uz=U10, zw=ZW, elev=169.0, lat=43.1566,
                                           lon=-77.6088, doy=DOY_UTC, time=HOUR_UTC, method="asce").eto())

    # sensitivity: ASCE's low-sun fcd rule (needs the day before the window)
    stamps_ext = [stamps[0] - dt.timedelta(hours=k) for k in range(24, 0, -1)] + stamps
    eto_ext, fcd_ext = asce_night_fcd(stamps_ext, by_t, to_utc, ZW, elev, lat, lon)
    eto_asce_nightfcd, fcd_night = eto_ext[24:], fcd_ext[24:]
    assert not np.isnan(eto_asce_nightfcd).any()

    # Sanity checks of conventions
    assert np.max(np.abs(eto_asce - eto_asce_pyet)) < 1e-4, "refet vs pyet (ASCE hourly)"
    assert np.max(np.abs(et0_fao - et0_eq53)) < 2e-4, "pyet FAO-56 vs own eq. 53"
    # same doy on both sides: refet's UTC time + east longitude == FAO eq. 31 in LST
    assert np.max(np.abs(h_doylst.ra - ra_eq53)) < 1e-4, "Ra hourly: UTC vs LST convention"
    for d in range(WINDOW_DAYS):
        sl = slice(24 * d, 24 * d + 24)
        k = int(np.argmax(h.ra[sl]))
        # solar noon at 79.95 W, UTC-5, early August: ~12:26 LST -> hour ending 13:00
        assert stamps[24 * d + k].hour == 13, f"Ra peak at {stamps[24 * d + k]}"
        assert int(np.argmax(GHI[sl])) in (k - 1, k, k + 1)

    vers = {m: metadata.version(m) for m in ("refet", "pyet", "numpy", "pandas")}
    pyver = sys.version.split()[0]
    refet_call = ("refet.Hourly(tmean=T, ea=ea, rs=Rs, uz=u10, zw=10.0, elev=273.0, lat=36.1, "
                  "lon=-79.95, doy=doy_utc, time=hour_utc_start, method='asce').eto()")
    common = [
        f"# generated by tools/ref_et0.py (python {pyver}, refet {vers['refet']}, pyet {vers['pyet']}, "
        f"numpy {vers['numpy']}, pandas {vers['pandas']})",
        "# command: tools/.venv-et0/bin/python tools/ref_et0.py   (see tests/data/ref_et0_README.md)",
        f"# weather: scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv (NREL TMY3 {station['usaf']} "
        f"{station['name']}, lat {lat} N, lon {lon} E, elev {elev} m, LST = UTC{off:+.0f} h, wind at 10 m)",
        f"# window: {WINDOW_DAYS} local-standard-time days {WINDOW_FIRST_DAY} .. "
        f"{WINDOW_FIRST_DAY + dt.timedelta(days=WINDOW_DAYS - 1)} (hours ending 01:00 .. 24:00 LST)",
    ]

    # ---- hourly file ----------------------------------------------------------
    with open(OUT_H, "w", newline="") as f:
        for line in common:
            f.write(line + "\n")
        f.write("# inputs per hour: t_air_c, t_dew_c, u10 = means of the hour-start and hour-end TMY3 stamps "
                "(= hour means of irsig's linear interpolation); ea = 0.6108 exp(17.27 Td/(Td+237.3)); "
                "rs = GHI * 0.0036; u2 = u10 * 4.87 / ln(67.8*10 - 5.42) (FAO-56 eq. 47)\n")
        f.write(f"# reference: eto_asce_mm_h = {refet_call}  (time = UTC hour at the START of the hour, "
                "lon degrees east; Cn 37, Cd 0.96 and G 0.5 Rn where Rn < 0, else Cd 0.24 and G 0.1 Rn; pressure from elevation)\n")
        f.write("# et0_fao56_mm_h = pyet.pm_asce(T, u2, rn=rn, g=g_fao56, ea=ea, elevation=273, cn=37, cd=0.34, "
                "clip_zero=False): FAO-56 eq. 53 (rs 70 s/m, ra 208/u2), with refet's hourly rn\n")
        f.write("# latent_*_w_m2 = ET [mm/h] * 2.45e6 / 3600 (lambda = 2.45 MJ/kg, FAO-56). Negative = dew. "
                "Cross-checks: eto_asce_pyet_mm_h, et0_fao56_eq53_mm_h. Sensitivities: eto_asce_*_mm_h "
                "(see README)\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["time_utc_end", "time_utc_mid", "time_lst_end", "doy_utc", "hour_utc_start",
                    "t_air_c", "t_dew_c", "ea_kpa", "es_kpa", "ghi_w_m2", "rs_mj_m2_h", "u10_m_s", "u2_m_s",
                    "pressure_std_kpa", "pressure_tmy3_kpa", "cloud_tenths",
                    "ra_mj_m2_h", "rso_mj_m2_h", "fcd", "rnl_mj_m2_h", "rn_mj_m2_h", "rn_w_m2",
                    "g_asce_w_m2", "cd_asce", "eto_asce_mm_h", "latent_asce_w_m2",
                    "g_fao56_w_m2", "et0_fao56_mm_h", "latent_fao56_w_m2",
                    "eto_asce_pyet_mm_h", "et0_fao56_eq53_mm_h",
                    "eto_asce_doylst_mm_h", "eto_asce_u2min05_mm_h", "eto_asce_endval_mm_h",
                    "eto_asce_rochester_mm_h", "fcd_asce_rule", "eto_asce_nightfcd_mm_h"])
        for i in range(n):
            w.writerow([rfc3339z(t_end_utc[i]), rfc3339z(t_mid_utc[i]),
                        stamps[i].strftime("%Y-%m-%dT%H:%M:%S") + f"{int(off):+03d}:00",
                        int(DOY_UTC[i]), f"{HOUR_UTC[i]:.1f}",
                        f"{T[i]:.2f}", f"{TD[i]:.2f}", f"{EA[i]:.6f}", f"{h.es[i]:.6f}", f"{GHI[i]:.0f}",
                        f"{RS[i]:.6f}", f"{U10[i]:.3f}", f"{u2[i]:.6f}",
                        f"{float(h.pair[0]):.5f}", f"{cur[i]['p_mbar'] / 10:.1f}", f"{cur[i]['cloud']:.0f}",
                        f"{h.ra[i]:.6f}", f"{h.rso[i]:.6f}", f"{h.fcd[i]:.6f}", f"{h.rnl[i]:.6f}",
                        f"{rn[i]:.6f}", f"{rn[i] * MJH_TO_WM2:.3f}",
                        f"{g_asce[i] * MJH_TO_WM2:.3f}", f"{cd_asce[i]:.2f}",
                        f"{eto_asce[i]:.6f}", f"{eto_asce[i] * LE_PER_MM_H:.3f}",
                        f"{g_fao[i] * MJH_TO_WM2:.3f}", f"{et0_fao[i]:.6f}", f"{et0_fao[i] * LE_PER_MM_H:.3f}",
                        f"{eto_asce_pyet[i]:.6f}", f"{et0_eq53[i]:.6f}",
                        f"{eto_asce_doylst[i]:.6f}", f"{eto_asce_ufloor[i]:.6f}", f"{eto_asce_endval[i]:.6f}",
                        f"{eto_asce_roc[i]:.6f}", f"{fcd_night[i]:.6f}", f"{eto_asce_nightfcd[i]:.6f}"])

    # ---- daily ------------------------------------------------------------------
    days = [WINDOW_FIRST_DAY + dt.timedelta(days=d) for d in range(WINDOW_DAYS)]
    dd = {k: [] for k in ("tmax", "tmin", "ea", "tdew", "rs", "u10", "u2")}
    for d in range(WINDOW_DAYS):
        st = cur[24 * d: 24 * d + 24]                    # the day's 24 stamps, 01:00 .. 24:00
        tt = np.array([r["t"] for r in st])
        dd["tmax"].append(tt.max()); dd["tmin"].append(tt.min())
        dd["ea"].append(float(np.mean(e0(np.array([r["td"] for r in st])))))
        dd["tdew"].append(float(np.mean([r["td"] for r in st])))
        dd["rs"].append(float(np.sum(RS[24 * d: 24 * d + 24])))
        u = float(np.mean([r["u"] for r in st]))
        dd["u10"].append(u); dd["u2"].append(u * 4.87 / math.log(67.8 * ZW - 5.42))
    dd = {k: np.array(v) for k, v in dd.items()}
    doy_d = np.array([x.timetuple().tm_yday for x in days], dtype=float)
    daily_refet = np.asarray(refet.Daily(tmin=dd["tmin"], tmax=dd["tmax"], ea=dd["ea"], rs=dd["rs"], uz=dd["u10"],
                                         zw=ZW, elev=elev, lat=lat, doy=doy_d, method="asce").eto())
    didx = pd.DatetimeIndex([pd.Timestamp(x) for x in days])
    D = lambda a: pd.Series(np.asarray(a, dtype=float), index=didx)
    daily_pyet = pyet.pm_fao56(D((dd["tmax"] + dd["tmin"]) / 2), D(dd["u2"]), rs=D(dd["rs"]), tmax=D(dd["tmax"]),
                               tmin=D(dd["tmin"]), ea=D(dd["ea"]), elevation=elev,
                               lat=pyet.utils.deg_to_rad(lat), clip_zero=False).to_numpy()
    sums = {}
    for name, arr in (("asce", eto_asce), ("fao56", et0_fao), ("asce_u2min05", eto_asce_ufloor),
                      ("asce_endval", eto_asce_endval), ("asce_rochester", eto_asce_roc),
                      ("asce_doylst", eto_asce_doylst), ("asce_nightfcd", eto_asce_nightfcd)):
        sums[name] = arr.reshape(WINDOW_DAYS, 24).sum(axis=1)

    with open(OUT_D, "w", newline="") as f:
        for line in common:
            f.write(line + "\n")
        f.write("# eto_asce_hsum_mm, et0_fao56_hsum_mm: sums of the 24 hourly values of ref_et0_greensboro.csv "
                "(hours ending 01:00 .. 24:00 LST); latent_*_mean_w_m2 = the day's mean latent flux\n")
        f.write("# eto_asce_daily_refet_mm = refet.Daily(tmin=, tmax=, ea=, rs=, uz=u10, zw=10.0, elev=273.0, "
                "lat=36.1, doy=, method='asce').eto()  (Cn 900, Cd 0.34, G = 0)\n")
        f.write("# et0_fao56_daily_pyet_mm = pyet.pm_fao56(tmean=(tmax+tmin)/2, wind=u2, rs=, tmax=, tmin=, ea=, "
                "elevation=273.0, lat=radians(36.1), clip_zero=False)  (FAO-56 eq. 6)\n")
        f.write("# daily inputs: tmax/tmin of the 24 stamps; ea = mean of the 24 stamps' e0(Td); rs = sum of "
                "hourly Rs; u10 = mean of the 24 stamps; u2 = u10 * 0.74795 (FAO-56 eq. 47)\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["date_lst", "day_start_utc", "day_end_utc", "tmax_c", "tmin_c", "tdew_mean_c", "ea_kpa",
                    "rs_mj_m2_d", "u10_m_s", "u2_m_s",
                    "eto_asce_hsum_mm", "et0_fao56_hsum_mm", "latent_asce_mean_w_m2", "latent_fao56_mean_w_m2",
                    "eto_asce_daily_refet_mm", "et0_fao56_daily_pyet_mm",
                    "eto_asce_u2min05_hsum_mm", "eto_asce_endval_hsum_mm", "eto_asce_rochester_hsum_mm",
                    "eto_asce_nightfcd_hsum_mm"])
        for d, day in enumerate(days):
            d0 = dt.datetime.combine(day, dt.time(0)) + to_utc
            w.writerow([day.isoformat(), rfc3339z(d0), rfc3339z(d0 + dt.timedelta(days=1)),
                        f"{dd['tmax'][d]:.1f}", f"{dd['tmin'][d]:.1f}", f"{dd['tdew'][d]:.3f}", f"{dd['ea'][d]:.6f}",
                        f"{dd['rs'][d]:.4f}", f"{dd['u10'][d]:.4f}", f"{dd['u2'][d]:.4f}",
                        f"{sums['asce'][d]:.4f}", f"{sums['fao56'][d]:.4f}",
                        f"{sums['asce'][d] * LAMBDA * 1e6 / 86400:.3f}", f"{sums['fao56'][d] * LAMBDA * 1e6 / 86400:.3f}",
                        f"{daily_refet[d]:.4f}", f"{daily_pyet[d]:.4f}",
                        f"{sums['asce_u2min05'][d]:.4f}", f"{sums['asce_endval'][d]:.4f}",
                        f"{sums['asce_rochester'][d]:.4f}", f"{sums['asce_nightfcd'][d]:.4f}"])

    # ---- aerodynamic resistance of the FAO reference grass ----------------------
    hc, zm, zh, k = 0.12, 2.0, 2.0, 0.41
    d0, zom = 2.0 / 3.0 * hc, 0.123 * hc
    zoh = 0.1 * zom
    lnm, lnh = math.log((zm - d0) / zom), math.log((zh - d0) / zoh)
    fac10 = 4.87 / math.log(67.8 * ZW - 5.42)
    with open(OUT_A, "w", newline="") as f:
        f.write(f"# generated by tools/ref_et0.py (python {pyver}, pyet {vers['pyet']})\n")
        f.write("# FAO-56 (Allen et al. 1998) reference grass: h = 0.12 m, zm = zh = 2 m, d = 2/3 h = 0.08 m, "
                "zom = 0.123 h = 0.01476 m, zoh = 0.1 zom = 0.001476 m, k = 0.41\n")
        f.write(f"# ra_general_s_m = ln((zm-d)/zom) * ln((zh-d)/zoh) / (k^2 u2)  (FAO-56 eq. 4) "
                f"= {lnm * lnh / k**2:.6f} / u2;  ln((zm-d)/zom) = {lnm:.6f}, ln((zh-d)/zoh) = {lnh:.6f}\n")
        f.write("# ra_208_s_m = 208 / u2  (FAO-56 Chapter 2, the rounded value for the reference grass used in "
                "eq. 6/53); rs = 70 s/m (eq. 5: 100 / (0.5 * 24 * 0.12) = 69.4); rs_over_ra_208 = 70 u2 / 208 "
                "(-> the 0.34 u2 of eqs. 6/53)\n")
        f.write(f"# u10_m_s = u2 / f10, f10 = 4.87 / ln(67.8 * 10 - 5.42) = {fac10:.6f} (FAO-56 eq. 47, z = 10 m); "
                "u2_from_u10_m_s applies eq. 47 to u10 = u2_m_s (the second use of the table)\n")
        f.write("# ra_pyet_s_m = pyet.meteo_utils.calc_res_aero(u2, croph=0.12, zw=2, zh=2, ra_method=1) "
                "(pyet uses d = 0.667 h, zoh = 0.0123 h), cross-check of ra_general_s_m\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["u2_m_s", "ra_208_s_m", "ra_general_s_m", "ra_pyet_s_m", "rs_over_ra_208", "u10_m_s",
                    "u2_from_u10_m_s"])
        for uu in (0.5, 1.0, 2.0, 4.0, 8.0):
            ra_p = float(pyet.meteo_utils.calc_res_aero(pd.Series([uu]), croph=hc, zw=zm, zh=zh,
                                                        ra_method=1).iloc[0])
            w.writerow([f"{uu}", f"{208 / uu:.6f}", f"{lnm * lnh / (k**2 * uu):.6f}", f"{ra_p:.6f}",
                        f"{70 * uu / 208:.6f}", f"{uu / fac10:.6f}", f"{uu * fac10:.6f}"])

    # ---- console summary --------------------------------------------------------
    print(f"refet {vers['refet']}  pyet {vers['pyet']}  window {days[0]} .. {days[-1]} LST ({n} h)")
    print("date        asce_hsum fao56_hsum refet_daily pyet_daily  u2min05 endval rochester doylst nightfcd")
    for d, day in enumerate(days):
        print(f"{day}  {sums['asce'][d]:9.3f} {sums['fao56'][d]:10.3f} {daily_refet[d]:11.3f} {daily_pyet[d]:10.3f}"
              f"  {sums['asce_u2min05'][d]:7.3f} {sums['asce_endval'][d]:6.3f} {sums['asce_rochester'][d]:9.3f}"
              f" {sums['asce_doylst'][d]:6.3f} {sums['asce_nightfcd'][d]:8.3f}")
    print(f"max |refet asce - pyet asce| hourly   = {np.max(np.abs(eto_asce - eto_asce_pyet)):.2e} mm/h")
    print(f"max |pyet fao56 - own eq.53| hourly   = {np.max(np.abs(et0_fao - et0_eq53)):.2e} mm/h")
    print(f"max |Ra refet(UTC, doy LST) - Ra eq.28(LST)| = {np.max(np.abs(h_doylst.ra - ra_eq53)):.2e} MJ/m2/h;"
          f" with doy UTC: {np.max(np.abs(h.ra - ra_eq53)):.2e}")
    print(f"max |eto_asce doy UTC - doy LST| hourly = {np.max(np.abs(eto_asce - eto_asce_doylst)):.2e} mm/h")
    rel = (daily_refet - daily_pyet) / daily_pyet
    print(f"refet.Daily vs pyet.pm_fao56: rel diff {', '.join(f'{x:+.4%}' for x in rel)}")
    rel = (sums['asce'] - daily_refet) / daily_refet
    print(f"hourly-sum ASCE vs daily ASCE: {', '.join(f'{x:+.2%}' for x in rel)}")
    rel = (sums['fao56'] - sums['asce']) / sums['asce']
    print(f"hourly-sum FAO56 vs ASCE: {', '.join(f'{x:+.2%}' for x in rel)}")
    day_h = rn > 0
    print(f"hours Rn>0: {int(day_h.sum())}; calm hours (u10 mean 0): {int((U10 == 0).sum())}; "
          f"min/max eto_asce {eto_asce.min():.4f}/{eto_asce.max():.4f} mm/h")


if __name__ == "__main__":
    main()
