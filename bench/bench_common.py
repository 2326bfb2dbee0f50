"""What the render benchmarks share: running `algray render` with --stats, naming the machine, and replacing
one section of bench/RESULTS.md."""
import json
import os
import platform
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_render(binary, scene, args, env, workdir):
    """Runs `algray render SCENE ARGS` once; returns (wall ms of the whole process, parsed --stats)."""
    stats = workdir / "stats.json"
    cmd = [str(binary), "render", str(scene), "-o", str(workdir / "out.exr"), "--stats", str(stats)] + list(args)
    start = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = (time.perf_counter() - start) * 1000
    return wall, json.loads(stats.read_text())


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


def replace_section(path, heading, section):
    """Puts `section` (starting with `heading`) in place of the old one in the Markdown file, or appends it."""
    out = Path(path)
    text = out.read_text() if out.exists() else "# Benchmark results\n\n"
    if heading in text:
        start = text.index(heading)
        end = text.find("\n## ", start + len(heading))
        text = text[:start] + section + (text[end + 1:] if end != -1 else "")
    else:
        text = text.rstrip("\n") + "\n\n" + section
    out.write_text(text)
