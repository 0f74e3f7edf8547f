#!/usr/bin/env bash
# Builds Talus with AddressSanitizer + UndefinedBehaviorSanitizer (-DTALUS_SANITIZE=ON) in a
# build directory of its own and runs the whole CTest suite under it. Assertions are on (a Debug
# build at -O1: ASan's usual level, fast enough for the calibration tests). Any sanitizer report
# fails the test that produced it. Not part of scripts/test.sh: it takes about an hour on two
# cores. The Debian packages come from scripts/setup.sh (run it once first).
# Usage: scripts/sanitize.sh [build-dir]     (default: build-sanitize)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build-sanitize}"
supp="$root/scripts/sanitize"

if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
        -DCMAKE_C_FLAGS_DEBUG="-g -O1" -DTALUS_SANITIZE=ON -DTALUS_WITH_MPI=ON \
        -DTALUS_BUILD_BENCH=OFF -DTALUS_WITH_PYTHON=OFF >/dev/null
fi
cmake --build "$build" --parallel "$(nproc)"

# The Python module is not built here: the interpreter is not instrumented, and ASan's runtime must
# be loaded before everything else. Its C++ is the libraries' the suite checks, plus the bindings.
# Every report is fatal; leaks are checked at exit. Third-party reports that are not Talus'
# defects are suppressed in scripts/sanitize/*.supp, one commented entry each.
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1:halt_on_error=1:detect_odr_violation=2"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$supp/ubsan.supp"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"

# Excluded: the tests that start Open MPI (SimulateMpi.*, CalibrateMpi.* through mpirun; MpiSession.*
# and mpi_session_test_* in the test process itself). Open MPI's runtime is not instrumented, keeps
# its own allocations to the end and unloads its plugins before the leak check, so every rank
# reports leaks that no suppression can name (frames in <unknown module> and ompi_op_base_op_select).
# The MPI code of talus is a thin layer (app/mpi_session.cpp) that the ordinary suite runs.
ctest --test-dir "$build" --output-on-failure --parallel "$(nproc)" --timeout 3600 \
  --exclude-regex '^(SimulateMpi\.|CalibrateMpi\.|MpiSession\.|mpi_session_test_)'

# Every shipped case's scenes (talus simulate) and events (talus validate), two rocks per release or
# run: the readers of real terrain, point clouds, forests, barriers and observation tables on real
# inputs, and the writers of every output. A sanitizer report ends talus with a non-zero status.
talus="${TALUS:-$build/app/talus}"
cases_out="$(mktemp -d)"
trap 'rm -rf "$cases_out"' EXIT
for file in "$root"/cases/*/*.toml; do
  name="$(basename "$(dirname "$file")")_$(basename "$file" .toml)"
  if grep -q '^\[\[parameters\]\]' "$file"; then
    continue   # calibrations: the calibration tests run the same code under the sanitizers
  elif grep -q '^\[\[observations\]\]' "$file"; then
    verb=validate
  else
    verb=simulate
  fi
  echo "sanitize: talus $verb ${file#"$root"/}"
  "$talus" "$verb" "$file" --rocks 2 --threads 2 --seed 1 --out "$cases_out/$name" --quiet
done
echo "sanitize: the suite and every case ran clean"
