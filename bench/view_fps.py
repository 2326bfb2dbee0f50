#!/usr/bin/env python3
"""Issue 19's benchmark: frames per second and input-to-frame latency of `algray view` inside headless Chromium,
during a scripted 10-second orbit whose frames are 512x512 previews (the page renders half its 1024x1024 size
while the input moves). The page reports both: its frame counter and its per-frame latencies.

Writes its section of bench/RESULTS.md ("algray view: frames per second"), with the date, machine, commit and
command. Usage: python3 bench/view_fps.py [--seconds S] [--scenes NAME ...]"""
import argparse
import datetime
import statistics
import subprocess
import sys

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

from bench_common import ROOT, command_line, commit, machine, replace_section

HEADING = "## algray view: frames per second"

ORBIT = """
const seconds = arguments[0], done = arguments[arguments.length - 1];
view.width = view.height = 1024;
const before = Number(document.getElementById('frame').dataset.frames || 0), first = latencies.length;
const timer = setInterval(() => {
  const c = view.camera;
  c.eye = add(c.look_at, rotate(sub(c.eye, c.look_at), c.up, 0.02));
  changed();
}, 16);
setTimeout(() => {
  clearInterval(timer);
  done({frames: Number(document.getElementById('frame').dataset.frames) - before,
        latencies: latencies.slice(first)});
}, seconds * 1000);
"""


def measure(binary, scene, seconds):
    server = subprocess.Popen([str(binary), "view", str(scene), "--port", "0"], stdout=subprocess.PIPE, text=True)
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    try:
        driver.set_script_timeout(seconds + 60)
        driver.get(server.stdout.readline().strip())
        # Warm: the first frame builds (or loads) the kernels.
        driver.execute_async_script(
            "const done = arguments[0]; (function w() { if (Number(document.getElementById('frame').dataset.frames"
            " || 0) > 0 && !inFlight) done(); else setTimeout(w, 50); })();")
        result = driver.execute_async_script(ORBIT, seconds)
    finally:
        driver.quit()
        server.terminate()
        server.wait()
    return result["frames"] / seconds, statistics.median(result["latencies"]), len(result["latencies"])


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--binary", default=ROOT / "build/apps/algray/algray")
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--scenes", nargs="*", default=["barth_sextic", "barth_decic"])
    args = ap.parse_args()
    targets = {"barth_sextic": 15, "barth_decic": 6}
    rows = []
    for name in args.scenes:
        fps, latency, n = measure(args.binary, ROOT / "scenes" / f"{name}.toml", args.seconds)
        rows.append((name, fps, latency, n))
        print(f"{name}: {fps:.1f} fps, median latency {latency:.0f} ms over {n} frames", file=sys.stderr)
    lines = [HEADING, "", f"- Date: {datetime.date.today().isoformat()}", f"- Machine: {machine()}",
             f"- Commit: {commit(args.binary)}",
             f"- Command: `{command_line()}` (headless Chromium on the same machine as the server)", "",
             f"A scripted {args.seconds:g}-second orbit (the eye turned 0.02 rad every 16 ms), frames 512x512 in "
             "preview; fps is frames shown per second, latency the median time from an input to the frame that "
             "includes it. Targets: 15 fps on the sextic, 6 on the decic, latency under 150 ms.", "",
             "| scene | fps | target | median latency ms | frames |", "|---|---|---|---|---|"]
    for name, fps, latency, n in rows:
        lines.append(f"| {name} | {fps:.1f} | {targets.get(name, '-')} | {latency:.0f} | {n} |")
    replace_section(ROOT / "bench/RESULTS.md", HEADING, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
