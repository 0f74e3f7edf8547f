#!/usr/bin/env python3
"""Whether two sets of runs of one scene differ in distribution: per-rock quantities of rocks.csv.

A change that alters a step's arithmetic at the level of round-off (a reordered sum, another
iteration of a converged solve) makes every chaotic trajectory diverge, so its runs cannot be
compared with `cmp`; they should still be draws from the same distribution. For each quantity this
prints both sets' means with their standard errors, the difference in units of its standard error,
and the two-sample Kolmogorov-Smirnov statistic with its asymptotic p-value; for the endings, the
shares and the difference of each in units of its standard error. Standard library only.

    python3 bench/compare_runs.py --a RUN_DIR ... --b RUN_DIR ... [--columns c1,c2]

Each RUN_DIR holds a rocks.csv (e.g. one `talus simulate --seed K` per directory, the same seeds
on both sides; the rocks are pooled per side).
"""

import argparse
import csv
import math
import os
import sys

DEFAULT_COLUMNS = [
    "runout_m",
    "travel_time_s",
    "max_speed_m_s",
    "max_kinetic_energy_j",
    "max_jump_height_m",
    "max_angular_speed_rad_s",
    "max_scar_m",
]


def read_rocks(directories):
    rows = []
    for d in directories:
        path = os.path.join(d, "rocks.csv")
        with open(path, newline="") as f:
            rows.extend(csv.DictReader(f))
    if not rows:
        sys.exit(f"compare_runs: no rocks in {directories}")
    return rows


def mean_se(values):
    n = len(values)
    mean = sum(values) / n
    var = sum((v - mean) ** 2 for v in values) / (n - 1) if n > 1 else 0.0
    return mean, math.sqrt(var / n)


def ks_two_sample(a, b):
    """D = sup |F_a - F_b| and its asymptotic p-value (Kolmogorov's series)."""
    a, b = sorted(a), sorted(b)
    i = j = 0
    d = 0.0
    while i < len(a) and j < len(b):
        x = min(a[i], b[j])
        while i < len(a) and a[i] == x:
            i += 1
        while j < len(b) and b[j] == x:
            j += 1
        d = max(d, abs(i / len(a) - j / len(b)))
    n_eff = len(a) * len(b) / (len(a) + len(b))
    lam = (math.sqrt(n_eff) + 0.12 + 0.11 / math.sqrt(n_eff)) * d
    if lam < 1e-3:
        return d, 1.0
    p = 2 * sum((-1) ** (k - 1) * math.exp(-2 * k * k * lam * lam) for k in range(1, 101))
    return d, min(1.0, max(0.0, p))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--a", nargs="+", required=True, help="run directories of set A")
    parser.add_argument("--b", nargs="+", required=True, help="run directories of set B")
    parser.add_argument("--columns", default=",".join(DEFAULT_COLUMNS))
    args = parser.parse_args()
    rows_a, rows_b = read_rocks(args.a), read_rocks(args.b)
    print(f"rocks: A {len(rows_a)} ({len(args.a)} runs), B {len(rows_b)} ({len(args.b)} runs)")
    print(f"{'quantity':26} {'A mean +- se':>24} {'B mean +- se':>24} {'(B-A)/se':>9} "
          f"{'KS D':>7} {'KS p':>6}")
    for column in args.columns.split(","):
        try:
            a = [float(r[column]) for r in rows_a]
            b = [float(r[column]) for r in rows_b]
        except KeyError:
            sys.exit(f"compare_runs: rocks.csv has no column '{column}'")
        ma, sa = mean_se(a)
        mb, sb = mean_se(b)
        se = math.hypot(sa, sb)
        z = (mb - ma) / se if se > 0 else 0.0
        d, p = ks_two_sample(a, b)
        print(f"{column:26} {ma:13.4g} +- {sa:<8.3g} {mb:13.4g} +- {sb:<8.3g} {z:9.2f} "
              f"{d:7.3f} {p:6.3f}")
    endings = sorted({r["end"] for r in rows_a} | {r["end"] for r in rows_b})
    for end in endings:
        pa = sum(r["end"] == end for r in rows_a) / len(rows_a)
        pb = sum(r["end"] == end for r in rows_b) / len(rows_b)
        se = math.sqrt(pa * (1 - pa) / len(rows_a) + pb * (1 - pb) / len(rows_b))
        z = (pb - pa) / se if se > 0 else 0.0
        print(f"{'end = ' + end:26} {100 * pa:22.2f} % {100 * pb:22.2f} % {z:9.2f}")


if __name__ == "__main__":
    main()
