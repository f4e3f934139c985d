#!/usr/bin/env python3
"""Writes the station-day excerpts whose skin temperature is measured by an
infrared thermometer (IRT) rather than derived from the upwelling longwave
(tools/station_excerpt.py writes the others). Same output format
(tests/data/stations/README.md): an irsig plain weather CSV with the
measured forcing plus `x_` columns; here `x_skin_temp_c` is the IRT reading
and `x_lw_up_w_m2` is empty (not measured), and the header says
`skin_source: ir_thermometer`.

Station-days (the compared day is the whole local day named; the day before
it, measured, is the 24-h spin-up):

  bnd-19980517  NOAA ATDD/ARL Bondville, IL (Champaign) flux site, 1998 --
  bnd-19980725  the Noah LSM's test forcing (forcing98_with_validation.dat,
  bnd-19980801  30-min, LST = UTC-6, stamps at the END of each half hour):
                bare residue-covered soil before emergence (May 17, hot,
                clear); a calm clear night after a sunny day (Jul 25); the
                crop at full cover and peak transpiration (Aug 1, latent
                heat flux up to 525 W/m2).
  bnd-19980224  More Bondville 1998 days, chosen by the rule of
  bnd-19980310  select_bondville_days() (the clearest day of a season by the
  bnd-19980712  measured against the clear-sky shortwave, before any model run):
  bnd-19981215  winter snow-free residue (Feb 24), snow cover (Mar 10), crop
                (Jul 12), after harvest (Dec 15); raw lines in
                noah98_bondville_excerpt2.dat.
  bnd-19980405  The two windows added later by the same rule: spring (Apr 5,
  bnd-19980923  bare soil with residue) and early autumn (Sep 23, the crop
                standing and senescent); raw lines in
                noah98_bondville_excerpt3.dat.
  cdp-20020110  Col de Porte (1325 m, French Alps), snow-covered meadow,
                clear and calm (Morin et al. 2012 forcing via GEOtop's test
                data: hourly, UTC, stamps at the END of each hour; the snow
                surface temperature from the CRYOBSCLIM.CDP hourly file).
  cdp-20011231  More Col de Porte days, chosen by the rule of
  cdp-20020219  select_cdp_days() (the clearest day of December 2001 and of
                February 2002, before any model run); raw lines in
                cdp_meteo0001_more.txt and cdp_surface_temp_more.csv.

Raw inputs: tools/data/stations-raw/ holds unchanged line excerpts of the
Noah and Col de Porte forcing files and the surface-temperature column of the
Col de Porte hourly netCDF for the same hours (cdp_surface_temp_2002-01.csv,
written by --cdp-nc from the full 120 MB file, which is not committed).

Standard library only. Run:
    python3 tools/station_excerpt_more.py [--cdp-nc CDP_hourly_19930801_20170731.nc]
    python3 tools/station_excerpt_more.py --select-cdp meteo0001.txt CDP_hourly_19930801_20170731.nc
"""
import argparse
import datetime as dt
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import station_excerpt as se  # noqa: E402  (helpers: fill_required, midday_albedo, fmt, iso)

RAW = se.RAW
OUT = se.OUT
UTC = se.UTC

# SHA-256 of the raw excerpts the committed station-days were written from
# (station_excerpt.check_raw warns when an input differs).
RAW_SHA256 = {
    "noah98_bondville_excerpt.dat": "42f4bebcd20a94cfca4fe4fb39ac55e47d88e21e09e8796749e307d55d575bcd",
    "noah98_bondville_excerpt2.dat": "76682ed795cb281dacdde6fa9ca47723b8494562aa74e85bbfa2e3b98d0d3b59",
    "noah98_bondville_excerpt3.dat": "e94277e4434a045ddf205d7fb61fa94433bbdc6fdb81923cd67ea8ff338de775",
    "cdp_meteo0001_2002-01.txt": "5f3ea8e641ad1583b1f723a49cec235e9d52e51260f6146da078e6ad7b3ab171",
    "cdp_surface_temp_2002-01.csv": "76b03c0ba288135fbcd308580b8d3b43c42100264f83519d3cbfad5e40ef2360",
    "cdp_meteo0001_more.txt": "4d1bc2535bef1e243d0da5ea77d075ee6aa9dc9e389e62fa9d1240deb10d1291",
    "cdp_surface_temp_more.csv": "4182bd1843df0cbde6b113c2dbfbb972a269ba5018412672ebe48076a3956f05",
    "de-tha_bigleaf_DE_Tha_Jun_2014_doy157-158.csv": "d0f4e774187ac5571e3991d690245d0e96f890092419560071f234d6ba1f17bc",
    "ssw_dlseb_2013-08-29_30_2013-10-07_08.csv": "53460128ea23311f6c7afb580c5e6b152626de878e2ffdc39d6cd310998a74a7",
}
se.RAW_SHA256.update(RAW_SHA256)

NOAH_COLS = ("jday time w_speed w_dir ta rh pres rg par_in par_out rnet ghf rain wet irt "
             "t2 t4 t8 t16 t32 t64 u_bar uw u2 v2 w2 h le co2 lw_in sm5 sm20 sm60").split()


def read_noah98(path):
    """Noah LSM forcing98_with_validation.dat (User's Guide 2.7.1, sec. 6.1):
    33 columns, 30-min records, `time` = LST (UTC-6) hhmm at the END of the
    half hour; missing = -6999. Returns records with UTC 'end' times."""
    recs = []
    for ln in se.check_raw(path).read_text().splitlines():
        f = ln.split()
        if len(f) != len(NOAH_COLS):
            continue
        v = dict(zip(NOAH_COLS, (float(x) for x in f)))
        num = lambda k: None if v[k] <= -6000 else v[k]
        hhmm = int(v["time"])
        lst_end = (dt.datetime(1998, 1, 1) + dt.timedelta(days=int(v["jday"]) - 1,
                                                           hours=hhmm // 100, minutes=hhmm % 100))
        end = (lst_end + dt.timedelta(hours=6)).replace(tzinfo=UTC)
        rain_in = num("rain")
        recs.append({"end": end, "span": dt.timedelta(minutes=30),
                     "ghi": num("rg"), "dni": None, "dhi": None, "sw_up": None,
                     "lw_dn": num("lw_in"), "lw_up": None,
                     "t_air_c": num("ta"), "rh": num("rh"),
                     # u_bar: vector-mean wind at 6 m, the LSM's wind
                     "wind": num("u_bar"), "p_hpa": num("pres"),
                     "precip": None if rain_in is None else rain_in * 25.4 * 2.0,
                     "irt": num("irt"), "le": num("le"), "h": num("h"), "g": num("ghf"),
                     "rnet": num("rnet"),
                     "par_in": num("par_in"), "par_out": num("par_out"),
                     "w_speed": num("w_speed")})
    # As the Noah driver does (User's Guide sec. 6.1): where the 6-m u_bar is
    # missing, the 10-m propeller wind times a reduction factor; here the
    # median ratio u_bar / w_speed of the excerpt's records with both.
    ratios = sorted(r["wind"] / r["w_speed"] for r in recs
                    if r["wind"] is not None and r["w_speed"] and r["w_speed"] > 0.5)
    factor = ratios[len(ratios) // 2]
    n_sub = 0
    for r in recs:
        if r["wind"] is None and r["w_speed"] is not None:
            r["wind"] = factor * r["w_speed"]
            r["wind_sub"] = True
            n_sub += 1
    print(f"noah98: u_bar missing in {n_sub} records, 10-m wind x {factor:.3f} used")
    return recs


def read_cdp(meteo_path, ts_path):
    """Col de Porte: GEOtop meteo file (Date dd/mm/YYYY HH:MM, hourly, UTC,
    end of the hour; Prec mm/h, Ws m/s, RH %, Tair degC, SWdir SWdif SW W/m2
    (horizontal), LW W/m2 down) + the surface temperature (K) and snow depth
    (cm) of the CRYOBSCLIM.CDP hourly file for the same stamps."""
    ts = {}
    for ln in se.check_raw(ts_path).read_text().splitlines()[1:]:
        t, tk, sd = ln.split(",")
        ts[t] = (float(tk) if tk else None, float(sd) if sd else None)
    recs = []
    lines = se.check_raw(meteo_path).read_text().splitlines()
    head = lines[0].split(",")
    for ln in lines[1:]:
        v = dict(zip(head, ln.split(",")))
        end = dt.datetime.strptime(v["Date"], "%d/%m/%Y %H:%M").replace(tzinfo=UTC)
        tk, sd = ts.get(end.strftime("%Y-%m-%dT%H:%M"), (None, None))
        recs.append({"end": end, "span": dt.timedelta(hours=1),
                     "ghi": float(v["SW"]), "dni": None, "dhi": float(v["SWdif"]),
                     "sw_up": None, "lw_dn": float(v["LW"]), "lw_up": None,
                     "t_air_c": float(v["Tair"]), "rh": float(v["RH"]), "wind": float(v["Ws"]),
                     "p_hpa": None, "precip": float(v["Prec"]),
                     "irt": None if tk is None else tk - 273.15, "snow_cm": sd})
    return recs


# PPFD to global shortwave: PAR is about 0.46 of the global irradiance and
# 1 W/m2 of daylight PAR is about 4.57 umol/(m2 s) (McCree 1972), so
# GHI ~ PPFD / 2.10 (uncertain by about 5 %: the PAR fraction varies with
# sky and sun).
PPFD_PER_GHI = 0.46 * 4.57


def read_bigleaf(path):
    """Rows of a bigleaf FLUXNET2015 excerpt (half-hourly; `hour` = START of
    the half hour in local standard time, CET = UTC+1 for DE-Tha; Tair degC,
    VPD kPa, pressure kPa, wind m/s, PPFD umol/m2/s, LW_up/LW_down, LE, H,
    G, Rn W/m2). RH from VPD and the FAO-56 saturation vapour pressure."""
    import math

    lines = [ln for ln in se.check_raw(path).read_text().splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    recs = []
    for ln in lines[1:]:
        v = dict(zip(head, (float(x) for x in ln.split(","))))
        start = (dt.datetime(int(v["year"]), 1, 1) + dt.timedelta(days=int(v["doy"]) - 1, hours=v["hour"])
                 - dt.timedelta(hours=1)).replace(tzinfo=UTC)
        es = 0.6108 * math.exp(17.27 * v["Tair"] / (v["Tair"] + 237.3))
        recs.append({"end": start + dt.timedelta(minutes=30), "span": dt.timedelta(minutes=30),
                     "ghi": max(v["PPFD"], 0.0) / PPFD_PER_GHI, "dni": None, "dhi": None, "sw_up": None,
                     "lw_dn": v["LW_down"], "lw_up": v["LW_up"], "t_air_c": v["Tair"],
                     "rh": 100.0 * max(es - v["VPD"], 0.0) / es, "wind": v["wind"],
                     "p_hpa": 10.0 * v["pressure"], "precip": 2.0 * v["precip"],
                     "le": v["LE"], "h": v["H"], "g": v["G"], "rnet": v["Rn"]})
    return recs


def haurwitz_ghi_w_m2(doy, lst_h, lat=40.01, lon=-88.37, utc_offset_h=-6):
    """Clear-sky global irradiance of Haurwitz (1945), `1098 cos z exp(-0.057/cos z)`
    W/m2, at local standard time `lst_h` (h) of day `doy`; the sun from
    Spencer's (1971) declination and equation of time."""
    import math

    g = 2 * math.pi * (doy - 1) / 365
    eot = 229.18 * (0.000075 + 0.001868 * math.cos(g) - 0.032077 * math.sin(g)
                    - 0.014615 * math.cos(2 * g) - 0.040849 * math.sin(2 * g))
    dec = (0.006918 - 0.399912 * math.cos(g) + 0.070257 * math.sin(g) - 0.006758 * math.cos(2 * g)
           + 0.000907 * math.sin(2 * g) - 0.002697 * math.cos(3 * g) + 0.00148 * math.sin(3 * g))
    solar_h = lst_h + (4 * (lon - 15 * utc_offset_h) + eot) / 60
    ha = math.radians(15 * (solar_h - 12))
    cz = (math.sin(math.radians(lat)) * math.sin(dec)
          + math.cos(math.radians(lat)) * math.cos(dec) * math.cos(ha))
    return 1098 * cz * math.exp(-0.057 / cz) if cz > 0 else 0.0


# Seasons of the Bondville 1998 selection (day of year, inclusive) and the
# rule: in each, the local day with the largest ratio of measured daily GHI
# to Haurwitz's clear-sky GHI, whose 48 IRT values are all present and whose
# day before is in the file. Fixed before any model run on these days.
# The first four windows were run in session 18; the last two (spring and
# early autumn, issue #30 session 19) were added, with their surface and
# material rule below, before any model run on the days they pick.
SEASONS = (
    ("winter, snow-free", 1, 74, lambda alb: alb < 0.4),
    ("snow cover (midday PAR albedo > 0.4)", 1, 365, lambda alb: alb > 0.4),
    ("crop (Jun 15 - Aug 31; not Jul 25 or Aug 1, already in the set)", 166, 243, lambda alb: alb < 0.4),
    ("after harvest (Oct 15 - Dec 31)", 288, 365, lambda alb: alb < 0.4),
    ("spring (Mar 16 - Jun 14; not May 17, already in the set)", 75, 165, lambda alb: alb < 0.4),
    ("early autumn (Sep 1 - Oct 14: ripening crop, harvest)", 244, 287, lambda alb: alb < 0.4),
)
ALREADY = {137, 206, 213}

# The surface, and the library material that stands for it, by a rule fixed
# with the windows (tests/data/stations/README.md, "How the Bondville days
# were chosen"):
#   * midday PAR albedo > 0.4: snow -> `snow`;
#   * the crop window (Jun 15 - Aug 31): the crop at (or near) full cover -> `crop`;
#   * spring (Mar 16 - Jun 14): bare soil with the crop residue of no-till
#     before and around emergence (midday PAR albedo 0.08-0.13 all through
#     the window, as May 17's 0.11; the green canopy's 0.03-0.06 is first
#     reached in July) -> the bare-soil rule;
#   * early autumn (Sep 1 - Oct 14): the standing crop until harvest. The
#     Noah forcing's documentation (User's Guide 2.7.1, sec. 6.1) names
#     neither the crop nor its harvest date (its green vegetation fraction
#     for the site falls 0.96 -> 0.65 -> 0.24 from August to October), so
#     both are read from the file: harvest = the first day from Sep 1 whose
#     daytime median u*/u_bar(6 m) (a measure of the surface roughness) is
#     below HARVEST_USTAR_RATIO and stays below it for the next 5 days with
#     data (printed by --select-noah98: Oct 11; the standing crop reads
#     0.09-0.16, the bare field of spring 0.05-0.09). Before it the crop
#     stands: midday PAR albedo < GREEN_PAR_ALBEDO (green leaves; the July
#     and August crop days read 0.035-0.06) -> `crop`; otherwise senescent
#     (yellowing and dropping leaves, PAR albedo rising to 0.09-0.11 from
#     mid-September) -> `grass_dry`, the library's senescent vegetation
#     (a dry sparse canopy, LAI 1, over dry soil). From harvest on -> the
#     bare-soil rule;
#   * the bare-soil rule (soil with residue): `soil_moist` where theta(5 cm)
#     >= 0.3 at the start of the day (as May 17), else `soil_bare`.
GREEN_PAR_ALBEDO = 0.07
HARVEST_USTAR_RATIO = 0.09


def bondville_material(season, d, alb, sm5, harvest_doy):
    """The library material of a chosen Bondville day by the rule above."""
    if alb > 0.4:
        return "snow"
    if season.startswith("crop"):
        return "crop"
    if season.startswith("early autumn") and d < harvest_doy:
        return "crop" if alb < GREEN_PAR_ALBEDO else "grass_dry"
    return "soil_moist" if sm5 >= 0.3 else "soil_bare"


def harvest_day(days):
    """First day of year >= 244 (Sep 1) whose daytime (GHI > 50 W/m2, u_bar >
    2 m/s) median u*/u_bar is below HARVEST_USTAR_RATIO, with the next 5 days
    that have such records below it too (u* = sqrt(-u'w'))."""
    ratio = {}
    for d, rs in days.items():
        r = sorted((-v["uw"]) ** 0.5 / v["u_bar"] for _, v in rs
                   if -6000 < v["uw"] < 0 and v["u_bar"] > 2 and v["rg"] > 50)
        if r:
            ratio[d] = r[len(r) // 2]
    ds = sorted(d for d in ratio if d >= 244)
    for i, d in enumerate(ds):
        if all(ratio[e] < HARVEST_USTAR_RATIO for e in ds[i:i + 6]):
            return d, ratio
    return 366, ratio


def select_bondville_days(path):
    """Applies the SEASONS rule to the whole Noah LSM 1998 file (not
    committed: 4.2 MB) and prints the day chosen in each season with its
    clearness, midday PAR albedo (median of PAR_out/PAR_in where PAR_in >
    500 umol/m2/s), 5-cm soil water and the material the rule gives."""
    days = {}
    for ln in pathlib.Path(path).read_text().splitlines():
        f = ln.split()
        if len(f) != len(NOAH_COLS):
            continue
        v = dict(zip(NOAH_COLS, (float(x) for x in f)))
        hhmm = int(v["time"])
        centre = (int(v["jday"]) - 1) * 1440 + hhmm // 100 * 60 + hhmm % 100 - 15
        days.setdefault(centre // 1440 + 1, []).append((centre % 1440, v))
    harvest, ratio = harvest_day(days)
    hdate = dt.date(1998, 1, 1) + dt.timedelta(days=harvest - 1)
    print(f"harvest (daytime median u*/u_bar < {HARVEST_USTAR_RATIO} from then on): day {harvest} ({hdate}); "
          f"u*/u_bar the 3 days before {[round(ratio.get(d, float('nan')), 3) for d in range(harvest - 3, harvest)]}, "
          f"from it {[round(ratio.get(d, float('nan')), 3) for d in range(harvest, harvest + 3)]}")
    stats = {}
    for d, rs in days.items():
        if len(rs) != 48 or len(days.get(d - 1, [])) != 48 or any(v["irt"] <= -6000 for _, v in rs):
            continue
        ghi = sum(max(v["rg"], 0.0) for _, v in rs)
        cs = sum(haurwitz_ghi_w_m2(d, m / 60) for m, _ in rs)
        alb = sorted(v["par_out"] / v["par_in"] for _, v in rs if v["par_in"] > 500 and v["par_out"] > -6000)
        if alb:
            stats[d] = (ghi / cs, alb[len(alb) // 2], rs[0][1]["sm5"])
    chosen = []
    for name, lo, hi, surface in SEASONS:
        cands = [d for d, (_, alb, _) in stats.items() if lo <= d <= hi and d not in ALREADY and surface(alb)]
        d = max(cands, key=lambda d: stats[d][0])
        date = dt.date(1998, 1, 1) + dt.timedelta(days=d - 1)
        mat = bondville_material(name, d, stats[d][1], stats[d][2], harvest)
        print(f"{name}: day {d} ({date}), clearness {stats[d][0]:.3f}, PAR albedo {stats[d][1]:.3f}, "
              f"theta(5 cm) {stats[d][2]:.2f} -> {mat}")
        chosen.append(d)
    return chosen


# Col de Porte days beyond cdp-20020110 (issue #30, session 18). The rule,
# fixed before any model run on them: for each of December 2001, February
# 2002 and March 2002 (the other full winter months of meteo0001.txt, which
# runs 2001-09-21 .. 2002-04-10), the day with the smallest daily mean of
# LWdn / (sigma Ta^4) (the clearest sky: effective sky emissivity) among the
# days whose 24 hourly surface temperatures are all present, whose snow
# depth is >= 20 cm in every hour (a settled cover: `snow` is 0.3 m of
# settled snow), with no precipitation on the day and a complete day before
# it (the spin-up). A month with no such day gives none. Each chosen day
# stays in the set whatever the model does on it.
CDP_MONTHS = (("December 2001", 2001, 12), ("February 2002", 2002, 2), ("March 2002", 2002, 3))
# What --select-cdp printed (March 2002 has no day that passes the rule).
CDP_MORE_DAYS = (dt.date(2001, 12, 31), dt.date(2002, 2, 19))


def select_cdp_days(meteo_path, nc_path):
    """Applies the CDP_MONTHS rule to the whole meteo0001.txt (not
    committed) and the CRYOBSCLIM.CDP hourly netCDF (needs h5py); prints
    and returns the chosen days (UTC dates)."""
    import h5py  # only for this one-off selection

    f = h5py.File(nc_path, "r")
    base = dt.datetime(1960, 8, 1)
    t, ts, sd = f["time"][:], f["Surface_temperature"][:], f["Snow_depth"][:]
    obs = {}
    for i, s in enumerate(t):
        obs[base + dt.timedelta(seconds=int(s))] = (ts[i], sd[i])
    days = {}
    lines = pathlib.Path(meteo_path).read_text().splitlines()
    head = lines[0].split(",")
    for ln in lines[1:]:
        v = dict(zip(head, ln.split(",")))
        end = dt.datetime.strptime(v["Date"], "%d/%m/%Y %H:%M")
        day = (end - dt.timedelta(minutes=30)).date()  # hour-ending stamps: 01:00 .. 24:00 make a day
        days.setdefault(day, []).append((end, float(v["Prec"]), float(v["Tair"]), float(v["LW"])))
    chosen = []
    for name, y, m in CDP_MONTHS:
        cands = []
        for d, rs in days.items():
            if (d.year, d.month) != (y, m) or len(rs) != 24 or len(days.get(d - dt.timedelta(days=1), [])) != 24:
                continue
            if any(p > 0 for _, p, _, _ in rs):
                continue
            o = [obs.get(e, (-1e9, -1e9)) for e, _, _, _ in rs]
            if any(tk < -9e6 or s < 20 for tk, s in o):
                continue
            eps = sum(lw / (se.SIGMA * (ta + 273.15) ** 4) for _, _, ta, lw in rs) / 24
            cands.append((eps, d))
        if not cands:
            print(f"{name}: no day passes the rule")
            continue
        eps, d = min(cands)
        print(f"{name}: {d} (mean LWdn/(sigma Ta^4) {eps:.3f}; {len(cands)} candidate days)")
        chosen.append(d)
    return chosen


# --- Shenshawo sandy desert (HiWATER, Heihe River Basin), the desert day ---
# Source: the 30-min file of the dLSEB repository (github.com/Shuaichen-He/dLSEB,
# data/1.origin/Shenshawo sandy desert/Shenshawo_valid_10d_periods.csv, commit
# 5c04dd9): the HiWATER automatic weather station (10-min means averaged to the
# half hour ending at the stamp) joined with the station's eddy covariance
# (half hour ending at the stamp), Beijing time (UTC+8), for the repository's
# "valid periods" (10-day windows with no rain, 2-cm soil moisture < 5 % and
# no frost). Columns used: DR, UR, DLR_Cor, ULR_Cor (CNR1 at 6 m), Ta_5m,
# Press, Gs_1-3 (plates at 6 cm), and from the eddy covariance at 4.5 m Wnd,
# H2O (vapour density, g/m3), Hs, LE.
SSW = {"lat": 38.7892, "lon": 100.4933, "elev": 1594}
SSW_NEED = ("DR", "DLR_Cor", "ULR_Cor", "Ta_5m", "H2O", "Wnd", "Press")
# The day, by a rule fixed before any model run on it (select_ssw_day):
# among the local days with all 48 half-hours of SSW_NEED and a day before
# that has them too, the "summer days" (daily maximum air temperature >=
# 25 C, the SU25 index of the ETCCDI climate indices), the one with the
# largest ratio of daily measured GHI (DR) to Haurwitz's clear-sky GHI
# (-> 2013-10-08); and, a second rule fixed with it, the hottest of the same
# candidates (largest daily maximum air temperature; -> 2013-08-30).
SSW_HOT_C = 25.0
SSW_UTC_OFFSET_H = 8
# Its material, by the rule of the bare-soil days (Bondville: theta(5 cm) <
# 0.3 -> `soil_bare`): dry bare sand without vegetation (theta(2 cm) < 0.05)
# -> `soil_bare`, the library's bare soil without soil evaporation. The skin
# temperature is derived from ULR_Cor with that material's emissivity, 0.94
# (desert sands read 0.93-0.95 broadband; the source's IRT columns are not in
# the file).
SSW_EPS = 0.94


def read_ssw(path):
    """Records (UTC 'end' times) of the Shenshawo 30-min file: vapour
    pressure e = rho_v R_v T from the eddy covariance's vapour density and
    the 5-m air temperature, RH = e / e_s (FAO-56 e_s); G = mean of the three
    plates at 6 cm; R_n from the four components."""
    import csv
    import math

    recs = []
    for v in csv.DictReader(se.check_raw(path).read_text().splitlines()):
        num = lambda k: None if v.get(k, "") in ("", "nan", "NaN") else float(v[k])
        end = (dt.datetime.strptime(v["time"], "%Y-%m-%d %H:%M:%S")
               - dt.timedelta(hours=SSW_UTC_OFFSET_H)).replace(tzinfo=UTC)
        ta, rho_v = num("Ta_5m"), num("H2O")
        rh = None
        if ta is not None and rho_v is not None:
            e_kpa = rho_v * 1e-3 * 461.5 * (ta + 273.15) / 1000.0
            es = 0.6108 * math.exp(17.27 * ta / (ta + 237.3))
            rh = 100.0 * e_kpa / es
        gs = [num(k) for k in ("Gs_1", "Gs_2", "Gs_3")]
        four = [num(k) for k in ("DR", "UR", "DLR_Cor", "ULR_Cor")]
        recs.append({"end": end, "span": dt.timedelta(minutes=30), "local": v["time"],
                     "ghi": num("DR"), "dni": None, "dhi": None, "sw_up": num("UR"),
                     "lw_dn": num("DLR_Cor"), "lw_up": num("ULR_Cor"), "t_air_c": ta, "rh": rh,
                     "wind": num("Wnd"), "p_hpa": num("Press"), "precip": num("Rain"),
                     "le": num("LE"), "h": num("Hs"),
                     "g": None if None in gs else sum(gs) / 3.0,
                     "rnet": None if None in four else four[0] - four[1] + four[2] - four[3],
                     "ms2": num("Ms_2cm"), "ok": all(num(k) is not None for k in SSW_NEED)})
    return recs


def select_ssw_day(path):
    """Prints the candidate days of the Shenshawo rules and returns the
    chosen local days (dates): (the clearest, the hottest)."""
    recs = read_ssw(path)
    by_day = {}
    for r in recs:
        local_centre = r["end"] - r["span"] / 2 + dt.timedelta(hours=SSW_UTC_OFFSET_H)
        by_day.setdefault(local_centre.date(), []).append((local_centre, r))
    complete = {d for d, rs in by_day.items() if len(rs) == 48 and all(r["ok"] for _, r in rs)}
    best, hottest = None, None
    for d in sorted(complete):
        if d - dt.timedelta(days=1) not in complete:
            continue
        rs = by_day[d]
        tmax = max(r["t_air_c"] for _, r in rs)
        if tmax < SSW_HOT_C:
            continue
        doy = d.timetuple().tm_yday
        cs = sum(haurwitz_ghi_w_m2(doy, c.hour + c.minute / 60, SSW["lat"], SSW["lon"], SSW_UTC_OFFSET_H)
                 for c, _ in rs)
        ratio = sum(r["ghi"] for _, r in rs) / cs
        ms = max(r["ms2"] for _, r in rs)
        print(f"  {d}: Ta max {tmax:.1f} C, daily GHI / clear-sky GHI {ratio:.3f}, Ms_2cm max {ms:.2f} %")
        if best is None or ratio > best[1]:
            best = (d, ratio)
        if hottest is None or tmax > hottest[1]:
            hottest = (d, tmax)
    print(f"Shenshawo: the clearest summer day {best[0]} (ratio {best[1]:.3f}); "
          f"the hottest {hottest[0]} (air up to {hottest[1]:.1f} C)")
    return best[0], hottest[0]


def rows_of(recs, t0, t1):
    """One row per record whose interval centre lies in [t0, t1)."""
    out = []
    for r in recs:
        c = r["end"] - r["span"] / 2
        if t0 <= c < t1:
            out.append(dict(r, time=c))
    return out


def write_ir_station(name, spin, day, meta, eps_irt_note, source_lines, notes, heights, eps=None):
    """Writes one station-day. The skin temperature is the IRT reading
    (`irt`), or with `eps` derived from the measured up- and downwelling
    longwave as tools/station_excerpt.py does."""
    filled = se.fill_required(spin) + se.fill_required(day)
    for r in spin + day:
        if eps is not None:
            r["irt"] = (se.skin_temp_c(r["lw_up"], r["lw_dn"], eps)
                        if r["lw_up"] is not None and r["lw_dn"] is not None else None)
    out_rows = [(r, True) for r in spin] + [(r, False) for r in day]
    compare_from, compare_to = day[0]["time"], day[-1]["time"]
    spin_up_h = (compare_from - spin[0]["time"]).total_seconds() / 3600
    has_p = any(r["p_hpa"] is not None for r in day)
    cols = ["time", "air_temp_c", "rh_percent", "wind_m_s"] + (["pressure_hpa"] if has_p else []) + [
        "cloud_fraction", "ghi_w_m2", "dni_w_m2", "dhi_w_m2", "sky_temp_c", "precip_mm_h",
        "x_lw_up_w_m2", "x_lw_dn_w_m2", "x_sw_up_w_m2", "x_skin_temp_c", "x_spinup",
        "x_le_w_m2", "x_h_w_m2", "x_g_w_m2", "x_rnet_w_m2"]
    hdr = [
        f"# {name}: irsig plain weather CSV (docs/weather-format.md) written by tools/station_excerpt_more.py",
        *[f"# {s}" for s in source_lines],
        f"# lat: {meta['lat']:.5f}",
        f"# lon: {meta['lon']:.5f}",
        f"# elevation_m: {meta['elev']:.0f}",
        f"# compare_from: {se.iso(compare_from)}",
        f"# compare_to: {se.iso(compare_to)}",
        f"# spin_up_h: {spin_up_h:g}",
        f"# wind_height_m: {heights[0]:g}",
        f"# air_height_m: {heights[1]:g}",
        *(["# skin_source: ir_thermometer"] if eps is None else
          [f"# emissivity: {eps}  ({eps_irt_note})", "# skin_source: longwave"]),
        f"# skin: {eps_irt_note}",
        "# Times: UTC, centre of each averaging interval. Irradiances and longwave are interval means.",
        "# sky_temp_c = (LWdn/sigma)^(1/4) - 273.15 (effective sky temperature of the measured LWdn).",
        *(["# x_skin_temp_c: the infrared thermometer's surface temperature as published (no emissivity",
           "#   correction applied here); x_lw_up_w_m2 and x_sw_up_w_m2: not measured (empty)."] if eps is None else
          ["# x_skin_temp_c = ((LWup - (1-eps)*LWdn)/(eps*sigma))^(1/4) - 273.15, sigma = 5.670374419e-8;",
           "#   x_sw_up_w_m2: not measured (empty)." if all(r.get("sw_up") is None for r in day) else
           "#   x_sw_up_w_m2: the measured reflected shortwave."]),
        "# x_le_w_m2, x_h_w_m2, x_g_w_m2: measured latent, sensible and ground heat flux where the source has",
        "#   them (eddy covariance, not closure-corrected; positive away from the surface, G into the ground).",
        "# x_rnet_w_m2: measured net radiation where the source has it (net radiometer; positive into the",
        "#   surface), for the energy-balance closure of the measured fluxes (Twine et al. 2000).",
        "# cloud_fraction: required by the reader today; unused (0) because sky_temp_c and the irradiances are measured.",
        "# precip_mm_h: measured (0 on these days).",
        "# x_ columns are ignored by the weather reader; x_spinup = 1 marks spin-up rows (not compared).",
        *[f"# note: {n}" for n in notes],
    ]
    if filled:
        hdr.append(f"# note: {filled} value(s) of air temperature/RH/wind linearly interpolated over short gaps")
    lines = hdr + [",".join(cols)]
    for r, copy in out_rows:
        sky = None if r["lw_dn"] is None else (r["lw_dn"] / se.SIGMA) ** 0.25 - 273.15
        clip = lambda v: None if v is None else max(v, 0.0)
        cells = [se.iso(r["time"]), se.fmt(r["t_air_c"]), se.fmt(min(r["rh"], 100.0), 1), se.fmt(r["wind"])]
        if has_p:
            cells.append(se.fmt(r["p_hpa"], 1))
        cells += ["0", se.fmt(clip(r["ghi"]), 1), se.fmt(clip(r["dni"]), 1), se.fmt(clip(r["dhi"]), 1),
                  se.fmt(sky), se.fmt(r["precip"] or 0.0, 2)]
        cells += [se.fmt(r["lw_up"], 1), se.fmt(r["lw_dn"], 1), se.fmt(r.get("sw_up"), 1), se.fmt(r["irt"]),
                  "1" if copy else "0",
                  se.fmt(r.get("le"), 1), se.fmt(r.get("h"), 1), se.fmt(r.get("g"), 1),
                  se.fmt(r.get("rnet"), 1)]
        lines.append(",".join(cells))
    p = OUT / f"{name}.csv"
    p.write_text("\n".join(lines) + "\n")
    n_skin = sum(1 for r in day if r["irt"] is not None)
    print(f"{p.relative_to(se.ROOT)}: {len(out_rows)} rows, compare {se.iso(compare_from)} .. "
          f"{se.iso(compare_to)} ({n_skin} with skin), spin-up {spin_up_h:g} h")


def cdp_surface_temp_from_nc(nc_path, out_path, t0, t1, windows=None):
    """Extracts Surface_temperature and Snow_depth for [t0, t1) (or for
    each (t0, t1) of `windows`) from the CRYOBSCLIM.CDP hourly netCDF-4
    file (needs h5py; run once)."""
    windows = windows or [(t0, t1)]
    import h5py  # only for this one-off extraction

    f = h5py.File(nc_path, "r")
    base = dt.datetime(1960, 8, 1)
    t = f["time"][:]
    ts, sd = f["Surface_temperature"][:], f["Snow_depth"][:]
    lines = ["time_utc_end_of_hour,surface_temperature_k,snow_depth_cm"]
    for i, s in enumerate(t):
        tt = base + dt.timedelta(seconds=int(s))
        if any(a <= tt < b for a, b in windows):
            v = lambda x: "" if x < -9e6 else f"{x:.2f}"
            lines.append(f"{tt:%Y-%m-%dT%H:%M},{v(ts[i])},{v(sd[i])}")
    pathlib.Path(out_path).write_text("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--select-noah98", type=pathlib.Path,
                    help="forcing98_with_validation.dat: print the Bondville days the selection rule picks")
    ap.add_argument("--select-cdp", type=pathlib.Path, nargs=2, metavar=("METEO0001", "NC"),
                    help="meteo0001.txt and CDP_hourly_19930801_20170731.nc: print the Col de Porte days "
                         "the selection rule picks")
    ap.add_argument("--select-ssw", type=pathlib.Path,
                    help="Shenshawo_valid_10d_periods.csv (dLSEB repository): print the Shenshawo day the rule picks")
    ap.add_argument("--cdp-nc", type=pathlib.Path,
                    help="CDP_hourly_19930801_20170731.nc: re-extract the surface temperature excerpt")
    a = ap.parse_args()
    if a.select_noah98:
        select_bondville_days(a.select_noah98)
        return 0
    if a.select_cdp:
        select_cdp_days(*a.select_cdp)
        return 0
    if a.select_ssw:
        select_ssw_day(a.select_ssw)
        return 0
    if a.cdp_nc:
        cdp_surface_temp_from_nc(a.cdp_nc, RAW / "cdp_surface_temp_2002-01.csv",
                                 dt.datetime(2002, 1, 9, 0), dt.datetime(2002, 1, 11, 1))
        cdp_surface_temp_from_nc(a.cdp_nc, RAW / "cdp_surface_temp_more.csv", None, None,
                                 [(dt.datetime(d.year, d.month, d.day) - dt.timedelta(days=1),
                                   dt.datetime(d.year, d.month, d.day) + dt.timedelta(days=1, hours=1))
                                  for d in CDP_MORE_DAYS])

    # --- Bondville (ATDD/ARL flux site), 1998: three local days ---
    recs = read_noah98(RAW / "noah98_bondville_excerpt.dat")
    bnd = {"lat": 40.01, "lon": -88.37, "elev": 219}
    src = ["source: NOAA ATDD/ARL Bondville (Champaign), IL flux site of T. Meyers, 1998, 30-min means, as",
           "        distributed with the Noah LSM 2.7 (github.com/NOAA-EMC/NoahLSM test/forcing98_with_validation.dat;",
           "        see tests/data/stations/README.md)",
           "data: NOAA Air Resources Laboratory, U.S. Government work (public domain)"]
    irt_note = ("infrared thermometer surface temperature (IRT column of the Noah LSM forcing file; "
                "instrument emissivity setting not stated)")
    lst = lambda y, m, d: dt.datetime(y, m, d, 6, tzinfo=UTC)  # local (CST) midnight in UTC
    days = [
        ("bnd-19980517", lst(1998, 5, 17),
         ["bare soil with crop residue before emergence (no-till maize/soybean rotation; PAR albedo 0.11-0.12)",
          "clear, hot (air 15-31 C, IRT up to 38 C), light wind; latent heat flux up to 205 W/m2"]),
        ("bnd-19980725", lst(1998, 7, 25),
         ["crop at full cover (PAR albedo 0.04); calm (6-m wind 0.1-2 m/s) and clear night 00-06 LST after",
          "the sunny July 24; cloud arrives in the evening of July 25 (LWdn 315 -> 388 W/m2)"]),
        ("bnd-19980801", lst(1998, 8, 1),
         ["crop at full cover, peak transpiration: eddy-covariance latent heat flux up to 525 W/m2 at midday,",
          "sensible heat flux under 90 W/m2; clear (LWdn / sigma Ta^4 about 0.82)"]),
    ]
    for name, t0, notes in days:
        spin = rows_of(recs, t0 - dt.timedelta(days=1), t0)
        day = rows_of(recs, t0, t0 + dt.timedelta(days=1))
        n_sub = sum(1 for r in spin + day if r.get("wind_sub"))
        sub_note = ([f"{n_sub} half-hours without the 6-m u_bar: 10-m propeller wind x the excerpt's median "
                     "u_bar/w_speed ratio (the Noah driver's substitution)"] if n_sub else [])
        write_ir_station(name, spin, day, bnd, irt_note, src,
                         notes + sub_note + ["LST = UTC-6; the compared window is the local day (06:15-05:45 UTC)",
                                  "heights: air temperature and RH 3 m, wind (u_bar) 6 m; DNI/DHI not measured "
                                  "(irsig splits GHI)",
                                  "site 40.01 N, 88.37 W as the Noah LSM guide states; elevation 219 m (AmeriFlux "
                                  "US-Bo1; only the measured pressure depends on it)"],
                         (6.0, 3.0))

    # --- More Bondville 1998 days (select_bondville_days' rule) ---
    recs = read_noah98(RAW / "noah98_bondville_excerpt2.dat")
    more = [
        ("bnd-19980224", lst(1998, 2, 24),
         ["winter, snow-free: bare soil with crop residue, dormant (PAR albedo 0.10); the clearest snow-free",
          "day of Jan 1 - Mar 15 1998 (daily GHI / clear-sky GHI 1.01); theta(5 cm) 0.38"]),
        ("bnd-19980310", lst(1998, 3, 10),
         ["snow cover (midday PAR albedo 0.65) after the snowfall of Mar 9; the clearest day of 1998 with PAR",
          "albedo > 0.4 (daily GHI / clear-sky GHI 1.00); snow depth not measured"]),
        ("bnd-19980712", lst(1998, 7, 12),
         ["crop at full cover (PAR albedo 0.056); the clearest day of Jun 15 - Aug 31 1998 other than the two",
          "already in the set (daily GHI / clear-sky GHI 0.90); theta(5 cm) 0.35"]),
        ("bnd-19981215", lst(1998, 12, 15),
         ["after harvest: bare soil with residue (PAR albedo 0.10); the clearest day of Oct 15 - Dec 31 1998",
          "(daily GHI / clear-sky GHI 1.01); theta(5 cm) 0.33"]),
    ]
    # --- Spring and early autumn (the two windows added in session 19) ---
    recs3 = read_noah98(RAW / "noah98_bondville_excerpt3.dat")
    more3 = [
        ("bnd-19980405", lst(1998, 4, 5),
         ["spring: bare soil with crop residue before emergence (PAR albedo 0.097); the clearest day of",
          "Mar 16 - Jun 14 1998 other than May 17 (daily GHI / clear-sky GHI 0.96); theta(5 cm) 0.40;",
          "air -0.4 to 14 C, IRT -0.6 to 23 C; calm clear night (6-m wind down to 0.15 m/s) after a windy day"]),
        ("bnd-19980923", lst(1998, 9, 23),
         ["early autumn: the crop standing but senescent (PAR albedo 0.093, up from 0.04 in August; harvest",
          "Oct 11 by the drop of u*/u_bar); the clearest day of Sep 1 - Oct 14 1998 (daily GHI / clear-sky",
          "GHI 0.95); theta(5 cm) 0.32; latent heat flux at most 106 W/m2, sensible heat up to 318 W/m2"]),
    ]
    for name, t0, notes, recs in [(*m, recs) for m in more] + [(*m, recs3) for m in more3]:
        spin = rows_of(recs, t0 - dt.timedelta(days=1), t0)
        day = rows_of(recs, t0, t0 + dt.timedelta(days=1))
        n_sub = sum(1 for r in spin + day if r.get("wind_sub"))
        sub_note = ([f"{n_sub} half-hours without the 6-m u_bar: 10-m propeller wind x the excerpt's median "
                     "u_bar/w_speed ratio (the Noah driver's substitution)"] if n_sub else [])
        write_ir_station(name, spin, day, bnd, irt_note, src,
                         notes + sub_note + ["chosen by tools/station_excerpt_more.py select_bondville_days "
                                             "(clearest day of its season; rule fixed before any model run)",
                                             "LST = UTC-6; the compared window is the local day (06:15-05:45 UTC)",
                                             "heights: air temperature and RH 3 m, wind (u_bar) 6 m; DNI/DHI not "
                                             "measured (irsig splits GHI)",
                                             "site 40.01 N, 88.37 W as the Noah LSM guide states; elevation 219 m "
                                             "(AmeriFlux US-Bo1; only the measured pressure depends on it)"],
                         (6.0, 3.0))

    # --- DE-Tha (Tharandt, spruce forest), 2014-06-07 ---
    recs = read_bigleaf(RAW / "de-tha_bigleaf_DE_Tha_Jun_2014_doy157-158.csv")
    t0 = dt.datetime(2014, 6, 6, 23, tzinfo=UTC)  # local (CET) midnight
    spin = rows_of(recs, t0 - dt.timedelta(days=1), t0)
    day = rows_of(recs, t0, t0 + dt.timedelta(days=1))
    write_ir_station(
        "de-tha-20140607", spin, day, {"lat": 50.9626, "lon": 13.5651, "elev": 380},
        "closed spruce canopy, typical broadband value (bigleaf's own DE-Tha example uses 0.98)",
        ["source: FLUXNET2015 DE-Tha (Anchor Station Tharandt, Norway spruce forest), half-hourly, as shipped in",
         "        the R package bigleaf 0.8.2 (data set DE_Tha_Jun_2014; github.com/cran/bigleaf data/)",
         "        (see tests/data/stations/README.md)",
         "data: FLUXNET2015 (Pastorello et al. 2020), TU Dresden; CC-BY-4.0; bigleaf is GPL (>= 2)"],
        ["closed Norway spruce forest (canopy about 27 m; sensors on the 42-m tower, Gruenwald & Bernhofer 2007)",
         "clear, warm (air 17-28 C); eddy-covariance latent heat flux up to 270 W/m2",
         "GHI = PPFD / 2.10 (PAR fraction 0.46 x 4.57 umol/J, McCree 1972): shortwave not in the data set, "
         "uncertain by about 5 %",
         "RH from VPD and the FAO-56 saturation vapour pressure; LW_down is FLUXNET's LW_IN_F (measured, "
         "gap-filled where missing)",
         "times: local standard time CET (UTC+1), hour = start of the half hour (the PPFD-weighted mean "
         "hour is 11.7 CET on both days, solar noon 12.1 CET)"],
        (42.0, 42.0), eps=0.98)

    # --- Col de Porte: 2002-01-10 (snow, clear, calm) and the CDP_MONTHS days ---
    cdp_days = [(dt.datetime(2002, 1, 10, tzinfo=UTC), "cdp_meteo0001_2002-01.txt", "cdp_surface_temp_2002-01.csv",
                 ["snow-covered meadow, 37 cm of settled snow (hourly snow depth 37 cm both days); no snowfall",
                  "clear and calm both days (LWdn 220-230 W/m2, wind 0.3-0.6 m/s mean); air -3 to +3.5 C, snow "
                  "surface -16 to -7 C"])]
    for d in CDP_MORE_DAYS:
        cdp_days.append((dt.datetime(d.year, d.month, d.day, tzinfo=UTC), "cdp_meteo0001_more.txt",
                         "cdp_surface_temp_more.csv", None))
    for t0, meteo, stemp, notes in cdp_days:
        write_cdp_day(RAW / meteo, RAW / stemp, t0, notes)

    # --- Shenshawo sandy desert (HiWATER): the desert days of select_ssw_day ---
    recs = read_ssw(RAW / "ssw_dlseb_2013-08-29_30_2013-10-07_08.csv")
    for d, why in [(dt.date(2013, 10, 8), "the clearest summer day (daily max air >= 25 C) of the file"),
                   (dt.date(2013, 8, 30), "the hottest day of the same candidates")]:
        write_ssw_day(recs, d, why)
    return 0


def write_ssw_day(recs, d, why):
    """One Shenshawo station-day: the local (Beijing, UTC+8) day `d`, the day
    before as the measured spin-up."""
    t0 = dt.datetime(d.year, d.month, d.day, tzinfo=UTC) - dt.timedelta(hours=SSW_UTC_OFFSET_H)
    spin = rows_of(recs, t0 - dt.timedelta(days=1), t0)
    day = rows_of(recs, t0, t0 + dt.timedelta(days=1))
    rng = lambda k: (min(r[k] for r in day), max(r[k] for r in day))
    skin = [se.skin_temp_c(r["lw_up"], r["lw_dn"], SSW_EPS) for r in day]
    alb = se.midday_albedo(day, SSW["lon"])
    write_ir_station(
        f"ssw-{d:%Y%m%d}", spin, day, SSW,
        "the library's soil_bare (the material the rule picks); desert sands read 0.93-0.95 broadband",
        ["source: HiWATER Shenshawo sandy desert station (Heihe River Basin, Gansu, China): automatic weather station",
         "        and eddy covariance, 30-min, as the file data/1.origin/Shenshawo sandy desert/",
         "        Shenshawo_valid_10d_periods.csv of github.com/Shuaichen-He/dLSEB (commit 5c04dd9; MIT licence)",
         "        (see tests/data/stations/README.md)",
         "data: Heihe hydrometeorological observation network (Liu et al. 2018, Vadose Zone J. 17:180072; Li et al.",
         "      2013, BAMS 94:1145), published by the National Tibetan Plateau / Third Pole Environment Data Center"],
        [f"dry bare sand (sandy desert, no vegetation): 2-cm soil moisture {rng('ms2')[0]:.1f}-{rng('ms2')[1]:.1f} %"
         + f"; midday albedo {alb:.3f}",
         f"chosen by select_ssw_day: {why} (rule fixed before any model run)",
         "air {:.1f} to {:.1f} C, wind {:.1f}-{:.1f} m/s, RH {:.0f}-{:.0f} %, skin (eps {}) {:.1f} to {:.1f} C".format(
             *rng("t_air_c"), *rng("wind"), *rng("rh"), SSW_EPS, min(skin), max(skin)),
         "times: Beijing time (UTC+8), AWS 10-min means averaged to the half hour ending at the stamp, eddy",
         "covariance half hour ending at the stamp (DR-weighted mean hour {:.2f} BJT; solar noon 13.1 BJT on Oct 8,".format(
             sum(r["ghi"] * ((r["time"].hour + SSW_UTC_OFFSET_H) % 24 + r["time"].minute / 60) for r in day)
             / sum(r["ghi"] for r in day)),
         "13.3 on Aug 30)",
         "heights: air temperature 5 m (HMP45AC), wind and vapour density 4.5 m (eddy covariance: CSAT3 and",
         "LI-7500), radiometers 6 m (CNR1), pressure 2 m; RH = rho_v R_v T_a / e_s(T_a) (FAO-56 e_s)",
         "x_g_w_m2: mean of the three plates at 6 cm (no storage correction above them); x_rnet_w_m2: the four",
         "components DR - UR + DLR_Cor - ULR_Cor; DNI/DHI not measured (irsig splits GHI)"],
        (4.5, 5.0), eps=SSW_EPS)


def write_cdp_day(meteo, stemp, t0, notes):
    """One Col de Porte station-day (the UTC day from t0; the day before
    as the measured spin-up). `notes`: the day's description; None writes
    the rule's description with the measured ranges."""
    recs = read_cdp(meteo, stemp)
    spin = rows_of(recs, t0 - dt.timedelta(days=1), t0)
    day = rows_of(recs, t0, t0 + dt.timedelta(days=1))
    p_est = 1013.25 * (1 - 2.25577e-5 * 1325) ** 5.25588
    if notes is None:
        rng = lambda k: (min(r[k] for r in day if r[k] is not None), max(r[k] for r in day if r[k] is not None))
        eps = sum(r["lw_dn"] / (se.SIGMA * (r["t_air_c"] + 273.15) ** 4) for r in day) / len(day)
        notes = [f"snow-covered meadow, {rng('snow_cm')[0]:.0f}-{rng('snow_cm')[1]:.0f} cm of snow (hourly snow depth); "
                 "no precipitation on the day",
                 f"chosen by select_cdp_days (the clearest day of its month, mean LWdn/(sigma Ta^4) {eps:.3f}; rule "
                 "fixed before any model run)",
                 "air {:.1f} to {:.1f} C, wind {:.1f}-{:.1f} m/s, snow surface {:.1f} to {:.1f} C".format(
                     *rng("t_air_c"), *rng("wind"), *rng("irt"))]
    for r in spin + day:
        r["p_hpa"] = p_est
    write_ir_station(
        f"cdp-{t0:%Y%m%d}", spin, day, {"lat": 45.30, "lon": 5.77, "elev": 1325},
        "snow surface temperature of the CRYOBSCLIM.CDP hourly file (infrared radiometer; Lejeune et al. 2019)",
        ["source: Col de Porte (Chartreuse, France), CNRM/CEN: forcing of Morin et al. 2012 (doi:10.1594/PANGAEA.774249)",
         "        as GEOtop's test input, and the CRYOBSCLIM.CDP hourly file (Lejeune et al. 2019, doi:10.17178/CRYOBSCLIM.CDP.2018),",
         "        both via github.com/EURAC-Ecohydro/GEOtopExamples tests/ColdelaPorte/obss (see tests/data/stations/README.md)",
         "data: Meteo-France - CNRS, CNRM, Centre d'Etudes de la Neige; Morin et al. 2012 data CC-BY-3.0"],
        notes + ["the site is ringed by mountains and forest: the measured GHI already carries the horizon mask",
         "(direct sun only about 10:00-15:00 UTC in January); DHI measured, DNI left to irsig",
         f"pressure not in the forcing file: {p_est:.1f} hPa = standard atmosphere at 1325 m",
         "times: UTC, hourly means stamped at the end of the hour (checked against the horizon mask: the",
         "direct beam correlates 0.88 with the sun above the mask for hour-ending UTC, 0.42 for hour-ending CET)",
         "heights: the files do not state the sensor heights above the snow; taken as 2 m for wind and air"],
        (2.0, 2.0))


if __name__ == "__main__":
    sys.exit(main())
