#!/usr/bin/python3
"""SciPy peer for bench/fit_bench.cpp: the same weighted cauchy3 fit with
scipy.optimize.least_squares, timed over many repetitions.

Usage: /usr/bin/python3 fit_peer_scipy.py DATA.csv [MIN_SECONDS]
DATA.csv: wavelength_nm,n,sigma (as written by fit_bench). Prints one JSON line:
{"fits_per_s": F, "fits": K, "coeffs": [A, B, C], "sigma": [sA, sB, sC], "scipy": "1.10.1"}

Each fit does what eikon's does: residuals r = (n_model - n)/sigma with an analytic Jacobian,
Levenberg-Marquardt (method='lm', MINPACK), tolerances 1e-12, then the 1-sigma errors from
(J^T J)^-1. Start: A = mean(n), B = C = 0 (eikon starts from its own linear solve, which is
counted in eikon's time).
"""
import json
import sys
import time

import numpy as np
import scipy
from scipy.optimize import least_squares


def fit(lam_um, n, sigma):
    inv2 = 1.0 / lam_um**2
    basis = np.stack([np.ones_like(inv2), inv2, inv2**2], axis=1) / sigma[:, None]
    target = n / sigma

    def fun(p):
        return basis @ p - target

    def jac(p):
        return basis

    x0 = np.array([np.mean(n), 0.0, 0.0])
    res = least_squares(fun, x0, jac=jac, method="lm", ftol=1e-12, xtol=1e-12, gtol=1e-12)
    cov = np.linalg.inv(res.jac.T @ res.jac)
    return res.x, np.sqrt(np.diag(cov))


def main():
    path = sys.argv[1]
    min_seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    lam_um, n, sigma = data[:, 0] * 1e-3, data[:, 1], data[:, 2]
    coeffs, sig = fit(lam_um, n, sigma)  # warm-up
    fits = 0
    t0 = time.perf_counter()
    while True:
        coeffs, sig = fit(lam_um, n, sigma)
        fits += 1
        elapsed = time.perf_counter() - t0
        if elapsed >= min_seconds and fits >= 20:
            break
    print(json.dumps({"fits_per_s": fits / elapsed, "fits": fits, "coeffs": coeffs.tolist(),
                      "sigma": sig.tolist(), "scipy": scipy.__version__}))


if __name__ == "__main__":
    main()
