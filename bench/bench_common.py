"""What the render benchmarks share: running `algray render` with --stats (or `algray batch` for several frames), naming the machine and the commit, the
command line as run, and replacing one section of bench/RESULTS.md (a page of current figures, a table per area
with its date, machine, commit and command; the history is in bench/history/)."""
import datetime
import json
import os
import platform
import re
import shlex
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS_MD = ROOT / "bench" / "RESULTS.md"


def run_render(binary, scene, args, env, workdir):
    """Runs `algray render SCENE ARGS` once; returns (wall ms of the whole process, parsed --stats)."""
    stats = workdir / "stats.json"
    cmd = [str(binary), "render", str(scene), "-o", str(workdir / "out.exr"), "--stats", str(stats)] + list(args)
    start = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = (time.perf_counter() - start) * 1000
    return wall, json.loads(stats.read_text())


def run_frames(binary, scene, args, env, workdir, frames):
    """Renders SCENE `frames` + 1 times in one `algray batch` process (an orbit of 0 degrees: the same camera each
    frame), with ARGS on its command line; returns the --stats of every frame but the first. Frames in one process
    share its device, programs and buffers, so a frame's kernel time is free of one process's start-up and of a
    single frame's stall: on a shared VM one-frame processes of the same kernels read up to 2x apart."""
    jobs, log = workdir / "frames.toml", workdir / "frames.log.jsonl"
    log.unlink(missing_ok=True)
    jobs.write_text(f'[[job]]\nscene = {json.dumps(str(Path(scene).resolve()))}\n'
                    f'output = {json.dumps(str(workdir / "frame_{frame}.exr"))}\n'
                    f'orbit = {{ frames = {frames + 1}, degrees = 0 }}\n')
    cmd = [str(binary), "batch", str(jobs), "--log", str(log)] + list(args)
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    lines = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
    return [line["stats"] for line in sorted(lines, key=lambda line: line["frame"])[1:]]


def parse_degrees(text):
    """Degrees given as a range ("1-32") or a list ("2,6,10")."""
    if "-" in text:
        lo, hi = (int(x) for x in text.split("-"))
        return list(range(lo, hi + 1))
    return [int(x) for x in text.split(",")]


def fresh_caches(parent):
    """An environment whose algray and PoCL program caches start empty (a cold run)."""
    caches = Path(parent)
    return dict(os.environ, ALGRAY_CACHE_DIR=str(caches / "algray"), POCL_CACHE_DIR=str(caches / "pocl"))


def machine():
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def commit(binary=None):
    """The commit the figures are of. For an algray binary, the git revision its `--version` names (what it was
    built from, "-dirty" when its tree had changes), or "not recorded"; without one (a tool built from this tree),
    the working tree's HEAD, "-dirty" when tracked files differ from it."""
    if binary is not None:
        try:
            out = subprocess.run([str(binary), "--version"], capture_output=True, text=True, timeout=30).stdout
            found = re.search(r"\(git ([0-9a-f]{7,40}(?:-dirty)?)\)", out)
            return found.group(1) if found else "not recorded"
        except (OSError, subprocess.SubprocessError):
            return "not recorded"
    try:
        head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=30)
        if head.returncode != 0 or not head.stdout.strip():
            return "not recorded"
        dirty = subprocess.run(["git", "-C", str(ROOT), "diff", "--no-ext-diff", "--quiet", "HEAD", "--"],
                               capture_output=True, timeout=60).returncode == 1
        return head.stdout.strip() + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "not recorded"


def command_line(prefix="python3"):
    """The command as run, quoted so that it can be pasted back into a shell: `python3 bench/NAME.py ARGS`."""
    script = Path(sys.argv[0]).resolve()
    try:
        script = script.relative_to(ROOT)
    except ValueError:
        pass
    return shlex.join(([prefix] if prefix else []) + [str(script)] + sys.argv[1:])


def heading_level(heading):
    return len(heading) - len(heading.lstrip("#"))


def _find_heading(text, heading):
    """Where the line that is exactly `heading` starts, or None."""
    found = re.search(r"^" + re.escape(heading.rstrip()) + r"[ \t]*$", text, re.MULTILINE)
    return found.start() if found else None


def _section_end(text, start, level):
    """Where the section whose heading line starts at `start` ends: at the next heading of its level or above."""
    line_end = text.find("\n", start)
    if line_end == -1:
        return len(text)
    found = re.compile(r"^#{1,%d} " % level, re.MULTILINE).search(text, line_end + 1)
    return found.start() if found else len(text)


def _join(before, section, after):
    """before + section + after, with one blank line between the section and what comes after it."""
    section = section.rstrip("\n") + "\n"
    if after.strip():
        section += "\n"
    return before + section + after


def _to_history(old, heading):
    """A section of bench/RESULTS.md about to be replaced, verbatim, at the end of this month's history file, its
    heading saying when and by which script."""
    old = old.rstrip("\n")
    path = ROOT / "bench" / "history" / f"{datetime.date.today():%Y-%m}.md"
    history = path.read_text() if path.exists() else "Superseded sections of bench/RESULTS.md, verbatim.\n"
    script = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "a script"
    replaced = f"(replaced on {datetime.date.today().isoformat()} by bench/{script}'s next run)"
    # One level down from `##` at most, so that the history file's own `##` sections stay its top level.
    title = "## " + heading.lstrip("#").strip()
    path.write_text(history.rstrip("\n") + "\n\n" + old.replace(heading, title + " " + replaced, 1) + "\n")


def replace_section(path, heading, section, under=None):
    """Puts `section` (starting with the Markdown heading line `heading`) in place of the old one in the file: from
    that heading's line to the next heading of the same or a higher level, so that a `##` section keeps going past
    its `###` ones and a `###` one stops at the next `###` or `##`. Where the file has no such heading, the section
    is appended: at the end of the section `under` names (its area's `##` heading, added too when missing), or
    at the end of the file. A section of bench/RESULTS.md that is replaced goes to bench/history/YYYY-MM.md."""
    out = Path(path)
    text = out.read_text() if out.exists() else "# Benchmark results\n\n"
    start = _find_heading(text, heading)
    if start is not None:
        end = _section_end(text, start, heading_level(heading))
        if out.resolve() == RESULTS_MD.resolve() and text[start:end].strip() != section.strip():
            _to_history(text[start:end], heading)
        text = _join(text[:start], section, text[end:])
    elif under and _find_heading(text, under) is not None:
        parent = _find_heading(text, under)
        end = _section_end(text, parent, heading_level(under))
        text = _join(text[:end].rstrip("\n") + "\n\n", section, text[end:])
    else:
        if under:
            section = under + "\n\n" + section
        text = text.rstrip("\n") + "\n\n" + section.rstrip("\n") + "\n"
    out.write_text(text)


def replace_bullet(path, heading, prefix, bullet, under=None):
    """Puts the one-line `bullet` (starting with `prefix`, such as "- surf:") in place of the section's line that
    starts with `prefix`, keeping its other lines: for sections that several scripts write a line each of, where
    RESULTS.md has no room for a section apiece. The section is made when missing."""
    out = Path(path)
    text = out.read_text() if out.exists() else "# Benchmark results\n\n"
    start = _find_heading(text, heading)
    lines = []
    if start is not None:
        end = _section_end(text, start, heading_level(heading))
        lines = [l for l in text[start:end].splitlines()[1:] if l.startswith("- ")]
    lines = sorted([l for l in lines if not l.startswith(prefix)] + [bullet])
    replace_section(path, heading, heading + "\n\n" + "\n".join(lines) + "\n", under=under)


def read_png(path, rgb=False):
    """(width, height, rows of channel tuples) of a non-interlaced 8- or 16-bit grey, RGB or RGBA PNG; with rgb,
    each pixel's first three channels (an RGB or RGBA picture's colour)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", data[pos + 8:pos + 8 + length])
        elif kind == b"IDAT":
            idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    assert depth in (8, 16) and interlace == 0, f"{path}: unsupported PNG layout"
    bpp = channels * depth // 8
    stride = width * bpp
    raw = zlib.decompress(idat)
    rows, previous, i = [], bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = previous[x]
            c = previous[x - bpp] if x >= bpp else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        if depth == 8:
            values = list(line)
        else:
            values = [line[k] << 8 | line[k + 1] for k in range(0, stride, 2)]
        kept = min(channels, 3) if rgb else channels
        rows.append([tuple(values[x * channels:x * channels + kept]) for x in range(width)])
        previous = line
    return width, height, rows
