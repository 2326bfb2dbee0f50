#!/usr/bin/env bash
# Installs what is missing, builds algray and runs the whole test suite, then the sanitize-labelled tests and the
# fuzzers under ASan+UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."

start=$SECONDS
# Each phase line gives the wall time so far and the CPU time (user + sys) of everything run so far, apt included:
# on shared cores the CPU time is the steadier measure of what a change saved.
# (`times` into a file: in a $(...) subshell it would report the subshell's children, none.)
times_file=$(mktemp)
trap 'rm -f "$times_file"' EXIT
phase() {
  local cpu
  times > "$times_file"
  cpu=$(awk 'NR == 2 { n = 0; for (i = 1; i <= 2; i++) { split($i, t, "m"); n += t[1] * 60 + t[2] } printf "%d", n }' \
            "$times_file")
  echo "test.sh: $1 ($((SECONDS - start)) s so far, $cpu s CPU)"
}
# Ninja when it is there (scripts/install-deps.sh installs it): it compiles a target's files while the libraries it
# links are still being built, where Make waits for each library, so both cores stay busy. A tree that is already
# configured keeps its generator.
generator() {
  if [ ! -f "$1/CMakeCache.txt" ] && command -v ninja >/dev/null; then echo Ninja; fi
}

scripts/install-deps.sh test
phase "dependencies installed"
gen=$(generator build)
cmake -S . -B build ${gen:+-G "$gen"} -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=ON
cmake --build build -j"$(nproc)"
# The Python package into the system Python, where `import algray` finds it; the tests use the build tree's copy.
scripts/install-python.sh
phase "release build done"
# The same code once more under AddressSanitizer and UndefinedBehaviorSanitizer, in a clang tree of its own that
# builds only what `ctest -L sanitize` (tests/CMakeLists.txt says which) and the fuzzers need (docs/fuzzing.md).
# Debug: -O0 compiles twice as fast.
# clang++-15 is the clang PoCL itself depends on in Debian 12, and its compiler-rt (ASan, UBSan, libFuzzer) comes
# with it; any other clang++ with those runtimes will do.
cxx=
for c in clang++-15 clang++; do
  if command -v "$c" >/dev/null; then cxx=$c; break; fi
done
if [ -z "$cxx" ]; then
  echo "test.sh: clang++ not found; the sanitizer and fuzz tests need clang-15 (PoCL's; scripts/install-deps.sh" \
       "installs it)" >&2
  exit 1
fi
gen=$(generator build-sanitize)
# Its tests use the Release tree's kernel cache: the kernels are the same, so none is compiled twice.
cmake -S . -B build-sanitize ${gen:+-G "$gen"} -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER="$cxx" \
      -DALGRAY_SANITIZE=ON -DALGRAY_FUZZ=ON -DALGRAY_TEST_KERNEL_CACHE="$PWD/build/kernel-cache" \
      -DALGRAY_BUILD_FULL_WITH_CLI=OFF
# Built at the lowest priority while the Release tests run: those leave about a sixth of the two cores idle (tests
# waiting on processes, sockets and single-threaded kernel builds), which this build takes; it yields to them
# otherwise. Its log is printed if it fails.
sanitize_log=build-sanitize/build.log
# Job control gives it a process group of its own, which a failing test's exit takes down with its compilers; not
# setsid, whose new session would be a scheduling group of its own (autogroup), where nice counts for nothing.
set -m
nice -n 19 cmake --build build-sanitize -j"$(nproc)" --target algray_sanitize_tests algray_fuzzers > "$sanitize_log" 2>&1 &
sanitize_build=$!
set +m
# '|| true': set -e holds in the trap too, and the build has usually ended by then (kill then fails).
trap 'kill -- -"$sanitize_build" 2>/dev/null || true; rm -f "$times_file"' EXIT
# In parallel: tests that assert their own wall time are RUN_SERIAL (TIMED in tests/CMakeLists.txt), and the
# longest start first (COST), so the single-threaded kernel builds of one test overlap another's. Every test
# shares one kernel cache, build/kernel-cache (algray's and PoCL's). The sweeps run a seeded sample with their
# ends; their every case is the `exhaustive` label's (`ctest --test-dir build -L exhaustive`).
ctest --test-dir build --output-on-failure --timeout 900 -j"$(nproc)" -LE exhaustive
phase "full test suite passed"
if ! wait "$sanitize_build"; then
  tail -n 100 "$sanitize_log" >&2
  echo "test.sh: the sanitizer build failed (whole log: $sanitize_log)" >&2
  exit 1
fi
phase "sanitizer build done"
ctest --test-dir build-sanitize -L sanitize --output-on-failure --timeout 900 -j"$(nproc)"
phase "sanitize-labelled tests passed under the sanitizers"
# Each fuzzer runs 5 s from its seeds on one core (a smoke test of the readers; docs/fuzzing.md has the hour-long
# runs); the tests print their runs and coverage.
ctest --test-dir build-sanitize -L fuzz -j"$(nproc)" --output-on-failure --verbose
phase "fuzzers found nothing"
