#!/usr/bin/env bash
# Installs what is missing, builds algray and runs the whole test suite, then the fast tests and fuzzers under ASan+UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."

start=$SECONDS
phase() { echo "test.sh: $1 ($((SECONDS - start)) s so far)"; }

scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
phase "release build done"
ctest --test-dir build --output-on-failure --timeout 900
phase "full test suite passed"

# The same code once more under AddressSanitizer and UndefinedBehaviorSanitizer, in a clang tree of its own that
# builds only what `ctest -L fast` and the fuzzers need (docs/fuzzing.md). Debug: -O0 compiles twice as fast.
if ! command -v clang++ >/dev/null; then
  echo "test.sh: clang++ not found; the sanitizer and fuzz tests need clang and libclang-rt-14-dev" \
       "(scripts/install-deps.sh installs them)" >&2
  exit 1
fi
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++ -DALGRAY_SANITIZE=ON -DALGRAY_FUZZ=ON
cmake --build build-sanitize -j"$(nproc)" --target algray_fast_tests algray_fuzzers
phase "sanitizer build done"
ctest --test-dir build-sanitize -L fast --output-on-failure --timeout 900
phase "fast tests passed under the sanitizers"
# Each fuzzer runs 30 s from its seeds on one core; the tests print their runs and coverage.
ctest --test-dir build-sanitize -L fuzz -j"$(nproc)" --output-on-failure --verbose
phase "fuzzers found nothing"
