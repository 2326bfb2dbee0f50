#!/usr/bin/env python3
"""Issue 45's "what must not move" for shading on the device: every shipped scene rendered by this build (the
shading kernel) and by a baseline binary (the host's shading), compared channel by channel with exr_compare.

Per scene, in preview and full mode (double, this CPU's auto) and with --no-fp64 (adaptive float; the shading
kernel then runs in float): the largest colour difference in 8-bit steps, the pixels more than 1/255 off, hit/miss
disagreements and depth differences, and whether every EXR channel (half-float colour, float depth and normal) is
the same bit for bit. Goal: colour within 1/255, depth and normal bit for bit.

Usage: python3 bench/device_shading.py --baseline OLD_ALGRAY [--binary NEW_ALGRAY] [--size 320x240] [--results]
--results writes its section of bench/RESULTS.md ("Shading on the device against the host's", under "Precision
modes: time and accuracy") with the date, machine, commits and command."""
import argparse
import datetime
import re
import subprocess
import tempfile
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_section

AREA = "## Precision modes: time and accuracy"
HEADING = "### Shading on the device against the host's"
MODES = {"preview": ["--preview"], "full": [], "no fp64": ["--no-fp64"]}


def scenes():
    found = sorted((ROOT / "scenes").glob("*.toml")) + sorted((ROOT / "scenes" / "examples").glob("*"))
    return [p for p in found if p.suffix in (".toml", ".pov", ".jsurf", ".pic")]


def render(binary, scene, args, size, out):
    w, h = size.split("x")
    subprocess.run([str(binary), "render", str(scene), "-q", "--width", w, "--height", h, "-o", str(out)] + args,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def compare(tool, new, old):
    """exr_compare's verdict as numbers: colour steps, pixels off by > 1/255, disagreements, depth, identical."""
    text = subprocess.run([str(tool), str(new), str(old)], check=True, capture_output=True, text=True).stdout
    number = lambda pattern: float(re.search(pattern, text).group(1))
    return {"largest": number(r"largest ([0-9.]+)/255"),
            "off": int(number(r"colour off by >1/255 (\d+) pixels")),
            "disagree": int(number(r"hit/miss disagreements (\d+)")),
            "depth": number(r"worst relative depth difference ([0-9.e+-]+)"),
            "channels": "all" if "bit-identical: all" in text else
            re.search(r"differing: ([A-Za-z, ]+)", text).group(1).strip()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--baseline", required=True, help="an algray binary that shades on the host")
    ap.add_argument("--exr-compare", default=ROOT / "build/bench/exr_compare")
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--results", action="store_true")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes():
            for mode, args in MODES.items():
                new, old = Path(tmp) / "new.exr", Path(tmp) / "old.exr"
                render(a.binary, scene, args, a.size, new)
                render(a.baseline, scene, args, a.size, old)
                r = compare(a.exr_compare, new, old)
                rows.append((scene.stem, mode, r))
                print(scene.stem, mode, r, flush=True)
    # One row per scene, a cell per mode: the largest colour difference, and which channels differ at all.
    lines = ["| scene | " + " | ".join(MODES) + " |", "|---|" + "---|" * len(MODES)]
    for name in dict.fromkeys(n for n, _, _ in rows):
        cells = []
        for mode in MODES:
            r = next(r for n, m, r in rows if n == name and m == mode)
            differs = "" if r["channels"] == "all" else f", {r['channels']} differ"
            wrong = f", {r['off']} px > 1/255, {r['disagree']} hit/miss" if r["off"] or r["disagree"] else ""
            cells.append(f"{r['largest']:.1f}/255{differs}{wrong}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    worst = max(r["largest"] for _, _, r in rows)
    identical = sum(r["channels"] == "all" for _, _, r in rows)
    summary = (f"{len(rows)} renders: largest colour difference {worst:.1f}/255; every channel bit for bit in "
               f"{identical}; depth and normal bit for bit in "
               f"{sum(r['channels'] in ('all', 'RGBA') for _, _, r in rows)}.")
    table = "\n".join(lines)
    print(summary)
    if a.results:
        body = (f"- Date {datetime.date.today()}; machine: {machine()}; commit {commit(a.binary)} against "
                f"{commit(a.baseline)} (host shading)\n"
                f"- Command: `{command_line()}`\n"
                f"- Every shipped scene at {a.size}, preview and full mode in double (this CPU's auto) and with "
                f"--no-fp64 (the shading kernel in float). Issue 45: colour within 1/255, depth and normal bit for "
                f"bit. {summary}\n\n" + table + "\n")
        replace_section(ROOT / "bench/RESULTS.md", HEADING, HEADING + "\n\n" + body, under=AREA)


if __name__ == "__main__":
    main()
