#!/usr/bin/env bash
# Installs what is missing for a render, builds the algray command alone, and renders the built-in default scene
# (the Barth sextic) to out/. The tests, the Python package, MPI and the browser come with scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh render
# Ninja compiles a target's files while the libraries it links are still being built; a configured tree keeps
# its generator. No tests here: their Catch2 and their 40 programs are scripts/test.sh's.
gen=
if [ ! -f build/CMakeCache.txt ]; then gen=Ninja; fi
cmake -S . -B build ${gen:+-G "$gen"} -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF
cmake --build build -j"$(nproc)" --target algray
mkdir -p out
./build/apps/algray/algray render -o out/barth_sextic.exr -o out/barth_sextic.png --stats out/barth_sextic.json
