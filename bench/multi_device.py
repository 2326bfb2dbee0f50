#!/usr/bin/env python3
"""One image on two devices against one: `algray render --device 0,1` against `--device 0`, on two PoCL devices
of one thread each, whole process, runs interleaved after one warm-up each. PoCL's "basic" devices run each
kernel on the thread that enqueues it, so each device has a core of its own. Its "pthread" devices would not
do: PoCL 3.1 has one worker pool per process, sized by the first pthread device, which all of them share
(POCL_DEVICES="pthread pthread" with POCL_MAX_PTHREAD_COUNT=1 is two devices on one thread). Reports medians, the speed-up per pair (one device's time over two devices') with its
spread, each device's share of the tiles, and whether the two images are bit-identical. With --results the
table replaces its section of bench/RESULTS.md ("One image on two devices", under "Several devices, MPI and
Slurm"), with the date, machine, commit and command."""
import argparse
import datetime
import os
import statistics
import subprocess
import tempfile
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section, run_render

AREA = "## Several devices, MPI and Slurm"
HEADING = "### One image on two devices"


def identical(exr_compare, a, b):
    out = subprocess.run([str(exr_compare), str(a), str(b)], capture_output=True, text=True).stdout
    return "channels bit-identical: all" in out


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--algray", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--exr-compare", default=str(ROOT / "build/bench/exr_compare"))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scenes", nargs="*", default=["barth_decic"])
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--preview", action="store_true", help="preview mode instead of the scene as shipped")
    ap.add_argument("--results", action="store_true", help="write the table into its section of bench/RESULTS.md")
    a = ap.parse_args()
    env = dict(os.environ, POCL_DEVICES="basic basic")
    args = ["--width", str(a.width), "--height", str(a.height)] + (["--preview"] if a.preview else [])
    specs = ["0", "0,1"]
    about = (f"`POCL_DEVICES=\"basic basic\" algray render SCENE {' '.join(args)} --device D` to EXR, wall ms of "
             f"the whole process, median of {a.repeat} interleaved runs each after one warm-up; speed-up = "
             "ms(--device 0) / ms(--device 0,1) per pair (median, min-max).")
    print(f"Machine: {machine()}. {about}\n")
    table = ["| scene | 1 device ms | 2 devices ms | speed-up (median) | min-max | tiles per device | image |",
             "|---|---|---|---|---|---|---|"]
    print("\n".join(table))
    with tempfile.TemporaryDirectory() as tmp:
        work = [Path(tmp) / "one", Path(tmp) / "two"]
        for w in work:
            w.mkdir()
        for name in a.scenes:
            scene = ROOT / "scenes" / f"{name}.toml"
            for spec, w in zip(specs, work):
                run_render(a.algray, scene, args + ["--device", spec], env, w)
            times = [[], []]
            stats = None
            for _ in range(a.repeat):
                for k, (spec, w) in enumerate(zip(specs, work)):
                    ms, s = run_render(a.algray, scene, args + ["--device", spec], env, w)
                    times[k].append(ms)
                    if k == 1:
                        stats = s
            speedups = [one / two for one, two in zip(times[0], times[1])]
            tiles = "/".join(str(d["tiles"]) for d in stats["devices"])
            same = "bit-identical" if identical(a.exr_compare, work[0] / "out.exr", work[1] / "out.exr") else "DIFFERS"
            table.append(f"| {name} | {statistics.median(times[0]):.0f} | {statistics.median(times[1]):.0f} | "
                         f"{statistics.median(speedups):.2f} | {min(speedups):.2f}-{max(speedups):.2f} | {tiles} | "
                         f"{same} |")
            print(table[-1], flush=True)
    if a.results:
        lines = [HEADING, "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; commit: {commit(a.algray)}",
                 f"- Command: `{command_line()}` (after `cmake --build build --target algray exr_compare`)",
                 "- Two PoCL `basic` devices, each running its kernels on the thread that launches them, so each has "
                 f"a core. {about} Target: at least 1.8x.", ""] + table
        replace_section(RESULTS_MD, HEADING, "\n".join(lines) + "\n", under=AREA)
        print(f"wrote {RESULTS_MD}")


if __name__ == "__main__":
    main()
