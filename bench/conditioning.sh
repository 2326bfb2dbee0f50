#!/usr/bin/env bash
# Float against double, per method: how far each construction of P*(t) carries in float (Barth sextic by default).
# usage: bench/conditioning.sh [SCENE] (after cmake --build build); prints one line per configuration.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/barth_sextic.toml}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
algray=build/apps/algray/algray
"$algray" render "$scene" -o "$work/ref.exr" --width 1024 --height 768 --precision double
while IFS='|' read -r label args; do
  # shellcheck disable=SC2086
  "$algray" render "$scene" -o "$work/test.exr" --width 1024 --height 768 $args
  echo "$label: $(build/bench/exr_compare "$work/test.exr" "$work/ref.exr")"
done <<'CONFIGS'
float, Bernstein on the segment (default)|--precision float
float, power basis around the entry point|--precision float --set render.isolation=descartes
float, power basis around the eye (the paper)|--precision float --set render.isolation=descartes --set render.ray_origin=eye
double, power basis around the eye (the paper)|--precision double --set render.isolation=descartes --set render.ray_origin=eye
CONFIGS
