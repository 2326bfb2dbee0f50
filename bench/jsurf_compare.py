#!/usr/bin/env python3
"""jsurf comparison (issue 7): every example .jsurf file of Debian's jsurf-alggeo, rendered by jsurf and by
algray at the same size; how well the silhouettes agree (intersection over union of the pixels that are not
background) and how far the colours are apart inside both. Writes its section of bench/RESULTS.md ("jsurf's own
examples", under "Against the peers"): the date, machine, commit and command, the summary and the files whose
silhouettes agree least (IoU under 0.98); every file's row is printed as it goes.

Needs `apt-get install jsurf-alggeo` (its launcher wants JAVA_HOME; this script finds a JDK). jsurf renders
with -q 0 (one ray per pixel) and algray without antialiasing, so the masks are the surfaces' own.
"""
import argparse
import datetime
import glob
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import bench_common
from bench_common import ROOT, command_line, commit, machine, replace_section

EXAMPLES = "/usr/share/doc/jsurf-alggeo/examples"
AREA = "## Against the peers"
HEADING = "### jsurf's own examples"
# Files whose IoU is under this are named on the page; the others are summed up in one line.
SHOWN_BELOW = 0.98


def read_png(path):
    """(width, height, rows of (r, g, b)) of an RGB or RGBA PNG."""
    return bench_common.read_png(path, rgb=True)


def background_of(jsurf_file):
    for line in Path(jsurf_file).read_text(errors="replace").splitlines():
        if line.startswith("background_color"):
            values = line.split("=", 1)[1].split()
            return tuple(int(float(v) * 255 + 0.5) for v in values[:3])
    return (255, 255, 255)


def mask(rows, background):
    # Not background: any channel more than 3 levels away (antialiasing is off, edges are crisp).
    return [[max(abs(p[k] - background[k]) for k in range(3)) > 3 for p in row] for row in rows]


def find_java_home():
    for candidate in sorted(glob.glob("/usr/lib/jvm/*"), reverse=True):
        if os.path.exists(os.path.join(candidate, "bin/java")):
            return candidate
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    args = ap.parse_args()
    java_home = os.environ.get("JAVA_HOME") or find_java_home()
    if not java_home or not os.path.isdir(EXAMPLES):
        sys.exit("needs jsurf-alggeo and a Java runtime: apt-get install jsurf-alggeo")
    env = dict(os.environ, JAVA_HOME=java_home)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for f in sorted(glob.glob(f"{EXAMPLES}/*.jsurf")):
            name = Path(f).stem
            ours, theirs = Path(tmp) / f"{name}_algray.png", Path(tmp) / f"{name}_jsurf.png"
            subprocess.run(["jsurf-alggeo", "-s", str(args.size), "-q", "0", f, str(theirs)], env=env, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            result = subprocess.run([str(args.binary), "render", f, "-o", str(ours), "--width", str(args.size),
                                     "--height", str(args.size), "--set", "antialias.samples=1",
                                     "--set", "antialias.adaptive=false"], capture_output=True, text=True)
            if result.returncode != 0:
                rows.append((name, None, None, None, (result.stderr.strip().splitlines() or ["no message"])[0]))
                continue
            background = background_of(f)
            _, _, a = read_png(ours)
            _, _, b = read_png(theirs)
            ma, mb = mask(a, background), mask(b, background)
            both = either = 0
            colour = []
            for y in range(args.size):
                for x in range(args.size):
                    both += ma[y][x] and mb[y][x]
                    either += ma[y][x] or mb[y][x]
                    if ma[y][x] and mb[y][x]:
                        colour.append(sum(abs(a[y][x][k] - b[y][x][k]) for k in range(3)) / 3)
            iou = both / either if either else 1.0
            warnings = len([l for l in result.stderr.splitlines() if "warning" in l])
            rows.append((name, iou, statistics.median(colour) if colour else 0.0, either, f"{warnings} warnings"))
            print(f"{name:32s} IoU {iou:.4f}  median |colour difference| "
                  f"{rows[-1][2]:.1f}/255  {rows[-1][4]}", flush=True)

    ok = [r for r in rows if r[1] is not None]
    ious = [r[1] for r in ok]
    if not ious:
        sys.exit("no file rendered: nothing to compare")
    lines = [
        HEADING,
        "",
        f"- Date: {datetime.date.today()}; machine: {machine()}; commit: {commit(args.binary)}.",
        f"- Command: `{command_line()}` (needs `apt-get install jsurf-alggeo`); jsurf-alggeo "
        f"{'0.4.1' if ok else '?'}, `-s {args.size} -q 0`; algray at {args.size}x{args.size} without antialiasing.",
        "- IoU: intersection over union of the non-background pixels of the two images (1 = the same silhouette). "
        "Colour: median over the pixels both cover of the mean |difference| of the 8-bit channels; the shading "
        "models differ on purpose (README), so this is a likeness, not an error.",
        "- Pixel centres: jsurf puts the first and last on the view's edges (pitch h/(N-1)), algray at half a "
        "pixel inside (pitch h/N), so edges move by up to half a pixel. That weighs most on thin silhouettes: "
        "tutorial_kreis is a cylinder seen along its axis, a ring a few pixels wide (the two images look alike).",
        f"- {len(ok)} of {len(rows)} files render; IoU median {statistics.median(ious):.4f}, lowest "
        f"{min(ious):.4f} ({min(ok, key=lambda r: r[1])[0]}).",
    ]
    low = sorted((r for r in ok if r[1] < SHOWN_BELOW), key=lambda r: r[1])
    rest = [r for r in ok if r[1] >= SHOWN_BELOW]
    if low:
        lines.append(f"- IoU under {SHOWN_BELOW}: " + ", ".join(
            f"{name} {iou:.4f} (colour {colour:.1f} of 255, {either} pixels in either)"
            for name, iou, colour, either, _ in low) + ".")
    if rest:
        lines.append(f"- The other {len(rest)} files: IoU {min(r[1] for r in rest):.4f}-{max(r[1] for r in rest):.4f}"
                     " (every file's row is in the script's output).")
    failed = [r for r in rows if r[1] is None]
    if failed:
        lines.append("- Failed: " + ", ".join(f"{name} ({note})" for name, _, _, _, note in failed) + ".")
    lines.append("")
    replace_section(args.output, HEADING, "\n".join(lines) + "\n", under=AREA)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    sys.exit(main())
