#!/bin/sh
# Run-out and rest-position scores of the 62 runs for the ground models (README.md, "Ground
# models"): `talus validate` of event_variants.toml with the rock-like shape (32 points, roughness 0.15),
# contact friction, each ground category in GROUNDS as the meadow, with the seed's hard contact and
# with the scarring soil (model = "lu2019", the paper's M_E 15 MN/m^2 and C_s 1.5) under it.
# Usage: cases/tschamut2014/validate_models.sh [TALUS] [OUT] [ROCKS] [SEED]
#   (defaults: build/app/talus, out/tschamut-models, 20, 1; GROUNDS="hard medium"). Needs jq.
set -eu
case_dir=$(cd "$(dirname "$0")" && pwd)
talus=${1:-build/app/talus}
out=${2:-out/tschamut-models}
rocks=${3:-20}
seed=${4:-1}
mkdir -p "$out"
out=$(cd "$out" && pwd)
printf '| ground | model | run-out CRPS (m) | rest-position ES (m) | climatology run-out CRPS (m) | median run-out sim / obs (m) | max_time |\n'
printf '|---|---|---|---|---|---|---|\n'
for ground in ${GROUNDS:-hard medium}; do
  for model in hard lu2019; do
    dir="$out/$ground-$model"
    mkdir -p "$dir"
    sed -e "s|^default_ground = \"[a-z_]*\"|default_ground = \"$ground\"|" \
        -e "s|^shape = \"ellipsoid\".*|shape = \"rock\"\npoints = 32\nroughness = 0.15|" \
        -e "s|^\[solver\]|[solver]\nviscous = \"contact_friction\"|" \
        -e "s|\"terrain.asc\"|\"$case_dir/terrain.asc\"|" \
        -e "s|\"block_metadata.csv\"|\"$case_dir/block_metadata.csv\"|" \
        -e "s|\"release_points.csv\"|\"$case_dir/release_points.csv\"|" \
        "$case_dir/scene.toml" > "$dir/scene.toml"
    [ "$model" = hard ] || printf '\n[ground.%s]\nmodel = "%s"\n' "$ground" "$model" >> "$dir/scene.toml"
    sed -e "s|\"observed_deposition.csv\"|\"$case_dir/observed_deposition.csv\"|" \
        "$case_dir/event_variants.toml" > "$dir/event.toml"
    "$talus" validate "$dir/event.toml" --out "$dir/out" --rocks "$rocks" --seed "$seed" \
      > "$dir/validate.log"
    jq -r --arg g "$ground" --arg m "$model" '"| \($g) | \($m) | \(.kinds.runout.mean_score*100|round/100) | \(.kinds.deposit.mean_score*100|round/100) | \(.kinds.runout.mean_climatology_score*100|round/100) | " ' \
      "$dir/out/scores.json" | tr -d '\n'
    awk -F, '$1 == "runout" && $7 == 1 { print $12, $4 }' "$dir/out/observations.csv" |
      sort -n | awk '{ s[NR] = $1 } END { printf "%.0f / ", s[int((NR + 1) / 2)] }'
    awk -F, '$1 == "runout" && $7 == 1 { print $4 }' "$dir/out/observations.csv" |
      sort -n | awk '{ o[NR] = $1 } END { printf "%.0f | ", o[int((NR + 1) / 2)] }'
    grep -o '[0-9]* max time' "$dir/validate.log" | head -1 | sed 's/ max time//' | tr -d '\n'
    printf ' |\n'
  done
done
