#!/usr/bin/env bash
# Sets up and builds (scripts/setup.sh), then runs the flagship case and prints its results.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/build/app/talus" demo "$@"
