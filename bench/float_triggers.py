#!/usr/bin/env python3
"""Issue 18's question, measured before any escalation is built: of the pixels that plain float gets wrong
against solver_ref, how many does the float kernel already mark as undecided (the flags it sets today:
isolation depth limit 8, exact zero 32, cluster 64)? And what share of all pixels carries those marks, the
cost of redoing them? Every scene in scenes/ (or those given), preview, one ray per pixel, at 160x120, float
kernel against solver_ref on the same float rays. Wrong: a hit/miss disagreement on a pixel the reference
certifies (class 1 miss or 2 simple root), or both hit with relative depth error over 1e-3. Prints a Markdown
table."""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "build/python"))
import algray  # noqa: E402

FLAG_HIT, FLAG_BUDGET, FLAG_EXACT, FLAG_CLUSTER = 1, 8, 32, 64
MARKS = FLAG_BUDGET | FLAG_EXACT | FLAG_CLUSTER


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--scenes", nargs="*", default=sorted(p.stem for p in (ROOT / "scenes").glob("*.toml")))
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=120)
    a = ap.parse_args()
    renderer = algray.Renderer()
    print("| scene | certified px | float wrong | wrong and marked | marked px (share) |")
    print("|---|---|---|---|---|")
    for name in a.scenes:
        scene = algray.Scene.load(str(ROOT / "scenes" / f"{name}.toml"))
        scene.set("antialias.samples", 1)
        scene.set("render.precision", "float")
        size = dict(width=a.width, height=a.height, preview=True)
        ref = renderer.render(scene, reference=True, **size)
        flt = renderer.render(scene, aov=["flags"], **size)
        cls = ref.aov["reference.class"]
        certified = (cls == 1) | (cls == 2)
        ref_hit, flt_hit = np.isfinite(ref.depth), np.isfinite(flt.depth)
        flags = flt.aov["flags"]
        both = certified & ref_hit & flt_hit
        rel = np.zeros(ref.depth.shape)
        rel[both] = np.abs(flt.depth[both] - ref.depth[both]) / np.maximum(np.abs(ref.depth[both]), 1e-30)
        wrong = certified & ((ref_hit != flt_hit) | (both & (rel > 1e-3)))
        marked = (flags & MARKS) != 0
        n_wrong = int(wrong.sum())
        caught = int((wrong & marked).sum())
        print(f"| {name} | {int(certified.sum())} | {n_wrong} | {caught} ({100 * caught / max(n_wrong, 1):.0f}%) | "
              f"{int(marked.sum())} ({100 * marked.mean():.2f}%) |", flush=True)


if __name__ == "__main__":
    main()
