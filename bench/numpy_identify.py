"""The paper's algebraic identifier in numpy/pandas: the baseline `rotorid identify` is
compared against (bench/identify_vs_numpy.sh).

What a Python user would write: pandas.read_csv of the response CSV, then the identifier
vectorised over the whole record (docs/method.md section 3): the ten signals (y, tau y,
tau^2 y, u, v for y = x, z), their iterated integrals I1..I4 by the cumulative trapezoid
rule, the 3x3 systems A theta = b of every sample assembled as arrays and solved in one
batched numpy.linalg.solve, and every N-th estimate written as CSV, like
`rotorid identify --quadrature trapezoid --every N`.

    python bench/numpy_identify.py RESPONSE.csv OUT.csv --every 1000 \
        [--a 0.0 --mud 4.9e-5 --alpha 0.0]

The unbalance and gyroscopic coefficient default to the paper's table1 (docs/method.md
section 1); the time grid is t_k = t_0 + k dt with dt from the first two stamps.
"""

import argparse

import numpy as np
import pandas as pd


def cumtrapz(f, dt):
    """The running integral from the first sample, trapezoid rule (I[0] = 0)."""
    out = np.empty_like(f)
    out[0] = 0.0
    np.cumsum((f[1:] + f[:-1]) * (0.5 * dt), out=out[1:])
    return out


def identify(t, x, z, phi, w, wd, a, mud, alpha):
    """m, c, k of both directions at every sample (NaN at the first)."""
    dt = t[1] - t[0]
    tau = np.arange(len(t)) * dt
    t2 = tau * tau
    sn, cs = np.sin(phi + alpha), np.cos(phi + alpha)
    fx = w * w * sn - wd * cs
    fz = wd * sn + w * w * cs
    out = {}
    for name, y, u, v in (
        ("x", x, a * t2 * w * z, -2.0 * a * tau * w * z + mud * t2 * fx),
        ("z", z, -a * t2 * w * x, 2.0 * a * tau * w * x + a * t2 * wd * x + mud * t2 * fz),
    ):
        # I_k of each signal, k = 0..4 (I_0 = the signal itself)
        def levels(s):
            lv = [s]
            for _ in range(4):
                lv.append(cumtrapz(lv[-1], dt))
            return lv

        y0, ty, t2y, uu, vv = levels(y), levels(tau * y), levels(t2 * y), levels(u), levels(v)
        n = len(t)
        A = np.empty((n, 3, 3))
        b = np.empty((n, 3))
        for i in range(3):
            # row i is I_i of (P, Q, R), P = tau^2 y - 4 I1[tau y] + 2 I2[y], ...
            A[:, i, 0] = t2y[i] - 4.0 * ty[i + 1] + 2.0 * y0[i + 2]
            A[:, i, 1] = t2y[i + 1] - 2.0 * ty[i + 2]
            A[:, i, 2] = t2y[i + 2]
            b[:, i] = uu[i + 1] + vv[i + 2]
        theta = np.full((n, 3), np.nan)
        ok = np.abs(np.linalg.det(A[1:])) > 0.0
        theta[1:][ok] = np.linalg.solve(A[1:][ok], b[1:][ok][..., None])[..., 0]
        out[name] = theta
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--every", type=int, default=1)
    p.add_argument("--a", type=float, default=2.871, help="N s^2/m (table1)")
    p.add_argument("--mud", type=float, default=1.5e-5, help="m_u d, kg m (table1)")
    p.add_argument("--alpha", type=float, default=np.pi / 4, help="rad (table1)")
    args = p.parse_args()
    df = pd.read_csv(args.input)
    t = df["t"].to_numpy()
    r = identify(
        t,
        df["x"].to_numpy(),
        df["z"].to_numpy(),
        df["phi"].to_numpy(),
        df["phi_dot"].to_numpy(),
        df["phi_ddot"].to_numpy(),
        args.a,
        args.mud,
        args.alpha,
    )
    keep = slice(0, len(t), args.every)
    est = pd.DataFrame(
        {
            "t": t[keep],
            "m_x": r["x"][keep, 0],
            "c_x": r["x"][keep, 1],
            "k_x": r["x"][keep, 2],
            "m_z": r["z"][keep, 0],
            "c_z": r["z"][keep, 1],
            "k_z": r["z"][keep, 2],
        }
    )
    est.to_csv(args.output, index=False, float_format="%.17g")


if __name__ == "__main__":
    main()
