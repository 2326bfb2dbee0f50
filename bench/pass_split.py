#!/usr/bin/env python3
"""Per-pass device time of several variants of one render, side by side: precisions, binaries or kernel
directories (ALGRAY_KERNEL_DIR), run interleaved in a rotating order, with each variant's ratio to the first taken
per round (median and range) and of the fastest rounds. The first pass of each kernel and the second pass of
adaptive precision (its escalation) are split, so a change to either can be told from the machine's noise.

A variant is LABEL=PRECISION[@BINARY][+KERNEL_DIR], for example
  float=float  adaptive=adaptive  old=adaptive@/tmp/base/algray  trial=adaptive+/tmp/kernels-copy
"""
import argparse
import os
import statistics
import tempfile
from pathlib import Path

from bench_common import ROOT, machine, run_render


def parse_variant(text, default_binary):
    label, _, rest = text.partition("=")
    rest, _, kernels = rest.partition("+")
    precision, _, binary = rest.partition("@")
    if not label or not precision:
        raise SystemExit(f"bad variant '{text}': LABEL=PRECISION[@BINARY][+KERNEL_DIR]")
    return {"label": label, "precision": precision, "binary": binary or default_binary, "kernels": kernels}


def split(stats):
    """{pass name: (first-pass ms, escalation ms, escalated rays)} of one render's --stats."""
    return {p["name"]: (p["kernel_ms"] - p.get("escalation_ms", 0), p.get("escalation_ms", 0),
                        p.get("escalated", 0)) for p in stats["passes"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("variants", nargs="+")
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--binary", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene setting for every variant, as `algray render --set` takes it")
    a = ap.parse_args()
    variants = [parse_variant(v, a.binary) for v in a.variants]
    args = ["--width", str(a.width), "--height", str(a.height), "--set", "antialias.samples=1"]
    for setting in a.set:
        args += ["--set", setting]
    runs = {v["label"]: [] for v in variants}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(a.rounds):
            for v in variants[r % len(variants):] + variants[:r % len(variants)]:
                env = dict(os.environ)
                if v["kernels"]:
                    env["ALGRAY_KERNEL_DIR"] = v["kernels"]
                _, stats = run_render(v["binary"], a.scene, args + ["--precision", v["precision"]], env, Path(tmp))
                runs[v["label"]].append(split(stats))
    print(f"Machine: {machine()}. `algray render {a.scene} {' '.join(args)}`, {a.rounds} rounds, variants "
          f"interleaved; ms are device time, medians; x first: this variant's total over the first's, per round "
          f"(median, range) and of each one's fastest round.\n")
    names = list(runs[variants[0]["label"]][0])
    head = " | ".join(f"{n} first pass | {n} second pass | {n} escalated" for n in names)
    print(f"| variant | total | x first (median) | range | x first (fastest) | {head} |")
    print("|---|---|---|---|---|" + "---|" * (3 * len(names)))
    base = [sum(a + b for a, b, _ in s.values()) for s in runs[variants[0]["label"]]]
    for v in variants:
        rounds = runs[v["label"]]
        totals = [sum(a + b for a, b, _ in s.values()) for s in rounds]
        ratios = [t / b for t, b in zip(totals, base)]
        cells = " | ".join(f"{statistics.median(s[n][0] for s in rounds):.0f} | "
                           f"{statistics.median(s[n][1] for s in rounds):.0f} | {rounds[0][n][2]}" for n in names)
        print(f"| {v['label']} | {statistics.median(totals):.0f} | {statistics.median(ratios):.3f} | "
              f"{min(ratios):.3f}-{max(ratios):.3f} | {min(totals) / min(base):.3f} | {cells} |")


if __name__ == "__main__":
    main()
