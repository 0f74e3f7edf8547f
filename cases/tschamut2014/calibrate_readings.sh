#!/bin/sh
# The calibrated comparison of the two readings of the viscous term (docs/model.md, "Which reading
# the data support"): for each reading, `talus calibrate` fits mu_min and nu of `hard` (the rock
# shape on `hard` scored best uncalibrated, README.md) to the 62 run-outs, and `talus validate`
# scores Table 1 and the fitted table. The holdout part fits on the odd-numbered runs of
# release_points.csv (31) and scores the even-numbered ones (31) with the fitted table.
# Usage: cases/tschamut2014/calibrate_readings.sh [TALUS] [OUT] [PART]
#   (defaults: build/app/talus, out/tschamut-readings, all; PART: full, holdout or all). Needs jq.
set -eu
case_dir=$(cd "$(dirname "$0")" && pwd)
talus=${1:-build/app/talus}
out=${2:-out/tschamut-readings}
part=${3:-all}
case $part in full|holdout|all) ;; *)
  echo "calibrate_readings.sh: PART must be full, holdout or all, not '$part'" >&2; exit 2 ;;
esac
mkdir -p "$out"
out=$(cd "$out" && pwd)

# scene.toml with the rock shape, `hard`, the reading $2 and the runs of $3, written to $1.
write_scene() {
  sed -e "s#\"terrain.asc\"#\"$case_dir/terrain.asc\"#; s#\"block_metadata.csv\"#\"$case_dir/block_metadata.csv\"#" \
      -e "s#\"release_points.csv\"#\"$3\"#; s#default_ground = \"medium\"#default_ground = \"hard\"#" \
      -e "s#shape = \"ellipsoid\"#shape = \"rock\"#; s#^max_time_s = 120#max_time_s = 120\nviscous = \"$2\"#" \
      "$case_dir/scene.toml" > "$1"
}
# event.toml in directory $1 for the scene there and the observations of $2.
write_event() {
  sed -e "s#\"observed_deposition.csv\"#\"$2\"#" "$case_dir/event_variants.toml" > "$1/event.toml"
}
write_calibration() {
  cat > "$1/cal.toml" <<'CAL'
# Tschamut 2014, rock shape on `hard`: fit mu_min and nu of `hard` to the run-outs.
event = "event.toml"
rocks = 20
seed = 1

[[parameters]]
category = "hard"
field = "mu_min"
lower = 0.2
upper = 1.2

[[parameters]]
category = "hard"
field = "nu"
lower = 0.05
upper = 3.0

[objective]
weights = { runout = 1.0, deposit = 0.0 }

[optimizer]
algorithm = "direct_l"    # global and deterministic: the objective is rough (docs/calibration.md)
max_evaluations = 24

[roughness]
steps = [1e-2]
seeds = 2
profile_points = 3
CAL
}
# The fitted [ground.hard] of calibration $1 with mu_min and nu at full precision (jq prints
# doubles to 17 digits; ground_table.toml has 10, and a change in the tenth digit of mu_min, nu moves
# the mean run-out CRPS by up to 0.75 m: docs/model.md).
exact_table() {
  mu_min=$(jq '.parameters[] | select(.field == "mu_min") | .final' "$1/cal/calibration.json")
  nu=$(jq '.parameters[] | select(.field == "nu") | .final' "$1/cal/calibration.json")
  sed -e "s/^mu_min = .*/mu_min = $mu_min/; s/^nu = .*/nu = $nu/" "$1/cal/ground_table.toml" \
    > "$1/cal/ground_table_exact.toml"
  echo "$1/cal/ground_table_exact.toml"
}
# Validates the event of directory $1 into $1/$2 (with the fitted table of $3 appended, if given).
validate() {
  if [ -n "${3:-}" ]; then
    mkdir -p "$1/$2"
    cat "$1/scene.toml" "$3" > "$1/$2/scene.toml"
    sed -e "s#^scene = \"scene.toml\"#scene = \"$1/$2/scene.toml\"#" "$1/event.toml" > "$1/$2/event.toml"
    "$talus" validate "$1/$2/event.toml" --out "$1/$2/out" > "$1/$2.log"
  else
    "$talus" validate "$1/event.toml" --out "$1/$2/out" > "$1/$2.log"
  fi
}
score() {  # mean run-out CRPS / rest-position energy score, m
  jq -r '"\(.kinds.runout.mean_score*100|round/100) / \(.kinds.deposit.mean_score*100|round/100)"' \
    "$1/out/scores.json"
}
climatology() {  # the climatology's mean run-out CRPS, m
  jq -r '.kinds.runout.mean_climatology_score*100|round/100' "$1/out/scores.json"
}
fitted() {  # fitted mu_min, nu (identified?), seed sd and noise of the normalised objective
  jq -r '[.parameters[] | "\(.final*1000|round/1000)\(if .identified == false then " (unidentified)" else "" end)"]
    + ["\(.roughness.seed_sd*1000|round/1000)", "\(.roughness.noise*1000|round/1000)",
       "\(.evaluations)"] | join(" | ")' "$1/cal/calibration.json"
}

if [ "$part" != holdout ]; then
  printf '| reading | fitted mu_min | fitted nu (1/s) | objective sd over seeds | noise | evaluations | Table 1: run-out CRPS / rest-position ES (m) | fitted: run-out CRPS / rest-position ES (m) | climatology run-out CRPS (m) |\n'
  printf '|---|---|---|---|---|---|---|---|---|\n'
  for viscous in centre_of_mass contact_friction; do
    d="$out/$viscous"
    mkdir -p "$d"
    write_scene "$d/scene.toml" "$viscous" "$case_dir/release_points.csv"
    write_event "$d" "$case_dir/observed_deposition.csv"
    write_calibration "$d"
    "$talus" calibrate "$d/cal.toml" --out "$d/cal" > "$d/cal.log"
    validate "$d" table1
    validate "$d" fitted "$(exact_table "$d")"
    printf '| %s | %s | %s | %s | %s |\n' "$viscous" "$(fitted "$d")" "$(score "$d/table1")" \
      "$(score "$d/fitted")" "$(climatology "$d/fitted")"
  done
fi

if [ "$part" != full ]; then
  # Odd-numbered data rows (1, 3, ...) fit, even-numbered ones test; the header goes to both.
  split() {
    awk -v keep="$3" 'NR == 1 || (NR % 2 == 0) == (keep == "fit")' "$1" > "$2"
  }
  printf '\n| reading | fitted on odd runs: mu_min | nu (1/s) | objective sd over seeds | noise | evaluations | even runs, Table 1: run-out CRPS / rest-position ES (m) | even runs, fitted on odd runs (m) | even runs, climatology run-out CRPS (m) |\n'
  printf '|---|---|---|---|---|---|---|---|---|\n'
  for viscous in centre_of_mass contact_friction; do
    fit="$out/$viscous-fit-odd"
    test="$out/$viscous-test-even"
    mkdir -p "$fit" "$test"
    split "$case_dir/release_points.csv" "$fit/release_points.csv" fit
    split "$case_dir/observed_deposition.csv" "$fit/observed_deposition.csv" fit
    split "$case_dir/release_points.csv" "$test/release_points.csv" test
    split "$case_dir/observed_deposition.csv" "$test/observed_deposition.csv" test
    write_scene "$fit/scene.toml" "$viscous" "$fit/release_points.csv"
    write_event "$fit" "$fit/observed_deposition.csv"
    write_calibration "$fit"
    "$talus" calibrate "$fit/cal.toml" --out "$fit/cal" > "$fit/cal.log"
    write_scene "$test/scene.toml" "$viscous" "$test/release_points.csv"
    write_event "$test" "$test/observed_deposition.csv"
    validate "$test" table1
    validate "$test" fitted "$(exact_table "$fit")"
    printf '| %s | %s | %s | %s | %s |\n' "$viscous" "$(fitted "$fit")" "$(score "$test/table1")" \
      "$(score "$test/fitted")" "$(climatology "$test/fitted")"
  done
fi
