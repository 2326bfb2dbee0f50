#!/usr/bin/env python3
"""Issue 45's view benchmark: frames per second and input-to-frame latency of `algray view` inside headless
Chromium, during a scripted orbit (the azimuth turned 0.02 rad every 16 ms) of a page 1024x1024 in size. Two
modes: moving (the page asks for 512x512 previews while the input moves) and still (each input asks for the
page's full-size 1024x1024 frame at rest, as after a click). The page reports both: its frame counter and its
per-frame latencies; the streaming page also reports each frame's server timings (queue, render with its kernels,
passes and shading, encoding, sending), whose medians say where a frame's time goes.

With --baseline, an older binary runs interleaved with this one (rounds of: each scene and mode, old then new),
each figure the median over the rounds. Writes its section of bench/RESULTS.md ("algray view: frames per second")
with the date, machine, commits and command; the section it replaces goes to bench/history/YYYY-MM.md.
Usage: python3 bench/view_fps.py [--baseline OLD_ALGRAY] [--rounds N] [--seconds S] [--scenes NAME ...]"""
import argparse
import datetime
import os
import statistics
import subprocess
import sys

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

from bench_common import ROOT, command_line, commit, machine, replace_section

HEADING = "## algray view: frames per second"
MODES = ("moving", "still")

# Both pages (the one frame request at a time of before issue 45, and the stream) have view.camera, changed()
# (moving input), request("still"), latencies and the frame counter; only the stream has frameTimes.
ORBIT = """
const seconds = arguments[0], mode = arguments[1], done = arguments[arguments.length - 1];
view.width = view.height = 1024;
const frameCount = () => Number(document.getElementById('frame').dataset.frames || 0);
const before = frameCount(), first = latencies.length;
const timed = typeof frameTimes === 'undefined' ? null : frameTimes.length;
const timer = setInterval(() => {
  view.camera.azimuth = (view.camera.azimuth + 0.02 * 180 / Math.PI) % 360;
  if (mode === 'moving') changed(); else request('still');
}, 16);
setTimeout(() => {
  clearInterval(timer);
  done({frames: frameCount() - before, latencies: latencies.slice(first),
        times: timed === null ? [] : frameTimes.slice(timed)});
}, seconds * 1000);
"""

WARM = """
const done = arguments[0];
(function wait() {
  if (Number(document.getElementById('frame').dataset.frames || 0) > 0 && !inFlight) done();
  else setTimeout(wait, 50);
})();"""

# The stream's per-frame timings, medians reported (ms, but bytes).
TIMINGS = ("queue_ms", "render_ms", "kernel_ms", "passes_ms", "shade_ms", "rest_ms", "encode_ms", "previous_send_ms",
           "bytes")


def measure(binary, scene, seconds, mode):
    server = subprocess.Popen([str(binary), "view", str(scene), "--port", "0"], stdout=subprocess.PIPE, text=True)
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--window-size=1400,1100"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    try:
        driver.set_script_timeout(seconds + 120)
        driver.get(server.stdout.readline().strip())
        # Warm: the first frame builds (or loads) the kernels; then one orbit second unmeasured, which builds the
        # half-size frame's programs and fills the caches.
        driver.execute_async_script(WARM)
        driver.execute_async_script(ORBIT, 1, mode)
        driver.execute_async_script(WARM)
        result = driver.execute_async_script(ORBIT, seconds, mode)
    finally:
        driver.quit()
        server.terminate()
        server.wait()
    for t in result["times"]:
        t["rest_ms"] = t["render_ms"] - t["passes_ms"] - t["shade_ms"]
    times = {k: statistics.median(t[k] for t in result["times"]) for k in TIMINGS} if result["times"] else None
    latency = statistics.median(result["latencies"]) if result["latencies"] else float("nan")
    return {"fps": result["frames"] / seconds, "latency": latency, "frames": len(result["latencies"]),
            "times": times}


def fmt(x, digits=1):
    return "-" if x is None or x != x else f"{x:.{digits}f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--baseline", help="an older algray binary, run interleaved with --binary")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--scenes", nargs="*", default=["barth_sextic", "barth_decic"])
    ap.add_argument("--no-results", action="store_true", help="print only; leave bench/RESULTS.md as it is")
    args = ap.parse_args()
    binaries = [("before", args.baseline)] if args.baseline else []
    binaries.append(("after", args.binary))
    runs = {}  # (scene, mode, which) -> [run, ...]
    for r in range(args.rounds):
        for name in args.scenes:
            for mode in MODES:
                for which, binary in binaries:
                    run = measure(binary, ROOT / "scenes" / f"{name}.toml", args.seconds, mode)
                    runs.setdefault((name, mode, which), []).append(run)
                    print(f"round {r + 1} {name} {mode} {which}: {run['fps']:.1f} fps, median latency "
                          f"{run['latency']:.0f} ms over {run['frames']} frames; {run['times']}", file=sys.stderr)

    def median(name, mode, which, key):
        values = [run[key] for run in runs.get((name, mode, which), [])]
        return statistics.median(values) if values else None

    def median_time(name, mode, key):
        values = [run["times"][key] for run in runs.get((name, mode, "after"), []) if run["times"]]
        return statistics.median(values) if values else None

    commits = f"{commit(args.binary)}" + (f" against {commit(args.baseline)}" if args.baseline else "")
    lines = [HEADING, "", f"- Date: {datetime.date.today().isoformat()}", f"- Machine: {machine()}",
             f"- Commit: {commits}",
             f"- Command: `{command_line()}` (headless Chromium on the same machine as the server)", "",
             f"A scripted {args.seconds:g}-second orbit of a 1024x1024 page (the azimuth turned 0.02 rad every 16 ms) "
             "after a warm-up; moving: the page asks for 512x512 previews as the input moves (JPEG at quality 80 on "
             "the stream, PNG before); still: each input asks for the full-size 1024x1024 frame at rest (PNG). fps: "
             "frames shown per second; latency: the median over frames of the time from the oldest input a frame "
             f"is the first to include to the frame on screen. Each figure is the median of {args.rounds} "
             "interleaved rounds. Issue 45's goals: moving, sextic 60 fps and decic 30, latency 35 ms; still, "
             "sextic 15 fps.", "",
             "| scene | mode | fps before | fps after | latency ms before | latency ms after |",
             "|---|---|---|---|---|---|"]
    for name in args.scenes:
        for mode in MODES:
            lines.append(f"| {name} | {mode} | {fmt(median(name, mode, 'before', 'fps'))} | "
                         f"{fmt(median(name, mode, 'after', 'fps'))} | "
                         f"{fmt(median(name, mode, 'before', 'latency'), 0)} | "
                         f"{fmt(median(name, mode, 'after', 'latency'), 0)} |")
    lines += ["", "Where a streamed frame's time goes (after; the server's own timings, median per frame): queue, from "
              "the state's arrival to its render's start; render, the library's whole render call, of which kernels "
              "(device time, the shading kernel's included), passes (the passes' wall time: launches, staging, read-back), shading (the shading kernel's launch and the host's part: host shading before the shading kernel) and the "
              "rest (the library's set-up around the passes each frame: plan, film, tile buffers, stats); encode "
              "(to JPEG or PNG, on the stream's thread while the next frame renders); send, the write of the frame "
              "before.", "",
              "| scene | mode | queue | render | kernels | passes | shading | rest | encode | send | KB |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name in args.scenes:
        for mode in MODES:
            t = {k: median_time(name, mode, k) for k in TIMINGS}
            lines.append(f"| {name} | {mode} | " + " | ".join(fmt(t[k]) for k in TIMINGS[:-1]) +
                         f" | {fmt(t['bytes'] / 1024 if t['bytes'] is not None else None, 0)} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if not args.no_results:
        replace_section(ROOT / "bench" / "RESULTS.md", HEADING, text)  # the old section goes to bench/history/


if __name__ == "__main__":
    main()
