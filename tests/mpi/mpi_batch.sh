#!/usr/bin/env bash
# test_mpi_batch: `mpirun -n 2 algray batch` on this machine. A 16-frame sweep must have every frame rendered
# exactly once, by both ranks between them, byte-identical to a single-process batch, and with --video encoded in
# the sweep's order by rank 0; a batch with one failing
# frame must report and log it and render the rest (exit 1); a bad jobs file must end every rank with exit 2 and
# nothing written. Without mpirun it fails, saying what to install.
#   mpi_batch.sh ALGRAY_BINARY WORK_DIR
set -uo pipefail
algray=$1
work=$2
rm -rf "$work"
mkdir -p "$work"/{single,mpi,failing,bad}

test_name=test_mpi_batch
source "$(dirname "$0")/../support/script_test.sh"
mpi_ready

scene=$(growing_ball_scene)
sweep='[defaults]
set = { image = { width = 160, height = 120 } }
[[job]]
name = "grow"
scene = "ball.toml"
output = "grow_{frame:02}.png"
sweep.r = { from = 0.4, to = 1.5, steps = 16 }'
for dir in single mpi failing bad; do echo "$scene" > "$work/$dir/ball.toml"; done
echo "$sweep" > "$work/single/jobs.toml"
echo "$sweep" > "$work/mpi/jobs.toml"

# The single process first: it also fills the program cache, so that both ranks start alike.
(cd "$work/single" && POCL_MAX_PTHREAD_COUNT=1 "$algray" batch jobs.toml) || fail "the single-process batch failed"
(cd "$work/mpi" && "${mpirun_2[@]}" "$algray" batch jobs.toml --stats summary.json) ||
  fail "the 2-rank batch failed (exit $?)"
status=0
python3 - "$work/mpi/jobs.log.jsonl" <<'PY' || status=1
import json, sys
entries = [json.loads(line) for line in open(sys.argv[1])]
frames = sorted(e["frame"] for e in entries)
ranks = {e["rank"] for e in entries}
problems = []
if frames != list(range(16)): problems.append(f"frames in the log: {frames}, not 0..15 once each")
if any(e["status"] != "ok" for e in entries): problems.append("a frame is not ok")
if any(e.get("ranks") != 2 for e in entries): problems.append("an entry without \"ranks\": 2")
if ranks != {0, 1}: problems.append(f"frames rendered by ranks {sorted(ranks)}, not by both 0 and 1")
for p in problems: print("test_mpi_batch:", p, file=sys.stderr)
sys.exit(1 if problems else 0)
PY
for f in $(seq -f %02g 0 15); do
  cmp -s "$work/single/grow_$f.png" "$work/mpi/grow_$f.png" || { echo "frame $f differs or is missing" >&2; status=1; }
done
grep -q '"ok": 16' "$work/mpi/summary.json" || { echo "the summary does not count 16 frames ok" >&2; status=1; }
[ $status = 0 ] || fail "the 2-rank sweep is wrong (above)"

# --video under MPI: both ranks render, rank 0's one writer encodes the frames in the sweep's order. Each decoded
# frame must be nearest to its own single-process PNG (the frames differ from each other by far more than H.264).
command -v ffmpeg >/dev/null || fail "ffmpeg is missing (scripts/install-deps.sh test installs it)"
(cd "$work/mpi" && "${mpirun_2[@]}" "$algray" batch jobs.toml --log video.jsonl --video sweep.mp4 2> video.txt) ||
  fail "the 2-rank --video batch failed: $(cat "$work/mpi/video.txt")"
python3 - "$work/mpi/sweep.mp4" "$work/single" "$work/mpi/video.jsonl" <<'PY' || fail "the 2-rank video is wrong (above)"
import json, subprocess, sys
def frames(path):
    return subprocess.run(["ffmpeg", "-v", "error", "-i", path, "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                          capture_output=True, check=True).stdout
size = 160 * 120 * 3
video = frames(sys.argv[1])
pngs = [frames(f"{sys.argv[2]}/grow_{i:02}.png") for i in range(16)]
problems = [] if len(video) == 16 * size else [f"{len(video) / size} frames in the video, not 16"]
for i in range(len(video) // size):
    frame = video[i * size:(i + 1) * size]
    nearest = min(range(16), key=lambda k: sum(abs(a - b) for a, b in zip(frame[::7], pngs[k][::7])))
    if nearest != i: problems.append(f"video frame {i} is nearest to PNG {nearest}")
if {json.loads(l)["rank"] for l in open(sys.argv[3])} != {0, 1}: problems.append("not both ranks rendered")
for p in problems: print("test_mpi_batch:", p, file=sys.stderr)
sys.exit(1 if problems else 0)
PY

# One failing frame among six: reported on rank 0's stderr, logged with its error, the rest rendered.
cat > "$work/failing/jobs.toml" <<'JOBS'
[defaults]
set = { image = { width = 64, height = 48 } }
[[job]]
name = "grow"
scene = "ball.toml"
output = "grow_{frame}.png"
sweep.r = { from = 0.5, to = 1, steps = 5 }
[[job]]
name = "bad"
scene = "ball.toml"
set = { r = "huge" }
output = "bad.png"
JOBS
(cd "$work/failing" && "${mpirun_2[@]}" "$algray" batch jobs.toml 2> stderr.txt)
code=$?
[ $code = 1 ] || fail "a batch with a failing frame exited $code, not 1: $(cat "$work/failing/stderr.txt")"
grep -q "job bad frame 0 failed" "$work/failing/stderr.txt" || fail "the failing frame was not reported: $(cat "$work/failing/stderr.txt")"
[ "$(grep -c "job bad frame 0 failed" "$work/failing/stderr.txt")" = 1 ] || fail "the failure was reported more than once"
python3 - "$work/failing/jobs.log.jsonl" <<'PY' || fail "the failing batch's log is wrong (above)"
import json, sys
entries = {(e["job"], e["frame"]): e for e in map(json.loads, open(sys.argv[1]))}
problems = []
if len(entries) != 6: problems.append(f"{len(entries)} frames in the log, not 6")
bad = entries.get(("bad", 0), {})
if bad.get("status") != "failed" or "must be a number" not in bad.get("error", ""): problems.append(f"bad frame: {bad}")
if bad.get("rank") not in (0, 1): problems.append("the failed frame does not say which rank tried it")
if any(entries.get(("grow", f), {}).get("status") != "ok" for f in range(5)): problems.append("a good frame is not ok")
for p in problems: print("test_mpi_batch:", p, file=sys.stderr)
sys.exit(1 if problems else 0)
PY
for f in 0 1 2 3 4; do [ -f "$work/failing/grow_$f.png" ] || fail "grow_$f.png was not rendered"; done
[ ! -e "$work/failing/bad.png" ] || fail "the failing frame left bad.png"

# Bad input: every rank finds it and exits 2 before anything renders, without waiting for the others forever.
printf '[[job]]\nscene = 3\noutput = "x.png"\n' > "$work/bad/jobs.toml"
(cd "$work/bad" && "${mpirun_2[@]}" "$algray" batch jobs.toml 2> stderr.txt)
code=$?
[ $code = 2 ] || fail "a bad jobs file exited $code, not 2: $(cat "$work/bad/stderr.txt")"
grep -q "jobs.toml:2:9" "$work/bad/stderr.txt" || fail "the jobs file's error does not say where: $(cat "$work/bad/stderr.txt")"
[ ! -e "$work/bad/jobs.log.jsonl" ] || fail "a refused batch wrote its log"
(cd "$work/mpi" && "${mpirun_2[@]}" "$algray" batch jobs.toml --shard 0/2 2> shard.txt)
code=$?
[ $code = 2 ] || fail "--shard under MPI exited $code, not 2"
grep -q "does not combine with MPI" "$work/mpi/shard.txt" || fail "--shard under MPI was not refused: $(cat "$work/mpi/shard.txt")"
echo "test_mpi_batch: 2 ranks, 16 frames each once and identical to one process; their --video in order; a failing frame logged; bad input exit 2"
