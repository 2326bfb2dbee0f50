#!/usr/bin/env python3
"""Issue 18 beyond the repository's scenes: classic surfaces that are in neither scenes/ nor
tests/data/hard_surfaces, each written to a temporary scene at 160x120 (camera three extent radii out), with the
accuracy of camera rays in float, adaptive, mixed and double against solver_ref (precision_modes.py's
accuracy()), and with --speed adaptive's kernel time over float's at --size (1024x768), with fp64 and without.

  python3 bench/outside_surfaces.py [--speed] [--only NAME ...] [--results]

With --results the table replaces its section of bench/RESULTS.md ("Surfaces outside the repository", under
"Precision modes: time and accuracy"), with the date, machine, commit and command.
"""
import argparse
import datetime
import os
import statistics
import sys
import tempfile
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section, run_render
from precision_modes import FLOAT_LINE, accuracy

# name: (equation, extent radius). Facts from the literature (surfaces.md's sources, MathWorld); the shells and
# products are built to stress float: close sheets, tangent sheets, nearly triple roots.
SURFACES = {
    "clebsch_cubic": ("81*(x^3+y^3+z^3)-189*(x^2*y+x^2*z+y^2*x+y^2*z+z^2*x+z^2*y)+54*x*y*z+126*(x*y+x*z+y*z)"
                      "-9*(x^2+y^2+z^2)-9*(x+y+z)+1", 2.0),
    "ding_dong": ("x^2+y^2-(1-z)*z^2", 1.6),
    "heart": ("(x^2+2.25*y^2+z^2-1)^3-x^2*z^3-0.1125*y^2*z^3", 1.6),
    "kiss": ("x^2+y^2-(1-z)*z^4", 1.3),
    "cross_cap": ("4*x^2*(x^2+y^2+z^2+z)+y^2*(y^2+z^2-1)", 1.5),
    "hunt_sextic": ("4*(x^2+y^2+z^2-13)^3+27*(3*x^2+y^2-4*z^2-12)^2", 5.0),
    "dupin_cyclide": ("(x^2+y^2+z^2+0.75-0.25)^2-4*(1.0*x-0.5)^2-4*0.75*y^2", 2.5),
    "sphere_shell": ("(x^2+y^2+z^2-1)^2-0.000001", 1.5),
    "sphere_and_tangent_plane": ("(x^2+y^2+z^2-1)*(z-1)", 1.8),
    "chebyshev_octic": ("(128*x^8-256*x^6+160*x^4-32*x^2+1)+(128*y^8-256*y^6+160*y^4-32*y^2+1)"
                        "+(128*z^8-256*z^6+160*z^4-32*z^2+1)+1", 1.8),
    "sphere_cylinder_cubic": ("(x^2+y^2+z^2-1)*(x^2+y^2-0.25)*(z^3-0.5*x^2*z+0.1)", 1.6),
    "whitney_shell": ("(x^2-y^2*z)^2-0.0001", 1.5),
}


AREA = "## Precision modes: time and accuracy"
HEADING = "### Surfaces outside the repository"


def write_scene(folder, name, equation, radius):
    d = 3 * radius
    path = Path(folder) / f"{name}.toml"
    path.write_text(f'[surface]\nname = "{name}"\nequation = "{equation}"\n\n[extent]\ntype = "sphere"\n'
                    f'centre = [0, 0, 0]\nradius = {radius}\n\n[camera]\n'
                    f'eye = [{0.44 * d:.4f}, {0.33 * d:.4f}, {0.835 * d:.4f}]\nlook_at = [0, 0, 0]\n'
                    f'up = [0, 1, 0]\nfov_y = 45\n\n[image]\nwidth = 160\nheight = 120\n\n[render]\npreview = true\n')
    return path


def speed_ratio(binary, scene, rounds, work, no_fp64, size):
    """Median over interleaved rounds of adaptive's kernel time over float's, at size (width, height)."""
    env = dict(os.environ, ALGRAY_NO_FP64="1" if no_fp64 else "")
    args = ["--width", str(size[0]), "--height", str(size[1])]
    ratios = []
    for r in range(rounds):
        times = {}
        for precision in (["float", "adaptive"] if r % 2 == 0 else ["adaptive", "float"]):
            _, stats = run_render(binary, scene, args + ["--precision", precision], env, work)
            times[precision] = sum(p["kernel_ms"] for p in stats["passes"])
        ratios.append(times["adaptive"] / times["float"])
    return statistics.median(ratios)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", help="surface names (default: all)")
    ap.add_argument("--speed", action="store_true", help="also adaptive over float (--size, --rounds)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--size", default="1024x768",
                    help="WIDTHxHEIGHT of the speed renders: previews of a few ms at 1024x768 read to 0.1-0.2 only")
    ap.add_argument("--binary", default=str(ROOT / "build/apps/algray/algray"))
    ap.add_argument("--results", action="store_true", help="write the table into its section of bench/RESULTS.md")
    a = ap.parse_args()
    try:
        size = tuple(int(v) for v in a.size.lower().split("x"))
        if len(size) != 2 or min(size) < 1:
            raise ValueError
    except ValueError:
        sys.exit(f"--size: expected WIDTHxHEIGHT, got {a.size!r}")
    names = a.only or list(SURFACES)
    unknown = [n for n in names if n not in SURFACES]
    if unknown:
        sys.exit(f"unknown surface(s) {', '.join(unknown)}; known: {', '.join(SURFACES)}")
    about = (f"Accuracy: camera rays at 160x120 against solver_ref, disagreements among certified pixels / worst "
             f"relative depth error (the float line: {FLOAT_LINE[0]:.1%} and {FLOAT_LINE[1]:g}); escalated: the "
             "share of camera rays adaptive sent to its second pass.")
    if a.speed:
        about += (f" Speed: adaptive's kernel time over float's at {size[0]}x{size[1]}, previews, median of "
                  f"{a.rounds} interleaved pairs, with fp64 and without (ALGRAY_NO_FP64=1).")
    print(f"Machine: {machine()}. {about}\n")
    head = "| surface | float | adaptive | escalated | adaptive, no fp64 | escalated | mixed | double |"
    if a.speed:
        head += " adaptive / float | (no fp64) |"
    table = [head, "|---" * (head.count("|") - 1) + "|"]
    print("\n".join(table))
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            scene = write_scene(tmp, name, *SURFACES[name])
            acc = accuracy(scene, 160, 120)
            cell = {m: f"{acc[m]['disagree']} / {acc[m]['worst_depth']:.1e}" for m in acc}
            row = (f"| {name} | {cell['float']} | {cell['adaptive']} | {acc['adaptive']['escalated_share']:.1%} | "
                   f"{cell['adaptive, no fp64']} | {acc['adaptive, no fp64']['escalated_share']:.1%} | "
                   f"{cell['mixed']} | {cell['double']} |")
            if a.speed:
                ratio = speed_ratio(a.binary, scene, a.rounds, Path(tmp), False, size)
                ratio_no = speed_ratio(a.binary, scene, a.rounds, Path(tmp), True, size)
                row += f" {ratio:.2f} | {ratio_no:.2f} |"
            table.append(row)
            print(row, flush=True)
    if a.results:
        lines = [HEADING, "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; "
                 f"commit: {commit(a.binary if a.speed else None)}",
                 f"- Command: `{command_line()}`",
                 "- Classic surfaces in neither scenes/ nor tests/data/hard_surfaces, each written to a temporary "
                 f"scene. {about}", ""] + table
        replace_section(RESULTS_MD, HEADING, "\n".join(lines) + "\n", under=AREA)
        print(f"wrote {RESULTS_MD}")


if __name__ == "__main__":
    main()
