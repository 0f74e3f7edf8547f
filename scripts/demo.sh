#!/usr/bin/env bash
# Sets up and builds (scripts/setup.sh), then runs the flagship case (200 blocks over the cliff band
# of the real Tyrol terrain, cases/tirol) and shows its results. Usage: scripts/demo.sh [out-dir]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/out/tirol}"
"$root/scripts/setup.sh"
"$root/build/app/talus" simulate "$root/cases/tirol/scene.toml" --out "$out"
echo
echo "First rocks of $out/rocks.csv:"
if command -v column >/dev/null; then head -n 6 "$out/rocks.csv" | column -s, -t; else head -n 6 "$out/rocks.csv"; fi
echo
echo "Rasters (GeoTIFF, EPSG:31287, on the DEM grid): $(cd "$out" && ls ./*.tif | tr '\n' ' ')"
echo "Quick look: $out/quicklook.png   Summary: $out/summary.json"
echo "Report for a browser (maps with legends, histograms, tables): $out/report.html"
