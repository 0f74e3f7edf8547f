#!/usr/bin/env python3
"""Held-out scores of a calibration's fit and of its stationary point.

Reads OUT/calibration.json of `talus calibrate FILE --holdout N --out OUT` with `[uncertainty]`
enabled. Loads FILE with the fitted runs held out, so that `talus.Calibration.evaluate` scores
the runs the calibration held out. Then evaluates the fit (`parameters[].final`) and, where the
uncertainty located it, the stationary point (`uncertainty.stationary_values`). Each model seed
(the file's top-level `seed`) is one row. Both points share each seed's rocks (common random
numbers), so the paired differences are the figure to read.

    PYTHONPATH=build/python /usr/bin/python3 bench/heldout_points.py OUT FILE [--seeds 1 2 3 4 5]
"""
import argparse
import json
import pathlib
import re
import statistics
import tempfile

import numpy as np

import talus


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=pathlib.Path, help="the calibration's output directory")
    parser.add_argument("file", type=pathlib.Path, help="the calibration file it ran")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--threads", type=int, default=0)
    args = parser.parse_args()

    result = json.loads((args.out / "calibration.json").read_text())
    if result["holdout"] is None or result["uncertainty"] is None:
        raise SystemExit(f"{args.out}/calibration.json: needs a --holdout run with [uncertainty]")
    held = list(result["holdout"]["runs"])
    points = {"fit": np.array([p["final"] for p in result["parameters"]])}
    if result["uncertainty"]["stationary_located"]:
        points["stationary point"] = np.array(result["uncertainty"]["stationary_values"])
    for name, values in points.items():
        print(f"{name}: {', '.join(f'{v:.4g}' for v in values)}")

    # The copies live elsewhere: the event's path is made absolute.
    text = args.file.read_text()
    event = re.search(r'^event\s*=\s*"([^"]+)"', text, flags=re.M)
    if event is None:
        raise SystemExit(f"{args.file}: no event = \"...\" line")
    absolute = (args.file.parent / event.group(1)).resolve()
    text = text[: event.start(1)] + str(absolute) + text[event.end(1):]
    all_runs = talus.Calibration.load(args.file).fitted_runs
    fitted = [r for r in all_runs if r not in held]
    print(f"{len(held)} of {len(all_runs)} runs held out; kind scores (the event's units)")

    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for seed in args.seeds:
            copy = pathlib.Path(scratch) / f"seed{seed}.toml"
            copy.write_text(re.sub(r"^seed\s*=\s*\d+", f"seed = {seed}", text, count=1,
                                   flags=re.M))
            calibration = talus.Calibration.load(copy, holdout=",".join(fitted),
                                                 threads=args.threads)
            assert sorted(calibration.fitted_runs) == sorted(held)
            row = {name: calibration.evaluate(values)["kind_scores"]
                   for name, values in points.items()}
            rows.append(row)
            print(f"seed {seed}: " + " | ".join(
                f"{name} " + ", ".join(f"{k} {v:.3f}" for k, v in scores.items())
                for name, scores in row.items()), flush=True)

    if len(points) == 2 and len(rows) > 1:
        for kind in rows[0]["fit"]:
            d = [r["stationary point"][kind] - r["fit"][kind] for r in rows]
            se = statistics.stdev(d) / len(d) ** 0.5
            print(f"stationary point - fit, {kind}: {statistics.mean(d):+.3f} +- {se:.3f}")


if __name__ == "__main__":
    main()
