#!/usr/bin/env python3
"""What Python adds per frame: a parameter sweep rendered from Python (render, then save as PNG) against the same
sweep through `algray batch`, which writes the same PNGs; rounds alternate between the two, per-frame medians.
Run from the build tree: python3 bench/python_sweep.py (it imports build/python's package first)

With --results the table replaces its section of bench/RESULTS.md (under "Python per frame": "Python rendering what
a PNG holds", or with --depth "Python keeping depth and normals"), with the date, machine, commit and command."""
import argparse
import datetime
import json
import statistics
import subprocess
import tempfile
import sys
import time
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section

# The build tree's package first: `python3` alone imports the one scripts/install-python.sh put in the system
# Python, which is the build of the last test.sh and can be older than the binary this sweep compares it with.
sys.path.insert(0, str(ROOT / "build/python"))
import algray  # noqa: E402

AREA = "## Python per frame"
HEADINGS = {False: "### Python rendering what a PNG holds", True: "### Python keeping depth and normals"}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--algray", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scene", default="torus")
    ap.add_argument("--key", default="r", help="the swept parameter or scene key")
    ap.add_argument("--range", default="0.3,1.2")
    ap.add_argument("--depth", action="store_true", help="keep depth and normals in Python (a PNG holds neither)")
    ap.add_argument("--results", action="store_true", help="write the table into its section of bench/RESULTS.md")
    a = ap.parse_args()
    lo, hi = (float(x) for x in a.range.split(","))
    scene_path = ROOT / "scenes" / f"{a.scene}.toml"
    values = [lo + (hi - lo) * k / (a.frames - 1) for k in range(a.frames)]
    renderer = algray.Renderer()
    batch_ms, python_ms = [], []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        jobs = work / "jobs.toml"
        jobs.write_text(f'[defaults]\nset = {{ image = {{ width = {a.size}, height = {a.size} }}, '
                        f'render = {{ preview = true }} }}\n[[job]]\nname = "sweep"\nscene = "{scene_path}"\n'
                        f'output = "batch_{{frame:03}}.png"\n'
                        f'sweep.{a.key} = {{ from = {lo}, to = {hi}, steps = {a.frames} }}\n')
        base = algray.Scene.load(str(scene_path))
        # One frame each first: both program caches warm.
        renderer.render(base, width=a.size, height=a.size, preview=True)
        for r in range(a.rounds + 1):
            log = work / "batch.log.jsonl"
            log.unlink(missing_ok=True)
            subprocess.run([a.algray, "batch", str(jobs), "--log", str(log)], check=True)
            frames = [json.loads(line)["ms"] for line in log.read_text().splitlines()]
            times = []
            for k, v in enumerate(values):
                start = time.perf_counter()
                scene = algray.Scene.load(str(scene_path)).set(a.key, v)
                image = renderer.render(scene, width=a.size, height=a.size, preview=True, depth=a.depth)
                image.save(str(work / f"py_{k:03}.png"))
                del image  # as the batch frees each frame's film before the next
                times.append((time.perf_counter() - start) * 1000)
            if r > 0:  # round 0 warms both
                batch_ms.append(statistics.median(frames))
                python_ms.append(statistics.median(times))
    about = (f"{a.frames}-frame sweep of {a.key} in {lo}..{hi} on {a.scene}, {a.size}x{a.size} preview, PNG per "
             f"frame{'; Python keeps depth and normals' if a.depth else ''}; per-frame median of each round, "
             f"{a.rounds} rounds alternating (round 0 discarded as a warm-up).")
    table = ["| round | algray batch ms/frame | Python ms/frame | Python / batch |", "|---|---|---|---|"]
    for k, (b, p) in enumerate(zip(batch_ms, python_ms)):
        table.append(f"| {k + 1} | {b:.1f} | {p:.1f} | {p / b:.3f} |")
    ratios = [p / b for b, p in zip(batch_ms, python_ms)]
    median = f"median Python / batch: {statistics.median(ratios):.3f}"
    print(f"Machine: {machine()}. {about}\n")
    print("\n".join(table))
    print(f"\n{median}")
    if a.results:
        lines = [HEADINGS[a.depth], "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; commit: {commit(a.algray)}",
                 f"- Command: `PYTHONPATH=build/python {command_line()}`",
                 f"- {about}", ""] + table + ["", median]
        replace_section(RESULTS_MD, HEADINGS[a.depth], "\n".join(lines) + "\n", under=AREA)
        print(f"wrote {RESULTS_MD}")


if __name__ == "__main__":
    main()
