#!/usr/bin/env python3
"""How much one calibration-objective evaluation from Python costs beyond the evaluation itself.

Each repeat calls Calibration.evaluate_unit at the scene's values and times it from Python; the
evaluation's own wall_time_s is measured inside the C++ call (calibration::Objective::Evaluate),
the same timer talus calibrate writes to history.csv for every evaluation. The difference is what
the module adds (argument conversion, releasing and taking the GIL, building the result). Then
`talus calibrate` runs the same file with the same rocks and its history's times are listed beside.

  PYTHONPATH=build/python /usr/bin/python3 bench/python_objective.py \
      [--calibration cases/tschamut2014/calibrate.toml] [--rocks 4] [--repeats 9] [--threads 2]
"""

import argparse
import csv
import os
import pathlib
import platform
import statistics
import subprocess
import tempfile
import time

import talus


def machine():
    model = "?"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{platform.node()}: {model}, {os.cpu_count()} cores, Python {platform.python_version()}"


def main():
    root = pathlib.Path(__file__).resolve().parents[1]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calibration", default=str(root / "cases/tschamut2014/calibrate.toml"))
    parser.add_argument("--rocks", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--program", default=str(root / "build/app/talus"))
    args = parser.parse_args()

    print(f"Machine: {machine()}")
    calibration = talus.Calibration.load(args.calibration, rocks=args.rocks, threads=args.threads)
    u = calibration.start_unit
    calibration.evaluate_unit(u)  # warm-up: page in the terrain and shapes
    outer, inner = [], []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        e = calibration.evaluate_unit(u)
        outer.append(time.perf_counter() - t0)
        inner.append(e["wall_time_s"])
    added = [o - i for o, i in zip(outer, inner)]
    print(f"{args.calibration}: {e['rocks']} rocks per evaluation, {args.threads} threads, "
          f"{args.repeats} repeats")
    print(f"  from Python:          median {statistics.median(outer) * 1e3:9.2f} ms")
    print(f"  inside the C++ call:  median {statistics.median(inner) * 1e3:9.2f} ms")
    print(f"  added by the module:  median {statistics.median(added) * 1e3:9.3f} ms "
          f"({statistics.median(a / i for a, i in zip(added, inner)) * 100:.3f} % of the evaluation)")

    # talus calibrate on the same file and rocks: the times of its own evaluations (other points).
    text = pathlib.Path(args.calibration).read_text()
    base = pathlib.Path(args.calibration).resolve().parent
    with tempfile.TemporaryDirectory() as tmp:
        copy = pathlib.Path(tmp) / "calibrate.toml"
        lines = []
        for line in text.splitlines():
            key = line.split("=")[0].strip()
            if key == "rocks":
                line = f"rocks = {args.rocks}"
            elif key == "event":
                line = f'event = "{base / line.split("=", 1)[1].split("#")[0].strip().strip(chr(34))}"'
            elif key == "max_evaluations":
                line = f"max_evaluations = {args.repeats}"
            lines.append(line)
        text = "\n".join(lines) + "\n[roughness]\nenabled = false\n" if "[roughness]" not in text \
            else "\n".join(lines).replace("[roughness]", "[roughness]\nenabled = false", 1)
        text = text.replace("[uncertainty]", "[uncertainty]\nenabled = false", 1)
        copy.write_text(text)
        subprocess.run([args.program, "calibrate", copy, "--out", pathlib.Path(tmp) / "out",
                        "--threads", str(args.threads)], check=True, capture_output=True)
        with open(pathlib.Path(tmp) / "out" / "history.csv") as f:
            program = [float(row["wall_time_s"]) for row in csv.DictReader(f)]
    print(f"  talus calibrate:      median {statistics.median(program) * 1e3:9.2f} ms over its "
          f"{len(program)} evaluations (its own points)")


if __name__ == "__main__":
    main()
