#!/usr/bin/env python3
"""bench/lattice_stability.py [L0] [G]: the linear stability of an infinite
2-D particle lattice under eq. 5's pair repulsion, for each gradient weight.

A reading of issue 13's column mode (docs/notes/mps.md, "resting3" and
"kernel"), no solver involved. Eq. 5 with p^_i the neighbourhood minimum,

    a_i = -(1/rho) (d / n0_g) sum_j (p_j - p^_i) w_g(r) R / r^2,  R = x_j - x_i,

linearised about a lattice at rest with each particle's pressure frozen
(carried with the particle: the PPE's answer is left out; for the three
Brillouin-zone points below the number density and eq. 7's divergence do
not change to first order, so the PPE has nothing to answer there). With
h(r) = w_g / r^2 the pair term's Jacobian is J(R) = h I + (h'/r) R R^T and a
plane wave u_i = U exp(i k.x_i) gives s^2 U = A(k) U,

    A(k) = -(d / n0_g) sum_R P(R) J(R) (exp(i k.R) - 1),  P(R) = (p_j - p^_i)/rho,

growth rate Re sqrt(mu) for each eigenvalue mu of A. Two models of P:
  hydrostatic: p = rho g (depth), p^_i the highest neighbour's (the
               interior of the resting layer): P(R) = g (Ymax - R_y);
  uniform:     P(R) = g l0 (a constant pair pressure: the setting of
               Dehnen & Aly 2012, MNRAS 425, 1068, whose SPH pair force
               -P W'(r) is stable when W's Fourier transform is positive).
Weights as core/particles/mf_kernel.h: paper re/r - 1 (eq. 3), wendland
-r W'(r) = 20 q^2 (1 - q)^3, wendlandW W = (1 - q)^4 (1 + 4q), q = r/re,
each scaled by its own lattice sum n0_g. Lattices: square (spacing l0) and
hexagonal (the same area per particle, as the hex branch's start).

Prints, per lattice, weight and re: s (1/s) at k = (pi/a, 0), (0, pi/a)
and (pi/a, pi/a) of the square lattice for both polarisations (the column
mode is k = (pi/l0, 0) polarised along y), the largest growth over a k grid
of the zone (where the PPE would act: a bound, not a prediction), and the
largest growth of the square lattice's shear waves k = (kx, 0) polarised
along y (the PPE does not act on them either) with its kx.
"""
import cmath
import math
import sys

L0 = 0.01
G = 9.81


def w_paper(r, re):
    return re / r - 1.0 if 0.0 < r < re else 0.0


def w_wendland(r, re):
    if not 0.0 < r < re:
        return 0.0
    q = r / re
    return 20.0 * q * q * (1.0 - q) ** 3


def w_wendland_w(r, re):
    if not 0.0 < r < re:
        return 0.0
    q = r / re
    return (1.0 - q) ** 4 * (1.0 + 4.0 * q)


WEIGHTS = {"paper": w_paper, "wendland": w_wendland, "wendlandW": w_wendland_w}


def lattice(kind, l0, re):
    """Neighbour offsets R (R != 0, |R| < re) of the square or hexagonal
    lattice of area l0^2 a particle."""
    if kind == "square":
        a1, a2 = (l0, 0.0), (0.0, l0)
    else:
        s = math.sqrt(2.0 / math.sqrt(3.0))
        a1, a2 = (s * l0, 0.0), (0.5 * s * l0, 0.5 * math.sqrt(3.0) * s * l0)
    m = int(math.ceil(re / l0 * 1.2)) + 1
    out = []
    for i in range(-m, m + 1):
        for j in range(-m, m + 1):
            x, y = i * a1[0] + j * a2[0], i * a1[1] + j * a2[1]
            r = math.hypot(x, y)
            if 0.0 < r < re:
                out.append((x, y, r))
    return out, a1, a2


def jacobian(wf, x, y, r, re):
    """J = d(w R / r^2)/dR: h I + (h'/r) R R^T, h = w/r^2 (h' by central
    difference, the weights being smooth inside the support)."""
    eps = 1e-6 * r
    h = wf(r, re) / (r * r)
    hp = (wf(r + eps, re) / (r + eps) ** 2 - wf(r - eps, re) / (r - eps) ** 2) / (2 * eps)
    c = hp / r
    return ((h + c * x * x, c * x * y), (c * x * y, h + c * y * y))


def eig2(a):
    """Eigenvalues of a complex 2x2 matrix."""
    tr = a[0][0] + a[1][1]
    det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    disc = cmath.sqrt(tr * tr / 4 - det)
    return tr / 2 + disc, tr / 2 - disc


def amatrix(nb, wf, re, n0g, P, kx, ky, d=2):
    a = [[0j, 0j], [0j, 0j]]
    for x, y, r in nb:
        jm = jacobian(wf, x, y, r, re)
        ph = cmath.exp(1j * (kx * x + ky * y)) - 1.0
        f = -(d / n0g) * P(x, y) * ph
        for p in range(2):
            for q in range(2):
                a[p][q] += f * jm[p][q]
    return a


def growth(a):
    return max(cmath.sqrt(mu).real for mu in eig2(a))


def main():
    global L0, G
    if len(sys.argv) > 1:
        L0 = float(sys.argv[1])
    if len(sys.argv) > 2:
        G = float(sys.argv[2])
    print(f"# l0 {L0} m, g {G} m/s^2; s in 1/s (growth rate; 0 = stable or neutral)")
    print("# lattice  weight     re/l0  P model      n0_g    s(pi,0)x s(pi,0)y s(0,pi)x s(0,pi)y "
          "s(pi,pi) max-over-zone  shear-waves(ky=0,v)")
    for kind in ("square", "hexagonal"):
        for name, wf in WEIGHTS.items():
            for rel in (2.1, 2.5, 3.1, 4.0):
                re = rel * L0
                nb, a1, a2 = lattice(kind, L0, re)
                n0g = sum(wf(r, re) for _, _, r in nb)
                ymax = max([0.0] + [y for _, y, _ in nb])
                models = {"hydrostatic": lambda x, y, ym=ymax: G * (ym - y),
                          "uniform": lambda x, y: G * L0}
                for mname, P in models.items():
                    k = math.pi / L0
                    pts = []
                    for kx, ky in ((k, 0.0), (0.0, k), (k, k)):
                        a = amatrix(nb, wf, re, n0g, P, kx, ky)
                        # polarisation x and y: the diagonal terms (A is
                        # diagonal at these points on the square lattice)
                        pts.append((cmath.sqrt(a[0][0]).real, cmath.sqrt(a[1][1]).real,
                                    growth(a)))
                    # the zone: reciprocal basis b1, b2 of (a1, a2)
                    det = a1[0] * a2[1] - a1[1] * a2[0]
                    b1 = (2 * math.pi * a2[1] / det, -2 * math.pi * a2[0] / det)
                    b2 = (-2 * math.pi * a1[1] / det, 2 * math.pi * a1[0] / det)
                    n = 24
                    best = 0.0
                    for i in range(n + 1):
                        for j in range(n + 1):
                            u, v = i / n - 0.5, j / n - 0.5
                            kx, ky = u * b1[0] + v * b2[0], u * b1[1] + v * b2[1]
                            best = max(best, growth(amatrix(nb, wf, re, n0g, P, kx, ky)))
                    # shear waves k = (kx, 0) polarised along y: the number
                    # density and the divergence do not change (the pairs
                    # (x, y) and (x, -y) cancel), the PPE has nothing to answer
                    shear, kshear = 0.0, 0.0
                    if kind == "square":
                        for i in range(1, 21):
                            kx = math.pi * i / 20 / L0
                            a = amatrix(nb, wf, re, n0g, P, kx, 0.0)
                            sv = cmath.sqrt(a[1][1]).real
                            if sv > shear + 1e-9:
                                shear, kshear = sv, i / 20
                    if kind == "square":
                        cols = (f"{pts[0][0]:8.2f} {pts[0][1]:8.2f} {pts[1][0]:8.2f} "
                                f"{pts[1][1]:8.2f} {pts[2][2]:8.2f}")
                    else:
                        cols = " " * 44
                    print(f"{kind:10s} {name:10s} {rel:5.1f}  {mname:11s} {n0g:7.3f}  {cols} "
                          f"{best:8.2f}  " +
                          (f"{shear:8.2f} at kx l0/pi {kshear:4.2f}" if kind == "square" else "       -"))


if __name__ == "__main__":
    main()
