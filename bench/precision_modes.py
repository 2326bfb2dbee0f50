#!/usr/bin/env python3
"""Issue 18's table: what each precision costs and what it gets right, on every scene (and, with --hard, on
tests/data/hard_surfaces).

Speed: `algray render` at 1024x768, one camera ray per pixel, the scene's lights and shadows, in float, adaptive,
adaptive with fp64 hidden (its second pass then in mixed precision, as on a GPU without fast fp64), mixed and
double; --runs rounds, the modes interleaved in a rotating order, median kernel time (device time of every pass,
escalations included). The share of escalated rays is per pass, of the rays the pass traced.

Accuracy: camera rays only (preview) at 320x240 through the Python module, against solver_ref on the same rays:
hit/miss disagreements among the pixels the reference certifies, and the worst relative depth error where both
hit. The float line: at most 0.1% disagreements, depth error at most 1e-3.

Writes bench/results/precision_modes.json (--json) and its section of bench/RESULTS.md ("Float, adaptive, mixed and
double", under "Precision modes: time and accuracy"; --heading names another, a GPU's say), with the date,
machine, commit and command.
"""
import argparse
import datetime
import json
import os
import statistics
import sys
import tempfile
from pathlib import Path

from bench_common import (ROOT, command_line, commit, heading_level, machine, replace_section, run_frames,
                          run_render)

AREA = "## Precision modes: time and accuracy"
HEADING = "### Float, adaptive, mixed and double"
# (column name, --precision, extra environment)
SPEED_MODES = [("float", "float", {}), ("adaptive", "adaptive", {}),
               ("adaptive, no fp64", "adaptive", {"ALGRAY_NO_FP64": "1"}), ("mixed", "mixed", {}),
               ("double", "double", {})]
# "adaptive, no fp64": adaptive with fp64 hidden, whose float pass also settles what a float-float second pass would
# redo (KernelConfig::settle_doubts), as on a GPU without fast fp64.
ACCURACY_MODES = ["float", "adaptive", "adaptive, no fp64", "mixed", "double"]
FLOAT_LINE = (0.001, 1e-3)
# The page's accuracy table has the rows where precision matters: plain float misses the float line, or adaptive
# sends at least this share of the camera rays to its second pass; the others are summed up in one line (every row
# is in the --json file).
ESCALATED_SHOWN = 0.01


def misses_line(a):
    return a["disagree"] > FLOAT_LINE[0] * a["certified"] or a["worst_depth"] > FLOAT_LINE[1]


def shown_on_page(row):
    acc = row["accuracy"]
    return misses_line(acc["float"]) or any(acc[m]["escalated_share"] >= ESCALATED_SHOWN
                                            for m in ACCURACY_MODES if m.startswith("adaptive"))


def pass_sum(stats, key, name=None):
    return sum(p[key] for p in stats["passes"] if name is None or p["name"] == name)


def speed(binary, scene, runs, work, modes=SPEED_MODES, args=None, warm_up=False, frames=1):
    """Each mode's median kernel time over `runs` rounds, the modes' order rotating from round to round (a first
    round not counted with warm_up), and each mode's escalated share per pass. modes: (name, --precision, extra
    environment); args: the render's other arguments (default 1024x768, one ray per pixel). frames > 1: each
    round's figure for a mode is the median of that many frames in one process (run_frames), not one render's."""
    if args is None:
        args = ["--width", "1024", "--height", "768", "--set", "antialias.samples=1"]
    times = {m[0]: [] for m in modes}
    shares = {}
    first = -1 if warm_up else 0
    for r in range(first, runs):
        order = modes[r % len(modes):] + modes[:r % len(modes)]
        for name, precision, extra in order:
            env = dict(os.environ, **extra)
            if frames > 1:
                every = run_frames(binary, scene, args + ["--precision", precision], env, work, frames)
                stats = every[-1]
                kernel_ms = statistics.median(pass_sum(s, "kernel_ms") for s in every)
            else:
                _, stats = run_render(binary, scene, args + ["--precision", precision], env, work)
                kernel_ms = pass_sum(stats, "kernel_ms")
            if r < 0:
                continue
            times[name].append(kernel_ms)
            shares[name] = {p["name"]: p["escalated"] / max(p["rays"], 1) for p in stats["passes"]}
    return {m: statistics.median(t) for m, t in times.items()}, shares


def accuracy(path, width, height):
    # Imported here so that the speed part runs where the module is not built (a lent GPU's other Python).
    import numpy as np
    sys.path.insert(0, str(ROOT / "build/python"))
    import algray

    renderer, no_fp64 = algray.Renderer(), algray.Renderer()
    out = {}
    refs = {}
    for mode in ACCURACY_MODES:
        scene = algray.Scene.load(str(path))
        scene.set("antialias.samples", 1)
        scene.set("render.precision", mode.split(",")[0])
        size = dict(width=width, height=height, preview=True)
        rays = "double" if mode == "double" else "float"  # float, adaptive and mixed trace the same float rays
        if rays not in refs:
            refs[rays] = renderer.render(scene, reference=True, **size)
        ref = refs[rays]
        if mode == "adaptive, no fp64":
            # A device counts as without fp64 where ALGRAY_NO_FP64 is set when it is opened, at the first render.
            os.environ["ALGRAY_NO_FP64"] = "1"
            try:
                img = no_fp64.render(scene, aov=["flags"], **size)
            finally:
                del os.environ["ALGRAY_NO_FP64"]
        else:
            img = renderer.render(scene, aov=["flags"], **size)
        cls = ref.aov["reference.class"]
        certified = (cls == 1) | (cls == 2)
        ref_hit, hit = np.isfinite(ref.depth), np.isfinite(img.depth)
        both = certified & ref_hit & hit
        rel = np.zeros(ref.depth.shape)
        rel[both] = np.abs(img.depth[both] - ref.depth[both]) / np.maximum(np.abs(ref.depth[both]), 1e-30)
        disagree = int((certified & (ref_hit != hit)).sum())
        flags = img.aov["flags"].astype(np.uint32)
        in_extent = (flags & 16) != 0
        escalated = int(((flags & 256) != 0).sum())
        out[mode] = {"certified": int(certified.sum()), "disagree": disagree,
                     "worst_depth": float(rel.max()) if both.any() else 0.0,
                     "escalated_share": escalated / max(int(in_extent.sum()), 1)}
    return out


def section(results, heading, json_path, output):
    """The RESULTS.md section for `results` (as --json holds them), linking the raw figures from `output`."""
    rows = results["rows"]
    raw = json_path.resolve()
    raw_name = os.path.relpath(raw, ROOT) if raw.is_relative_to(ROOT) else str(raw)
    link = os.path.relpath(raw, output.resolve().parent)
    lines = [heading, "", f"- Date: {results['date']}", f"- Machine: {results['machine']}",
             f"- Commit: {results.get('commit', 'not recorded')}",
             f"- Command: `{results['command']}` (after `cmake --build build`); raw figures in "
             f"[{raw_name}]({link})", ""]
    speed_rows = [r for r in rows if "kernel_ms" in r]
    if speed_rows:
        lines += [
            "Kernel time at 1024x768, one camera ray per pixel, shadows as the scene casts them (median of "
            f"{results['runs']} interleaved rounds; device time of all passes, the second pass included). Escalated: "
            "the share of each pass's rays the float kernel doubted. \"no fp64\" runs with ALGRAY_NO_FP64=1, so "
            "the doubted rays go to mixed precision, as on a GPU without fast fp64; otherwise this CPU's fp64 is "
            "fast and they go to double. Target: adaptive within 1.25x float.",
            "",
            "| scene | float ms | adaptive ms | (x float) | adaptive, no fp64 ms | (x float) | mixed ms | double ms "
            "| escalated: camera | escalated: shadow |",
            "|---|---|---|---|---|---|---|---|---|---|"]
        for r in speed_rows:
            t, e = r["kernel_ms"], r["escalated"]["adaptive"]
            f = t["float"]
            lines.append(f"| {r['scene']} | {f:.0f} | {t['adaptive']:.0f} | {t['adaptive'] / f:.2f} | "
                         f"{t['adaptive, no fp64']:.0f} | {t['adaptive, no fp64'] / f:.2f} | {t['mixed']:.0f} | "
                         f"{t['double']:.0f} | {100 * e.get('primary', 0):.1f}% | {100 * e.get('shadow', 0):.1f}% |")
        lines.append("")
    acc_rows = [r for r in rows if "accuracy" in r]
    if acc_rows:
        page_rows = [r for r in acc_rows if shown_on_page(r)]
        others = [r for r in acc_rows if not shown_on_page(r)]
        lines += [
            "Accuracy of camera rays at 320x240 against solver_ref on the same rays: hit/miss disagreements among "
            "certified pixels, worst relative depth error (the float line: 0.1% and 1e-3; **bold** where missed), "
            "and for adaptive the share of rays in the extent that were escalated. \"No fp64\": adaptive with fp64 "
            "hidden, its float pass settling more doubts in float-float. Scenes marked (hard) are "
            "tests/data/hard_surfaces. The rows where plain float misses the line or adaptive escalates "
            f"{ESCALATED_SHOWN:.0%} or more; every row is in the raw figures.",
            ""]
        if others:
            worst = max(r["accuracy"][m]["worst_depth"] for r in others for m in ACCURACY_MODES if m != "double")
            missed = [r["scene"] for r in others
                      if any(misses_line(r["accuracy"][m]) for m in ACCURACY_MODES if m != "double")]
            lines += [f"- The other {len(others)} ({', '.join(r['scene'] for r in others)}): "
                      + (f"the float line missed by {', '.join(missed)}" if missed else
                         "every mode within the float line")
                      + f", worst depth error in float, adaptive and mixed {worst:.1e}, adaptive escalating under "
                      f"{ESCALATED_SHOWN:.0%}.", ""]
        lines += ["| scene | float | adaptive | escalated | adaptive, no fp64 | escalated | mixed | double |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in page_rows:
            cells = []
            for mode in ACCURACY_MODES:
                a = r["accuracy"][mode]
                text = f"{a['disagree']} / {a['worst_depth']:.1e}"
                cells.append(f"**{text}**" if misses_line(a) and mode != "double" else text)
                if mode.startswith("adaptive"):
                    cells.append(f"{100 * a['escalated_share']:.1f}%")
            name = r["scene"] + (" (hard)" if r["hard"] else "")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--scenes", nargs="*", default=None, help="scene names in scenes/ (default: all)")
    ap.add_argument("--hard", action="store_true", help="also tests/data/hard_surfaces")
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--no-accuracy", action="store_true")
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    ap.add_argument("--json", default=ROOT / "bench/results/precision_modes.json", help="where the raw figures go")
    ap.add_argument("--heading", default=HEADING, help="the RESULTS.md section to write (another device's, say)")
    args = ap.parse_args()
    names = args.scenes or sorted(p.stem for p in (ROOT / "scenes").glob("*.toml"))
    paths = [ROOT / "scenes" / f"{n}.toml" for n in names]
    if args.hard:
        paths += sorted((ROOT / "tests/data/hard_surfaces").glob("*.toml"))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for path in paths:
            row = {"scene": path.stem, "hard": "hard_surfaces" in str(path)}
            if not args.no_speed and not row["hard"]:
                row["kernel_ms"], row["escalated"] = speed(args.binary, path, args.runs, Path(tmp))
            if not args.no_accuracy:
                row["accuracy"] = accuracy(path, 320, 240)
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)

    results = {"date": datetime.date.today().isoformat(), "machine": machine(),
               "commit": commit(None if args.no_speed else args.binary), "command": command_line(),
               "runs": args.runs, "rows": rows}
    Path(args.json).write_text(json.dumps(results, indent=1) + "\n")

    lines = section(results, args.heading, Path(args.json), Path(args.output))
    # A section of the page's own level (a GPU's "## ...", in a file of its own) goes at the top level.
    replace_section(args.output, args.heading, "\n".join(lines) + "\n",
                    under=AREA if heading_level(args.heading) > heading_level(AREA) else None)
    print(f"wrote {args.output}", file=sys.stderr)


if __name__ == "__main__":
    main()
