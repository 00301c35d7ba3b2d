#!/usr/bin/env bash
# Many full-size bunny-swarm runs of every mode, start-up and exit included, to catch rare
# heap corruption and races (issue: "free(): corrupted unsorted chunks" in `run --mode
# simple`; docs/RELIABILITY.md, "Heap corruption in llvmpipe"). Each configuration runs
# the CLI as a user does; any non-zero exit, sanitizer report or glibc heap message fails.
#   scripts/stress_runs.sh [rounds, default 5]
# Configurations, each round, every mode (vfc, simple, full):
#   release   build/        with glibc's heap checks (libc_malloc_debug, MALLOC_CHECK_=3) and
#                           freed memory filled (MALLOC_PERTURB_), llvmpipe threads as default
#   threads   build/        LP_NUM_THREADS=4 (more rasteriser threads than cores: more preemption)
#   asan      build-asan/   AddressSanitizer + UBSan (built by scripts/test.sh)
#   tsan      build-tsan/   ThreadSanitizer (built here if missing)
# Needs the Stanford bunny (DYNCULL_ASSETS or ./assets); the npm bunny works too.
set -euo pipefail
cd "$(dirname "$0")/.."

ROUNDS=${1:-5}
FRAMES=${STRESS_FRAMES:-4}
OUT=out/stress
mkdir -p "$OUT"
MALLOC_DEBUG=$(ls /usr/lib/*/libc_malloc_debug.so.0 2>/dev/null | head -1 || true)

[[ -x build/bin/dyncull ]] || ./scripts/setup.sh
if [[ ! -x build-asan/bin/dyncull ]]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_SANITIZE=address -DDYNCULL_BUILD_BENCH=OFF >/dev/null
  cmake --build build-asan -j"$(nproc)" --target dyncull
fi
if [[ ! -x build-tsan/bin/dyncull ]]; then
  cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_SANITIZE=thread -DDYNCULL_BUILD_BENCH=OFF \
    -DDYNCULL_BUILD_TESTS=OFF >/dev/null
  cmake --build build-tsan -j"$(nproc)" --target dyncull
fi

failures=0
runs=0
one() {  # one <label> <binary> <mode> [env...]
  local label=$1 bin=$2 mode=$3
  shift 3
  local log="$OUT/${label}_${mode}_$round.log"
  local rc=0
  env "$@" "$bin" run bunnies --mode "$mode" --frames "$FRAMES" --size 640x360 --out "$OUT/$label" >"$log" 2>&1 || rc=$?
  runs=$((runs + 1))
  if [[ $rc -ne 0 ]] || grep -qE "ERROR: (Address|Thread)Sanitizer|WARNING: ThreadSanitizer|runtime error|corrupted|free\(\)|malloc\(\)" "$log"; then
    failures=$((failures + 1))
    echo "stress: FAILED ($label, mode $mode, round $round, exit $rc): $log"
  fi
}

for round in $(seq 1 "$ROUNDS"); do
  for mode in vfc simple full; do
    if [[ -n $MALLOC_DEBUG ]]; then
      one release build/bin/dyncull "$mode" LD_PRELOAD="$MALLOC_DEBUG" MALLOC_CHECK_=3 MALLOC_PERTURB_=165
    else
      one release build/bin/dyncull "$mode" MALLOC_PERTURB_=165
    fi
    one threads build/bin/dyncull "$mode" LP_NUM_THREADS=4 MALLOC_PERTURB_=165
    one asan build-asan/bin/dyncull "$mode" ASAN_OPTIONS=intercept_tls_get_addr=0:detect_leaks=1
    one tsan build-tsan/bin/dyncull "$mode" TSAN_OPTIONS=halt_on_error=0
  done
  echo "stress: round $round of $ROUNDS done ($runs runs, $failures failed)"
done
[[ $failures -eq 0 ]] || { echo "stress: $failures of $runs runs failed (logs in $OUT)"; exit 1; }
echo "stress: all $runs runs passed (logs in $OUT)"
