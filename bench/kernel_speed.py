#!/usr/bin/env python3
"""Primary-kernel speed of two algray binaries side by side: rays/s per degree on seeded random surfaces and
kernel ms on the paper's surfaces, each pair of runs interleaved, with the ratio's median and spread.

With --results each table replaces its section of bench/RESULTS.md ("Random surfaces, per degree" and "The paper's
surfaces, preview kernel", under "Rays per second per degree"), with the date, machine, commit and command; the
whole output goes to bench/results/kernel_speed_SIDE_COMMIT.md (degrees) and kernel_speed_surfaces_COMMIT.md,
and the page shows the degrees in PAGE_DEGREES when more than 16 were run."""
import argparse
import datetime
import random
import statistics
import tempfile
from pathlib import Path

from bench_common import (RESULTS_MD, ROOT, command_line, commit, machine, parse_degrees, replace_section,
                          run_render)

PAPER_SURFACES = ["barth_sextic", "cusp_catastrophe", "torus", "tooth", "lemniscate", "tanglecube", "barth_decic"]
AREA = "## Rays per second per degree"
HEADINGS = {"degrees": "### Random surfaces, per degree", "surfaces": "### The paper's surfaces, preview kernel"}
PAGE_DEGREES = {1, 2, 3, 4, 5, 6, 8, 12, 16, 24, 32}


def random_surface(degree, seed, side):
    """A seeded random surface of exactly `degree` in the unit sphere: x^n + y^n + z^n - 1/4, then 3n random
    monomials of lower degrees with coefficients in [-1, 1] (the family of solver_bench's per-degree table)."""
    rng = random.Random(seed)
    terms = [[degree, 0, 0, 1], [0, degree, 0, 1], [0, 0, degree, 1], [0, 0, 0, -0.25]]
    for _ in range(3 * degree):
        total = rng.randint(1, max(1, degree - 1))
        i = rng.randint(0, total)
        j = rng.randint(0, total - i)
        terms.append([i, j, total - i - j, rng.uniform(-1, 1)])
    return (f"[surface]\nname = \"random degree {degree}\"\nterms = {terms}\n"
            "[extent]\ntype = \"sphere\"\nradius = 1\n"
            "[camera]\neye = [1.2, 0.9, 2.6]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n"
            f"[image]\nwidth = {side}\nheight = {side}\n")


def kernel_ms(stats):
    return next(p["kernel_ms"] for p in stats["passes"] if p["name"] == "primary")


def compare(binaries, scene, args, repeat, workdir):
    """Kernel ms of each binary, interleaved A B A B ...; one warm-up each first (fills the program caches)."""
    for b in binaries:
        run_render(b, scene, args, None, workdir)
    times = [[] for _ in binaries]
    for _ in range(repeat):
        for k, b in enumerate(binaries):
            times[k].append(kernel_ms(run_render(b, scene, args, None, workdir)[1]))
    ratios = [new / old for old, new in zip(times[0], times[1])]
    return [statistics.median(t) for t in times], statistics.median(ratios), min(ratios), max(ratios)


def timed(binary, scene, args, repeat, workdir):
    """Kernel ms of one binary: (median, min, max) of `repeat` runs after one warm-up."""
    run_render(binary, scene, args, None, workdir)
    times = [kernel_ms(run_render(binary, scene, args, None, workdir)[1]) for _ in range(repeat)]
    return statistics.median(times), min(times), max(times)


def degree_row(binaries, d, scene, a, work):
    """One row of the per-degree table: Mrays/s of one binary, or of both and the speed-up."""
    args = ["--set", f"render.precision={a.precision}"]
    rays = a.side * a.side / 1e3
    if len(binaries) == 1:
        ms, lo, hi = timed(binaries[0], scene, args, a.repeat, work)
        return f"| {d} | {rays / ms:.2f} | {rays / hi:.2f}-{rays / lo:.2f} |"
    (old, new), ratio, lo, hi = compare(binaries, scene, args, a.repeat, work)
    return f"| {d} | {rays / old:.2f} | {rays / new:.2f} | {1 / ratio:.2f}x | {1 / hi:.2f}-{1 / lo:.2f} |"


def surface_row(binaries, name, a, work):
    # One ray per pixel in both: a baseline from before preview dropped antialiasing traced 2x2.
    args = ["--preview", "--width", "1024", "--height", "768", "--set", f"render.precision={a.precision}",
            "--set", "antialias.samples=1"]
    scene = ROOT / "scenes" / f"{name}.toml"
    if len(binaries) == 1:
        ms, lo, hi = timed(binaries[0], scene, args, a.repeat, work)
        return f"| {name} | {ms:.2f} | {lo:.2f}-{hi:.2f} |"
    (old, new), ratio, lo, hi = compare(binaries, scene, args, a.repeat, work)
    return f"| {name} | {old:.1f} | {new:.1f} | {1 / ratio:.2f}x | {1 / hi:.2f}-{1 / lo:.2f} |"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--baseline", help="the algray binary to compare against (none: time --algray alone)")
    ap.add_argument("--algray", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--side", type=int, default=512, help="random surfaces: side x side rays")
    ap.add_argument("--degrees", default="1-32", help="e.g. 1-32 or 2,6,10")
    ap.add_argument("--only", choices=["degrees", "surfaces"])
    ap.add_argument("--precision", default="double")
    ap.add_argument("--results", action="store_true", help="write the tables into their sections of "
                    "bench/RESULTS.md and the whole output to bench/results/")
    a = ap.parse_args()
    degrees = parse_degrees(a.degrees)
    if a.baseline is None:  # a device where no earlier build is at hand (a lent GPU)
        binaries = [a.algray]
        about = (f"`{a.algray}`; kernel ms of the primary pass, median of {a.repeat} runs after one warm-up. "
                 f"Precision {a.precision}.")
        heads = [f"| degree | Mrays/s ({a.side}x{a.side}) | min-max |\n|---|---|---|",
                 "| surface (1024x768 preview, one ray per pixel) | kernel ms | min-max |\n|---|---|---|"]
    else:
        binaries = [a.baseline, a.algray]
        about = (f"Baseline `{a.baseline}`, current `{a.algray}`; kernel ms of the primary pass, median of {a.repeat} "
                 "interleaved runs each after one warm-up; ratio = current/baseline time per pair (median, min-max). "
                 f"Precision {a.precision}.")
        heads = ["| degree | baseline Mrays/s | current Mrays/s | speed-up (median) | min-max |\n|---|---|---|---|---|",
                 "| surface (1024x768 preview, one ray per pixel) | baseline kernel ms | current kernel ms | "
                 "speed-up (median) | min-max |\n|---|---|---|---|---|"]
    print(f"Machine: {machine()}. {about}\n")
    tables = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        if a.only != "surfaces":
            print(heads[0])
            tables["degrees"] = []
            for d in degrees:
                scene = work / f"random{d}.toml"
                scene.write_text(random_surface(d, 1000 + d, a.side))
                tables["degrees"].append((d, degree_row(binaries, d, scene, a, work)))
                print(tables["degrees"][-1][1], flush=True)
            print()
        if a.only != "degrees":
            print(heads[1])
            tables["surfaces"] = []
            for name in PAPER_SURFACES:
                tables["surfaces"].append((name, surface_row(binaries, name, a, work)))
                print(tables["surfaces"][-1][1], flush=True)
    if a.results:
        write_results(a, binaries, about, heads, tables)


def write_results(a, binaries, about, heads, tables):
    """Each table in place of its section of RESULTS.md; the whole output in bench/results/."""
    revision = commit(binaries[-1])
    baseline = f" against the baseline's {commit(binaries[0])}" if len(binaries) == 2 else ""
    for part, head in zip(("degrees", "surfaces"), heads):
        if part not in tables:
            continue
        rows = tables[part]
        name = f"kernel_speed_{a.side if part == 'degrees' else 'surfaces'}_{revision.replace(' ', '_')}.md"
        whole = ROOT / "bench" / "results" / name
        whole.write_text(f"Machine: {machine()}. {about}\n\n{head}\n" + "\n".join(r for _, r in rows) + "\n")
        shown = [r for d, r in rows if d in PAGE_DEGREES] if part == "degrees" and len(rows) > 16 else \
            [r for _, r in rows]
        what = (f"Seeded random surfaces of each degree (x^n + y^n + z^n - 1/4 and 3n random lower monomials, seed "
                f"1000 + n), {a.side}x{a.side} rays" if part == "degrees" else
                "The paper's surfaces, preview at 1024x768, one ray per pixel")
        lines = [HEADINGS[part], "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; commit: {revision}{baseline}",
                 f"- Command: `{command_line()}`",
                 f"- {what}. {about} Whole output: [bench/results/{name}](results/{name})"
                 + (f"; the page shows degrees {', '.join(str(d) for d in sorted(PAGE_DEGREES))}." if
                    len(shown) < len(rows) else "."), "", head] + shown
        replace_section(RESULTS_MD, HEADINGS[part], "\n".join(lines) + "\n", under=AREA)
        print(f"wrote {RESULTS_MD} and {whole}")


if __name__ == "__main__":
    main()
