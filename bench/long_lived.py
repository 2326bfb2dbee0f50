#!/usr/bin/env python3
"""The long-lived renderer's frame against its kernels (issue 45): Python `Renderer.render(scene, W, H, preview=True)`
in a loop, one Renderer, the camera turning a little each frame; per frame the wall time of the call and the
device time of its kernels (stats `render_ms.kernel`, the shading kernel's included), with shading's wall time
(`render_ms.shading`; `host_shading` in builds before the shading kernel). Scenes alternate frame by
frame; medians over the frames after a warm-up. Goal: wall at most 1.3x kernel.
Run with the package on the path: PYTHONPATH=build/python /usr/bin/python3 bench/long_lived.py

--baseline DIR compares with another build's package (DIR holds its `algray` package, e.g. an older commit's
build/python): rounds alternate between the two, each round a fresh process per package, medians over the rounds'
frames. With --results the table replaces its section of bench/RESULTS.md, with the date, machine, commit and
command."""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
import time

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section

AREA = "## Python per frame"
HEADING = "### The long-lived renderer: frame against kernels"


def measure(a):
    """One process's frames: {scene: {"wall": [...], "kernel": [...], "shade": [...]}}."""
    import algray
    names = a.scenes.split(",")
    renderer = algray.Renderer()
    scenes = {n: algray.Scene.load(str(ROOT / "scenes" / f"{n}.toml")) for n in names}
    azimuth = {n: scenes[n].camera_angles["azimuth"] for n in names}
    rows = {n: {"wall": [], "kernel": [], "shade": []} for n in names}
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
            rows[n]["wall"].append(wall)
            rows[n]["kernel"].append(stats["render_ms"]["kernel"])
            rows[n]["shade"].append(stats["render_ms"].get("shading", stats["render_ms"].get("host_shading")))
    return rows


def in_child(package_dir, a):
    """measure() in a fresh process with `package_dir`'s algray package."""
    args = [sys.executable, __file__, "--child", "--scenes", a.scenes, "--width", str(a.width), "--height",
            str(a.height), "--frames", str(a.frames), "--warmup", str(a.warmup)] + (["--depth"] if a.depth else [])
    env = dict(os.environ, PYTHONPATH=str(package_dir))
    return json.loads(subprocess.run(args, env=env, check=True, capture_output=True, text=True).stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--scenes", default="barth_sextic,barth_decic")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--frames", type=int, default=20, help="measured frames per scene and round")
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--depth", action="store_true", help="keep depth and normals (the default leaves them out)")
    ap.add_argument("--baseline", help="a directory holding another build's algray package")
    ap.add_argument("--results", action="store_true", help="write the table into its section of bench/RESULTS.md")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(measure(a)))
        return
    current = os.environ.get("PYTHONPATH", str(ROOT / "build/python"))
    builds = [("this build", current)] + ([("baseline", a.baseline)] if a.baseline else [])
    rows = {label: {} for label, _ in builds}
    for r in range(a.rounds):
        # Alternating which goes first, so neither always follows the other.
        for label, path in builds if r % 2 == 0 else builds[::-1]:
            for scene, got in in_child(path, a).items():
                into = rows[label].setdefault(scene, {"wall": [], "kernel": [], "shade": []})
                for k, v in got.items():
                    into[k] += v
    med = statistics.median
    lines = ["| scene | build | frame wall ms | kernel ms | wall / kernel | shading ms |", "|---|---|---|---|---|---|"]
    for scene in a.scenes.split(","):
        for label, _ in builds:
            r = rows[label][scene]
            ratio = med([w / k for w, k in zip(r["wall"], r["kernel"])])
            lines.append(f"| {scene} | {label} | {med(r['wall']):.1f} | {med(r['kernel']):.1f} | **{ratio:.2f}** | "
                         f"{med(r['shade']):.1f} |")
    table = "\n".join(lines)
    print(table)
    if a.results:
        body = (f"- Date {datetime.date.today()}; machine: {machine()}; commit {commit()}"
                + (f"; baseline: the package in {a.baseline}" if a.baseline else "") + "\n"
                f"- Command: `PYTHONPATH=build/python {command_line('/usr/bin/python3')}`\n"
                f"- {a.width}x{a.height} preview{'' if a.depth else ' without depth and normals'}, one Renderer per "
                f"process, the scenes alternating frame by frame, the camera turning 0.5 degrees a frame; {a.rounds} "
                f"rounds of a fresh process per build (alternating), {a.frames} frames per scene each after "
                f"{a.warmup} of warm-up; medians over all. Issue 45's goal: wall at most 1.3x kernel. Kernel ms counts the "
                f"shading kernel where a build has one; shading ms is shading's wall time (host shading before it).\n\n"
                + table + "\n")
        replace_section(RESULTS_MD, HEADING, HEADING + "\n\n" + body, under=AREA)


if __name__ == "__main__":
    main()
