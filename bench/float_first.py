#!/usr/bin/env python3
"""Issue 44's goal 1: float and adaptive precision against double, kernel time at 1024x768 on the paper's seven
surfaces and the Endrass octic, the Kummer surface, Goursat's dodecic and the Chebyshev nonic, in preview (camera
rays, one per pixel) and in full mode (the scene as it is: its lights, shadows and antialiasing).

Each mode's figure in a round is the median kernel time of --frames frames rendered in one process (algray batch,
after a first frame not counted).

Modes: double, float, adaptive (its second pass in double: this CPU's fp64 is fast) and adaptive with
ALGRAY_NO_FP64=1 (its second pass in float-float, as on a GPU without fast fp64). Each round runs every mode once,
the order rotating from round to round; the table gives each mode's median kernel time (device time of every pass,
the second pass included) and its ratio to double's median. Targets: float at most 0.6x double, adaptive (either)
at most 0.7x.

Writes its section of bench/RESULTS.md ("Float first: float and adaptive against double", under "Precision modes:
time and accuracy"), with the date, machine, commit and command.
"""
import argparse
import datetime
import tempfile
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_section
from precision_modes import speed

AREA = "## Precision modes: time and accuracy"
HEADING = "### Float first: float and adaptive against double"
SCENES = ["barth_sextic", "cusp_catastrophe", "torus", "tooth", "lemniscate", "barth_decic", "tanglecube",
          "endrass_octic", "kummer", "goursat12", "chebyshev_nonic"]
# (column, --precision, extra environment)
MODES = [("double", "double", {}), ("float", "float", {}), ("adaptive", "adaptive", {}),
         ("adaptive, no fp64", "adaptive", {"ALGRAY_NO_FP64": "1"})]
TARGETS = {"float": 0.6, "adaptive": 0.7, "adaptive, no fp64": 0.7}


def measure(binary, scene, preview, runs, frames, work):
    args = ["--width", "1024", "--height", "768"] + (["--preview", "--set", "antialias.samples=1"] if preview else [])
    medians, _ = speed(binary, scene, runs, work, modes=MODES, args=args, warm_up=True, frames=frames)
    return medians


def cell(ms, double_ms, target):
    ratio = ms / double_ms
    text = f"{ms:.1f} ({ratio:.2f})"
    return f"**{text}**" if target is not None and ratio > target else text


def section(rows, runs, preview_runs, frames, binary, note):
    lines = [HEADING, "", f"- Date: {datetime.date.today().isoformat()}", f"- Machine: {machine()}",
             f"- Commit: {commit(binary)}", f"- Command: `{command_line()}` (after `cmake --build build`)"]
    lines += [f"- Conditions: {note}", ""] if note else [""]
    lines += [
             "Kernel ms at 1024x768 (median of " + str(runs) + " interleaved rounds in full mode, " + str(preview_runs)
             + " in preview, after a warm-up round; "
             + (f"each round's figure the median of {frames} frames in one `algray batch` process, after a first "
                "frame not counted; " if frames > 1 else "")
             + "device "
             "time of every pass, adaptive's second pass included) and the ratio to double's. **Bold**: over the "
             "target (float 0.6x, adaptive 0.7x). Preview: camera rays, one per pixel; full: the scene's lights, "
             "shadows and antialiasing.", "",
             "| scene | mode | double ms | float | adaptive | adaptive, no fp64 |", "|---|---|---|---|---|---|"]
    for r in rows:
        t = r["ms"]
        lines.append(f"| {r['scene']} | {r['mode']} | {t['double']:.1f} | "
                     + " | ".join(cell(t[m], t["double"], TARGETS[m]) for m in ("float", "adaptive",
                                                                              "adaptive, no fp64")) + " |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--preview-runs", type=int,
                    help="rounds in preview (default: 3x --runs): kernels of 10-60 ms swing by a third between runs "
                         "on a shared 2-core VM, where full mode's seconds hold within a few per cent")
    ap.add_argument("--frames", type=int, default=3,
                    help="frames per mode and round, in one process (their median is the round's figure); 1: one "
                         "`algray render` process per figure, as before 2026-12-07, whose single frames read up to "
                         "2x apart for the same kernels")
    ap.add_argument("--scenes", nargs="*", default=SCENES)
    ap.add_argument("--modes", nargs="*", default=["preview", "full"], choices=["preview", "full"])
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    ap.add_argument("--note", default="", help="a line on the conditions of the run, for the page")
    args = ap.parse_args()
    preview_runs = args.preview_runs or 3 * args.runs
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            for mode in args.modes:
                runs = preview_runs if mode == "preview" else args.runs
                ms = measure(args.binary, ROOT / "scenes" / f"{name}.toml", mode == "preview", runs, args.frames,
                             Path(tmp))
                rows.append({"scene": name, "mode": mode, "ms": ms})
                print(name, mode, {m: round(v, 1) for m, v in ms.items()}, flush=True)
    replace_section(args.output, HEADING, section(rows, args.runs, preview_runs, args.frames, args.binary, args.note), under=AREA)


if __name__ == "__main__":
    main()
