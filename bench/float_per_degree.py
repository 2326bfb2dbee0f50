#!/usr/bin/env python3
"""Issue 44's goal 2: float's rays per second against double's, per degree, on the seeded random surfaces of
kernel_speed.py: camera rays (the primary pass, preview) and shadow rays (the shadow pass of the same surface lit by
one 3x3 area light, one camera ray per pixel). Each pass's device time includes its second pass (plain float
redoes what adaptive's float kernels doubt: render_plan.h, float_measures_noise). Rounds alternate the order of
the two precisions after a warm-up round; the table gives medians and float's rate over double's (target: 1.5x
at every degree).

With --results it writes its section of bench/RESULTS.md ("Float against double, per degree", under "Rays per
second per degree") with the date, machine, commit and command.
"""
import argparse
import datetime
import statistics
import tempfile
from pathlib import Path

from bench_common import (ROOT, command_line, commit, machine, parse_degrees, replace_section, run_frames,
                          run_render)
from kernel_speed import random_surface

AREA = "## Rays per second per degree"
HEADING = "### Float against double, per degree"
LIGHT = ("[[light]]\ntype = \"rectangle\"\nposition = [2, 4, 5]\nedge_u = [0.5, 0, 0]\nedge_v = [0, 0.5, 0]\n"
         "samples = 3\n")
PRECISIONS = ["double", "float"]


def pass_ms(stats, name):
    return sum(p["kernel_ms"] for p in stats["passes"] if p["name"] == name)


def measure(binary, scene, runs, frames, work):
    """Median primary and shadow ms per precision over `runs` alternating rounds after a warm-up round; with
    frames > 1 each round's figure is the median of that many frames in one process (run_frames), whose first,
    uncounted frame is the warm-up."""
    ms = {p: {"primary": [], "shadow": []} for p in PRECISIONS}
    args = ["--precision", None, "--set", "antialias.samples=1"]
    for r in range(-1 if frames == 1 else 0, runs):
        for precision in (PRECISIONS if r % 2 == 0 else PRECISIONS[::-1]):
            args[1] = precision
            every = (run_frames(binary, scene, args, None, work, frames) if frames > 1
                     else [run_render(binary, scene, args, None, work)[1]])
            if r >= 0:
                for name in ("primary", "shadow"):
                    ms[precision][name].append(statistics.median(pass_ms(stats, name) for stats in every))
    return {p: {n: statistics.median(v) for n, v in d.items()} for p, d in ms.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--side", type=int, default=2048, help="side x side camera rays")
    ap.add_argument("--frames", type=int, default=2,
                    help="frames per precision and round in one process, their median the round's figure (1: one "
                         "`algray render` process per figure after a warm-up round, as before 2026-12-07)")
    ap.add_argument("--degrees", default="1,2,3,4,5,6,8,12,15,16,24,32", help="e.g. 1-32 or 2,6,10")
    ap.add_argument("--results", action="store_true", help="write the section of bench/RESULTS.md")
    a = ap.parse_args()
    degrees = parse_degrees(a.degrees)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for d in degrees:
            scene = work / f"random{d}.toml"
            scene.write_text(random_surface(d, 1000 + d, a.side) + LIGHT)
            m = measure(a.binary, scene, a.runs, a.frames, work)
            row = (f"| {d} | {m['double']['primary']:.1f} | {m['float']['primary']:.1f} | "
                   f"{m['double']['primary'] / m['float']['primary']:.2f}x | {m['double']['shadow']:.1f} | "
                   f"{m['float']['shadow']:.1f} | {m['double']['shadow'] / m['float']['shadow']:.2f}x |")
            rows.append(row)
            print(row, flush=True)
    if a.results:
        lines = [HEADING, "", f"- Date: {datetime.date.today().isoformat()}", f"- Machine: {machine()}",
                 f"- Commit: {commit(a.binary)}", f"- Command: `{command_line()}` (after `cmake --build build`)", "",
                 f"Seeded random surfaces (kernel_speed.py's), {a.side}x{a.side} camera rays, one 3x3 area light; "
                 f"kernel ms (medians of {a.runs} alternating rounds after a warm-up"
                 + (f", each round's figure the median of {a.frames} frames in one `algray batch` process"
                    if a.frames > 1 else "") + ", second passes included) and "
                 "float's rate over double's. Goal: 1.5x at every degree, camera and shadow rays. Float runs "
                 "adaptive's float kernels at every degree: camera rays in the screen form, in lanes (above degree 15 "
                 "too since 4cc9f4c), shadow rays in the point form up to degree 15 and the extent form above.", "",
                 "| degree | double camera ms | float camera ms | float rate | double shadow ms | float shadow ms | "
                 "float rate |", "|---|---|---|---|---|---|---|"] + rows
        replace_section(ROOT / "bench/RESULTS.md", HEADING, "\n".join(lines) + "\n", under=AREA)


if __name__ == "__main__":
    main()
