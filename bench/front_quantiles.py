#!/usr/bin/env python3
"""front_quantiles.py A RUN ...: how a dam-break run's leading fluid is spread, snapshot by snapshot.

For docs/notes/front.md. A is the column width in m.
At the snapshots nearest T = t sqrt(2g/A) = 1, 2, 3, 4, 5 it prints, in units of A:
  max      the largest x of a fluid particle (surgeFront's front, before its neighbour test)
  q0.5 ... the x beyond which 0.5%, 2%, 5% of the fluid particles lie: a front defined by a
           fraction of the fluid, which has a limit as l0 -> 0 whatever the tip's thickness
  rule     surgeFront's front: the largest x of a particle with at least two others within 2.1 l0
  drop     how many leading particles that rule passed over (isolated spray)
  head     the particles within 4 l0 of the rule's front particle: how thick the tip is
  h2% h5%  the end of the layer at least 0.02 a (0.05 a) deep, from the back wall on: the fluid's
           depth in bins 2 l0 wide (particles times l0^2 over the bin's width), the first bin
           below the depth ends the layer; a front set by a physical depth, not by l0, that
           ignores the sheet thinner than it (and spray ahead of a gap)
and the fluid's kinetic energy is in the run's postProcessing/energy. Reads the HDF5 snapshots
with h5dump (hdf5-tools), no numpy.
"""
import glob
import subprocess
import sys


def dataset(path, name):
    out = subprocess.run(["h5dump", "-y", "-w", "0", "-d", "/PartType0/" + name, path],
                         capture_output=True, text=True, check=True).stdout
    body = out.split("DATA {", 1)[1].split("}", 1)[0]
    return [float(v) for v in body.replace(",", " ").split()]


def header(path, name):
    out = subprocess.run(["h5dump", "-a", "/Header/" + name, path],
                         capture_output=True, text=True, check=True).stdout
    return float(out.split("(0):", 1)[1].split()[0])


def fluid_xy(path):
    xyz, kind = dataset(path, "Coordinates"), dataset(path, "Kind")
    return [(xyz[3 * i], xyz[3 * i + 1]) for i, k in enumerate(kind) if k == 0]


def rule_front(points, l0):
    """surgeFront's rule (driver/post/metric_surge_front.c): the leading particle with at least two
    fluid neighbours within 2.1 l0; returns its index in x order (descending) and its head count."""
    order = sorted(points, key=lambda p: -p[0])
    r2, h2 = (2.1 * l0) ** 2, (4 * l0) ** 2
    for k, (x, y) in enumerate(order):
        near = [q for q in order if abs(q[0] - x) <= 4 * l0]
        count = sum(1 for q in near if (q[0] - x) ** 2 + (q[1] - y) ** 2 <= r2) - 1
        if count >= 2:
            head = sum(1 for q in near if (q[0] - x) ** 2 + (q[1] - y) ** 2 <= h2) - 1
            return k, x, head
    return len(order), 0.0, 0


def layer_front(points, l0, depth):
    """The largest x in the last bin of the layer at least DEPTH deep, walking from the back
    wall (x = 0); 0 if the first bin is shallower."""
    width = 2 * l0
    count, far = {}, {}
    for x, _ in points:
        k = int(x // width)
        count[k] = count.get(k, 0) + 1
        far[k] = max(far.get(k, x), x)
    k = 0
    while count.get(k, 0) * l0 * l0 / width >= depth:
        k += 1
    return far[k - 1] if k > 0 else 0.0


def main():
    a = float(sys.argv[1])
    tscale = (2 * 9.81 / a) ** 0.5
    for run in sys.argv[2:]:
        print(run)
        done = set()
        for path in sorted(glob.glob(run + "/output/snapshot_*.h5")):
            T = header(path, "Time") * tscale
            want = round(T)
            if want < 1 or want > 5 or want in done or abs(T - want) > 0.045:
                continue
            done.add(want)
            l0 = header(path, "ParticleSpacing")
            pts = fluid_xy(path)
            xs = sorted((x for x, _ in pts), reverse=True)
            q = [xs[int(f * len(xs))] / a for f in (0.005, 0.02, 0.05)]
            drop, x_rule, head = rule_front(pts, l0)
            h = [layer_front(pts, l0, f * a) / a for f in (0.02, 0.05)]
            print("  T %.2f  max %.3f  rule %.3f  drop %d  head %d  q0.5%% %.3f  q2%% %.3f  q5%% %.3f"
                  "  h2%% %.3f  h5%% %.3f"
                  % (T, xs[0] / a, x_rule / a, drop, head, q[0], q[1], q[2], h[0], h[1]))


if __name__ == "__main__":
    main()
