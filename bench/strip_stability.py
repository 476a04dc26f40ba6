#!/usr/bin/env python3
"""bench/strip_stability.py SNAPSHOT.h5 [WEIGHT [RE [M ...]]]: the linear
stability of the periodic resting layer's rows under eq. 5's pair repulsion,
with its floor and its free surface (docs/notes/mps.md, "kernel").

The layer of bench/periodic_layer.sh is a strip: fluid rows r = 0..N-1 at
the rows' mean heights y_r and mean pressures p_r of SNAPSHOT (a layer still
at rest, e.g. its first snapshot; the top row is the Dirichlet surface, p =
0, 0.71 l0 above the next in the square layer), columns x_c = (c + 1/2) l0,
on one wall row (y = -l0/2, its pressure from the snapshot; the dummies do
not enter eq. 5). Eq. 5 with p^_i the minimum over i and its fluid and wall
neighbours within re,

    a_i = -(d / (rho n0_g)) sum_j (p_j - p^_i) w_g(r) R / r^2,  R = x_j - x_i,

linearised with every pressure frozen (carried with its particle: the PPE's
answer to the motion is left out) and the walls fixed. A Bloch wave u_(r,c)
= U_r exp(i k x_c), k = 2 pi M / WIDTH, gives U'' = A(k) U, A a 2N x 2N
matrix (J = d(w R / r^2)/dR as in bench/lattice_stability.py). The growth
rate is measured by integrating U'' = A U (leapfrog, dt 2e-4 s, 3 s, from a
fixed pseudo-random start): the fastest growing motion takes over; its rate
is the slope of log |U| over the last second, its shape |u|, |v| by row.

Weights and n0_g as core/particles/mf_kernel.h: paper, wendland, wendlandW.
M: wavenumbers along x (of WIDTH/l0 = 40 columns; 20 = alternate columns);
default 4 8 12 16 20. Env FIXTOP=1 holds the surface row still (fixed like
a wall, its pressure 0 kept), leaving the bulk's own growth. Needs h5dump;
no numpy. Env L0: the spacing (default 0.01). Env SURF_PHAT=c: the surface row's p^
set to -c rho g l0 (docs/notes/mps.md, "surfrow")."""
import cmath
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lattice_stability import WEIGHTS  # noqa: E402
from layer_mode import dataset  # noqa: E402

L0 = float(os.environ.get("L0", "0.01"))  # the spacing (bench/periodic_layer.sh's L0)
WIDTH, RHO = 0.4, 1000.0
# Env SURF_PHAT=c: the surface row's p^_i set to -c rho g l0 (its own row's
# pairs then push with P = c rho g l0: the "surfrow" section's treatment)
SURF_PHAT = float(os.environ.get("SURF_PHAT", "0"))


def rows_of(path):
    """(y, p) of each fluid row (means over the row) and of the wall row."""
    out = []
    for part in ("PartType0", "PartType1"):
        xyz = dataset(path, f"/{part}/Coordinates")
        p = dataset(path, f"/{part}/Pressure")
        rows = {}
        for i in range(len(p)):
            rows.setdefault(int(round(xyz[3 * i + 1] / L0 - 0.5)), []).append((xyz[3 * i + 1], p[i]))
        for r in sorted(rows):
            v = rows[r]
            out.append((sum(a for a, _ in v) / len(v), sum(b for _, b in v) / len(v), part == "PartType0"))
    out.sort()
    return out


def build(rows, wf, re, k):
    """A(k) as a sparse list: for each moving dof, [(dof, value)]; rho and d
    = 2 as the solver's."""
    m = int(math.ceil(re / L0)) + 1
    # n0_g on the full square lattice (mf_kernel_set_gradient_weight)
    n0g = sum(wf(L0 * math.hypot(ix, iy), re) for ix in range(-m, m + 1) for iy in range(-m, m + 1))
    coef = 2.0 / (RHO * n0g)
    fluid = [i for i, r in enumerate(rows) if r[2]]
    fluid_all = list(fluid)
    if os.environ.get("FIXTOP"):  # the surface row held still: the bulk's own growth
        fluid = fluid[:-1]
    dof = {row: n for n, row in enumerate(fluid)}
    a = [dict() for _ in range(2 * len(fluid))]
    for ri in fluid:
        yi, pi, _ = rows[ri]
        nbrs = []
        for rj, (yj, pj, _) in enumerate(rows):
            for c in range(-m, m + 1):
                x, y = c * L0, yj - yi
                r = math.hypot(x, y)
                if 0.0 < r < re:
                    nbrs.append((rj, x, y, r, pj))
        phat = min([pi] + [n[4] for n in nbrs])
        if ri == fluid_all[-1] and SURF_PHAT:  # the surface row's p^ below zero ("surfrow")
            phat = -SURF_PHAT * RHO * 9.81 * L0
        ni = dof[ri]
        for rj, x, y, r, pj in nbrs:
            eps = 1e-6 * r
            h = wf(r, re) / (r * r)
            hp = (wf(r + eps, re) / (r + eps) ** 2 - wf(r - eps, re) / (r - eps) ** 2) / (2 * eps)
            cc = hp / r
            jm = ((h + cc * x * x, cc * x * y), (cc * x * y, h + cc * y * y))
            f = -coef * (pj - phat)
            ph = cmath.exp(1j * k * x)
            for p in range(2):
                for q in range(2):
                    # + f J u_j (a moving neighbour) - f J u_i
                    if rj in dof:
                        key = 2 * dof[rj] + q
                        a[2 * ni + p][key] = a[2 * ni + p].get(key, 0) + f * jm[p][q] * ph
                    key = 2 * ni + q
                    a[2 * ni + p][key] = a[2 * ni + p].get(key, 0) - f * jm[p][q]
    return [list(d.items()) for d in a], fluid


def grow(a, dt=2e-4, t_end=3.0):
    n = len(a)
    seed = 12345
    u = []
    for _ in range(n):
        seed = (1103515245 * seed + 12345) % 2 ** 31
        u.append(complex(seed / 2 ** 31 - 0.5, 0.0))
    um = list(u)
    steps = int(round(t_end / dt))
    log_norm, shift = [], 0.0
    for s in range(steps):
        acc = [sum(v * u[j] for j, v in row) for row in a]
        un = [2 * u[i] - um[i] + dt * dt * acc[i] for i in range(n)]
        um, u = u, un
        norm = math.sqrt(sum(abs(z) ** 2 for z in u))
        if norm > 1e100 or norm < 1e-100:  # keep the numbers finite
            u = [z / norm for z in u]
            um = [z / norm for z in um]
            shift += math.log(norm)
            norm = 1.0
        log_norm.append(shift + math.log(norm))
    k1 = int(round((t_end - 1.0) / dt))
    return (log_norm[-1] - log_norm[k1 - 1]) / 1.0, u


def main():
    path = sys.argv[1]
    names = [sys.argv[2]] if len(sys.argv) > 2 else list(WEIGHTS)
    re = float(sys.argv[3]) * L0 if len(sys.argv) > 3 else 2.1 * L0
    ms = [int(x) for x in sys.argv[4:]] or [4, 8, 12, 16, 20]
    rows = rows_of(path)
    print(f"# {path}: {sum(1 for r in rows if r[2])} fluid rows, top rows y/l0 " +
          ", ".join(f"{r[0] / L0:.2f} ({r[1]:.0f} Pa)" for r in rows[-3:]) +
          f"; wall row p {rows[0][1]:.0f} Pa; re {re / L0:.2f} l0")
    for name in names:
        wf = WEIGHTS[name]
        for m in ms:
            a, fluid = build(rows, wf, re, 2 * math.pi * m / WIDTH)
            rate, u = grow(a)
            amp = [(abs(u[2 * i]), abs(u[2 * i + 1])) for i in range(len(fluid))]
            top = max(max(p) for p in amp)
            prof = " ".join(f"{max(p) / top:.2f}{'u' if p[0] > p[1] else 'v'}" for p in amp[::2])
            print(f"{name:9s} M {m:2d}: growth {rate:7.2f} /s; |U| by row (every 2nd, floor first; "
                  f"u or v the larger): {prof} | top row {max(amp[-1]) / top:.2f}"
                  f"{'u' if amp[-1][0] > amp[-1][1] else 'v'}")


if __name__ == "__main__":
    main()
