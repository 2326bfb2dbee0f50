#!/usr/bin/env bash
# Runs on a lent GPU machine (the device tool's `run`): unpacks .gpu/bundle.tar.xz (bench/gpu/bundle.sh), points
# the OpenCL loader at the NVIDIA driver, then lists the devices, renders, times the kernels and runs the OpenCL
# tests on the GPU within GPU_CHECK_SECONDS; everything lands in $OUT (logs.tgz, images), a summary on stdout.
# GPU_CHECK_TESTS="test_a test_b" runs only those tests and no benchmarks (a second call's rerun).
# Issue 18's steps come first (tiles_adaptive, precision_modes), as what a GPU is still wanted for.
# GPU_CHECK_SCENES names the precision table's scenes: about 30 s each on an H200, mostly NVIDIA's compiler
# building each mode's programs cold (0.5-2 s a program); the default is the three where adaptive costs most on
# the CPU (the Barth decic, the Endrass octic, the Chebyshev nonic).
# The run of 2026-12-04 (450 s) fit everything but test_kernels, test_lanes, test_shadows_batched and
# test_univariate, which need several minutes each there for the same reason.
set -uo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
OUT=${OUT:-$root/out/gpu}
budget=${GPU_CHECK_SECONDS:-400}
mkdir -p "$OUT"
logs=$(mktemp -d)
deadline=$(($(date +%s) + budget))
left() { echo $((deadline - $(date +%s))); }
# Runs a step under the time left, keeping `reserve` seconds for what follows: step NAME RESERVE CMD...
step() {
  local name=$1 reserve=$2; shift 2
  local t=$(($(left) - reserve))
  if ((t < 5)); then echo "== $name: skipped, no time left" | tee -a "$logs/summary.txt"; return; fi
  echo "== $name (up to ${t}s)" >&2
  local s=$SECONDS
  timeout "$t" "$@" > "$logs/$name.log" 2>&1
  echo "== $name: rc=$? in $((SECONDS - s))s" | tee -a "$logs/summary.txt"
}
finish() {
  tar -C "$logs" -czf "$OUT/logs.tgz" .
  echo; cat "$logs/summary.txt"
}
trap finish EXIT

bundle=/tmp/algray-bundle
rm -rf "$bundle" && mkdir -p "$bundle" && tar -C "$bundle" -xJf .gpu/bundle.tar.xz || exit 1
[ -e build ] || ln -s "$bundle/build" build
src=$(cat "$bundle/source_dir")
[ -e "$src" ] || { mkdir -p "$(dirname "$src")" && ln -s "$root" "$src"; }
export LD_LIBRARY_PATH=$bundle/lib ALGRAY_CACHE_DIR=/tmp/algray-cache PYTHONUNBUFFERED=1

# The loader reads vendor files; this image may have none, so name the driver's OpenCL library ourselves.
icd=$(ldconfig -p | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}')
[ -n "$icd" ] || icd=$(find /usr /lib /lib64 /opt 2>/dev/null -name 'libnvidia-opencl.so.1' | head -1)
{
  echo "OpenCL driver library: ${icd:-none found}"
  ls /etc/OpenCL/vendors 2>/dev/null
  grep PRETTY /etc/os-release
  nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,memory.total --format=csv
} > "$logs/env.txt" 2>&1
cat "$logs/env.txt"
# Without it (a dry run at home), the loader's own vendor files stand.
if [ -n "$icd" ]; then
  mkdir -p /tmp/icd && echo "$icd" > /tmp/icd/nvidia.icd
  export OCL_ICD_VENDORS=/tmp/icd
fi

export algray=build/apps/algray/algray logs bundle deadline
if [ -n "${GPU_CHECK_TESTS:-}" ]; then
  printf '%s\n' $GPU_CHECK_TESTS > "$bundle/tests.txt"
else
  step devices 420 "$algray" devices --stats "$logs/devices.json"
  cat "$logs/devices.log"

  # Issue 18 first, as the reason a GPU is wanted: adaptive was 2.85x float on the decic here (2026-12-04), 12 tiles
  # of 256x256 rays, each with its own second pass. Per pass, first and second pass apart (pass_split.py), with the
  # second pass in double and, as on a GPU with slow fp64, in float-float; with 256 and 1024 tiles. If the first
  # passes differ, the adaptive kernel's own checks cost the time; if the second passes do, their launches' tails.
  tiles() {
    for tile in 256 1024; do
      for fp64 in "" 1; do
        echo "--- tile_size $tile${fp64:+, ALGRAY_NO_FP64=1}"
        ALGRAY_NO_FP64=$fp64 python3 bench/pass_split.py scenes/barth_decic.toml float=float adaptive=adaptive \
          --rounds 3 --set render.tile_size=$tile | tail -4 || return 1
      done
    done
  }
  export -f tiles
  step tiles_adaptive 330 bash -c tiles
  step precision_modes 230 python3 bench/precision_modes.py --no-accuracy --runs 3 --output "$logs/RESULTS.md" \
    --json "$logs/precision_modes.json" --heading "## Precision modes on a GPU" \
    --scenes ${GPU_CHECK_SCENES:-barth_decic endrass_octic chebyshev_nonic}

  # Images to compare with the CPU's at home: full mode and preview in double, preview in adaptive.
  step render_full 215 "$algray" render scenes/barth_sextic.toml -o "$OUT/sextic_full_double.exr" -o "$OUT/sextic_full.png" \
    --precision double --stats "$logs/sextic_full.json"
  step render_preview 210 "$algray" render scenes/barth_decic.toml --preview -o "$OUT/decic_preview_double.exr" \
    --precision double --stats "$logs/decic_preview.json"
  step render_adaptive 205 "$algray" render scenes/barth_decic.toml --preview -o "$OUT/decic_preview_adaptive.exr" \
    --precision adaptive --stats "$logs/decic_adaptive.json"

  # End to end, warm: full mode to PNG, wall time of the whole process (median of 5 after one warm-up).
  e2e() {
    for scene in barth_sextic barth_decic; do
      "$algray" render "scenes/$scene.toml" -o /tmp/e2e.png >/dev/null || return 1
      for _ in 1 2 3 4 5; do
        local s; s=$(date +%s%N); "$algray" render "scenes/$scene.toml" -o /tmp/e2e.png >/dev/null || return 1
        echo "$scene $(( ($(date +%s%N) - s) / 1000000 ))"
      done
    done
  }
  export -f e2e
  step e2e_full 185 bash -c e2e

  degrees=1,2,3,4,5,6,7,8,9,10,12,16,20,24,28,32
  step degrees_double 165 python3 bench/kernel_speed.py --only degrees --degrees $degrees --side 2048 --repeat 3
  step degrees_float 145 python3 bench/kernel_speed.py --only degrees --degrees $degrees --side 2048 --repeat 3 \
    --precision float
  step surfaces_double 130 python3 bench/kernel_speed.py --only surfaces --repeat 5
fi

# The OpenCL tests, several at once (the host has cores to spare); each one's log apart.
run_tests() {
  mkdir -p "$logs/tests"
  local t=$(($(left) - 10))
  xargs -P 8 -I{} sh -c "timeout $t build/tests/{} --durations yes > '$logs/tests/{}.log' 2>&1; echo \"{} rc=\$?\"" \
    < "$bundle/tests.txt" | sort
}
export -f run_tests left
step tests 5 bash -c run_tests
cat "$logs/tests.log" >> "$logs/summary.txt"
for f in "$logs"/degrees_*.log "$logs"/surfaces_*.log "$logs"/e2e_full.log "$logs"/tiles_adaptive.log \
  "$logs"/precision_modes.log; do
  [ -f "$f" ] && { echo "--- $(basename "$f")"; cat "$f"; } >> "$logs/summary.txt"
done
