#!/usr/bin/env bash
# Fuzzes every file format dyncull reads or writes with libFuzzer (ASan + UBSan):
#   scripts/fuzz.sh [seconds per target, default 600] [targets..., default all]
# targets: fuzz_ply fuzz_obj fuzz_gltf fuzz_scene_cache fuzz_subdivision_file. Two run at
# a time (2 cores); FUZZ_PARALLEL=1 runs one at a time on a shared machine.
# Seeds: the valid files build-fuzz/bin/fuzz_make_seeds writes (glTF, GLB, PLY, OBJ) and,
# when ./build has the unit tests (scripts/setup.sh), the files they write
# (DYNCULL_FUZZ_SEEDS); the scene cache and subdivision file seeds exist only that way.
# The text formats get their dictionary (fuzz/<format>.dict) and a structure-aware
# mutator (fuzz/numeric_mutator.hpp); see docs/RELIABILITY.md. Corpora grow in
# out/fuzz/<target>/corpus across runs; a crash, hang (>10 s per input) or out-of-memory
# (>2 GiB) leaves its input in out/fuzz/<target>/ and makes the script exit 1. Reproduce
# one with: build-fuzz/bin/<target> <input file>.
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_PER_TARGET=${1:-600}
shift || true
TARGETS=("$@")
((${#TARGETS[@]})) || TARGETS=(fuzz_ply fuzz_obj fuzz_gltf fuzz_scene_cache fuzz_subdivision_file)

PARALLEL=${FUZZ_PARALLEL:-2}

command -v clang++ >/dev/null || { echo "fuzz: needs clang (apt-get install clang)" >&2; exit 2; }
have_tests=0
[[ -x build/bin/objects_tests && -x build/bin/demos_tests && -x build/bin/test_subdivision ]] && have_tests=1
if ((!have_tests)); then
  for t in "${TARGETS[@]}"; do
    [[ $t == fuzz_scene_cache || $t == fuzz_subdivision_file ]] &&
      { echo "fuzz: $t's seeds come from ./build's tests: run scripts/setup.sh first" >&2; exit 2; }
  done
  echo "fuzz: no ./build tests, seeding from fuzz_make_seeds only"
fi

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_FUZZ=ON \
  -DDYNCULL_BUILD_TESTS=OFF -DDYNCULL_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$PARALLEL" --target "${TARGETS[@]}" fuzz_make_seeds

OUT=out/fuzz
SEEDS=$OUT/seeds
rm -rf "$SEEDS"
mkdir -p "$SEEDS"
build-fuzz/bin/fuzz_make_seeds "$SEEDS"
if ((have_tests)); then
  DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/objects_tests --gtest_filter='Ply*:Obj*:Gltf*:SceneLoader*' >/dev/null
  DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/demos_tests --gtest_filter='SceneCacheFile.TinySceneRoundTripsAndSeedsTheFuzzer' >/dev/null
  DYNCULL_FUZZ_SEEDS=$PWD/$SEEDS build/bin/test_subdivision --gtest_filter='SubdivisionFileTest.RoundTrip' >/dev/null
fi

seed_dirs() {
  case $1 in
    fuzz_ply) echo "$SEEDS/ply" ;;
    fuzz_obj) echo "$SEEDS/obj" ;;
    fuzz_gltf) echo "$SEEDS/gltf $SEEDS/glb" ;;
    fuzz_scene_cache) echo "$SEEDS/dcs" ;;
    fuzz_subdivision_file) echo "$SEEDS/dsub" ;;
  esac
}

# Per-target libFuzzer options: the dictionary; for glTF room for 15,000-deep nesting.
target_flags() {
  case $1 in
    fuzz_ply) echo "-dict=fuzz/ply.dict" ;;
    fuzz_obj) echo "-dict=fuzz/obj.dict" ;;
    fuzz_gltf) echo "-dict=fuzz/gltf.dict -max_len=32768" ;;
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
      -artifact_prefix="$dir/" -print_final_stats=1 $(target_flags "$t") "$dir/corpus" "${seeds[@]}" >"$dir/log.txt" 2>&1
}

pids=()
status=0
for t in "${TARGETS[@]}"; do
  run_one "$t" &
  pids+=($!)
  if ((${#pids[@]} == PARALLEL)); then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
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
