#!/bin/sh
# Work against precision on the 40 degree ramp (talus_bench_ramp, the default ground model): for
# each seed, the tight reference (tolerance 1e-7 m/s, dt 2 ms, Gauss-Seidel) and one knob changed at
# a time. Prints one line per run: trajectories/s on one core (median of 3 repeats), Gauss-Seidel
# sweeps per contact step, and the ensemble statistics with their standard errors. The same seed
# gives the same release orientations under every setting, so differences within a seed are the
# knob's, and differences between seeds are the sampling noise.
# Usage: bench/work_precision_ramp.sh [BENCH] [ROCKS]   (defaults: build/bench/talus_bench_ramp, 200)
set -eu
bench=${1:-build/bench/talus_bench_ramp}
rocks=${2:-200}
for seed in 1 2 3; do
  for knob in "--tolerance 1e-7" "--tolerance 1e-5" "--tolerance 1e-4" "--tolerance 1e-3" \
              "--tolerance 1e-2" "--contact-solve block" "--dt 0.001" "--dt 0.004"; do
    # shellcheck disable=SC2086  # the knob is an option and its value
    out=$("$bench" --rocks "$rocks" --repeats 3 --no-profile --seed "$seed" $knob 2>&1)
    rate=$(echo "$out" | sed -n 's/^trajectories per second (one core, median of 3): //p')
    figures=$(echo "$out" | sed -n 's/^accuracy figures (compare across --dt \/ --tolerance): //p')
    sweeps=$(echo "$out" | sed -n 's/.*mean Gauss-Seidel sweeps per contact step: \([0-9.]*\).*/\1/p')
    echo "seed $seed | $knob | $rate traj/s | sweeps $sweeps | $figures"
  done
done
