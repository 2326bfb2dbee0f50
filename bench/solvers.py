#!/usr/bin/env python3
"""What accuracy costs (issue 4): runs the four parts of solver_bench, plots them, and writes bench/RESULTS.md.

  bench/solvers.py --quick            # every part in its quick form (under 10 minutes on a 2-core CPU)
  bench/solvers.py --only fig2 decic  # some parts; the others keep their last results
  bench/solvers.py --plot-only        # redraw plots and RESULTS.md from bench/results/*.json
  bench/solvers.py --plot-only --no-plots  # RESULTS.md and bench/results/solvers.md only (no matplotlib)

Parts: degrees (rays/s and build times per degree), accuracy (time against error per tolerance), fig2 (the
paper's Fig. 2) and decic (the paper's Barth decic experiment). JSON goes to bench/results/, plots as PNG and
SVG to bench/figures/. The section "Solvers: what accuracy costs" of bench/RESULTS.md gets each part's date,
machine, commit and command and a short table; every table in full goes to bench/results/solvers.md.
"""
import argparse
import datetime
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, commit, replace_section

RESULTS = ROOT / "bench" / "results"
FIGURES = ROOT / "bench" / "figures"
PARTS = ["degrees", "accuracy", "fig2", "decic"]
HEADING = "## Solvers: what accuracy costs"
FULL = RESULTS / "solvers.md"
# What the page's per-degree table shows (the rest is in FULL): double, Brent after each isolation.
PAGE_PRECISION = "double"
PAGE_METHODS = ["bernstein/brent", "descartes/brent", "sturm/brent", "derivative-chain/brent"]
PAGE_DEGREES = [1, 2, 4, 6, 8, 10, 16, 24, 32]


def run_part(binary, part, quick, device, env):
    out = RESULTS / f"{part}.json"
    cmd = [str(binary), "--out", str(out)]
    if quick:
        cmd.append("--quick")
    if device:
        cmd += ["--device", device]
    cmd.append(part)
    if part == "decic":
        cmd += ["--figure", str(FIGURES / "decic_methods.png")]
    start = time.perf_counter()
    subprocess.run(cmd, check=True, env=env)
    data = json.loads(out.read_text())
    data["command"] = " ".join(["bench/solvers.py"] + (["--quick"] if quick else []) + ["--only", part])
    data["commit"] = commit()
    data["date"] = datetime.date.today().isoformat()
    data["seconds"] = round(time.perf_counter() - start, 1)
    data["cpu"] = cpu_name()
    out.write_text(json.dumps(data, indent=1) + "\n")
    print(f"solvers: {part} took {data['seconds']} s", file=sys.stderr)


def cpu_name():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return f"{line.split(':', 1)[1].strip()} ({os.cpu_count()} cores)"
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def save(fig, name):
    FIGURES.mkdir(parents=True, exist_ok=True)
    for ext in ("png", "svg"):
        fig.savefig(FIGURES / f"{name}.{ext}", dpi=110, bbox_inches="tight")


def method(row):
    return f"{row['isolation']}/{row['refinement']}"


def plot_degrees(data, plt):
    rows = data["rows"]
    precisions = [p for p in ("float", "double", "mixed") if any(r["precision"] == p for r in rows)]
    fig, axes = plt.subplots(1, len(precisions), figsize=(6 * len(precisions), 4.5), sharey=True, squeeze=False)
    for ax, precision in zip(axes[0], precisions):
        for m in sorted({method(r) for r in rows}):
            pts = sorted((r["degree"], r["rays_per_s"]) for r in rows if method(r) == m and r["precision"] == precision)
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=3, label=m)
        ax.set_yscale("log")
        ax.set_xlabel("degree")
        ax.set_title(precision)
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("rays per second (kernel time)")
    axes[0][-1].legend(fontsize=7, loc="upper right")
    save(fig, "rays_per_degree")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    for precision in precisions:
        for key, style in (("build_cold_ms", "-"), ("build_warm_ms", "--")):
            by_degree = {}
            for r in rows:
                if r["precision"] == precision:
                    by_degree.setdefault(r["degree"], []).append(r[key])
            degrees = sorted(by_degree)
            ax.plot(degrees, [statistics.median(by_degree[d]) for d in degrees], style, marker="o", ms=3,
                    label=f"{precision}, {'cold' if 'cold' in key else 'warm'}")
    ax.set_yscale("log")
    ax.set_xlabel("degree")
    ax.set_ylabel("program build ms (median over methods)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, "build_per_degree")
    plt.close(fig)


def pareto(points):
    """The points no other point beats in both time and error, sorted by time."""
    front, best = [], float("inf")
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def accuracy_error(row):
    """Error of a run: a wrong hit/miss counts as the worst possible depth error (1)."""
    return 1.0 if row["wrong_hit_miss"] > 0.001 * row["certified"] else max(row["max_depth_error"], 1e-17)


def plot_accuracy(data, plt):
    rows = data["rows"]
    surfaces = list(dict.fromkeys(r["surface"] for r in rows))
    cols = min(3, len(surfaces))
    fig, axes = plt.subplots((len(surfaces) + cols - 1) // cols, cols, figsize=(5.5 * cols, 4.2 * ((len(surfaces) + cols - 1) // cols)),
                             squeeze=False)
    markers = {"float": "o", "mixed": "s", "double": "^"}
    methods = sorted({method(r) for r in rows})
    colours = {m: plt.cm.tab10(i % 10) for i, m in enumerate(methods)}
    for ax, surface in zip(axes.flat, surfaces):
        mine = [r for r in rows if r["surface"] == surface]
        for r in mine:
            ax.scatter(r["kernel_ms"], accuracy_error(r), color=colours[method(r)], marker=markers[r["precision"]],
                       s=14, alpha=0.75)
        front = pareto([(r["kernel_ms"], accuracy_error(r)) for r in mine])
        ax.plot([p[0] for p in front], [p[1] for p in front], "k-", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(surface)
        ax.set_xlabel("kernel ms")
        ax.set_ylabel("max relative depth error (1 = wrong hit/miss > 0.1%)")
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(surfaces):]:
        ax.axis("off")
    handles = [plt.Line2D([], [], color=colours[m], marker="o", ls="", label=m) for m in methods]
    handles += [plt.Line2D([], [], color="grey", marker=mk, ls="", label=p) for p, mk in markers.items()]
    fig.legend(handles=handles, loc="lower center", ncol=6, fontsize=8)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    save(fig, "accuracy_pareto")
    plt.close(fig)


def header(data):
    return (f"- Machine: {data.get('cpu', '?')}; device {data['machine']['device']} "
            f"({data['machine']['platform']}). Date: {data.get('date', '?')}; commit: "
            f"{data.get('commit', 'not recorded')}.\n"
            f"- Command: `{data.get('command', '?')}` ({data.get('seconds', '?')} s).\n")


def provenance(data):
    """Date, machine and commit of a part, as the page gives them."""
    platform_text = data["machine"].get("platform", "")
    pocl = re.search(r"PoCL \S+", platform_text)
    runtime = pocl.group(0) if pocl else f"driver {data['machine'].get('driver', '?')}"
    return (f"Date: {data.get('date', '?')}; machine: {data.get('cpu', '?')}, device {data['machine']['device']} "
            f"({runtime}); commit: {data.get('commit', 'not recorded')}")


def page_header(data, shared):
    """The page's lines on when, where and how a part ran; the date, machine and commit only where the parts'
    differ (`shared` is None), else they are said once for all."""
    command = f"`{data.get('command', '?')}` ({data.get('seconds', '?')} s)"
    if shared:
        return [f"- Command: {command}"]
    return [f"- {provenance(data)}", f"- Command: {command}"]


def figure(name, prefix):
    return f"[{name}.png]({prefix}{name}.png)"


def section_degrees(data, figures="../figures/"):
    rows = data["rows"]
    out = ["### 1. Rays per second against degree", "", header(data),
           f"Seeded random surfaces of each degree in the unit sphere, {data['side']}x{data['side']} rays, median of "
           f"{data['runs']} runs. Plot: {figure('rays_per_degree', figures)} (and `.svg`); build times: "
           f"{figure('build_per_degree', figures)}.", ""]
    degrees = sorted({r["degree"] for r in rows})
    for precision in ("float", "double", "mixed"):
        mine = [r for r in rows if r["precision"] == precision]
        if not mine:
            continue
        methods = sorted({method(r) for r in mine})
        shown = [d for d in degrees if any(r["degree"] == d for r in mine)]
        out.append(f"Million rays/s, {precision}:")
        out.append("")
        out.append("| method | " + " | ".join(str(d) for d in shown) + " |")
        out.append("|---|" + "---|" * len(shown))
        for m in methods:
            cells = []
            for d in shown:
                r = [x for x in mine if method(x) == m and x["degree"] == d]
                cells.append(f"{r[0]['rays_per_s'] / 1e6:.2f}" if r else "")
            out.append(f"| {m} | " + " | ".join(cells) + " |")
        out.append("")
    out.append("Program build ms (median over methods), cold (compiled, PoCL cache off) / warm (binary from disk):")
    out.append("")
    out.append("| precision | " + " | ".join(str(d) for d in degrees) + " |")
    out.append("|---|" + "---|" * len(degrees))
    for precision in ("float", "double", "mixed"):
        cells = []
        for d in degrees:
            mine = [r for r in rows if r["precision"] == precision and r["degree"] == d]
            cells.append(f"{statistics.median(r['build_cold_ms'] for r in mine):.0f} / "
                         f"{statistics.median(r['build_warm_ms'] for r in mine):.0f}" if mine else "")
        out.append(f"| {precision} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def cheapest_table(rows):
    out = ["| surface | error <= 1e-3 | error <= 1e-6 | error <= 1e-9 |", "|---|---|---|---|"]
    for surface in dict.fromkeys(r["surface"] for r in rows):
        cells = []
        for line in (1e-3, 1e-6, 1e-9):
            ok = [r for r in rows if r["surface"] == surface and accuracy_error(r) <= line]
            if ok:
                best = min(ok, key=lambda r: r["kernel_ms"])
                cells.append(f"{best['precision']} {method(best)} tol {best['tolerance']:g}: {best['kernel_ms']:.1f} ms")
            else:
                cells.append("none")
        out.append(f"| {surface} | " + " | ".join(cells) + " |")
    return out


def section_accuracy(data, figures="../figures/"):
    rows = data["rows"]
    out = ["### 2. Accuracy against time", "", header(data),
           f"Each surface at {data['width']}x{data['height']}, kernel ms median of {data['runs']} runs, errors "
           "against solver_ref over the pixels it certifies (float and mixed against float rays, double against "
           f"double rays). Pareto fronts: {figure('accuracy_pareto', figures)} (and `.svg`).", "",
           "Cheapest setting per surface that meets each accuracy line (no hit/miss disagreement beyond 0.1% of "
           "certified pixels, and the stated maximum relative depth error):", ""]
    out += cheapest_table(rows)
    out.append("")
    out.append("What tightening the tolerance costs, per surface and precision, for the default method "
               "(bernstein/brent): kernel ms and max depth error at the loosest and the tightest tolerance.")
    out.append("")
    out.append("| surface | precision | loosest tol: ms, max error | tightest tol: ms, max error | time ratio |")
    out.append("|---|---|---|---|---|")
    for surface in dict.fromkeys(r["surface"] for r in rows):
        for precision in ("float", "mixed", "double"):
            mine = sorted((r for r in rows if r["surface"] == surface and r["precision"] == precision
                           and method(r) == "bernstein/brent"), key=lambda r: -r["tolerance"])
            if len(mine) < 2:
                continue
            lo, hi = mine[0], mine[-1]
            out.append(f"| {surface} | {precision} | {lo['tolerance']:g}: {lo['kernel_ms']:.1f}, "
                       f"{accuracy_error(lo):.1g} | {hi['tolerance']:g}: {hi['kernel_ms']:.1f}, "
                       f"{accuracy_error(hi):.1g} | {hi['kernel_ms'] / lo['kernel_ms']:.2f} |")
    out.append("")
    out.append("Every run, as (kernel ms, wrong hit/miss, max depth error), by method and tolerance:")
    out.append("")
    tolerances = sorted({r["tolerance"] for r in rows}, reverse=True)
    out.append("| surface | precision | method | " + " | ".join(f"{t:g}" for t in tolerances) + " |")
    out.append("|---|---|---|" + "---|" * len(tolerances))
    keyed = {}
    for r in rows:
        keyed.setdefault((r["surface"], r["precision"], method(r)), {})[r["tolerance"]] = r
    for (surface, precision, m), by_tol in keyed.items():
        cells = []
        for t in tolerances:
            r = by_tol.get(t)
            cells.append(f"{r['kernel_ms']:.1f}, {r['wrong_hit_miss']}, {r['max_depth_error']:.1g}" if r else "")
        out.append(f"| {surface} | {precision} | {m} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def fig2_about(data):
    return (f"Preview mode at {data['width']}x{data['height']} with {data['supersampling']}x{data['supersampling']} "
           f"supersampling (the rays of a {data['width'] * data['supersampling']}x{data['height'] * data['supersampling']} "
           "image), double, tolerance 1e-6. \"paper\": the paper's solver (power basis around the eye, Descartes); "
           f"\"ours\": Bernstein over the extent. Kernel ms, median of {data['runs']} runs. The paper's times are whole "
           "preview renders on a 1.1 GHz Celeron.")


def fig2_table(data):
    rows = data["rows"]
    out = ["| surface | setup | bisection ms | regula falsi ms | Brent ms | spread (max/min - 1) | paper: Brent s, spread |",
           "|---|---|---|---|---|---|---|"]
    paper_spread = {"barth_sextic": (464, 457, 457), "cusp_catastrophe": (115, 114, 114), "torus": (258, 260, 255),
                    "tooth": (116, 115, 114), "lemniscate": (248, 247, 245), "tanglecube": (243, 241, 239)}
    for surface in dict.fromkeys(r["surface"] for r in rows):
        for setup in ("paper", "ours"):
            ms = {r["refinement"]: r["kernel_ms"] for r in rows if r["surface"] == surface and r["setup"] == setup}
            values = [ms.get("bisection"), ms.get("regula-falsi"), ms.get("brent")]
            spread = max(values) / min(values) - 1
            p = paper_spread[surface]
            out.append(f"| {surface} | {setup} | " + " | ".join(f"{v:.0f}" for v in values) +
                       f" | {spread * 100:.1f}% | {p[2]} s, {(max(p) / min(p) - 1) * 100:.1f}% |")
    return out


def fig2_page_table(data):
    """Fig. 2 with one row per surface: each setup's three times and spread, and the paper's."""
    rows = data["rows"]
    out = ["| surface | paper's setup: bisection, regula falsi, Brent ms | spread | ours: bisection, regula falsi, Brent "
           "ms | spread | the paper: Brent s, spread |", "|---|---|---|---|---|---|"]
    for line in fig2_table(data)[2:]:
        cells = [c.strip() for c in line.strip("|").split("|")]
        surface, setup = cells[0], cells[1]
        if setup == "paper":
            current = [surface, ", ".join(cells[2:5]), cells[5]]
        else:
            out.append("| " + " | ".join(current + [", ".join(cells[2:5]), cells[5], cells[6]]) + " |")
    return out


def section_fig2(data):
    return ["### 3. The paper's Fig. 2", "", header(data), fig2_about(data), ""] + fig2_table(data) + [""]


def decic_about(data, figures):
    return (f"Barth decic at {data['width']}x{data['height']}, double, tolerance {data['tolerance']:g}, every method "
            f"capped at {data['max_iterations']} iterations. A defect is a certified pixel where the method disagrees "
            "with solver_ref on hit or miss, or whose root misses the requested accuracy (10x the stopping width "
            "4 eps max(|t|, 1)). Images, defects in red, regula falsi | Brent | bisection: "
            f"{figure('decic_methods_paper', figures)} and {figure('decic_methods_ours', figures)}.")


def decic_table(data):
    out = ["| setup | method | defects | of them wrong hit/miss | pixels at the iteration cap | kernel ms |",
           "|---|---|---|---|---|---|"]
    for r in data["rows"]:
        out.append(f"| {r['setup']} | {r['refinement']} | {r['defects']} | {r['wrong_hit_miss']} | "
                   f"{r['at_iteration_cap']} | {r['kernel_ms']:.0f} |")
    return out


def section_decic(data, figures="../figures/"):
    return ["### 4. The paper's Barth decic experiment", "", header(data), decic_about(data, figures), ""] + \
        decic_table(data) + [""]


def page_degrees(data, shared):
    """The page's part of the per-degree run: PAGE_PRECISION's rays/s for PAGE_METHODS at PAGE_DEGREES."""
    rows = [r for r in data["rows"] if r["precision"] == PAGE_PRECISION]
    degrees = [d for d in PAGE_DEGREES if any(r["degree"] == d for r in rows)]
    methods = [m for m in PAGE_METHODS if any(method(r) == m for r in rows)]
    out = ["### Rays per second against degree", ""] + page_header(data, shared) + [
        f"- Seeded random surfaces of each degree in the unit sphere, {data['side']}x{data['side']} rays, median of "
        f"{data['runs']} runs, every pair of isolation and refinement in float, double and mixed: "
        f"{figure('rays_per_degree', 'figures/')}; program build times: {figure('build_per_degree', 'figures/')}. "
        f"Below, million rays/s in {PAGE_PRECISION} with Brent's refinement after each isolation.", "",
        "| method | " + " | ".join(str(d) for d in degrees) + " |", "|---|" + "---|" * len(degrees)]
    for m in methods:
        cells = []
        for d in degrees:
            r = [x for x in rows if method(x) == m and x["degree"] == d]
            cells.append(f"{r[0]['rays_per_s'] / 1e6:.2f}" if r else "")
        out.append(f"| {m} | " + " | ".join(cells) + " |")
    return out + [""]


def page_accuracy(data, shared):
    return ["### Accuracy against time", ""] + page_header(data, shared) + [
        f"- Each surface at {data['width']}x{data['height']}, kernel ms median of {data['runs']} runs, errors against "
        "solver_ref over the pixels it certifies; Pareto fronts of every run: "
        f"{figure('accuracy_pareto', 'figures/')}. Below, the cheapest setting per surface that meets each accuracy "
        "line (no hit/miss disagreement beyond 0.1% of certified pixels, and the stated maximum relative depth "
        "error).", ""] + cheapest_table(data["rows"]) + [""]


def page_fig2(data, shared):
    return ["### The paper's Fig. 2", ""] + page_header(data, shared) + ["- " + fig2_about(data), ""] + \
        fig2_page_table(data) + [""]


def page_decic(data, shared):
    return ["### The paper's Barth decic experiment", ""] + page_header(data, shared) + \
        ["- " + decic_about(data, "figures/"), ""] + decic_table(data) + [""]


def write_results(page, full, shared):
    """The page's section in place in bench/RESULTS.md; every table in bench/results/solvers.md."""
    FULL.write_text("\n".join([
        "# Solvers: every table", "",
        "Written by `bench/solvers.py` from bench/results/{degrees,accuracy,fig2,decic}.json; the short tables are in "
        "[../RESULTS.md](../RESULTS.md#solvers-what-accuracy-costs).", ""] + full).rstrip("\n") + "\n")
    body = [HEADING, "",
            "solver_bench's four parts, each isolation and refinement in float, double and mixed. Every table in full: "
            "[bench/results/solvers.md](results/solvers.md).", ""] + ([f"- {shared}", ""] if shared else []) + page
    replace_section(RESULTS_MD, HEADING, "\n".join(body).rstrip("\n") + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="the quick form of every part")
    ap.add_argument("--only", nargs="+", choices=PARTS, help="run only these parts")
    ap.add_argument("--device", help="device index or name substring")
    ap.add_argument("--binary", default=str(ROOT / "build" / "bench" / "solver_bench"))
    ap.add_argument("--plot-only", action="store_true", help="redraw from bench/results without running")
    ap.add_argument("--no-plots", action="store_true", help="write the tables only, without redrawing the figures")
    args = ap.parse_args()

    RESULTS.mkdir(parents=True, exist_ok=True)
    FIGURES.mkdir(parents=True, exist_ok=True)
    if not args.plot_only:
        for part in args.only or PARTS:
            run_part(args.binary, part, args.quick, args.device, dict(os.environ))

    plt = None
    if not args.no_plots:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

    page, full = [], []
    writers = {"degrees": (plot_degrees, page_degrees, section_degrees),
               "accuracy": (plot_accuracy, page_accuracy, section_accuracy),
               "fig2": (None, page_fig2, section_fig2), "decic": (None, page_decic, section_decic)}
    parts = {}
    for part in PARTS:
        path = RESULTS / f"{part}.json"
        if path.exists():
            data = json.loads(path.read_text())
            data[part].update({k: data[k] for k in ("machine", "cpu", "date", "command", "seconds", "commit")
                               if k in data})
            parts[part] = data[part]
    # The parts' date, machine and commit, said once on the page where they all agree.
    said = {provenance(d) for d in parts.values()}
    shared = said.pop() if len(said) == 1 else None
    for part, data in parts.items():
        plot, short, section = writers[part]
        if plot and plt:
            plot(data, plt)
        page += short(data, shared)
        full += section(data)
    write_results(page, full, shared)
    print("solvers: wrote bench/RESULTS.md, bench/results/solvers.md" + ("" if args.no_plots else " and bench/figures/"),
          file=sys.stderr)


if __name__ == "__main__":
    main()
