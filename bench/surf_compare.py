#!/usr/bin/env python3
"""surf comparison (issue 47): the surface scripts among surf's own examples (Debian's surf-alggeo-doc), run by
surf-alggeo and rendered by algray from the same script; how well the silhouettes agree (intersection over union
of the pixels that show a surface). Writes its line of bench/RESULTS.md ("surf's and POV-Ray's own scenes",
under "Against the peers"); every script's row is printed as it goes.

Needs `apt-get install surf-alggeo surf-alggeo-doc` (installed here when missing and run as root). Both programs
read the same copy of each script, changed only where the comparison needs it: before every draw_surface the
image is made --scale times its size, antialiasing and depth cueing are turned off and the background is an odd
colour, (1, 2, 3), that no shaded pixel has; every save writes a PPM of its own (the first one is the picture
algray renders); dithered images are not saved. algray renders in full mode (transparent surfaces need its
transmission pass) with one ray per pixel; the lights of a surf script cast no shadows.
A pixel shows a surface where its colour is not the background's (in algray's PNG, off by more than 1 in a
channel: 8-bit sRGB of the linear background), so that surfaces made fully transparent, as gallery scripts do
with helper surfaces for plane sections, count as neither program shows them.
"""
import argparse
import datetime
import glob
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_bullet
from jsurf_compare import read_png

# SURF and SURF_EXAMPLES point elsewhere (a surf unpacked with dpkg -x, say); by default the installed ones.
EXAMPLES = os.environ.get("SURF_EXAMPLES", "/usr/share/doc/surf-alggeo/examples")
AREA = "## Against the peers"
HEADING = "### surf's and POV-Ray's own scenes"  # one section, a line per script (pov_compare.py writes the other)
SHOWN_BELOW = 0.97  # scripts whose IoU is under this are named on the page


def ensure_surf():
    surf = os.environ.get("SURF") or shutil.which("surf-alggeo-nox") or shutil.which("surf-alggeo")
    if surf and os.path.isdir(EXAMPLES):
        return surf
    if os.geteuid() == 0:
        subprocess.run(["apt-get", "install", "-y", "--no-install-recommends", "surf-alggeo", "surf-alggeo-doc"],
                       check=True, stdout=subprocess.DEVNULL)
        surf = shutil.which("surf-alggeo-nox") or shutil.which("surf-alggeo")
    if not surf or not os.path.isdir(EXAMPLES):
        sys.exit("needs surf-alggeo and surf-alggeo-doc: apt-get install surf-alggeo surf-alggeo-doc")
    return surf


def read_ppm(path):
    data = Path(path).read_bytes()
    fields = data.split(maxsplit=4)
    assert fields[0] == b"P6" and fields[3] == b"255", path
    width, height, pixels = int(fields[1]), int(fields[2]), fields[4]
    return width, height, [[tuple(pixels[3 * (y * width + x):3 * (y * width + x) + 3]) for x in range(width)]
                           for y in range(height)]


def comparable(script, scale, out_dir):
    """The script as both programs read it (see the module's text)."""
    text = Path(script).read_text(errors="replace")
    text = re.sub(r"\bsave_dithered_image\s*;", "", text)
    text = re.sub(r"\b(filename|color_file_format)\s*=[^;]*;", "", text)
    saves = [0]

    def save(_):
        saves[0] += 1
        return f'filename="{out_dir}/surf_{saves[0]}.ppm"; save_color_image;'

    text = re.sub(r"\bsave_color_image\s*;", save, text)
    # The size: surf's own, read from the script's last width and height, times `scale`.
    sizes = {k: int(v) for k, v in re.findall(r"\b(width|height)\s*=\s*(\d+)\s*;", text)}
    width, height = (max(16, int(sizes.get(k, 200) * scale)) for k in ("width", "height"))
    before = (f"width={width}; height={height}; antialiasing=1; depth_cueing=no; "
              "background_red=1; background_green=2; background_blue=3; ")
    text = re.sub(r"\bdraw_surface\s*;", lambda _: before + "draw_surface;", text)
    if saves[0] == 0:
        text += f'\ncolor_file_format=ppm;\nfilename="{out_dir}/surf_1.ppm";\nsave_color_image;\n'
    return "color_file_format=ppm;\n" + text, width, height


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--scale", type=float, default=1.0, help="image size relative to the script's own")
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    args = ap.parse_args()
    surf = ensure_surf()
    rows, skipped = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for f in sorted(glob.glob(f"{EXAMPLES}/**/*.pic", recursive=True)):
            rel = os.path.relpath(f, EXAMPLES)
            if "draw_surface" not in Path(f).read_text(errors="replace"):
                skipped.append(rel)  # plane curves only: algray draws surfaces
                continue
            work = Path(tmp) / rel.replace("/", "_")
            work.mkdir()
            text, width, height = comparable(f, args.scale, work)
            script = work / Path(f).name
            script.write_text(text)
            subprocess.run([surf, "-q", str(script)], cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                           timeout=600)
            theirs = work / "surf_1.ppm"
            ours = work / "algray.png"
            result = subprocess.run([str(args.binary), "render", str(script), "-o", str(ours), "--set",
                                     "antialias.samples=1", "--set", "antialias.adaptive=false"],
                                    capture_output=True, text=True, cwd=work, timeout=600)
            warnings = len([l for l in result.stderr.splitlines() if "warning" in l])
            if result.returncode != 0 or not theirs.exists():
                note = (result.stderr.strip().splitlines() or ["no message"])[0] if result.returncode else \
                    "surf wrote no image"
                note = note.replace(str(work) + "/", "")
                rows.append((rel, None, None, note))
                print(f"{rel:40s} FAILED: {note}", flush=True)
                continue
            w, h, a = read_png(ours)
            w2, h2, b = read_ppm(theirs)
            assert (w, h) == (w2, h2) == (width, height), f"{rel}: sizes {w}x{h}, {w2}x{h2}"
            both = either = 0
            for y in range(h):
                for x in range(w):
                    mine = max(abs(a[y][x][k] - (1, 2, 3)[k]) for k in range(3)) > 1
                    surfs = b[y][x] != (1, 2, 3)
                    both += mine and surfs
                    either += mine or surfs
            iou = both / either if either else 1.0
            rows.append((rel, iou, either, f"{warnings} warnings"))
            print(f"{rel:40s} IoU {iou:.4f}  {either} pixels in either  {warnings} warnings", flush=True)

    ok = [r for r in rows if r[1] is not None]
    if not ok:
        sys.exit("no script rendered: nothing to compare")
    ious = [r[1] for r in ok]
    version = subprocess.run([surf, "--version"], capture_output=True, text=True).stdout.strip().split("\n")[0] or "?"
    low = sorted((r for r in ok if r[1] < SHOWN_BELOW), key=lambda r: r[1])
    failed = [r for r in rows if r[1] is None]
    # One line: RESULTS.md is kept short; every script's row is in this script's output.
    bullet = (
        f"- surf: {datetime.date.today()}, {machine()}, commit {commit(args.binary)}, surf-alggeo {version}, "
        f"`{command_line()}`: every script of surf-alggeo-doc's examples that draws a surface, at {args.scale}x its "
        "size, antialiasing and depth cueing off (the script says how the copies differ), algray one ray per pixel. "
        f"{len(ok)} of {len(rows)} render ({len(skipped)} more draw plane curves only); silhouette IoU median "
        f"{statistics.median(ious):.4f}" +
        (f"; under {SHOWN_BELOW}: " + ", ".join(f"{name} {iou:.4f}" for name, iou, _, _ in low) if low else "") +
        ("; refused: " + ", ".join(f"{name} ({note.split(' error: ', 1)[-1]})" for name, _, _, note in failed)
         if failed else "") + ".")
    replace_bullet(args.output, HEADING, "- surf:", bullet, under=AREA)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    sys.exit(main())
