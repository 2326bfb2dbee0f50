#!/usr/bin/env bash
# test_mpi_render: `mpirun -n 2 algray render` on this machine. The image must be the single process's, bit for
# bit in every EXR channel and byte for byte as a PNG, with both ranks' devices in its stats; a rank whose device
# does not open must fail the render on every rank with nothing written; a rank that starts late must still render
# a band; bad input must end every rank with exit 2 and nothing written. Without mpirun it fails, saying what to
# install.
#   mpi_render.sh ALGRAY_BINARY EXR_COMPARE SOURCE_DIR WORK_DIR
set -uo pipefail
algray=$1
exr_compare=$2
source_dir=$3
work=$4
rm -rf "$work"
mkdir -p "$work"

test_name=test_mpi_render
source "$(dirname "$0")/../support/script_test.sh"
mpi_ready
cd "$work" || fail "no work directory"

# Everything that crosses a band's edge: adaptive antialiasing (its choice there needs the row beyond), two
# surfaces, bounces and an area light's shadows. Odd sizes, so that bands and tiles do not divide the image.
scene=$source_dir/scenes/examples/ball_and_ring.toml
size=(--width 97 --height 71 --set antialias.adaptive=true --set antialias.samples=3)
POCL_MAX_PTHREAD_COUNT=1 "$algray" render "$scene" "${size[@]}" -o single.exr -o single.png ||
  fail "the single-process render failed"
"${mpirun_2[@]}" "$algray" render "$scene" "${size[@]}" -o mpi.exr -o mpi.png --stats mpi.json ||
  fail "the 2-rank render failed (exit $?)"
compared=$("$exr_compare" single.exr mpi.exr) || fail "exr_compare failed: $compared"
grep -q "channels bit-identical: all" <<<"$compared" || fail "the 2-rank EXR differs from the single process's: $compared"
cmp -s single.png mpi.png || fail "the 2-rank PNG differs from the single process's"
python3 - mpi.json <<'PY' || fail "the 2-rank stats are wrong (above)"
import json, sys
stats = json.load(open(sys.argv[1]))
devices = stats["devices"]
problems = []
if sorted({d["rank"] for d in devices}) != [0, 1]: problems.append(f"devices of ranks {[d['rank'] for d in devices]}")
if any(d["tiles"] <= 0 or d["rays"] <= 0 for d in devices): problems.append(f"a rank traced nothing: {devices}")
if stats["pixels"]["count"] != 97 * 71: problems.append(f"pixels counted {stats['pixels']['count']}, not 97 x 71")
if sum(d["rays"] for d in devices) != sum(p["rays"] for p in stats["passes"]):
    problems.append("the ranks' rays do not add up to the passes'")
for p in problems: print("test_mpi_render:", p, file=sys.stderr)
sys.exit(1 if problems else 0)
PY

# A rank that starts late (its programs built from source while rank 0's come from the cache the single render
# filled) still renders the band kept for it: rank 0 used to render the whole image before it asked.
timeout 120 mpirun --oversubscribe --allow-run-as-root -x POCL_MAX_PTHREAD_COUNT=1 \
  -n 1 "$algray" render "$scene" "${size[@]}" -o late.exr --stats late.json : \
  -n 1 "$algray" render "$scene" "${size[@]}" -o late.exr --no-cache || fail "the render with a late rank failed"
python3 - late.json <<'PY' || fail "the late rank rendered nothing (above)"
import json, sys
devices = json.load(open(sys.argv[1]))["devices"]
late = [d for d in devices if d["rank"] == 1]
if not late or late[0]["tiles"] <= 0:
    print("test_mpi_render: the late rank traced nothing:", devices, file=sys.stderr)
    sys.exit(1)
PY
compared=$("$exr_compare" single.exr late.exr) || fail "exr_compare failed: $compared"
grep -q "channels bit-identical: all" <<<"$compared" || fail "the late-rank EXR differs from the single process's: $compared"

# Rank 1 cannot open its device: the render fails on both ranks (exit 1), naming the rank, and writes nothing.
timeout 120 mpirun --oversubscribe --allow-run-as-root -x POCL_MAX_PTHREAD_COUNT=1 \
  -n 1 "$algray" render "$scene" "${size[@]}" -o lost.exr : \
  -n 1 "$algray" render "$scene" "${size[@]}" -o lost.exr --device 99 2>lost.err
code=$?
[ $code -ne 0 ] && [ $code -ne 124 ] || fail "a rank without a device: exit $code, expected a failure (not a timeout)"
grep -q "rank 1" lost.err || fail "the failure does not name rank 1: $(cat lost.err)"
ls lost.exr* >/dev/null 2>&1 && fail "a failed render left $(ls lost.exr*)"

# Bad input: every rank exits 2 and nothing is written.
"${mpirun_2[@]}" "$algray" render no-such-scene.toml -o bad.exr 2>bad.err
code=$?
[ $code -eq 2 ] || fail "a missing scene: exit $code, expected 2: $(cat bad.err)"
ls bad.exr* >/dev/null 2>&1 && fail "bad input left $(ls bad.exr*)"
echo "test_mpi_render: passed"
