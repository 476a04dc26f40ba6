#!/usr/bin/env python3
"""Scaling model of an MPS step on P MPI ranks (issue 14); not a test.

Prints strong scaling (a fixed total of particles) and weak scaling (a fixed
count a rank) to 10,000 ranks, and the rank count where communication takes
half the step. docs/topics/parallel.md ("Scaling to 1,000 and 10,000 ranks")
explains every term and where each default was measured:

    bench/mpi_model.py                    the tables of the docs
    bench/mpi_model.py --alpha 5e-6       a slower network (latency, s)

A step on one rank of n owned particles and h(n) halo copies takes
    T(P) = c (n + g h) + s_solve(P) + t_halo + t_reduce
with
    h(n)      = F/6 ((n^(1/3) + 2k)^3 - n)   copies around a cube of n
                                              particles, k spacings deep, F =
                                              min(6, log2 P) faces on other ranks
    s_solve   = f c n q I(P) / I(1)          the PPE's share f of the work,
                                              iterations I(P) = I(1)(1 + a log2 P),
                                              q (P > 1) the solve's work a row
                                              on N ranks over the serial's
    t_halo    = E m alpha + h b / beta       E exchanges a step, m = min(26,
                                              P - 1) neighbours, b bytes a copy
                                              a step (all exchanges)
    t_reduce  = (R + r I(P)) alpha_r log2 P  R reductions a step, r a PCG
                                              iteration (tree allreduce)
              + A_msg(P) alpha               AMG's messages: its coarse
                                              levels' neighbours grow with P
"""
import argparse
import math


def model(args, N, P):
    n = N / P
    s = n ** (1.0 / 3.0)
    # Recursive bisection cuts one more face of each subdomain a level: a
    # subdomain has min(6, log2 P) faces that border other ranks.
    faces = min(6.0, math.log2(P)) if P > 1 else 0.0
    h = faces / 6.0 * ((s + 2 * args.k) ** 3 - n)
    m = min(args.m, P - 1)
    iters = args.iters * (1 + args.a * math.log2(P)) if P > 1 else args.iters
    comp = args.c * (n * (1 - args.f) + args.g * h)
    q = args.q if P > 1 else 1.0
    solve = args.f * args.c * n * q * iters / args.iters
    lg = math.log2(P) if P > 1 else 0.0
    halo = args.exchanges * m * args.alpha + h * args.bytes / args.beta if P > 1 else 0.0
    reduce = (args.R + args.r * iters) * args.alpha_r * lg
    # AMG: fine levels talk to the m geometric neighbours; coarse levels to
    # more ranks as the grid coarsens (Gahvari et al. 2011): grow as log2 P.
    amg = args.amg_msgs * iters / args.iters * (m + m * 0.5 * lg) * args.alpha if P > 1 else 0.0
    t = comp + solve + halo + reduce + amg
    return t, h / n, halo + reduce + amg


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--c", type=float, default=5e-6, help="s a particle-step, one core")
    ap.add_argument("--f", type=float, default=0.5, help="the PPE solve's share of a serial step")
    ap.add_argument("--g", type=float, default=0.5, help="cost of a halo copy / an owned particle")
    ap.add_argument("--k", type=float, default=3.1, help="halo depth in spacings (largest radius)")
    ap.add_argument("--q", type=float, default=2.0,
                    help="the solve's work a row on N ranks over the serial's (hypre's PCG and "
                         "V-cycle on a kept hierarchy against the serial run's own V-cycle: "
                         "2,043 M instructions of hypre a rank on 2 ranks against the serial "
                         "solve's 1,974 M, docs/topics/parallel.md, mpi4; 2.75 when hypre's "
                         "hierarchy was set up each solve; 1: the same)")
    ap.add_argument("--iters", type=float, default=9.2, help="PCG iterations on one rank")
    ap.add_argument("--a", type=float, default=0.05, help="iteration growth per doubling of P")
    ap.add_argument("--exchanges", type=float, default=8, help="halo builds + updates + migration a step")
    ap.add_argument("--m", type=float, default=26, help="neighbouring subdomains (3-D boxes)")
    ap.add_argument("--bytes", type=float, default=200, help="bytes a copy a step, all exchanges")
    ap.add_argument("--alpha", type=float, default=2e-6, help="message latency (s)")
    ap.add_argument("--beta", type=float, default=1e9, help="bytes/s a rank")
    ap.add_argument("--alpha_r", type=float, default=3e-6, help="allreduce cost a tree level (s)")
    ap.add_argument("--R", type=float, default=25, help="our reductions a step")
    ap.add_argument("--r", type=float, default=10, help="hypre's reductions a PCG iteration (+ setup)")
    ap.add_argument("--amg_msgs", type=float, default=345, help="hypre's messages a step to one neighbour")
    args = ap.parse_args()

    ranks = [1, 2, 8, 64, 256, 1000, 4096, 10000]
    for N in (1e6, 1e8):
        t1 = model(args, N, 1)[0]
        print(f"strong scaling, N = {N:.0e} particles")
        print("     P   per rank  halo/owned   step ms   comm ms  efficiency")
        for P in ranks:
            t, hr, comm = model(args, N, P)
            print(f"{P:6d} {N / P:10.0f} {hr:11.2f} {1e3 * t:9.2f} {1e3 * comm:9.3f} {t1 / (P * t):10.2f}")
        cap = next((P for P in range(2, 200001) if model(args, N, P)[2] > 0.5 * model(args, N, P)[0]), None)
        print(f"  communication half the step from P = {cap} ({N / cap:.0f} particles a rank)\n" if cap else "")
    n = 1e5
    t1 = model(args, n, 1)[0]
    print(f"weak scaling, {n:.0e} particles a rank")
    print("     P  particles  step ms   comm ms  efficiency")
    for P in ranks:
        t, hr, comm = model(args, n * P, P)
        print(f"{P:6d} {n * P:10.0e} {1e3 * t:8.1f} {1e3 * comm:9.3f} {t1 / t:10.2f}")


if __name__ == "__main__":
    main()
