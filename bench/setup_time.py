#!/usr/bin/env python3
"""Issue 42's timings: README's two commands, each in a fresh clone of HEAD (no build tree) with every kernel cache
cold, on this machine as it is (the packages already installed: bench/RESULTS.md gives apt's share from a bare
Debian 12 apart); then the second command again in the same clone, warm. Prints each phase line of
scripts/test.sh and writes the "Set-up and test time" table of bench/RESULTS.md. Takes about 20 minutes on 2 cores.

Usage: python3 bench/setup_time.py [--only render|test] [--keep DIR]"""
import argparse
import datetime
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_common import ROOT, command_line, commit, machine, replace_section

HEADING = "### The two commands on this machine, packages installed"
AREA = "## Set-up and test time"
PHASE = re.compile(r"^test\.sh: (.*) \((\d+) s so far, (\d+) s CPU\)$")


def fresh_clone(parent, name):
    clone = Path(parent) / name
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
    return clone


def run(command, cwd, env, log):
    """Runs `command` in `cwd`; returns (wall seconds, CPU seconds of its children, output lines)."""
    before = os.times()
    start = time.perf_counter()
    with open(log, "w") as out:
        done = subprocess.run(command, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - start
    after = os.times()
    lines = Path(log).read_text(errors="replace").splitlines()
    if done.returncode != 0:
        sys.exit(f"setup_time: {' '.join(command)} failed with {done.returncode}; the end of {log}:\n" +
                 "\n".join(lines[-30:]))
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, cpu, lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", choices=["render", "test"], help="time one command only")
    ap.add_argument("--keep", help="clone into this folder and keep it (default: a temporary one, removed)")
    ap.add_argument("--output", default=ROOT / "bench/RESULTS.md")
    args = ap.parse_args()

    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="algray-setup-time-"))
    work.mkdir(parents=True, exist_ok=True)
    # Cold: PoCL's and algray's default caches in a folder of this run (the tests use build/kernel-cache anyway).
    env = dict(os.environ, XDG_CACHE_HOME=str(work / "cache"))
    env.pop("ALGRAY_CACHE_DIR", None)
    env.pop("POCL_CACHE_DIR", None)
    rows = []
    try:
        if args.only in (None, "render"):
            clone = fresh_clone(work, "render")
            wall, cpu, _ = run(["bash", "scripts/render-default.sh"], clone, env, work / "render-default.log")
            print(f"setup_time: render-default.sh {wall:.0f} s, {cpu:.0f} s CPU", flush=True)
            rows.append(("`bash scripts/render-default.sh`", "to the picture", wall, cpu))
        if args.only in (None, "test"):
            clone = fresh_clone(work, "test")
            for state in ("cold", "warm"):
                wall, cpu, lines = run(["bash", "scripts/test.sh"], clone, env, work / f"test-{state}.log")
                phases = [(line, PHASE.match(line)) for line in lines]
                phases = [(line, found) for line, found in phases if found]
                for line, _ in phases:
                    print(line, flush=True)
                # Every phase of the cold run; of the warm one, its total.
                for _, found in phases if state == "cold" else phases[-1:]:
                    rows.append((f"`bash scripts/test.sh`, {state}", found.group(1), float(found.group(2)),
                                 float(found.group(3))))
                print(f"setup_time: test.sh {state} {wall:.0f} s, {cpu:.0f} s CPU", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    section = [HEADING, "",
               f"- Date: {now}; machine: {machine()}; commit: {commit()}",
               f"- Command: `{command_line()}`",
               "- Each command in a fresh clone (no build tree), PoCL's and algray's caches empty (cold); then "
               "scripts/test.sh once more in the same clone (warm: the build tree and build/kernel-cache kept). The "
               "packages were already installed: apt's own time is in the bare-Debian table. Wall and CPU "
               "(user + sys) seconds so far at each of scripts/test.sh's phase lines.",
               "",
               "| command | phase | wall s so far | CPU s so far |",
               "|---|---|---|---|"]
    for command, phase, wall, cpu in rows:
        section.append(f"| {command} | {phase} | {wall:.0f} | {cpu:.0f} |")
    replace_section(args.output, HEADING, "\n".join(section) + "\n", under=AREA)


if __name__ == "__main__":
    main()
