#!/usr/bin/env bash
# Does the glTF fuzzer (re)discover a bug? Runs fuzz_gltf, structure-aware, on one core
# from fresh seeds (fuzz_make_seeds) with fuzz/gltf.dict for at most N seconds:
#   scripts/fuzz_rediscover.sh [seconds, default 600] [--plain | --no-nesting] [libFuzzer flags...]
# Exit 0 iff it found a crash (input left in out/fuzz-rediscover/, its kind printed), 1 if
# it did not, 2 on a set-up error. --plain: same binary and seeds, but no dictionary and
# the custom mutator reduced to plain LLVMFuzzerMutate (DYNCULL_FUZZ_PLAIN=1), the
# byte-level baseline. --no-nesting: no deep-nesting mutation (DYNCULL_FUZZ_NO_NESTING=1),
# to look for the offset overflows on a tree where tinygltf's stack overflow is not fixed.
#
# To check that fuzzing finds a loader bug once its fix is reverted (issue 19):
#   git revert --no-commit <fix commit>
#   scripts/fuzz_rediscover.sh 600; echo "found: $?"   # expect 0 ("found: 0")
#   git revert --abort                                  # back to the fixed tree
# and on the fixed tree the same command should exit 1 (nothing found in the budget).
# The corpus is not kept between runs, so every run starts from the same seeds. One
# in-process fuzzer (no -jobs/-workers: those fork workers), so one core.
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_BUDGET=${1:-600}
shift || true
PLAIN=0 NO_NESTING=0
case ${1:-} in
  --plain) PLAIN=1; shift ;;
  --no-nesting) NO_NESTING=1; shift ;;
esac

command -v clang++ >/dev/null || { echo "fuzz_rediscover: needs clang" >&2; exit 2; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_FUZZ=ON \
  -DDYNCULL_BUILD_TESTS=OFF -DDYNCULL_BUILD_BENCH=OFF >/dev/null || exit 2
cmake --build build-fuzz -j1 --target fuzz_gltf fuzz_make_seeds >/dev/null || exit 2

OUT=out/fuzz-rediscover
rm -rf "$OUT"
mkdir -p "$OUT/corpus"
build-fuzz/bin/fuzz_make_seeds "$OUT/seeds" || exit 2

flags=(-max_total_time="$SECONDS_BUDGET" -timeout=10 -rss_limit_mb=2048 -max_len=32768
  -artifact_prefix="$OUT/" -print_final_stats=1)
((PLAIN)) || flags+=(-dict=fuzz/gltf.dict)
echo "fuzz_rediscover: fuzz_gltf for at most ${SECONDS_BUDGET}s ($( ((PLAIN)) && echo plain || echo structure-aware)), log $OUT/log.txt"
start=$(date +%s.%N)
# libFuzzer stops at the first failure; its exit code is not needed, the artifact is.
DYNCULL_FUZZ_PLAIN=$PLAIN DYNCULL_FUZZ_NO_NESTING=$NO_NESTING ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  build-fuzz/bin/fuzz_gltf "${flags[@]}" "$@" "$OUT/corpus" "$OUT/seeds/gltf" "$OUT/seeds/glb" >"$OUT/log.txt" 2>&1 || true
elapsed=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')

artifact=$(find "$OUT" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \) | head -1)
if [[ -n $artifact ]]; then
  kind=$(grep -m1 -o 'SUMMARY: .*\|loader contract violated.*' "$OUT/log.txt" || echo "?")
  echo "fuzz_rediscover: FOUND after ${elapsed}s: $kind"
  echo "fuzz_rediscover: input $artifact (reproduce: build-fuzz/bin/fuzz_gltf $artifact)"
  exit 0
fi
echo "fuzz_rediscover: nothing found in ${SECONDS_BUDGET}s ($(grep -o 'stat::number_of_executed_units: *[0-9]*' "$OUT/log.txt" || echo '?'))"
exit 1
