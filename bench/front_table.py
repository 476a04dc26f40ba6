#!/usr/bin/env python3
"""front_table.py [--also REFERENCE2.csv] REFERENCE.csv LABEL=RUN ...: the surge fronts of several damBreak2D runs side by side.

For bench/dambreak_front_refinement.sh. Each RUN holds validation/result.csv (the surgeFront metric's
Z at the reference T) and ztable.csv (Z at dense T, the same metric with a probe reference). Prints a
markdown table of Z at the reference T beside the reference, each run's RMS (the metric's number),
and the time shift dT that best fits the run to the reference (the run read at T - dT) with the RMS
that leaves, and the RMS difference of Z between successive runs (self-convergence: it falls
with refinement if the runs converge to some answer, whatever the experiment says); with --also,
each run's RMS against a second reference too (Z at its T from ztable.csv; the points the run
covers): a delayed start (a gate removed in finite time) shifts a front in T; a slower front
(friction, a smaller scale) changes its slope, which no shift removes.
"""
import math
import sys


def rows(path):
    """The numeric rows of a CSV with a header and # comments."""
    out = []
    for line in open(path):
        if line[:1].isdigit():
            out.append([float(v) for v in line.strip().split(",")])
    return out


def interp(table, t):
    """Linear interpolation in a (T, Z) table; None outside it."""
    for (t0, z0), (t1, z1) in zip(table, table[1:]):
        if t0 <= t <= t1 and not (math.isnan(z0) or math.isnan(z1)):
            return z0 + (z1 - z0) * (t - t0) / (t1 - t0) if t1 > t0 else z0
    return None


def rms_shifted(ref, dense, shift):
    """RMS of Z over the reference points the shifted run covers."""
    d = [interp(dense, t - shift) for t, _ in ref]
    e = [(z - zr) ** 2 for z, (_, zr) in zip(d, ref) if z is not None]
    return math.sqrt(sum(e) / len(e)) if e else float("nan"), len(e)


def main():
    args = sys.argv[1:]
    also = None
    if args[:1] == ["--also"]:
        also = [(r[0], r[1]) for r in rows(args[1])]
        args = args[2:]
    ref = [(r[0], r[1]) for r in rows(args[0])]
    runs = []
    for arg in args[1:]:
        label, path = arg.split("=", 1)
        result = rows(path + "/validation/result.csv")
        dense = [(r[0], r[1]) for r in rows(path + "/ztable.csv")]
        runs.append((label, [r[2] for r in result], dense))
    runs.sort(key=lambda r: float(r[0].split("_")[-1]) if r[0].split("_")[-1][0].isdigit() else 0)
    print("| T | reference Z | " + " | ".join(r[0] for r in runs) + " |")
    print("|---|---|" + "---|" * len(runs))
    for i, (t, z) in enumerate(ref):
        print("| %.3f | %.3f | " % (t, z) + " | ".join("%.3f" % r[1][i] for r in runs) + " |")
    for label, zs, dense in runs:
        e = [(z - zr) ** 2 for z, (_, zr) in zip(zs, ref) if not math.isnan(z)]
        base, n = math.sqrt(sum(e) / len(e)), len(e)
        best = min((rms_shifted(ref, dense, 0.005 * k)[0], 0.005 * k) for k in range(200))
        print("%s: RMS %.3f over %d points; best shift dT = %.3f leaves RMS %.3f" % (label, base, n, best[1], best[0]))
    for (l1, z1, _), (l2, z2, _) in zip(runs, runs[1:]):
        d = [(a - b) ** 2 for a, b in zip(z1, z2) if not (math.isnan(a) or math.isnan(b))]
        print("%s to %s: RMS difference of Z %.3f over %d points" % (l1, l2, math.sqrt(sum(d) / len(d)), len(d)))
    for label, _, dense in runs if also else []:
        e, n = rms_shifted(also, dense, 0.0)
        print("%s: RMS %.3f against the second reference over %d points" % (label, e, n))


if __name__ == "__main__":
    main()
