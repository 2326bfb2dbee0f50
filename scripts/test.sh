#!/usr/bin/env bash
# Installs what is missing, builds algray and runs the whole test suite (Catch2 through CTest, on PoCL).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
cd build
ctest --output-on-failure --timeout 900
