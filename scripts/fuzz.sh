#!/usr/bin/env bash
# Fuzzes every file format dyncull reads or writes with libFuzzer (ASan + UBSan):
#   scripts/fuzz.sh [seconds per target, default 600] [targets..., default all]
# targets: fuzz_ply fuzz_obj fuzz_gltf fuzz_scene_cache fuzz_subdivision_file. Two run at
# a time (2 cores).
# Seeds are the files the unit tests write (DYNCULL_FUZZ_SEEDS), taken from ./build, so run
# scripts/setup.sh first. Corpora grow in out/fuzz/<target>/corpus across runs; a crash,
# hang (>10 s per input) or out-of-memory (>2 GiB) leaves its input in out/fuzz/<target>/
# and makes the script exit 1. Reproduce one with: build-fuzz/bin/<target> <input file>.
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_PER_TARGET=${1:-600}
shift || true
TARGETS=("$@")
((${#TARGETS[@]})) || TARGETS=(fuzz_ply fuzz_obj fuzz_gltf fuzz_scene_cache fuzz_subdivision_file)

command -v clang++ >/dev/null || { echo "fuzz: needs clang (apt-get install clang)" >&2; exit 2; }
[[ -x build/bin/objects_tests && -x build/bin/demos_tests && -x build/bin/test_subdivision ]] || { echo "fuzz: run scripts/setup.sh first (seeds come from ./build's tests)" >&2; exit 2; }

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_FUZZ=ON \
  -DDYNCULL_BUILD_TESTS=OFF -DDYNCULL_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "${TARGETS[@]}"

OUT=out/fuzz
SEEDS=$OUT/seeds
rm -rf "$SEEDS"
mkdir -p "$SEEDS"
DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/objects_tests --gtest_filter='Ply*:Obj*:Gltf*:SceneLoader*' >/dev/null
DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/demos_tests --gtest_filter='SceneCacheFile.TinySceneRoundTripsAndSeedsTheFuzzer' >/dev/null
DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/test_subdivision --gtest_filter='SubdivisionFileTest.RoundTrip' >/dev/null

seed_dirs() {
  case $1 in
    fuzz_ply) echo "$SEEDS/ply" ;;
    fuzz_obj) echo "$SEEDS/obj" ;;
    fuzz_gltf) echo "$SEEDS/gltf $SEEDS/glb" ;;
    fuzz_scene_cache) echo "$SEEDS/dcs" ;;
    fuzz_subdivision_file) echo "$SEEDS/dsub" ;;
  esac
}

run_one() {
  local t=$1 dir=$OUT/$1
  mkdir -p "$dir/corpus"
  local seeds=()
  for d in $(seed_dirs "$t"); do [[ -d $d ]] && seeds+=("$d"); done
  echo "fuzz: $t for ${SECONDS_PER_TARGET}s, $(find "${seeds[@]}" -type f | wc -l) seed files"
  # Fuzzing ends at the first failure; the exit code says whether there was one.
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    build-fuzz/bin/"$t" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$dir/" -print_final_stats=1 "$dir/corpus" "${seeds[@]}" >"$dir/log.txt" 2>&1
}

pids=()
status=0
for t in "${TARGETS[@]}"; do
  run_one "$t" &
  pids+=($!)
  if ((${#pids[@]} == 2)); then
    wait "${pids[0]}" || status=1
    pids=("${pids[1]}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done

for t in "${TARGETS[@]}"; do
  dir=$OUT/$t
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$dir/log.txt" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$dir/log.txt" | tail -1 | grep -o '[0-9]*' || echo "?")
  found=$(find "$dir" -maxdepth 1 -name 'crash-*' -o -maxdepth 1 -name 'timeout-*' -o -maxdepth 1 -name 'oom-*' -o -maxdepth 1 -name 'leak-*' | wc -l)
  echo "fuzz: $t executions=$runs coverage=$cov corpus=$(ls "$dir/corpus" | wc -l) failures=$found (log $dir/log.txt)"
  ((found == 0)) || status=1
done
exit $status
