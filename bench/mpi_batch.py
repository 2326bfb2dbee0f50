#!/usr/bin/env python3
"""MPI batch benchmark (issue 17): a 20-frame preview sweep of the Kummer quartic's mu2 (as bench/batch.py
sweeps it) by `mpirun -n 1` and by `mpirun -n 2 algray batch`, each rank with a one-thread PoCL, so that two
ranks have one core each; writes its section of bench/RESULTS.md ("A batch across 2 MPI ranks", under "Several
devices, MPI and Slurm"), with the date, machine, commit and command.

The 1-rank and 2-rank runs alternate, so that a shared machine's load falls on both alike; each figure is the
whole mpirun's wall time, start-up included. The program cache is warm for all (one batch beforehand).
"""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_section

SCENE = ROOT / "scenes/kummer.toml"
AREA = "## Several devices, MPI and Slurm"
HEADING = "### A batch across 2 MPI ranks"


def write_jobs(workdir, frames, size):
    jobs = workdir / "jobs.toml"
    jobs.write_text(
        f'[[job]]\nname = "kummer"\nscene = "{SCENE}"\n'
        f'set = {{ "image.width" = {size}, "image.height" = {size}, "render.preview" = true }}\n'
        f'output = "kummer_{{frame:02}}.png"\nsweep.mu2 = {{ from = 1.0, to = 2.9, steps = {frames} }}\n')
    return jobs


def mpirun(ranks, binary, jobs):
    return ["mpirun", "--oversubscribe", "--allow-run-as-root", "-n", str(ranks), "-x", "POCL_MAX_PTHREAD_COUNT=1",
            str(binary), "batch", str(jobs)]


def timed(cmd, workdir):
    start = time.perf_counter()
    subprocess.run(cmd, cwd=workdir, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--size", type=int, default=1536)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--results", default=ROOT / "bench/RESULTS.md")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        jobs = write_jobs(workdir, args.frames, args.size)
        timed(mpirun(1, args.binary, jobs), workdir)  # fills the program cache
        times = {1: [], 2: []}
        frame_ms = {1: [], 2: []}
        for run in range(args.runs):
            for ranks in (1, 2):
                times[ranks].append(timed(mpirun(ranks, args.binary, jobs), workdir))
                log = [json.loads(line) for line in (workdir / "jobs.log.jsonl").read_text().splitlines()]
                assert len(log) == args.frames and all(e["status"] == "ok" for e in log), "a frame failed"
                assert {e["rank"] for e in log} == set(range(ranks)), "a rank rendered nothing"
                frame_ms[ranks] += [e["ms"] for e in log]
                print(f"run {run + 1}, {ranks} rank(s): {times[ranks][-1]:.2f} s", flush=True)
    median = {r: statistics.median(t) for r, t in times.items()}
    ratio = median[1] / median[2]
    spread = lambda t: f"{min(t):.2f}-{max(t):.2f} s"
    cmd = " ".join(mpirun(2, "algray", "jobs.toml"))
    section = f"""{HEADING}

- Date: {datetime.date.today().isoformat()}; machine: {machine()}; device: PoCL (CPU), one thread per rank;
  commit: {commit(args.binary)}.
- Command: `{command_line()}` (after `cmake --build build --target algray`), which runs `{cmd}` and the
  same with `-n 1`, alternating, {args.runs} runs each.
- {args.frames} frames of `scenes/kummer.toml` at {args.size}x{args.size}, preview (2x2 antialiased camera rays),
  mu2 swept from 1.0 to 2.9; program cache warm. Wall time of the whole mpirun, start-up included.

| ranks | median | spread ({args.runs} runs) | median frame (logs) |
|---|---|---|---|
| 1 | {median[1]:.2f} s | {spread(times[1])} | {statistics.median(frame_ms[1]):.0f} ms |
| 2 | {median[2]:.2f} s | {spread(times[2])} | {statistics.median(frame_ms[2]):.0f} ms |

- Speed-up (median 1 rank / median 2 ranks): **{ratio:.2f}x** (target: at least 1.8x).
"""
    replace_section(args.results, HEADING, section, under=AREA)
    print(section)


if __name__ == "__main__":
    main()
