#!/usr/bin/env python3
"""channel_column_model.py: the poiseuille2D and couette2D tutorials with
`wall wallWeight;` reduced to one column of particle rows, to separate the
errors of the channels' observed order (docs/topics/walls-and-obstacles.md,
"Why the channels' order falls").

The flow is parallel (u_x(y, t) only), so each row of particles moves as one
and the MPS step reduces to the rows' velocities:
  u_i += dt (nu Lap_i u + F)                      (eqs. 9-10, explicit viscosity)
  Lap_i u = 2d/(lambda n0) sum_j w_ij (u_j - u_i) (eq. 7, re = 3.1 l0, lambda and
                                                   n0 of the ideal lattice)
over the other rows' particles (a periodic row of spacing l0 at its own x
offset) and the wall's virtual points: the lattice continued behind each
face, aligned with the particle along it, carrying Morris, Fox & Zhu's
(1997) no-slip velocity u_v = u_w - (s_v/d)(u_i - u_w) (mf_wall_terms.h).
Options:
  --slide      the rows move along x with their own speed (X_i += dt u_i),
               as the solver's particles do; without it every row stays on
               the initial lattice (the offsets of all rows 0)
  --wall-gradient
               Poiseuille: the wall's share of the pressure gradient on the
               pressure continued along the body force, -(d/n0) t_xx F at
               the rows within the gradient's reach (re 2.1 l0;
               mf_wall_gradient_add with a = f)
  --maxdi X    dt = X l0^2 / nu (capped at 0.01 s, as the tutorials'
               maxDeltaT), fixed; 0.1 by default (the tutorials' maxDi)
  --scale S    F and U times S: the error relative to the speed does not
               change with the rows aligned (the problem is linear), the
               rows' strain t du/dy does
Prints the relative RMS error of u at t = 1 s against the series solutions
(Morris et al. 1997, eqs. 21-22; metric poiseuille/couette) for each
number of rows across the gap and the observed order between them.
  bench/channel_column_model.py couette 10 20 40 --slide
Pure Python (no NumPy); 40 rows take about a minute on one core."""
import argparse
import math

L, NU, F, U = 0.1, 1e-3, 0.008, 0.01  # the tutorials' gap, nu, body force, lid speed
RE_LAP, RE_GRAD = 3.1, 2.1


def weight(r, re):
    return re / r - 1.0 if 0 < r < re else 0.0


def lattice_kernel(re):
    """n0 and lambda of the ideal 2-D lattice (eqs. 3, 8), lengths in l0."""
    m = int(math.ceil(re))
    n0 = r2w = 0.0
    for ix in range(-m, m + 1):
        for iy in range(-m, m + 1):
            r = math.hypot(ix, iy)
            n0 += weight(r, re)
            r2w += r * r * weight(r, re)
    return n0, r2w / n0


def row_weight(dx, m, re):
    """sum of w over a periodic row of spacing 1 at x offset dx, y offset m."""
    return sum(weight(math.hypot(ix + dx, m), re) for ix in range(-6, 7))


def wall_txx(k, re):
    """t_xx = sum v_x^2/|v|^2 w over the virtual points of a face for a
    particle at (k + 1/2) l0 from it (rows at -(j + 1/2) l0 behind it)."""
    s = 0.0
    for j in range(0, 7):
        vy = -(j + 1 + k)
        for ix in range(-6, 7):
            r = math.hypot(ix, vy)
            if 0 < r < re:
                s += ix * ix / (r * r) * weight(r, re)
    return s


def poiseuille_u(y, t):  # eq. 21
    u = F / (2 * NU) * y * (L - y)
    for n in range(60):
        k = 2 * n + 1
        u -= (4 * F * L * L / (NU * math.pi ** 3 * k ** 3) * math.sin(math.pi * y * k / L) *
              math.exp(-k * k * math.pi ** 2 * NU * t / L ** 2))
    return u


def couette_u(y, t):  # eq. 22
    u = U * y / L
    for n in range(1, 400):
        u += (2 * U * (-1) ** n / (n * math.pi) * math.sin(n * math.pi * y / L) *
              math.exp(-n * n * math.pi ** 2 * NU * t / L ** 2))
    return u


def run(case, rows, slide, wall_gradient, maxdi, scale=1.0, t_end=1.0):
    global F, U
    F, U = 0.008 * scale, 0.01 * scale
    h = L / rows
    n0, lam = lattice_kernel(RE_LAP)
    n0_grad, _ = lattice_kernel(RE_GRAD)
    lap = 2 * 2 / (lam * n0)
    aligned = {m: row_weight(0.0, m, RE_LAP) for m in range(-3, 4)}
    txx = [wall_txx(k, RE_GRAD) for k in range(3)]
    y = [(i + 0.5) * h for i in range(rows)]
    u, x = [0.0] * rows, [0.0] * rows
    lid = U if case == "couette" else 0.0
    force = F if case == "poiseuille" else 0.0
    steps = int(round(t_end / min(maxdi * h * h / NU, 0.01)))
    dt = t_end / steps
    for _ in range(steps):
        acc = [0.0] * rows
        for i in range(rows):
            s = 0.0
            for m in range(-3, 4):
                j = i + m
                if m == 0:
                    continue
                if 0 <= j < rows:
                    w = row_weight(((x[j] - x[i]) / h) % 1.0, m, RE_LAP) if slide else aligned[m]
                    s += w * (u[j] - u[i])
                else:  # a virtual row behind a face: Morris's no-slip velocity
                    uw, d, sv = (0.0, y[i], -(j + 0.5) * h) if j < 0 else \
                                (lid, L - y[i], (j + 0.5) * h - L)
                    s += aligned[m] * (uw - sv / d * (u[i] - uw) - u[i])
            acc[i] = NU / (h * h) * lap * s + force
            k = min(i, rows - 1 - i)
            if wall_gradient and case == "poiseuille" and k < len(txx):
                acc[i] -= 2 / n0_grad * txx[k] * F
        u = [u[i] + dt * acc[i] for i in range(rows)]
        x = [x[i] + dt * u[i] for i in range(rows)]
    exact = poiseuille_u if case == "poiseuille" else couette_u
    scale = poiseuille_u(L / 2, t_end) if case == "poiseuille" else U
    return math.sqrt(sum(((u[i] - exact(y[i], t_end)) / scale) ** 2 for i in range(rows)) / rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case", choices=["poiseuille", "couette"])
    ap.add_argument("rows", type=int, nargs="+", help="rows across the gap (H/l0)")
    ap.add_argument("--slide", action="store_true")
    ap.add_argument("--wall-gradient", action="store_true")
    ap.add_argument("--maxdi", type=float, default=0.1)
    ap.add_argument("--scale", type=float, default=1.0)
    a = ap.parse_args()
    prev = None
    for n in a.rows:
        e = run(a.case, n, a.slide, a.wall_gradient, a.maxdi, a.scale)
        order = "" if prev is None else " order %.2f" % (math.log(prev[1] / e) / math.log(n / prev[0]))
        print("%s H/%d slide %s wall-gradient %s maxDi %g scale %g: error %.4g%s" %
              (a.case, n, a.slide, a.wall_gradient, a.maxdi, a.scale, e, order), flush=True)
        prev = (n, e)


if __name__ == "__main__":
    main()
