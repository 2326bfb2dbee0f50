#!/usr/bin/env python3
"""POV-Ray comparison (issue 47): .pov scenes rendered by Debian's povray and by algray from the same file; how
well the silhouettes agree (intersection over union of the pixels that show a surface) and how far the depths
are apart where both show one. Writes its line of bench/RESULTS.md ("surf's and POV-Ray's own scenes",
under "Against the peers"); every scene's row is printed as it goes.

The scenes: the twelve of tests/data/pov (poly, polynomial, quartic, cubic, sphere and torus objects with their
transforms and clips, a right-handed, an orthographic and a tilted camera, an area light), and the paper's seven
surfaces as bench/peers.py writes them for POV-Ray. Silhouettes: povray with +UA (the background transparent)
against algray's PNG alpha over a transparent background, one ray per pixel in both. Depth: povray once more with
every object's texture replaced at its `//@depth` line (the end of its modifiers, so in world coordinates) by
one whose colour is the distance from the camera over --far, written as a 16-bit PNG with File_Gamma 1, against
algray's EXR Z (the distance from the eye along the unit ray); compared at pixels whose 3x3 neighbourhood both
programs cover, as a relative difference.

POV-Ray's own samples (--samples, on by default): every scene of its distribution's objects/quartic directory
(Debian's povray-examples, read where it is installed, not copied), which #include colors.inc, shapesq.inc and
the like from povray-includes. Each is rendered by both programs from one prepared copy: its planes (the floor
POV-Ray's +UA would show as surface), its `object { Axes ... }` (axisbox.inc's cylinders) and its background taken
out; for depth, its textures other than Clear ones taken out and the distance texture put at the end of each
top-level object. Scenes algray refuses are listed with their message. They get their own line ("- POV-Ray's
samples:").

Needs `apt-get install povray povray-examples povray-includes` (installed here when missing and run as root);
POVRAY names another binary.
"""
import argparse
import datetime
import glob
import os
import re
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import zlib
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, read_png, replace_bullet

AREA = "## Against the peers"
HEADING = "### surf's and POV-Ray's own scenes"  # one section, a line per script (surf_compare.py writes the other)
SHOWN_BELOW = 0.99  # scenes whose IoU is under this are named on the page
SCENES = ROOT / "tests/data/pov"
SAMPLES = Path("/usr/share/povray-3.7/scenes/objects/quartic")
POV_INCLUDE = "/usr/share/povray-3.7/include"
TOP_OBJECTS = ("intersection", "object", "quartic", "union", "poly", "cubic", "polynomial", "merge", "sphere",
               "torus", "difference")


def ensure_povray():
    povray = os.environ.get("POVRAY") or shutil.which("povray")
    if (not povray or not SAMPLES.is_dir()) and os.geteuid() == 0:
        subprocess.run(["apt-get", "install", "-y", "--no-install-recommends", "povray", "povray-examples",
                        "povray-includes"], check=True, stdout=subprocess.DEVNULL)
        povray = shutil.which("povray")
    if not povray:
        sys.exit("needs povray: apt-get install povray")
    return povray


def read_exr_depth(path):
    """The Z channel of a scanline EXR (no, ZIPS or ZIP compression) as rows of floats."""
    data = Path(path).read_bytes()
    assert data[:4] == b"\x76\x2f\x31\x01", path
    pos, channels, compression, window = 8, [], 0, None
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        kind = data[end + 1:end2].decode()
        size = struct.unpack("<i", data[end2 + 1:end2 + 5])[0]
        value = data[end2 + 5:end2 + 5 + size]
        if name == "channels":
            k = 0
            while value[k] != 0:
                e = value.index(b"\0", k)
                channels.append((value[k:e].decode(), struct.unpack("<i", value[e + 1:e + 5])[0]))
                k = e + 17
        elif name == "compression":
            compression = value[0]
        elif name == "dataWindow":
            window = struct.unpack("<4i", value)
        pos = end2 + 5 + size
    pos += 1
    assert compression in (0, 2, 3), f"{path}: EXR compression {compression} is not read here"
    x0, y0, x1, y1 = window
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines_per_chunk = {0: 1, 2: 1, 3: 16}[compression]
    chunks = (height + lines_per_chunk - 1) // lines_per_chunk
    offsets = struct.unpack(f"<{chunks}Q", data[pos:pos + 8 * chunks])
    sizes = {0: 4, 1: 2, 2: 4}  # uint, half, float
    rows = {}
    for offset in offsets:
        y, size = struct.unpack("<ii", data[offset:offset + 8])
        block = data[offset + 8:offset + 8 + size]
        n = min(lines_per_chunk, y1 - y + 1)
        expected = n * width * sum(sizes[t] for _, t in channels)
        if compression and size < expected:
            t = bytearray(zlib.decompress(block))
            for k in range(1, len(t)):
                t[k] = (t[k - 1] + t[k] - 128) & 255
            half = (len(t) + 1) // 2
            out = bytearray(len(t))
            out[0::2] = t[:half]
            out[1::2] = t[half:]
            block = bytes(out)
        k = 0
        for line in range(n):
            for name, kind in channels:
                length = width * sizes[kind]
                if name == "Z":
                    assert kind == 2, "Z is a float channel"
                    rows[y + line - y0] = list(struct.unpack(f"<{width}f", block[k:k + length]))
                k += length
    return [rows[y] for y in range(height)]


def camera_location(text):
    found = re.search(r"location\s*<\s*([-0-9.eE+]+)\s*,\s*([-0-9.eE+]+)\s*,\s*([-0-9.eE+]+)\s*>", text)
    assert found, "the scene's camera location must be three numbers here"
    return [float(v) for v in found.groups()]


def look_at(text):
    found = re.search(r"look_at\s*<\s*([-0-9.eE+]+)\s*,\s*([-0-9.eE+]+)\s*,\s*([-0-9.eE+]+)\s*>", text)
    assert found, "the scene's look_at must be three numbers here"
    return [float(v) for v in found.groups()]


def paper_scenes(tmp):
    """The paper's surfaces as bench/peers.py writes them for POV-Ray, each object ending in a //@depth line."""
    sys.path.insert(0, str(ROOT / "bench"))
    import peers
    out = []
    for name in peers.SURFACES:
        scene = peers.read_scene(ROOT / "scenes" / f"{name}.toml")
        path = Path(tmp) / f"paper_{name}.pov"
        peers.write_pov(scene, path, 4, 3, full=False)
        text = path.read_text()
        cut = text.rstrip().rindex("}")
        path.write_text(text[:cut] + "  //@depth\n}\n")
        out.append(path)
    return out


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def blocks(text, words):
    """(start, open brace, end) of each `word {...}` block at brace depth 0 whose word is one of words."""
    out, depth, i = [], 0, 0
    pattern = re.compile(r"\b(" + "|".join(words) + r")\s*\{")
    while i < len(text):
        c = text[i]
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif depth == 0:
            found = pattern.match(text, i)
            if found and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
                before = text[:i].rstrip()
                declared = re.search(r"#(declare|local)\s+\w+\s*=$", before)
                brace, d, j = found.end() - 1, 0, found.end() - 1
                while j < len(text):
                    d += {"{": 1, "}": -1}.get(text[j], 0)
                    if d == 0:
                        break
                    j += 1
                if not declared:
                    out.append((i, brace, j))
                i = j + 1
                continue
        i += 1
    return out


def remove_blocks(text, pattern):
    """text without the blocks (at any depth) that start with the regular expression pattern and a '{'."""
    while True:
        found = re.search(pattern + r"\s*\{", text)
        if not found:
            return text
        d, j = 0, found.end() - 1
        while j < len(text):
            d += {"{": 1, "}": -1}.get(text[j], 0)
            if d == 0:
                break
            j += 1
        text = text[:found.start()] + text[j + 1:]


def sample_scene(path, tmp):
    """A POV-Ray sample prepared for both programs: planes, axes and background out; //@depth at the end of each
    top-level object."""
    text = strip_comments(path.read_text())
    for start, _, end in reversed(blocks(text, ("plane",))):  # top-level only: clipped_by uses planes too
        text = text[:start] + text[end + 1:]
    for start, brace, end in reversed(blocks(text, ("object",))):
        if re.match(r"\s*Axes\b", text[brace + 1:]):
            text = text[:start] + text[end + 1:]
    ends = [end for _, _, end in blocks(text, TOP_OBJECTS)]
    for end in reversed(ends):
        text = text[:end] + " //@depth\n" + text[end:]
    out = Path(tmp) / f"sample_{path.stem}.pov"
    out.write_text(text)
    return out


def summary(rows, what, w, h, far, every=False):
    """The results line's text after its head: what was rendered, the IoU median and lowest, the depth, failures
    (and, with every, each scene's IoU and depth median)."""
    ok = [r for r in rows if r[1] is not None]
    failed = [r for r in rows if r[1] is None]
    text = f"{what}, {w}x{h}, one ray per pixel. {len(ok)} of {len(rows)} render"
    if ok:
        ious = [r[1] for r in ok]
        medians = [r[2] for r in ok if r[2] is not None]
        p99s = [r[3] for r in ok if r[3] is not None]
        low = sorted((r for r in ok if r[1] < SHOWN_BELOW), key=lambda r: r[1])
        text += (f"; silhouette IoU median {statistics.median(ious):.4f}, lowest {min(ious):.4f} "
                 f"({min(ok, key=lambda r: r[1])[0]}); depth against POV-Ray's 16-bit distance image (step "
                 f"{far / 65535:.1e}), away from silhouettes: relative difference median per scene at most "
                 f"{max(medians):.1e}, 99th percentile at most {max(p99s):.1e}" if medians else "")
        if every:
            text += "; IoU (depth median): " + ", ".join(
                f"{r[0]} {r[1]:.4f} ({r[2]:.1e})" if r[2] is not None else f"{r[0]} {r[1]:.4f} (-)" for r in ok)
        elif low:
            text += f"; IoU under {SHOWN_BELOW}: " + ", ".join(f"{r[0]} {r[1]:.4f}" for r in low)
    if failed:
        def short(note):  # the message without its place (the scene is named) and at most 90 characters
            note = note.split(": error: ", 1)[-1]
            return note if len(note) <= 90 else note[:87] + "..."
        text += "; refused: " + ", ".join(f"{r[0]} ({short(r[4])})" for r in failed)
    return text + "."


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--far", type=float, default=40.0, help="the distance the depth image's white stands for")
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    ap.add_argument("--sample-far", type=float, default=200.0, help="--far for POV-Ray's samples")
    ap.add_argument("--no-samples", dest="samples", action="store_false", help="skip POV-Ray's own samples")
    ap.add_argument("--only-samples", action="store_true", help="only POV-Ray's own samples (their line alone)")
    args = ap.parse_args()
    povray = ensure_povray()
    w, h = args.width, args.height
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        files = [] if args.only_samples else \
            sorted(Path(f) for f in glob.glob(str(SCENES / "*.pov"))) + paper_scenes(tmp)
        if args.samples:
            files += [sample_scene(f, tmp) for f in sorted(SAMPLES.glob("*.pov"))]
        for f in files:
            name = f.stem
            work = Path(tmp) / name
            work.mkdir()
            text = f.read_text()
            # A sample's own includes (axisbox.inc) are beside the original; its depth copy has no Clear-less textures.
            sample = name.startswith("sample_")
            here = SAMPLES if sample else SCENES
            far = args.sample_far if sample else args.far  # the samples' objects lie up to 80 units away
            plain, deep = work / "plain.pov", work / "depth.pov"
            # Without a background POV-Ray's +UA leaves the background transparent.
            plain.write_text(re.sub(r"background\s*\{[^}]*\}", "", text).replace("//@depth", ""))
            eye = camera_location(text)
            if "orthographic" in text:  # algray's Z is then the distance from the eye's plane
                look = look_at(text)
                f = [look[i] - eye[i] for i in range(3)]
                n = sum(c * c for c in f) ** 0.5
                distance = "(" + "+".join(f"({v}-({eye[i]}))*{f[i] / n}" for i, v in enumerate("xyz")) + \
                    f")/{far}"
            else:
                distance = f"sqrt(pow(x-({eye[0]}),2)+pow(y-({eye[1]}),2)+pow(z-({eye[2]}),2))/{far}"
            depth_texture = (f"texture {{ pigment {{ function {{ {distance} }} color_map {{ [0 rgb 0] [1 rgb 1] }} }} "
                             "finish { ambient 1 diffuse 0 } }")
            depth_text = text
            if sample:
                depth_text = remove_blocks(depth_text, r"\btexture(?=\s*\{(?![^{}]*\{\s*Clear\s*\}))")
                depth_text = remove_blocks(depth_text, r"\b(pigment(?!\s*\{\s*Clear\s*\})|finish)")
            deep.write_text(re.sub(r"background\s*\{[^}]*\}", "", depth_text).replace(
                "//@depth", depth_texture + " interior_texture { " + depth_texture[len("texture { "):]))
            pov = ["+W%d" % w, "+H%d" % h, "-D", "-GA", f"+L{here}", f"+L{POV_INCLUDE}"]
            theirs = subprocess.run([povray, f"+I{plain}", f"+O{work}/pov.png", "+UA"] + pov, cwd=work,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=600)
            if theirs.returncode != 0:
                note = "povray: " + ([l for l in theirs.stderr.splitlines() if "Error" in l] or ["failed"])[0]
                rows.append((name, None, None, None, note))
                print(f"{name:28s} FAILED: {note}", flush=True)
                continue
            subprocess.run([povray, f"+I{deep}", f"+O{work}/pov_depth.png", "+FN16", "File_Gamma=1.0"] + pov,
                           cwd=work, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=600)
            result = subprocess.run([str(args.binary), "render", str(plain), "-o", str(work / "algray.png"), "-o",
                                     str(work / "algray.exr"), "--width", str(w), "--height", str(h), "--set",
                                     "antialias.samples=1", "--set", "antialias.adaptive=false", "--set",
                                     "image.background=[0, 0, 0, 0]"], capture_output=True, text=True, timeout=600,
                                    env=dict(os.environ, ALGRAY_POV_INCLUDE=str(here)))
            if result.returncode != 0:
                errors = [l for l in result.stderr.splitlines() if ": error: " in l] or ["no message"]
                note = errors[0].replace(str(plain), name + ".pov")
                rows.append((name, None, None, None, note))
                print(f"{name:28s} FAILED: {note}", flush=True)
                continue
            _, _, mine = read_png(work / "algray.png")
            _, _, theirs = read_png(work / "pov.png")
            _, _, pov_depth = read_png(work / "pov_depth.png")
            z = read_exr_depth(work / "algray.exr")
            ma = [[mine[y][x][3] > 0 for x in range(w)] for y in range(h)]
            mb = [[theirs[y][x][3] > 0 for x in range(w)] for y in range(h)]
            both = sum(ma[y][x] and mb[y][x] for y in range(h) for x in range(w))
            either = sum(ma[y][x] or mb[y][x] for y in range(h) for x in range(w))
            iou = both / either if either else 1.0
            errors = []
            for y in range(1, h - 1):
                for x in range(1, w - 1):
                    if all(ma[y + dy][x + dx] and mb[y + dy][x + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)):
                        d = pov_depth[y][x][0] / 65535 * far
                        if d > 0:
                            errors.append(abs(z[y][x] - d) / d)
            errors.sort()
            median = statistics.median(errors) if errors else None
            p99 = errors[int(0.99 * (len(errors) - 1))] if errors else None
            rows.append((name, iou, median, p99, f"{either} px"))
            print(f"{name:28s} IoU {iou:.4f}  depth |rel. diff| median {median or 0:.2e} p99 {p99 or 0:.2e}  "
                  f"{either} px",
                  flush=True)

    version = subprocess.run([povray, "--version"], capture_output=True, text=True)
    found = re.search(r"POV-Ray (\S+)", version.stdout + version.stderr)
    head = (f"{datetime.date.today()}, {machine()}, commit {commit(args.binary)}, POV-Ray "
            f"{found.group(1) if found else '?'}, `{command_line()}`: ")
    own = [r for r in rows if not r[0].startswith("sample_")]
    samples = [(r[0][len("sample_"):],) + r[1:] for r in rows if r[0].startswith("sample_")]
    if own:
        replace_bullet(args.output, HEADING, "- POV-Ray:", "- POV-Ray: " + head + summary(
            own, "tests/data/pov's twelve scenes and the paper's seven surfaces as bench/peers.py writes them", w, h,
            args.far), under=AREA)
    if samples:
        replace_bullet(args.output, HEADING, "- POV-Ray's samples:", "- POV-Ray's samples: " + head + summary(
            samples, f"the {len(samples)} scenes of POV-Ray's scenes/objects/quartic (planes, axes and background "
            "taken out)", w, h, args.sample_far, every=True), under=AREA)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    sys.exit(main())
