#!/usr/bin/env python3
"""Reference Planck band integrals by adaptive quadrature (scipy.integrate.quad),
independent of irsig's closed-form series. Writes tests/data/planck_band_ref.csv.

Usage: tools/.venv/bin/python tools/ref_planck.py
"""
import numpy as np
from scipy import constants as sc
from scipy.integrate import quad

H, C, K = sc.h, sc.c, sc.k  # exact SI 2019 values


def planck_um(lam_um, t):
    lam = lam_um * 1e-6
    x = H * C / (lam * K * t)
    if x > 700:
        return 2 * H * C**2 / lam**5 * np.exp(-x) * 1e-6
    return 2 * H * C**2 / lam**5 / np.expm1(x) * 1e-6


BANDS = [(0.25, 0.5), (0.5, 1.0), (1.0, 3.0), (3.0, 5.0), (8.0, 14.0), (14.0, 28.0), (0.25, 28.0), (10.0, 10.5)]
TEMPS = [1.0, 20.0, 77.0, 200.0, 300.0, 1000.0, 3000.0, 6000.0]

rows = []
for lo, hi in BANDS:
    for t in TEMPS:
        # split the band finely so quad resolves the peak; relative accuracy ~1e-13
        edges = np.geomspace(lo, hi, 65)
        # rough total first, then an absolute tolerance 1e-15 of it so that
        # negligible tail pieces do not chase an unreachable relative tolerance
        rough = sum(quad(planck_um, a, b, args=(t,), limit=200)[0] for a, b in zip(edges[:-1], edges[1:]))
        tot = 0.0
        for a, b in zip(edges[:-1], edges[1:]):
            v, _ = quad(planck_um, a, b, args=(t,), epsabs=1e-15 * rough, epsrel=1e-13, limit=200)
            tot += v
        if tot < 1e-250:
            continue  # below what f64 can hold accurately
        rows.append(f"{lo},{hi},{t},{tot:.15e}")

with open("tests/data/planck_band_ref.csv", "w") as f:
    f.write("# int_lo^hi L_lambda(lambda, T) dlambda, W m-2 sr-1; scipy.integrate.quad, tools/ref_planck.py\n")
    f.write("lambda1_um,lambda2_um,temp_k,band_w_m2_sr\n")
    f.write("\n".join(rows) + "\n")
print(len(rows), "rows")
