#!/usr/bin/env bash
# Installs what is missing (plus matplotlib for the plots), builds algray and runs the solver benchmarks of
# issue 4: bench/solvers.py with the arguments given (--quick, --only PART..., --device SPEC, --plot-only).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh test
if ! /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-matplotlib
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target solver_bench
# Debian's own python3, where apt put matplotlib (a python3 earlier on PATH may lack it).
exec /usr/bin/python3 bench/solvers.py "$@"
