#!/usr/bin/env python3
"""`algray view` without a browser: 200 concurrent valid and malformed requests to one server, the errors it
answers, saved scenes that `algray render` turns into the view's own frames, an orbit job that `algray batch`
renders, programs kept in memory across frames of one degree, and the page's frame stream: each encoding as asked,
its PNG the frame /frame.png gives, stale and refused states, and a second stream of one page replacing the first.

Usage: test_view_server.py ALGRAY_BINARY WORK_DIR. Fails (exit 1) on the first broken expectation, naming the
seed and the request; needs an OpenCL device, as every render does."""
import concurrent.futures
import json
import os
import random
import subprocess
import sys
import urllib.error
import urllib.parse
import urllib.request

from png_data import idat
from stream_client import Stream, post_state

BINARY, WORK = sys.argv[1], sys.argv[2]
SEED = int(os.environ.get("ALGRAY_TEST_SEED", "20261204"))
os.makedirs(WORK, exist_ok=True)


def fail(message):
    print(f"test_view_server: FAILED (seed {SEED}): {message}", file=sys.stderr)
    sys.exit(1)


def get(base, path, params=()):
    url = base + path + ("?" + urllib.parse.urlencode(list(params)) if params else "")
    try:
        with urllib.request.urlopen(url, timeout=120) as r:
            return r.status, r.headers, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers, e.read()


# Frames are compared bit for bit across requests and with `algray render`: double, as `auto` is here, since a
# stream's previews left to `auto` race double against adaptive (docs/solvers.md, "Previews in a stream").
server = subprocess.Popen([BINARY, "view", "--port", "0", "--precision", "double"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True)
try:
    url = server.stdout.readline().strip()
    if not url.startswith("http://127.0.0.1:"):
        fail(f"expected the URL on 127.0.0.1, got {url!r}; stderr: {server.stderr.read()}")
    base = url.rstrip("/")

    status, headers, page = get(base, "/")
    if status != 200 or b"<title>algray view</title>" not in page:
        fail(f"the page: {status}")
    status, _, body = get(base, "/scene.json")
    scene = json.loads(body)
    if status != 200 or scene["camera"]["look_at"] != [0.0, 0.0, 0.0] or "phi" not in scene["parameters"]:
        fail(f"scene.json: {status} {scene}")

    # 200 requests at once, a third of them malformed in each way the page could be wrong.
    rng = random.Random(SEED)
    malformed = [
        [("width", "abc")], [("width", "0")], [("height", "100000")], [("full", "2")],
        [("set", "no equals sign")], [("set", "=3")], [("set", "camera.eye=[1, 2")],
        [("set", "surface.equation=\"x^2+*y\"")], [("set", "render.precision=\"quadruple\"")],
        [("set", "phi=abc")], [("set", "camera.nonsense=1")],
    ]
    cases = []
    for k in range(200):
        if k % 3 == 0:
            cases.append(("bad", malformed[rng.randrange(len(malformed))]))
        else:
            eye = [round(rng.uniform(-6, 6), 3) for _ in range(3)]
            eye[2] = abs(eye[2]) + 3
            cases.append(("good", [("width", "24"), ("height", "16"), ("set", f"camera.eye={eye}"),
                                   ("set", f"phi={rng.uniform(1.4, 1.8):.4f}")]))

    def run(case):
        return case, get(base, "/frame.png", case[1])

    with concurrent.futures.ThreadPoolExecutor(max_workers=32) as pool:
        for index, ((kind, params), (status, headers, body)) in enumerate(pool.map(run, cases)):
            if kind == "good":
                if status != 200 or headers["Content-Type"] != "image/png" or not body.startswith(b"\x89PNG"):
                    fail(f"case {index}: a valid request {params} got {status}: {body[:200]!r}")
                if headers["X-Algray-Degree"] != "6":
                    fail(f"case {index}: degree {headers['X-Algray-Degree']}")
            else:
                error = json.loads(body) if status == 400 else None
                if not error or not error.get("error"):
                    fail(f"case {index}: a malformed request {params} got {status}: {body[:200]!r}")
    if server.poll() is not None:
        fail("the server stopped")

    # A bad equation: the error names the column the command line reports, as "character N".
    status, _, body = get(base, "/frame.png", [("set", 'surface.equation="x^2+*y"')])
    error = json.loads(body)
    cli = subprocess.run([BINARY, "render", "--set", 'surface.equation="x^2+*y"', "-o", f"{WORK}/never.png"],
                         capture_output=True, text=True)
    if status != 400 or error["key"] != "surface.equation" or error["column"] != 5 or cli.returncode != 2 \
            or "at character 5 of the equation" not in cli.stderr or os.path.exists(f"{WORK}/never.png"):
        fail(f"bad equation: {status} {error}; the CLI said {cli.returncode} {cli.stderr!r}")

    # The saved scene renders to the view's frame: the same pixels, in preview and in full mode.
    view = [("width", "64"), ("height", "48"), ("set", "camera.eye=[1.5, 4.0, 5.0]"), ("set", "phi=1.7"),
            ("set", "extent.radius=2.0")]
    for full in ("0", "1"):
        status, _, frame = get(base, "/frame.png", view + [("full", full)])
        status_toml, _, toml = get(base, "/scene.toml", view + [("full", full)])
        if status != 200 or status_toml != 200:
            fail(f"full={full}: frame {status}, scene.toml {status_toml}")
        path = f"{WORK}/saved_{full}.toml"
        with open(path, "wb") as f:
            f.write(toml)
        subprocess.run([BINARY, "render", path, "-o", f"{WORK}/saved_{full}.png"], check=True)
        with open(f"{WORK}/saved_{full}.png", "rb") as f:
            if idat(f.read()) != idat(frame):
                fail(f"full={full}: `algray render` of the saved scene is not the view's frame")

    # The frame's PNG embeds its scene: `algray render frame.png` renders it again.
    with open(f"{WORK}/frame.png", "wb") as f:
        f.write(frame)
    subprocess.run([BINARY, "render", f"{WORK}/frame.png", "-o", f"{WORK}/again.png"], check=True)
    with open(f"{WORK}/again.png", "rb") as f:
        if idat(f.read()) != idat(frame):
            fail("the frame's embedded scene does not render to the frame")

    # One context and program cache for the server's life: a parameter change builds nothing, a degree change does.
    small = [("width", "24"), ("height", "16")]
    get(base, "/frame.png", small + [("set", "phi=1.5")])
    _, headers, _ = get(base, "/frame.png", small + [("set", "phi=1.55")])
    if headers["X-Algray-New-Programs"] != "0":
        fail(f"a parameter change took {headers['X-Algray-New-Programs']} programs not in memory")
    _, headers, _ = get(base, "/frame.png", small + [("set", 'surface.equation="x^4+y^4+z^4-1"')])
    if headers["X-Algray-Degree"] != "4" or headers["X-Algray-New-Programs"] == "0":
        fail(f"a degree change: degree {headers['X-Algray-Degree']}, {headers['X-Algray-New-Programs']} new programs")

    # The orbit job: scene.toml and orbit.toml side by side, which `algray batch` renders; frame 0 is the view's.
    orbit_dir = os.path.join(WORK, "orbit")
    os.makedirs(orbit_dir, exist_ok=True)
    for name, params in (("scene.toml", view), ("orbit.toml", view + [("frames", "4")])):
        status, _, body = get(base, "/" + name, params + [("full", "0")])
        if status != 200:
            fail(f"{name}: {status} {body[:200]!r}")
        with open(os.path.join(orbit_dir, name), "wb") as f:
            f.write(body)
    subprocess.run([BINARY, "batch", os.path.join(orbit_dir, "orbit.toml")], check=True, capture_output=True)
    made = sorted(n for n in os.listdir(orbit_dir) if n.startswith("orbit_") and n.endswith(".png"))
    if made != [f"orbit_{k:03}.png" for k in range(4)]:
        fail(f"the orbit job wrote {made}")
    _, _, frame = get(base, "/frame.png", view + [("full", "0")])
    with open(os.path.join(orbit_dir, "orbit_000.png"), "rb") as f:
        first = f.read()
    with open(os.path.join(orbit_dir, "orbit_001.png"), "rb") as f:
        second = f.read()
    if idat(first) != idat(frame) or idat(second) == idat(frame):
        fail("the orbit's frame 0 is not the view's frame, or its frame 1 did not turn")
    status, _, _ = get(base, "/orbit.toml", view + [("frames", "1")])
    if status != 400:
        fail(f"an orbit of 1 frame got {status}")

    # The stream: a greeting, then a frame for each state posted, encoded as the state asks; the PNG is the frame
    # /frame.png gives for the same settings.
    parsed = urllib.parse.urlsplit(base)
    stream = Stream(parsed.hostname, parsed.port, "page1")
    hello, _ = stream.message()
    if stream.status != 200 or hello != {"type": "hello", "page": "page1", "encodings": ["png", "jpeg", "webp"]}:
        fail(f"the stream's greeting: {stream.status} {hello}")
    _, _, expected = get(base, "/frame.png", view + [("full", "0")])
    for seq, (encoding, mime, magic) in enumerate((("png", "image/png", b"\x89PNG"), ("jpeg", "image/jpeg", b"\xff\xd8"),
                                                   ("webp", "image/webp", b"RIFF")), 1):
        status, answer = post_state(base, "page1", seq, view + [("full", "0"), ("stage", "still"),
                                                                ("encoding", encoding), ("quality", "70")])
        if status != 200 or answer != {"seq": seq, "accepted": True}:
            fail(f"state {seq} ({encoding}): {status} {answer}")
        header, body = stream.message()
        if header["type"] != "frame" or header["seq"] != seq or header["mime"] != mime or not body.startswith(magic) \
                or (header["width"], header["height"]) != (64, 48) or header["stage"] != "still":
            fail(f"the frame of state {seq} ({encoding}): {header} {body[:8]!r}")
        if encoding == "png" and idat(body) != idat(expected):
            fail("the stream's PNG frame is not /frame.png's for the same settings")
    # A state not newer than the last is dropped; a bad equation is refused at its column, and no frame comes.
    status, answer = post_state(base, "page1", 2, view)
    if status != 200 or answer["accepted"]:
        fail(f"an older state: {status} {answer}")
    status, answer = post_state(base, "page1", 4, [("set", 'surface.equation="x^2+*y"')])
    if status != 400 or answer["key"] != "surface.equation" or answer["column"] != 5:
        fail(f"a bad equation on the stream: {status} {answer}")
    for params, why in (([("encoding", "gif")], "encoding must be"), ([("quality", "0")], "quality must be"),
                        ([("stage", "resting")], "stage must be")):
        status, answer = post_state(base, "page1", 5, params)
        if status != 400 or why not in answer["error"]:
            fail(f"{params}: {status} {answer}")
    status, answer = post_state(base, "nopage", 1, view)
    if status != 404 or "no stream is open" not in answer["error"]:
        fail(f"a state for a page without a stream: {status} {answer}")
    # A parameter change builds no program; the frame says so, with its timings.
    moved = [p for p in view if p != ("set", "phi=1.7")] + [("set", "phi=1.65"), ("encoding", "jpeg")]
    status, answer = post_state(base, "page1", 6, moved)
    if status != 200:
        fail(f"a parameter change on the stream: {status} {answer}")
    header, _ = stream.message()
    if header["seq"] != 6 or header["new_programs"] != 0 or header["degree"] != 6 or \
            not all(header[k] >= 0 for k in ("render_ms", "kernel_ms", "encode_ms", "queue_ms")):
        fail(f"a parameter change on the stream: {header}")
    # The page opens its stream again (after a network error, say): the new one replaces the old, which ends.
    again = Stream(parsed.hostname, parsed.port, "page1")
    again.message()
    if not stream.ended():
        fail("the first stream of page1 did not end when the page opened another")
    post_state(base, "page1", 7, view)
    header, _ = again.message()
    if header["seq"] != 7:
        fail(f"the new stream's frame: {header}")
    # A state that repeats the last one's first settings starts from the scene after them: the same frame as one
    # whose settings are all applied afresh.
    for seq, params in ((8, moved), (9, view + [("full", "0")])):
        post_state(base, "page1", seq, params)
        header, body = again.message()
    if header["seq"] != 9 or idat(body) != idat(expected):
        fail(f"a state after one differing only in phi: {header}, or not /frame.png's frame")
    again.close()
finally:
    server.terminate()
    server.wait(timeout=30)
print("test_view_server: 200 concurrent requests answered, errors located, saved scenes and orbit jobs render, "
      "programs kept, frames streamed in each encoding")
