#!/usr/bin/env python3
"""One image across MPI ranks: `mpirun -n 2 algray render` against `mpirun -n 1`, each rank with a one-thread
PoCL (POCL_MAX_PTHREAD_COUNT=1), so that two ranks have a core each. The scene as shipped (full mode) at
1024x768 by default. Runs alternate after one warm-up each; each figure is the whole mpirun's wall time,
start-up included. Checks that the two images are bit-identical in every channel, and reports each rank's
share of the bands. Writes its section of bench/RESULTS.md ("One image across 2 MPI ranks", under "Several
devices, MPI and Slurm"), with the date, machine, commit and command."""
import argparse
import datetime
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_section

AREA = "## Several devices, MPI and Slurm"
HEADING = "### One image across 2 MPI ranks"


def mpirun(ranks, binary, scene, args, out, stats):
    return ["mpirun", "--oversubscribe", "--allow-run-as-root", "-n", str(ranks), "-x", "POCL_MAX_PTHREAD_COUNT=1",
            str(binary), "render", str(scene), "-o", str(out), "--stats", str(stats)] + args


def timed(cmd):
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--exr-compare", default=ROOT / "build/bench/exr_compare")
    ap.add_argument("--scene", default="barth_decic")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--results", default=ROOT / "bench/RESULTS.md")
    a = ap.parse_args()
    scene = ROOT / "scenes" / f"{a.scene}.toml"
    args = ["--width", str(a.width), "--height", str(a.height)]
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        out = {r: work / f"ranks{r}.exr" for r in (1, 2)}
        stats = {r: work / f"ranks{r}.json" for r in (1, 2)}
        for r in (1, 2):
            timed(mpirun(r, a.binary, scene, args, out[r], stats[r]))
        times = {1: [], 2: []}
        for run in range(a.runs):
            for r in (1, 2):
                times[r].append(timed(mpirun(r, a.binary, scene, args, out[r], stats[r])))
                print(f"run {run + 1}, {r} rank(s): {times[r][-1]:.2f} s", flush=True)
        compared = subprocess.run([str(a.exr_compare), str(out[1]), str(out[2])], capture_output=True, text=True)
        same = "channels bit-identical: all" in compared.stdout
        devices = json.loads(stats[2].read_text())["devices"]
    tiles = "/".join(f"rank {d['rank']}: {d['tiles']}" for d in devices)
    median = {r: statistics.median(t) for r, t in times.items()}
    pairs = [one / two for one, two in zip(times[1], times[2])]
    cmd = " ".join(mpirun(2, "algray", f"scenes/{a.scene}.toml", args, "out.exr", "stats.json"))
    section = f"""{HEADING}

- Date: {datetime.date.today().isoformat()}; machine: {machine()}; device: PoCL (CPU), one thread per rank;
  commit: {commit(a.binary)}.
- Command: `{command_line()}` (after `cmake --build build --target algray exr_compare`): `{cmd}`
  against the same with `-n 1`, alternating, {a.runs} runs each after one warm-up; program cache warm. Wall time
  of the whole mpirun.

| ranks | median | spread |
|---|---|---|
| 1 | {median[1]:.2f} s | {min(times[1]):.2f}-{max(times[1]):.2f} s |
| 2 | {median[2]:.2f} s | {min(times[2]):.2f}-{max(times[2]):.2f} s |

- Speed-up (1 rank / 2 ranks, per pair): **{statistics.median(pairs):.2f}x** median, {min(pairs):.2f}-{max(pairs):.2f}
  (target: at least 1.8x). Tiles per rank's devices: {tiles}. Images {'bit-identical in every channel' if same else 'DIFFER'}.
"""
    replace_section(a.results, HEADING, section, under=AREA)
    print(section)


if __name__ == "__main__":
    main()
