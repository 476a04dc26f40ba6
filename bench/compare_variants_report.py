#!/usr/bin/env python3
"""bench/compare_variants_report.py WORK FIGS CASE...: the tables, the Pareto
front and the plots of bench/compare_variants.sh.

Reads WORK/<case>_l0_<l0>/compare/compare.csv (one `mpsflow compare` per
spacing), merges the spacings of a case and computes its Pareto front on CPU
(user + system) seconds: a run is on it when it has an error and no other
run of the case, at any spacing, is at least as accurate and as cheap and
strictly better in one. Writes FIGS/compare_variants_<case>.csv and .png
(gnuplot, error against CPU time, log-log) and prints a Markdown section:
the table per case and, for the default, whether it is on the front and,
if not, which runs dominate it and by how much.
"""
import csv
import glob
import math
import os
import subprocess
import sys


def read_runs(work, case):
    runs = []
    for path in sorted(glob.glob(os.path.join(work, f"{case}_l0_*", "compare", "compare.csv"))):
        with open(path) as f:
            for r in csv.DictReader(l for l in f if not l.startswith("#")):
                r["error"] = float(r["error"])
                r["cpu"] = float(r["cpu_seconds"])
                r["wall"] = float(r["wall_seconds"])
                r["l0v"] = float(r["l0"])
                runs.append(r)
    runs.sort(key=lambda r: (-r["l0v"], r["scheme"] != "default", r["scheme"]))
    return runs


def dominators(runs, r):
    """Runs at least as accurate and as cheap (CPU) as r, better in one."""
    if not math.isfinite(r["error"]):
        return []
    return [q for q in runs if q is not r and math.isfinite(q["error"])
            and q["error"] <= r["error"] and q["cpu"] <= r["cpu"]
            and (q["error"] < r["error"] or q["cpu"] < r["cpu"])]


def plot(runs, case, png):
    """Error against CPU time, one line per variant, the front in black."""
    data = png[:-4] + ".dat"
    # Variants with no finished run have no point (and would only warn).
    names = list(dict.fromkeys(r["scheme"] for r in runs
                               if math.isfinite(r["error"]) and r["error"] > 0))
    with open(data, "w") as f:
        for name in names:
            for r in runs:
                if r["scheme"] == name and math.isfinite(r["error"]) and r["error"] > 0:
                    f.write(f"{r['cpu']} {r['error']} {r['l0']}\n")
            f.write("\n\n")
        front = sorted((r for r in runs if r["front"]), key=lambda r: r["cpu"])
        for r in front:
            f.write(f"{r['cpu']} {r['error']} {r['l0']}\n")
    plots = []
    for i, name in enumerate(names):
        width = 4 if name == "default" else 1.5
        plots.append(f"'{data}' index {i} using 1:2 with linespoints lw {width} pt {i % 13 + 1} "
                     f"title '{name.replace('_', ' ')}'")
    plots.append(f"'{data}' index {len(names)} using 1:2 with points pt 6 ps 3 lc rgb 'black' "
                 "title 'Pareto front (CPU)'")
    script = f"""set terminal pngcairo size 1400,900 font ',11'
set output '{png}'
set logscale xy
set grid
set key outside right
set title 'Error against CPU time: {case}, every MPS variant at three spacings (finer = right)'
set xlabel 'CPU (user + system) time of the run, s'
set ylabel 'error (validation/metric)'
plot {', '.join(plots)}
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.remove(data)


def fmt(x):
    return "nan" if not math.isfinite(x) else f"{x:.4g}"


def main():
    work, figs, cases = sys.argv[1], sys.argv[2], sys.argv[3:]
    out = []
    for case in cases:
        runs = read_runs(work, case)
        if not runs:
            out.append(f"#### {case}\n\nno runs found in {work}\n")
            continue
        for r in runs:
            r["front"] = math.isfinite(r["error"]) and not dominators(runs, r)
        with open(os.path.join(figs, f"compare_variants_{case}.csv"), "w") as f:
            w = csv.writer(f)
            w.writerow(["case", "variant", "l0", "error", "wall_seconds", "cpu_seconds", "steps",
                        "status", "criterion", "pareto_cpu"])
            for r in runs:
                w.writerow([case, r["scheme"], r["l0"], r["error"], r["wall"], r["cpu"], r["steps"],
                            r["status"], r["criterion"], "yes" if r["front"] else "no"])
        plot(runs, case, os.path.join(figs, f"compare_variants_{case}.png"))
        out += [f"#### {case}", "",
                "| case | variant | l0 | error | wall s | CPU s | steps | status | Pareto (CPU) |",
                "|---|---|---|---|---|---|---|---|---|"]
        for r in runs:
            status = r["status"] if r["status"] == "completed" else f"{r['status']} ({r['criterion']})"
            name = f"**{r['scheme']}**" if r["scheme"] == "default" else r["scheme"]
            out.append(f"| {case} | {name} | {r['l0']} | {fmt(r['error'])} | {r['wall']:.3g} | "
                       f"{r['cpu']:.3g} | {r['steps']} | {status} | {'yes' if r['front'] else 'no'} |")
        out += ["", f"![error against CPU time, {case}](figures/compare_variants_{case}.png)", ""]
        defaults = [r for r in runs if r["scheme"] == "default"]
        # scheme robust is the default's arithmetic (the same errors): the
        # spread of its CPU time against the default's is the timing noise.
        twins = [(d, q) for d in defaults for q in runs
                 if q["scheme"] == "scheme_robust" and q["l0"] == d["l0"]]
        noise = max((abs(q["cpu"] / d["cpu"] - 1) for d, q in twins if d["cpu"] > 0), default=0.0)
        same = all(q["error"] == d["error"] or not (math.isfinite(q["error"]) or
                                                     math.isfinite(d["error"])) for d, q in twins)
        out.append(f"Timing noise: `scheme robust` (the default's arithmetic; errors "
                   f"{'identical' if same else 'NOT identical'}) differs from `default` by up to "
                   f"{100 * noise:.1f}% in CPU time. A dominating run marked * is better in "
                   "error by more than 1% and not slower by more than that noise: the others "
                   "dominate by a margin the timing cannot resolve.")
        out.append("")
        on = [r["l0"] for r in defaults if r["front"]]
        out.append(f"**{case}: the default is {'on' if on else 'not on'} the Pareto front (CPU time)**"
                   + (f" at l0 = {', '.join(on)}." if on else "."))
        out.append("")
        for r in defaults:
            if r["front"] or not math.isfinite(r["error"]):
                if not math.isfinite(r["error"]):
                    out.append(f"- l0 = {r['l0']}: the default has no error ({r['status']}).")
                continue
            dom = sorted(dominators(runs, r), key=lambda q: q["error"])
            out.append(f"- l0 = {r['l0']} (error {fmt(r['error'])}, {r['cpu']:.3g} CPU s) is dominated "
                       f"by {len(dom)} run(s); the most accurate of them:")
            for q in dom[:4]:
                clear = q["error"] < 0.99 * r["error"] and q["cpu"] <= r["cpu"] * (1 + noise)
                out.append(f"  - {'* ' if clear else ''}{q['scheme']} at l0 = {q['l0']}: error {fmt(q['error'])} "
                           f"({q['error'] / r['error']:.3g} x the default's), {q['cpu']:.3g} CPU s "
                           f"({q['cpu'] / r['cpu']:.3g} x)")
        out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main()
