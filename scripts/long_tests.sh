#!/usr/bin/env bash
# The long runs, out of the default suite (docs/RELIABILITY.md):
#   1. ctest label `long` in ./build (configuration `long`): the 10,000-frame soak;
#   2. scripts/fuzz.sh: every fuzzer for FUZZ_SECONDS (default 600) each, two at a time;
#   3. scripts/stress_runs.sh: STRESS_ROUNDS (default 5) rounds of full-size bunny runs of
#      every mode with glibc heap checks, more llvmpipe threads, ASan and TSan.
# Set-up and build first, like the test command. Takes about an hour on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/setup.sh
ctest --test-dir build --output-on-failure -C long -L long
./scripts/fuzz.sh "${FUZZ_SECONDS:-600}"
./scripts/stress_runs.sh "${STRESS_ROUNDS:-5}"
echo "long tests: all passed"
