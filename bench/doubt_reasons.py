#!/usr/bin/env python3
"""Why adaptive precision doubts a scene's camera rays (issue 18): `algray probe --json` on random pixels, and
each doubted ray's reason (isolation.h: discard, accept, cluster, flat) counted; flat doubts that P's values
confirmed and accept doubts whose brackets P's values settled, which go to no second pass, apart. Pixels whose ray misses the
extent are counted in the sample but need no search. Prints each doubted case with the seed and its index.

  python3 bench/doubt_reasons.py --count 1500 scenes/barth_decic.toml
"""
import argparse
import collections
import json
import random
import subprocess

from bench_common import ROOT


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default=str(ROOT / "scenes/barth_decic.toml"))
    ap.add_argument("--count", type=int, default=500, help="random pixels probed")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--height", type=int, default=768)
    ap.add_argument("--binary", default=str(ROOT / "build/apps/algray/algray"))
    a = ap.parse_args()
    rng = random.Random(a.seed)
    reasons = collections.Counter()
    for case in range(a.count):
        x, y = rng.randrange(a.width), rng.randrange(a.height)
        out = subprocess.run([a.binary, "probe", a.scene, "--precision", "adaptive", "--pixel", f"{x},{y}",
                              "--width", str(a.width), "--height", str(a.height), "--json"],
                             capture_output=True, text=True, check=True).stdout
        solver = json.loads(out)["surfaces"][0]["solvers"][0]
        if "doubt" not in solver:
            continue
        reason = solver["doubt"]["reason"]
        if "confirmed" in solver["doubt"]:
            # surface.h confirm_flat_roots kept the float root, or methods/bernstein.h settle_brackets the bracket
            reason += ", settled (no second pass)"
        reasons[reason] += 1
        print(f"seed {a.seed} case {case} pixel {x},{y}: {reason}", flush=True)
    total = sum(reasons.values())
    shares = ", ".join(f"{r} {n} ({100 * n / total:.0f}%)" for r, n in reasons.most_common()) if total else "none"
    print(f"{total} of {a.count} camera rays doubted ({100 * total / a.count:.1f}%): {shares}")


if __name__ == "__main__":
    main()
