#!/usr/bin/env bash
# Installs what is missing, builds algray, and renders the built-in default scene (the Barth sextic) to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
# The Python package into the system Python: `python3 -c "import algray"` works from here on.
scripts/install-python.sh
mkdir -p out
./build/apps/algray/algray render -o out/barth_sextic.exr -o out/barth_sextic.png --stats out/barth_sextic.json
echo "wrote out/barth_sextic.exr, out/barth_sextic.png and out/barth_sextic.json"
