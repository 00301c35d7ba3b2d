#!/usr/bin/env bash
# The README's test command, one step after another, stopping at the first failure:
#   1. scripts/setup.sh: packages, bunny, the normal build in ./build;
#   2. the whole default suite in ./build;
#   3. an ASan + UBSan build in ./build-asan (DYNCULL_SANITIZE=address, no benchmarks) and
#      the default suite again under the sanitizers, leaks included (docs/RELIABILITY.md);
#   4. a ThreadSanitizer build in ./build-tsan (DYNCULL_SANITIZE=thread) and the default
#      suite again under it, with only Mesa llvmpipe's own races suppressed
#      (tests/sanitizers/tsan.supp).
# Long tests (label `long`: soak, fuzzing) are not part of it: scripts/long_tests.sh.
# DYNCULL_SKIP_SANITIZE=1 skips steps 3 and 4 (e.g. for a quick local check).
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/setup.sh
ctest --test-dir build --output-on-failure -j2

if [[ ${DYNCULL_SKIP_SANITIZE:-0} == 1 ]]; then
  echo "test: sanitizer build skipped (DYNCULL_SKIP_SANITIZE=1)"
  exit 0
fi
echo "test: ASan + UBSan build in build-asan"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_SANITIZE=address -DDYNCULL_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$(nproc)"
# intercept_tls_get_addr=0: GCC 12's LeakSanitizer records the dynamic TLS blocks it sees
# through __tls_get_addr, and with Debian 12's glibc one record can be garbage (a block at
# 0xfbc of 100 GB); scanning it crashed the leak checker at exit in a test that had passed,
# depending only on the process's argv/env sizes (docs/RELIABILITY.md). Without the
# interception, dynamic TLS is simply not a root: the check can only get stricter.
ASAN_OPTIONS=intercept_tls_get_addr=0:detect_leaks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1 \
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j2
echo "test: ThreadSanitizer build in build-tsan"
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNCULL_SANITIZE=thread -DDYNCULL_BUILD_BENCH=OFF \
  -DDYNCULL_BUILD_TESTS=ON >/dev/null
cmake --build build-tsan -j"$(nproc)"
TSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/tsan.supp:halt_on_error=1:second_deadlock_stack=1" \
  ctest --test-dir build-tsan --output-on-failure -j2
echo "test: all passed (default suite, and again under ASan + UBSan and under TSan)"
