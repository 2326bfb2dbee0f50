#!/usr/bin/env python3
"""The long-lived renderer's frame against its kernels (issue 45): Python `Renderer.render(scene, W, H, preview=True)`
in a loop, one Renderer, the camera turning a little each frame; per frame the wall time of the call and the
device time of its kernels (stats `render_ms.kernel`), with the render's host shading and its phases. Scenes
alternate frame by frame; medians over the frames after a warm-up. Goal: wall at most 1.3x kernel.
Run with the package on the path: PYTHONPATH=build/python /usr/bin/python3 bench/long_lived.py

With --results the table replaces its section of bench/RESULTS.md, with the date, machine, commit and command."""
import argparse
import datetime
import statistics
import time

import algray

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section

HEADING = "## The long-lived renderer: frame against kernels"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--scenes", default="barth_sextic,barth_decic")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--depth", action="store_true", help="keep depth and normals (the default leaves them out)")
    ap.add_argument("--results", action="store_true", help="write the table into its section of bench/RESULTS.md")
    a = ap.parse_args()
    names = a.scenes.split(",")
    renderer = algray.Renderer()
    scenes = {n: algray.Scene.load(str(ROOT / "scenes" / f"{n}.toml")) for n in names}
    azimuth = {n: scenes[n].camera_angles["azimuth"] for n in names}
    rows = {n: {"wall": [], "kernel": [], "shade": [], "phases": {}} for n in names}
    for frame in range(a.warmup + a.frames):
        for n in names:
            # A camera move per frame, as the view and notebooks make: the scene changes, the programs do not.
            scenes[n].set("camera.azimuth", azimuth[n] + 0.5 * frame)
            start = time.perf_counter()
            image = renderer.render(scenes[n], width=a.width, height=a.height, preview=True, depth=a.depth)
            wall = 1000 * (time.perf_counter() - start)
            if frame < a.warmup:
                continue
            stats = image.stats
            r = rows[n]
            r["wall"].append(wall)
            r["kernel"].append(stats["render_ms"]["kernel"])
            r["shade"].append(stats["render_ms"]["host_shading"])
            for phase, ms in stats["phases_ms"].items():
                r["phases"].setdefault(phase, []).append(ms)
    med = statistics.median
    lines = ["| scene | frame wall ms | kernel ms | wall / kernel | host shading ms | phases (median ms) |",
             "|---|---|---|---|---|---|"]
    for n in names:
        r = rows[n]
        ratio = med([w / k for w, k in zip(r["wall"], r["kernel"])])
        phases = ", ".join(f"{p} {med(v):.1f}" for p, v in r["phases"].items())
        lines.append(f"| {n} | {med(r['wall']):.1f} | {med(r['kernel']):.1f} | **{ratio:.2f}** | "
                     f"{med(r['shade']):.1f} | {phases} |")
    table = "\n".join(lines)
    print(table)
    if a.results:
        body = (f"- Machine: {machine()}; date {datetime.date.today()}; commit {commit()}\n"
                f"- Command: `PYTHONPATH=build/python {command_line('/usr/bin/python3')}`\n"
                f"- {a.width}x{a.height} preview{'' if a.depth else ' without depth and normals'}, one Renderer, "
                f"scenes alternating frame by frame, the camera turning 0.5 degrees a frame; medians of {a.frames} "
                f"frames after {a.warmup} of warm-up. Issue 45's goal: wall at most 1.3x kernel.\n\n" + table + "\n")
        replace_section(RESULTS_MD, HEADING, HEADING + "\n\n" + body)


if __name__ == "__main__":
    main()
