#!/bin/sh
# The validation tables of README.md: `talus validate` of an event of this case for each ground
# category that could describe the slope and each reading of the viscous term, with 30 rocks per run.
# Usage: [MODELS="hard lu2019"] [READINGS="..."] cases/chant_sura/validate_table.sh [TALUS] [OUT]
#        [ROCKS] [SEED] [EVENT]
#   (defaults: build/app/talus, out/chant_sura, 30, 1, event.toml; MODELS: hard, the seed's contact
#   at the surface, and/or lu2019, the scarring soil under the category; READINGS: both readings of
#   the viscous term). Needs jq and awk.
#   EVENT: event.toml (the impacts), event_segments.toml (the flight segments) or
#   event_impacts.toml (the six single impacts of impacts_esurf2019.csv).
# Each variant is the event's scene with only `default_ground`, `[solver] viscous` and (lu2019) the
# category's `model` changed, written with absolute data paths into OUT/<category>-<reading>[-lu2019]/
# (segments: OUT/segments-..., single impacts: OUT/single-...), and the event naming it.
set -eu
case_dir=$(cd "$(dirname "$0")" && pwd)
talus=${1:-build/app/talus}
out=${2:-out/chant_sura}
rocks=${3:-30}
seed=${4:-1}
event=${5:-event.toml}
scene=scene.toml
case $event in
  event.toml)
    prefix=
    kinds="impact_energy_ratio impact_speed_out impact_angular_speed_out"
    printf '| ground | viscous | CRPS energy ratio | skill_c | in 90%% | CRPS speed out (m/s) | skill_c | in 90%% | CRPS angular speed out (rad/s) | skill_c | in 90%% | median energy ratio sim / obs | scored |\n'
    printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|\n' ;;
  event_segments.toml)
    prefix=segments-
    kinds="segment_max_speed segment_mean_angular_speed segment_max_jump_height"
    printf '| ground | viscous | CRPS max speed (m/s) | skill_c | in 90%% | CRPS mean angular speed (rad/s) | skill_c | in 90%% | CRPS max jump height (m) | skill_c | in 90%% | mean bias: speed / angular speed / jump height | scored |\n'
    printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|\n' ;;
  event_impacts.toml)
    prefix=single-
    scene=scene_impacts.toml
    kinds="impact_energy_ratio impact_scar_depth"
    printf '| ground | viscous | CRPS energy ratio | skill_c | in 90%% | CRPS scar depth (m) | skill_c | in 90%% | median energy ratio sim / obs | scored |\n'
    printf '|---|---|---|---|---|---|---|---|---|---|\n' ;;
  *) echo "validate_table.sh: EVENT must be event.toml, event_segments.toml or event_impacts.toml, not '$event'" >&2
     exit 2 ;;
esac
mkdir -p "$out"
out=$(cd "$out" && pwd)
for model in ${MODELS:-hard}; do
for ground in hard medium_hard medium; do
  for viscous in ${READINGS:-centre_of_mass contact_friction}; do
    suffix=; [ "$model" = hard ] || suffix="-$model"
    dir="$out/$prefix$ground-$viscous$suffix"
    mkdir -p "$dir"
    sed -e "s|^default_ground = \"[a-z_]*\"|default_ground = \"$ground\"|" \
        -e "s|^\[solver\]|[solver]\nviscous = \"$viscous\"|" \
        -e "s|\"terrain_rf16_patch.asc\"|\"$case_dir/terrain_rf16_patch.asc\"|" \
        -e "s|\"release_points.csv\"|\"$case_dir/release_points.csv\"|" \
        -e "s|\"impacts_esurf2019.csv\"|\"$case_dir/impacts_esurf2019.csv\"|" \
        "$case_dir/$scene" > "$dir/$scene"
    [ "$model" = hard ] || printf '\n[ground.%s]\nmodel = "%s"\n' "$ground" "$model" >> "$dir/$scene"
    sed -e "s|\"contact_events.csv\"|\"$case_dir/contact_events.csv\"|" \
        -e "s|\"observed_trajectories.csv\"|\"$case_dir/observed_trajectories.csv\"|" \
        -e "s|\"impacts_esurf2019.csv\"|\"$case_dir/impacts_esurf2019.csv\"|" \
        "$case_dir/$event" > "$dir/event.toml"
    "$talus" validate "$dir/event.toml" --out "$dir/out" --rocks "$rocks" --seed "$seed" \
      > "$dir/validate.log"
    kind() {  # mean CRPS, skill vs climatology, fraction inside the 90 % band
      jq -r --arg k "$1" '.kinds[$k] | if . == null then "-|-|-" else
        "\(.mean_score*1000|round/1000)|\(.skill_vs_climatology*100|round/100)|\(.inside_90_fraction*100|round/100)" end' \
        "$dir/out/scores.json" | sed 's/|/ | /g'
    }
    columns=
    for k in $kinds; do columns="$columns$(kind "$k") | "; done
    if [ "$event" != event_segments.toml ]; then
      # Medians over the scored energy-ratio observations: of the ensembles' medians, of the observed.
      extra=$(awk -F, '$1 == "impact_energy_ratio" && $7 == 1 { print $12, $4 }' "$dir/out/observations.csv" |
        awk '{ s[NR] = $1; o[NR] = $2 } END {
          n = NR; for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) {
            if (s[j] < s[i]) { t = s[i]; s[i] = s[j]; s[j] = t }
            if (o[j] < o[i]) { t = o[i]; o[i] = o[j]; o[j] = t } }
          m = int((n + 1) / 2); ms = (n % 2) ? s[m] : (s[m] + s[m + 1]) / 2; mo = (n % 2) ? o[m] : (o[m] + o[m + 1]) / 2
          printf "%.2f / %.2f", ms, mo }')
    else
      # Mean bias (ensemble mean - observed) of each segment quantity.
      extra=$(jq -r '[.kinds.segment_max_speed, .kinds.segment_mean_angular_speed,
          .kinds.segment_max_jump_height] | map(if . == null then "-" else .mean_bias*100|round/100 end) |
          join(" / ")' "$dir/out/scores.json")
    fi
    scored=$(jq -r '.observations_scored' "$dir/out/scores.json")
    printf '| %s | %s | %s%s | %s |\n' "$ground$suffix" "$viscous" "$columns" "$extra" "$scored"
  done
done
done
