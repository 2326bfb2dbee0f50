#!/usr/bin/env python3
"""End-to-end time of two algray binaries side by side: the whole `algray render` process per surface, each
pair of runs interleaved (A B A B ...) after one warm-up each, with the ratio's median and spread. For changes
that must not slow anything down, such as a refactor of the host."""
import argparse
import datetime
import statistics
import tempfile
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section, run_render

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
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene key for both binaries, as `algray render --set` takes it (render.lanes=1, say)")
    ap.add_argument("--results", metavar="HEADING",
                    help="also write the table into bench/RESULTS.md as this ### section, under ## Code shape "
                         "(a refactor's A/B against the commit it started from)")
    a = ap.parse_args()
    args = ["--width", str(a.width), "--height", str(a.height)]
    for kv in a.set:
        args += ["--set", kv]
    if not a.full:
        args += ["--preview", "--set", "antialias.samples=1"]
    binaries = [a.baseline, a.algray]
    print(f"Machine: {machine()}. Baseline `{a.baseline}`, current `{a.algray}`; `render {' '.join(args)}` to EXR, "
          f"wall ms of the whole process, median of {a.repeat} interleaved runs each after one warm-up; "
          f"ratio = current/baseline per pair (median, min-max); kernel ms: every pass's device time from --stats.\n")
    table = ["| surface | baseline ms | current ms | ratio (median) | min-max | kernel ms ratio (median) | min-max |",
             "|---|---|---|---|---|---|---|"]
    print("\n".join(table))
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name in a.scenes:
            scene = ROOT / "scenes" / f"{name}.toml"
            for b in binaries:
                run_render(b, scene, args, None, work)
            times, kernels = [[], []], [[], []]
            for _ in range(a.repeat):
                for k, b in enumerate(binaries):
                    wall, stats = run_render(b, scene, args, None, work)
                    times[k].append(wall)
                    kernels[k].append(sum(p["kernel_ms"] for p in stats["passes"]))  # every pass's device time
            ratios = [new / old for old, new in zip(times[0], times[1])]
            kernel_ratios = [new / old for old, new in zip(kernels[0], kernels[1])]
            table.append(f"| {name} | {statistics.median(times[0]):.0f} | {statistics.median(times[1]):.0f} | "
                         f"{statistics.median(ratios):.3f} | {min(ratios):.3f}-{max(ratios):.3f} | "
                         f"{statistics.median(kernel_ratios):.3f} | {min(kernel_ratios):.3f}-{max(kernel_ratios):.3f} |")
            print(table[-1], flush=True)
    if a.results:
        lines = [a.results, "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; current: {commit(a.algray)}, "
                 f"baseline: {commit(a.baseline)}",
                 f"- Command: `{command_line()}`: `render {' '.join(args)}`, median of {a.repeat} interleaved runs; "
                 "ratios current/baseline, wall of the whole process and every pass's kernel time", ""] + table
        replace_section(RESULTS_MD, a.results, "\n".join(lines) + "\n", under="## Code shape")
        print(f"wrote {RESULTS_MD}")


if __name__ == "__main__":
    main()
