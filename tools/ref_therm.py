#!/usr/bin/env python3
"""Fine-grid numerical reference for irsig's THERM-style slab solver.

Writes
  tests/data/therm_ref_forcing.csv  the forcing series (one row per 15 min)
  tests/data/therm_ref_cases.json   the materials / orientations / shadow histories
  tests/data/therm_ref_temps.csv    the reference surface temperature of each case

The Rust test (tests/therm_reference.rs) reads the forcing from the CSV, so it
does not depend on irsig's own weather/sun code.

Weather: pvlib's bundled TMY3 file 723170TYA.CSV (Greensboro NC), read with
pvlib.iotools.read_tmy3. We take 72 h (24 h spin-up + 48 h compared) starting at
local-standard-time midnight. Forcing scheme (simple and documented, shared by
both solvers through the CSV):
  * temperatures, dew point, wind, opaque cloud: instantaneous at the TMY3
    time stamp (hour end); irradiances (hourly totals for the preceding hour):
    placed at mid-hour (stamp - 30 min). Every quantity is then linearly
    interpolated onto a 15-min grid.
  * sun vector: pvlib SPA (get_solarposition, apparent zenith) at each 15-min
    sample; ENU = (sin z sin A, sin z cos A, cos z). DNI = 0 when the apparent
    zenith is >= 90 deg.
  * sky temperature: Berdahl & Martin (1984) clear-sky emissivity
    eps_clr = 0.711 + 0.56 (Td/100) + 0.73 (Td/100)^2 (Td dew point in C),
    with the Walton (1983) cloud factor (1 + 0.0224 N - 0.0035 N^2 + 0.00028 N^3),
    N = opaque cloud cover in tenths (as in EnergyPlus); T_sky = eps^0.25 T_air.

Physics (docs/models.md "Thermal model", the same continuous problem as irsig):
  rho c dT/dt = d/dz (k dT/dz), surface balance
  q_s = a [I DNI max(0, n.s) + DHI F_sky + rho_g GHI F_gnd]
      + e [F_sky sig T_sky^4 + F_gnd sig T_air^4] - e sig T_s^4
      + h_c (T_air - T_s) + q_int,   h_c = max(5.7 + 3.8 v, 1.31 |dT|^(1/3))
  back: insulated | exposed to air (A_f [h_c (T_air - T_b) + e sig (T_air^4 - T_b^4)])
        | deep ground (fixed temperature; mean forcing air temperature if unset).
  Between forcing samples every field is linear in time; the sun vector is
  interpolated linearly and renormalised. Sun/shadow flag: nearest sample
  of the history (sample i covers [t_i - dt/2, t_i + dt/2)), periodic before
  the first sample, held after the last. Initial state: steady state under
  the first forcing sample.

Numerics of the reference (independent of irsig's): method of lines on a
500-node finite-volume mesh graded geometrically from the surface (ratio
1.01, half cells at both faces), integrated with scipy solve_ivp Radau
(rtol 1e-10, atol 1e-8 K, analytic sparse Jacobian), restarted at every
forcing sample and shadow switch. The script also runs 250 nodes and
prints the difference as an estimate of the reference's own error.

Usage: tools/.venv/bin/python tools/ref_therm.py   (venv: numpy scipy pvlib)
"""

import json
import os
import sys

import numpy as np
import pandas as pd
import pvlib
import scipy
from scipy.integrate import solve_ivp
from scipy.sparse import diags
from scipy.sparse.linalg import spsolve

SIGMA = 5.670374419e-8
STEP_S = 900.0
HOURS = 72
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data")

CASES = [
    {
        "name": "concrete_wall",
        "material": {
            "density_kg_m3": 2300.0, "specific_heat_j_kgk": 880.0, "conductivity_w_mk": 1.4,
            "thickness_m": 0.2, "solar_absorptivity": 0.65, "thermal_emissivity": 0.92,
            "back": "insulated", "internal_power_w_m2": 15.0, "ground_albedo": 0.25,
        },
        "slope_deg": 90.0, "aspect_deg": 180.0,
        # shaded 13:00-15:00 local standard time (history over the last 24 h)
        "shade_hours": [13.0, 15.0],
    },
    {
        "name": "asphalt",
        "material": {
            "density_kg_m3": 2100.0, "specific_heat_j_kgk": 920.0, "conductivity_w_mk": 0.75,
            "thickness_m": 0.3, "solar_absorptivity": 0.9, "thermal_emissivity": 0.93,
            "back": {"deep_ground": {"temp_c": 16.85}},
        },
        "slope_deg": 0.0, "aspect_deg": 0.0,
    },
    {
        "name": "soil",
        "material": {
            "density_kg_m3": 1600.0, "specific_heat_j_kgk": 1300.0, "conductivity_w_mk": 1.0,
            "thickness_m": 1.0, "solar_absorptivity": 0.78, "thermal_emissivity": 0.97,
            "back": {"deep_ground": {}},
        },
        "slope_deg": 0.0, "aspect_deg": 0.0,
    },
    {
        "name": "aluminium_skin",
        "material": {
            "density_kg_m3": 2700.0, "specific_heat_j_kgk": 900.0, "conductivity_w_mk": 200.0,
            "thickness_m": 0.0005, "solar_absorptivity": 0.5, "thermal_emissivity": 0.85,
            "back": {"air": {"exposed_area": 1.0}},
        },
        "slope_deg": 30.0, "aspect_deg": 200.0,
    },
]


def load_weather():
    path = os.path.join(os.path.dirname(pvlib.__file__), "data", "723170TYA.CSV")
    df, meta = pvlib.iotools.read_tmy3(path, map_variables=True, coerce_year=2021)
    return df, meta


def pick_start(df):
    """Local midnight (LST) starting the 72 h window with the most DNI in
    May-September: sunny days give the sharpest transients."""
    dni = df["dni"].to_numpy()
    best, best_i = -1.0, None
    for i in range(0, len(df) - HOURS - 2, 24):
        ts = df.index[i]
        if ts.month < 5 or ts.month > 9 or ts.hour != 1:
            continue
        s = dni[i:i + HOURS].sum()
        if s > best:
            best, best_i = s, i
    # row i is the hour ending 01:00, so the window starts at 00:00 of that day
    return df.index[best_i] - pd.Timedelta(hours=1)


def build_forcing(df, meta, start):
    n = HOURS * 3600 // int(STEP_S) + 1
    t_s = np.arange(n) * STEP_S
    grid = start + pd.to_timedelta(t_s, unit="s")
    t_grid = (grid - start).total_seconds().to_numpy()
    sel = df[(df.index >= start - pd.Timedelta(hours=3)) & (df.index <= grid[-1] + pd.Timedelta(hours=3))]
    t_inst = (sel.index - start).total_seconds().to_numpy()
    t_mid = t_inst - 1800.0

    def lin(t_src, col):
        return np.interp(t_grid, t_src, sel[col].to_numpy(dtype=float))

    air_k = lin(t_inst, "temp_air") + 273.15
    dew_c = lin(t_inst, "temp_dew")
    wind = lin(t_inst, "wind_speed")
    opq = lin(t_inst, "OpqCld (tenths)")
    ghi, dni, dhi = lin(t_mid, "ghi"), lin(t_mid, "dni"), lin(t_mid, "dhi")
    sp = pvlib.solarposition.get_solarposition(
        grid, meta["latitude"], meta["longitude"], altitude=meta["altitude"], method="nrel_numpy")
    zen = np.radians(sp["apparent_zenith"].to_numpy())
    az = np.radians(sp["azimuth"].to_numpy())
    sun = np.stack([np.sin(zen) * np.sin(az), np.sin(zen) * np.cos(az), np.cos(zen)], axis=1)
    dni = np.where(sun[:, 2] > 0.0, dni, 0.0)
    td = dew_c / 100.0
    eps_clear = 0.711 + 0.56 * td + 0.73 * td * td
    eps = np.clip(eps_clear * (1 + 0.0224 * opq - 0.0035 * opq**2 + 0.00028 * opq**3), 0.0, 1.0)
    sky_k = eps ** 0.25 * air_k
    return {
        "t_s": t_s, "air_temp_k": air_k, "sky_temp_k": sky_k, "wind_speed_m_s": wind,
        "dni_w_m2": dni, "dhi_w_m2": dhi, "ghi_w_m2": ghi,
        "sun_e": sun[:, 0], "sun_n": sun[:, 1], "sun_u": sun[:, 2],
    }


def shadow_history(case, start, t_end):
    """48 samples every 30 min, the last at the final forcing time."""
    if "shade_hours" not in case:
        return None
    interval = 1800
    start_s = int(t_end) - 47 * interval
    h0, h1 = case["shade_hours"]
    bits = []
    for i in range(48):
        lst = start + pd.Timedelta(seconds=start_s + i * interval)
        hod = lst.hour + lst.minute / 60.0
        bits.append(not (h0 <= hod <= h1))
    return {"start_s": start_s, "interval_s": interval, "sunlit": bits}


def flag_at(hist, t):
    if hist is None:
        return True
    n = len(hist["sunlit"])
    i = int(np.floor((t - hist["start_s"]) / hist["interval_s"] + 0.5))
    i = n - 1 if i >= n else i % n
    return hist["sunlit"][i]


class Forcing:
    def __init__(self, f):
        self.f = f
        self.t = f["t_s"]

    def at(self, t):
        t0, t1 = self.t[0], self.t[-1]
        t = min(max(t, t0), t1)
        j = min(int(np.searchsorted(self.t, t, side="right")) - 1, len(self.t) - 2)
        w = (t - self.t[j]) / (self.t[j + 1] - self.t[j])
        v = {k: a[j] + w * (a[j + 1] - a[j]) for k, a in self.f.items()}
        s = np.array([v["sun_e"], v["sun_n"], v["sun_u"]])
        ln = np.linalg.norm(s)
        v["sun"] = s / ln if ln > 1e-12 else s
        return v


def hconv(v, dt):
    forced = 5.7 + 3.8 * max(v, 0.0)
    free = 1.31 * abs(dt) ** (1.0 / 3.0)
    return (forced, 0.0) if forced >= free else (free, 1.0)


class Slab:
    def __init__(self, case, nodes, ratio, forcing):
        m = case["material"]
        self.m = m
        L = m["thickness_m"]
        cells = nodes - 1
        d = ratio ** np.arange(cells)
        d *= L / d.sum()
        rc = m["density_kg_m3"] * m["specific_heat_j_kgk"]
        self.cap = np.zeros(nodes)
        self.cap[:-1] += 0.5 * rc * d
        self.cap[1:] += 0.5 * rc * d
        self.g = m["conductivity_w_mk"] / d
        b = np.radians(case["slope_deg"])
        a = np.radians(case["aspect_deg"])
        self.n = np.array([np.sin(b) * np.sin(a), np.sin(b) * np.cos(a), np.cos(b)])
        self.fsky = (1 + np.cos(b)) / 2
        self.fgnd = 1 - self.fsky
        back = m["back"]
        self.back = back
        self.deep = None
        if isinstance(back, dict) and "deep_ground" in back:
            t = back["deep_ground"].get("temp_c")
            self.deep = t + 273.15 if t is not None else float(np.mean(forcing.f["air_temp_k"]))
        self.N = nodes

    def surface(self, T, v, sunlit):
        m = self.m
        al, e = m["solar_absorptivity"], m["thermal_emissivity"]
        rg = m.get("ground_albedo", 0.2)
        cosi = max(0.0, float(self.n @ v["sun"]))
        sw = al * ((1.0 if sunlit else 0.0) * v["dni_w_m2"] * cosi + v["dhi_w_m2"] * self.fsky
                   + rg * v["ghi_w_m2"] * self.fgnd)
        lw = e * SIGMA * (self.fsky * v["sky_temp_k"] ** 4 + self.fgnd * v["air_temp_k"] ** 4)
        dT = v["air_temp_k"] - T
        h, free = hconv(v["wind_speed_m_s"], dT)
        conv = h * dT
        dconv = -(4.0 / 3.0) * h if free else -h
        q = sw + lw - e * SIGMA * T ** 4 + conv + m.get("internal_power_w_m2", 0.0)
        return q, dconv - 4 * e * SIGMA * T ** 3

    def backflux(self, T, v):
        if isinstance(self.back, dict) and "air" in self.back:
            af = self.back["air"]["exposed_area"]
            e = self.m["thermal_emissivity"]
            dT = v["air_temp_k"] - T
            h, free = hconv(v["wind_speed_m_s"], dT)
            dconv = -(4.0 / 3.0) * h if free else -h
            q = af * (h * dT + e * SIGMA * (v["air_temp_k"] ** 4 - T ** 4))
            return q, af * (dconv - 4 * e * SIGMA * T ** 3)
        return 0.0, 0.0

    def rhs_jac(self, T, v, sunlit, want_jac):
        """dE/dt per node (W/m^2) and its Jacobian (for the free nodes)."""
        g = self.g
        flow = np.zeros_like(T)
        cond = g * (T[1:] - T[:-1])
        flow[:-1] += cond
        flow[1:] -= cond
        qs, dqs = self.surface(T[0], v, sunlit)
        flow[0] += qs
        qb, dqb = self.backflux(T[-1], v)
        flow[-1] += qb
        if not want_jac:
            return flow, None
        main = np.zeros_like(T)
        main[:-1] -= g
        main[1:] -= g
        main[0] += dqs
        main[-1] += dqb
        J = diags([g, main, g], [-1, 0, 1], format="csc")
        return flow, J

    def free(self):
        return self.N - 1 if self.deep is not None else self.N

    def full(self, y):
        return np.append(y, self.deep) if self.deep is not None else y

    def equilibrium(self, v, sunlit):
        T = np.full(self.N, v["air_temp_k"])
        if self.deep is not None:
            T[-1] = self.deep
        nf = self.free()
        for _ in range(100):
            flow, J = self.rhs_jac(T, v, sunlit, True)
            J = J[:nf, :nf]
            dx = spsolve(J.tocsc(), -flow[:nf])
            T[:nf] += dx
            if np.max(np.abs(dx)) < 1e-11:
                return T
        raise RuntimeError("equilibrium did not converge")

    def run(self, forcing, hist):
        t = forcing.t
        bps = set(t.tolist())
        if hist is not None:
            n = len(hist["sunlit"])
            d = hist["interval_s"]
            for k in range(-2 * n, n + 2):
                tb = hist["start_s"] + (k + 0.5) * d
                if t[0] < tb < t[-1] and flag_at(hist, tb - 0.25 * d) != flag_at(hist, tb + 0.25 * d):
                    bps.add(tb)
        bps = sorted(bps)
        T = self.equilibrium(forcing.at(t[0]), flag_at(hist, t[0]))
        nf = self.free()
        capf = self.cap[:nf]
        out = {t[0]: T[0]}
        for a, b in zip(bps[:-1], bps[1:]):
            sunlit = flag_at(hist, 0.5 * (a + b))

            def fun(tt, y):
                flow, _ = self.rhs_jac(self.full(y), forcing.at(tt), sunlit, False)
                return flow[:nf] / capf

            def jac(tt, y):
                _, J = self.rhs_jac(self.full(y), forcing.at(tt), sunlit, True)
                return diags(1.0 / capf) @ J[:nf, :nf]

            sol = solve_ivp(fun, (a, b), T[:nf], method="Radau", jac=jac, rtol=1e-10, atol=1e-8)
            if not sol.success:
                raise RuntimeError(sol.message)
            T[:nf] = sol.y[:, -1]
            out[b] = T[0]
        return np.array([out[x] for x in t])


def main():
    df, meta = load_weather()
    start = pick_start(df)
    f = build_forcing(df, meta, start)
    forcing = Forcing(f)
    t_end = f["t_s"][-1]
    os.makedirs(OUT, exist_ok=True)
    cols = ["t_s", "air_temp_k", "sky_temp_k", "wind_speed_m_s", "dni_w_m2", "dhi_w_m2", "ghi_w_m2",
            "sun_e", "sun_n", "sun_u"]
    with open(os.path.join(OUT, "therm_ref_forcing.csv"), "w") as fh:
        fh.write(f"# tools/ref_therm.py: TMY3 723170TYA (Greensboro NC) from pvlib {pvlib.__version__}, "
                 f"window starts {start.isoformat()} (LST), t_s = seconds since then\n")
        fh.write(",".join(cols) + "\n")
        for i in range(len(f["t_s"])):
            fh.write(",".join(repr(float(f[c][i])) for c in cols) + "\n")
    cases_out = []
    temps = {}
    for case in CASES:
        hist = shadow_history(case, start, t_end)
        ref = Slab(case, 500, 1.01, forcing).run(forcing, hist)
        coarse = Slab(case, 250, 1.02, forcing).run(forcing, hist)
        print(f"{case['name']}: T range {ref.min():.2f}..{ref.max():.2f} K, "
              f"|500-node - 250-node| max {np.max(np.abs(ref - coarse)):.2e} K", flush=True)
        temps[case["name"]] = ref
        cases_out.append({
            "name": case["name"], "material": case["material"],
            "orientation": {"slope_deg": case["slope_deg"], "aspect_deg": case["aspect_deg"]},
            "shadow": hist,
        })
    with open(os.path.join(OUT, "therm_ref_cases.json"), "w") as fh:
        json.dump({
            "generator": "tools/ref_therm.py",
            "versions": {"pvlib": pvlib.__version__, "scipy": scipy.__version__, "numpy": np.__version__},
            "compare_from_s": 24 * 3600.0,
            "cases": cases_out,
        }, fh, indent=1)
    with open(os.path.join(OUT, "therm_ref_temps.csv"), "w") as fh:
        names = [c["name"] for c in CASES]
        fh.write("t_s," + ",".join(names) + "\n")
        for i, tt in enumerate(f["t_s"]):
            fh.write(repr(float(tt)) + "," + ",".join(f"{temps[n][i]:.6f}" for n in names) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
