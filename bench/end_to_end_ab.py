#!/usr/bin/env python3
"""End-to-end time of two algray binaries side by side: the whole `algray render` process per surface, each
pair of runs interleaved (A B A B ...) after one warm-up each, with the ratio's median and spread. For changes
that must not slow anything down, such as a refactor of the host."""
import argparse
import statistics
import tempfile
from pathlib import Path

from bench_common import ROOT, machine, run_render

PAPER_SURFACES = ["barth_sextic", "cusp_catastrophe", "torus", "tooth", "lemniscate", "tanglecube", "barth_decic"]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--baseline", required=True, help="the algray binary to compare against")
    ap.add_argument("--algray", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--scenes", nargs="*", default=PAPER_SURFACES)
    ap.add_argument("--full", action="store_true", help="the scenes as shipped, not the preview")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    a = ap.parse_args()
    args = ["--width", str(a.width), "--height", str(a.height)]
    if not a.full:
        args += ["--preview", "--set", "antialias.samples=1"]
    binaries = [a.baseline, a.algray]
    print(f"Machine: {machine()}. Baseline `{a.baseline}`, current `{a.algray}`; `render {' '.join(args)}` to EXR, "
          f"wall ms of the whole process, median of {a.repeat} interleaved runs each after one warm-up; "
          f"ratio = current/baseline per pair (median, min-max).\n")
    print("| surface | baseline ms | current ms | ratio (median) | min-max |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name in a.scenes:
            scene = ROOT / "scenes" / f"{name}.toml"
            for b in binaries:
                run_render(b, scene, args, None, work)
            times = [[], []]
            for _ in range(a.repeat):
                for k, b in enumerate(binaries):
                    times[k].append(run_render(b, scene, args, None, work)[0])
            ratios = [new / old for old, new in zip(times[0], times[1])]
            print(f"| {name} | {statistics.median(times[0]):.0f} | {statistics.median(times[1]):.0f} | "
                  f"{statistics.median(ratios):.3f} | {min(ratios):.3f}-{max(ratios):.3f} |", flush=True)


if __name__ == "__main__":
    main()
