#!/usr/bin/env python3
"""bench/layer_mode.py SNAPSHOT.h5 [L0] [WIDTH]: the shape of the periodic
layer's motion (bench/periodic_layer.sh) in one snapshot, for the kernel
branch's reading of issue 13 (docs/notes/mps.md, "kernel").

Fluid particles (PartType0) are binned into rows (round(y/L0 - 0.5)) and
columns (floor(x/L0) of the period WIDTH). Per row: the rms of u and v and,
for each, the dominant wavenumber m along x (a discrete Fourier sum over
the row's particles at their x: wavelength WIDTH/m; m = WIDTH/(2 L0) is
alternate columns) with its share of the row's power. Then the whole
layer's power by m. Needs h5dump (hdf5-tools); no numpy."""
import cmath
import math
import subprocess
import sys


def dataset(path, name):
    out = subprocess.run(["h5dump", "-d", name, "-y", "-w", "0", "-m", "%.17g", path],
                         capture_output=True, text=True, check=True).stdout
    body = out.split("DATA {", 1)[1].rsplit("}", 2)[0]
    vals = []
    for tok in body.replace(",", " ").split():
        try:
            vals.append(float(tok))
        except ValueError:
            pass
    return vals


def main():
    path = sys.argv[1]
    l0 = float(sys.argv[2]) if len(sys.argv) > 2 else 0.01
    width = float(sys.argv[3]) if len(sys.argv) > 3 else 0.4
    xyz = dataset(path, "/PartType0/Coordinates")
    vel = dataset(path, "/PartType0/Velocities")
    n = len(xyz) // 3
    rows = {}
    for i in range(n):
        x, y = xyz[3 * i] % width, xyz[3 * i + 1]
        u, v = vel[3 * i], vel[3 * i + 1]
        rows.setdefault(int(round(y / l0 - 0.5)), []).append((x, y, u, v))
    mmax = int(round(width / l0)) // 2
    total = {"u": [0.0] * (mmax + 1), "v": [0.0] * (mmax + 1)}
    print(f"# {path}: {n} fluid particles, {len(rows)} rows; per row: mean y/l0, count, "
          "rms u, rms v (m/s), dominant m of u and of v (wavelength width/m; "
          f"m {mmax} = alternate columns) with its share of the row's power")
    for r in sorted(rows):
        pts = rows[r]
        line = []
        for comp, idx in (("u", 2), ("v", 3)):
            spec = []
            for m in range(mmax + 1):
                s = sum(p[idx] * cmath.exp(-2j * math.pi * m * p[0] / width) for p in pts)
                spec.append(abs(s) ** 2)
                total[comp][m] += abs(s) ** 2
            best = max(range(1, mmax + 1), key=lambda m: spec[m])
            share = spec[best] / max(sum(spec), 1e-300)
            line.append((best, share))
        ru = math.sqrt(sum(p[2] ** 2 for p in pts) / len(pts))
        rv = math.sqrt(sum(p[3] ** 2 for p in pts) / len(pts))
        ym = sum(p[1] for p in pts) / len(pts) / l0
        print(f"row {r:3d} y/l0 {ym:6.2f} n {len(pts):3d}  rms u {ru:9.2e} v {rv:9.2e}  "
              f"m_u {line[0][0]:3d} ({line[0][1]:4.2f})  m_v {line[1][0]:3d} ({line[1][1]:4.2f})")
    for comp in ("u", "v"):
        sp = total[comp]
        tot = sum(sp)
        top = sorted(range(mmax + 1), key=lambda m: -sp[m])[:5]
        print(f"# layer power of {comp} by m (share): " +
              ", ".join(f"m {m} ({sp[m] / tot:.2f})" for m in top))


if __name__ == "__main__":
    main()
