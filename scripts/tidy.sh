#!/usr/bin/env bash
# Runs clang-tidy with the project's check list (.clang-tidy) over Talus' own sources -- every
# .cpp of the compile_commands.json a build exports, and the project headers they include -- and
# fails on any finding (.clang-tidy makes every warning an error). Needs a configured build
# (scripts/setup.sh) and clang-tidy-14 (Debian's clang-tidy-14 package).
# Usage: scripts/tidy.sh [build-dir] [file-regex]     (default: build, every own source)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build}"
own="^$root/(app|bench|calibration|common|ensemble|fieldobs|io|pointclouds|scenes|solver|tests)/"
files="${2:-$own}"
tidy="$(command -v clang-tidy-14 || command -v clang-tidy)"
runner="$(command -v run-clang-tidy-14 || command -v run-clang-tidy)"
if [[ ! -f "$build/compile_commands.json" ]]; then
  echo "tidy: no $build/compile_commands.json; configure a build first (scripts/setup.sh)" >&2
  exit 2
fi
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
"$runner" -clang-tidy-binary "$tidy" -p "$build" -quiet -j "$(nproc)" -header-filter "$own" \
  "$files" >"$log" 2>&1 || status=$?
# The findings only: no colours, command lines or counts of suppressed third-party warnings.
sed -e 's/\x1b\[[0-9;]*m//g' "$log" |
  grep -v -e 'clang-tidy[-0-9]* --use-color' -e 'warnings\? generated\.$' -e '^Suppressed [0-9]* warnings' \
    -e '^Use -header-filter=' -e '^Running clang-tidy' -e '^Error while processing' || true
if ((status == 0)); then echo "tidy: clean"; else echo "tidy: findings above" >&2; fi
exit "$status"
