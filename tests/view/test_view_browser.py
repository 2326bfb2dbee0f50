#!/usr/bin/env python3
"""`algray view` in a real browser: headless Chromium driven by Selenium loads the page and its first frame, a drag
turns the camera, a slider moves a parameter, each control of the panel (colours, light, background,
transparency, axis views, clip shape and radius, plane sections, clipping planes, reset, saved image) changes what the server
renders, frames come down the page's stream as JPEG or WebP while moving and PNG at rest, a bad equation shows its error at the command line's column and keeps the image, and the saved scene
renders to the view's last full-size frame.

Usage: test_view_browser.py ALGRAY_BINARY WORK_DIR. Needs chromium, chromium-driver and python3-selenium
(scripts/install-deps.sh installs them) and an OpenCL device; fails loudly without any of them."""
import base64
import os
import subprocess
import sys
import tomllib
import urllib.request

from png_data import idat

BINARY, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError as e:
    print(f"test_view_browser: FAILED: Selenium is missing ({e}); install python3-selenium", file=sys.stderr)
    sys.exit(1)
for tool in ("/usr/bin/chromium", "/usr/bin/chromedriver"):
    if not os.path.exists(tool):
        print(f"test_view_browser: FAILED: {tool} is missing; install chromium and chromium-driver", file=sys.stderr)
        sys.exit(1)


def fail(message):
    print(f"test_view_browser: FAILED: {message}", file=sys.stderr)
    sys.exit(1)


# The frame the page shows, as PNG bytes, read back from its blob URL.
SHOWN = """
const done = arguments[arguments.length - 1];
fetch(document.getElementById("frame").src).then(r => r.arrayBuffer()).then(b => {
  let s = ""; for (const x of new Uint8Array(b)) s += String.fromCharCode(x); done(btoa(s));
});"""

# Frames are compared bit for bit across requests and with `algray render`: double, as `auto` is here, since a
# stream's previews left to `auto` race double against adaptive (docs/solvers.md, "Previews in a stream").
server = subprocess.Popen([BINARY, "view", "--port", "0", "--precision", "double"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True)
driver = None
other = None  # a second server, for an equation alone with a box extent
try:
    url = server.stdout.readline().strip()
    if not url.startswith("http://127.0.0.1:"):
        fail(f"expected the URL, got {url!r}; stderr: {server.stderr.read()}")
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--window-size=1200,800"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    driver.set_script_timeout(60)
    wait = WebDriverWait(driver, 120)
    driver.get(url)

    def frames():
        return int(driver.execute_script("return Number(document.getElementById('frame').dataset.frames || 0)"))

    def settle(after):
        """Waits for a full-size frame newer than frame number `after`, with nothing in flight or waiting."""
        wait.until(lambda d: frames() > after and d.execute_script(
            "return !inFlight && waiting === null && document.getElementById('frame').dataset.stage === 'still'"))
        return base64.b64decode(driver.execute_async_script(SHOWN))

    # The page loads and shows its first frame, with the info line.
    first = settle(0)
    if not first.startswith(b"\x89PNG"):
        fail("the first frame is not a PNG")
    info = driver.find_element(By.ID, "info").text
    if "degree 6" not in info or "fps" in info:
        fail(f"info line at rest (degree, no fps): {info!r}")
    hint = driver.find_element(By.ID, "hint").text
    if "Drag" not in hint or "zoom" not in hint:
        fail(f"gesture hint: {hint!r}")
    # The solver selectors are under a closed "Advanced" fold.
    if driver.execute_script("return document.getElementById('advanced').open") or \
            driver.execute_script("return document.getElementById('isolation').closest('details').id") != "advanced":
        fail("the solver selectors are not in a closed Advanced fold")

    original = driver.execute_script("return view.equation")
    # A drag turns the camera about the look-at point, and the image changes; the info line shows the frame rate
    # while the frames come from moving input, and drops it at rest.
    camera = driver.execute_script("return Object.assign({}, view.camera)")
    driver.execute_script("""window.infoTexts = [];
      new MutationObserver(() => infoTexts.push(document.getElementById('info').textContent))
        .observe(document.getElementById('info'), {childList: true, characterData: true, subtree: true});""")
    n = frames()
    ActionChains(driver).move_to_element(driver.find_element(By.ID, "frame")).click_and_hold() \
        .move_by_offset(40, 0).move_by_offset(40, 15).release().perform()
    dragged = settle(n)
    turned = driver.execute_script("return Object.assign({}, view.camera)")
    if turned["azimuth"] == camera["azimuth"] or turned["distance"] != camera["distance"] \
            or turned["look_at"] != camera["look_at"]:
        fail(f"the drag changed the camera from {camera} to {turned}, not its angles about the look-at point")
    if dragged == first:
        fail("the image did not change with the drag")
    texts = driver.execute_script("return infoTexts")
    if not any("fps" in t for t in texts) or "fps" in texts[-1]:
        fail(f"the info line while moving and at rest: {texts}")

    # A slider moves the parameter, and the image changes.
    n = frames()
    driver.execute_script("""const s = document.getElementById('param-phi');
                             s.value = String(Number(s.value) + 0.15); s.dispatchEvent(new Event('input'));""")
    slid = settle(n)
    phi = driver.execute_script("return view.parameters.phi")
    if abs(phi - (1.618033988749895 + 0.15)) > 1e-9:
        fail(f"phi is {phi} after the slider")
    if slid == dragged:
        fail("the image did not change with the slider")

    # The wheel and a two-finger pinch zoom: the eye moves along its line to the look-at point.
    def distance():
        return driver.execute_script("return view.camera.distance")
    before = distance()
    n = frames()
    driver.execute_script("document.getElementById('frame').dispatchEvent("
                          "new WheelEvent('wheel', {deltaY: 200, cancelable: true}))")
    if abs(distance() / before - 2.718281828 ** 0.2) > 1e-9:
        fail(f"the wheel scaled the distance by {distance() / before}")
    before = distance()
    driver.execute_script("""const f = document.getElementById('frame');
      const p = (type, id, x) => f.dispatchEvent(new PointerEvent(type, {pointerId: id, clientX: x, clientY: 100,
                                                                        bubbles: true, cancelable: true}));
      p('pointerdown', 11, 100); p('pointerdown', 12, 200); p('pointermove', 12, 300);
      p('pointerup', 12, 300); p('pointerup', 11, 100);""")
    if abs(distance() / before - 0.5) > 1e-9:
        fail(f"spreading two fingers from 100 to 200 px scaled the distance by {distance() / before}, not 0.5")
    zoomed = settle(n)
    if zoomed == slid:
        fail("the image did not change with the zoom")
    # Frames while moving come down the stream as the Advanced fold says: JPEG by default, WebP when chosen; at
    # rest, PNG (the frames compared above).
    moving_as = "return frameTimes.some(t => t.stage === 'moving' && t.mime === arguments[0])"
    if not driver.execute_script(moving_as, "image/jpeg"):
        fail("no frame came as JPEG while the input moved")
    driver.execute_script("""const e = document.getElementById('moving-encoding'); e.value = 'webp';
                             e.dispatchEvent(new Event('change'));""")
    n = frames()
    driver.execute_script("document.getElementById('frame').dispatchEvent("
                          "new WheelEvent('wheel', {deltaY: -100, cancelable: true}))")
    zoomed = settle(n)
    if not driver.execute_script(moving_as, "image/webp"):
        fail("no frame came as WebP while the input moved, with WebP chosen")

    # Each control of the panel changes what the server renders, by the scene keys it names.
    def control(script, *args):
        n = frames()
        driver.execute_script(script, *args)
        return settle(n)

    def sent(key):
        return driver.execute_script("return Object.fromEntries(settings())[arguments[0]]", key)

    shown = zoomed
    for cid, key, value in (("front-colour", "surface.material.front.colour", "#20c040"),
                            ("back-colour", "surface.material.back.colour", "#c02020"),
                            ("background", "image.background", "#102030")):
        picture = control("""const e = document.getElementById(arguments[0]); e.value = arguments[1];
                             e.dispatchEvent(new Event('input'));""", cid, value)
        if picture == shown:
            fail(f"the image did not change with {cid}")
        if not sent(key).startswith("["):
            fail(f"{cid} sends no {key}")
        shown = picture
    lights = driver.execute_script("return view.lights.slice()")
    picture = control("""const e = document.getElementById('light'); e.value = '2';
                         e.dispatchEvent(new Event('input'));""")
    if not lights or abs(float(sent("light.0.intensity")) - 2 * lights[0]) > 1e-9 or picture == shown:
        fail(f"the light slider: intensities {lights}, light.0.intensity sent {sent('light.0.intensity')}")
    shown = picture
    control("""const e = document.getElementById('transparency'); e.value = '0.5';
               e.dispatchEvent(new Event('input'));""")
    if sent("surface.material.front.transparency") != "0.5" or sent("surface.material.back.transparency") != "0.5":
        fail("the transparency slider does not set both sides' transparency")
    picture = control("document.getElementById('view-y').click()")
    if driver.execute_script("return [view.camera.azimuth, view.camera.elevation]") != [0, 90] or picture == shown:
        fail("the y axis button does not look down the y axis")
    shown = picture
    picture = control("document.getElementById('view-x').click()")
    if driver.execute_script("return [view.camera.azimuth, view.camera.elevation]") != [90, 0] or picture == shown:
        fail("the x axis button does not look along the x axis")
    # Clip shape and radius, and plane sections: the server's scene (scene.toml from the page's settings) has what
    # the controls say, and the image changes with each.
    def server_scene():
        path = driver.execute_script("return '/scene.toml?' + query(view.width, view.height, false)")
        with urllib.request.urlopen(url.rstrip("/") + path, timeout=60) as r:
            return tomllib.loads(r.read().decode())

    def close(a, b):
        return len(a) == len(b) and all(abs(x - y) < 1e-9 for x, y in zip(a, b))

    for kind in ("box", "cylinder"):
        picture = control("""const e = document.getElementById('extent-type'); e.value = arguments[0];
                             e.dispatchEvent(new Event('change'));""", kind)
        if server_scene()["extent"]["type"] != kind or picture == shown:
            fail(f"the clip shape {kind}: the server's extent is {server_scene()['extent']}")
        shown = picture
    picture = control("""const e = document.getElementById('radius'); e.value = '0.7';
                         e.dispatchEvent(new Event('change'));""")
    extent = server_scene()["extent"]
    if extent["radius"] != 0.7 or picture == shown:
        fail(f"the clip radius 0.7: the server's extent is {extent}")
    shown = picture
    for axis, offset in (("z", "0.3"), ("x", "0")):
        picture = control("""document.getElementById('section-axis').value = arguments[0];
                             document.getElementById('section-offset').value = arguments[1];
                             document.getElementById('section-add').click();""", axis, offset)
        if picture == shown:
            fail(f"the image did not change with the section {axis} = {offset}")
        shown = picture
    planes = [x["plane"] for x in server_scene()["section"]]
    if len(planes) != 2 or not close(planes[0], [0, 0, 1, -0.3]) or not close(planes[1], [1, 0, 0, 0]):
        fail(f"two sections added, z = 0.3 and x = 0: the server has {planes}")
    picture = control("document.querySelector('#sections .section-remove').click()")
    planes = [x["plane"] for x in server_scene().get("section", [])]
    if len(planes) != 1 or not close(planes[0], [1, 0, 0, 0]) or picture == shown:
        fail(f"the first section removed: the server has {planes}")
    shown = picture
    # Clipping planes: keep z < 0.2, then x > 0; each cuts the surface open and is in the server's [[clip]] list.
    for axis, side, offset in (("z", "<", "0.2"), ("x", ">", "0")):
        picture = control("""document.getElementById('clip-axis').value = arguments[0];
                             document.getElementById('clip-side').value = arguments[1];
                             document.getElementById('clip-offset').value = arguments[2];
                             document.getElementById('clip-add').click();""", axis, side, offset)
        if picture == shown:
            fail(f"the image did not change with the clip {axis} {side} {offset}")
        shown = picture
    planes = [x["plane"] for x in server_scene()["clip"]]
    if len(planes) != 2 or not close(planes[0], [0, 0, 1, -0.2]) or not close(planes[1], [-1, 0, 0, 0]):
        fail(f"two clips added, z < 0.2 and x > 0: the server has {planes}")
    picture = control("document.querySelector('#clips .clip-remove').click()")
    planes = [x["plane"] for x in server_scene().get("clip", [])]
    if len(planes) != 1 or not close(planes[0], [-1, 0, 0, 0]) or picture == shown:
        fail(f"the first clip removed: the server has {planes}")
    # Reset: the scene's own view, colours, clip and sections again, and its first frame's pixels.
    n = frames()
    driver.execute_script("document.getElementById('reset').click()")
    reset = settle(n)
    if driver.execute_script("return [view.camera.azimuth, view.light, view.transparency, view.sections.length, "
                             "view.clips.length]") != [camera["azimuth"], 1, 0, 0, 0] or idat(reset) != idat(first) or \
            driver.execute_script("return document.getElementById('extent-type').value") != "sphere":
        fail("Reset does not bring back the scene's own view")
    # Save image: the server renders the size and quality asked for, not the frame on screen.
    driver.execute_script("""document.getElementById('save-width').value = '50';
                             document.getElementById('save-height').value = '30';
                             document.getElementById('save-quality').value = 'preview';
                             document.getElementById('save-png').click();""")
    wait.until(lambda d: d.find_element(By.ID, "save-png").get_attribute("data-saved") == "50x30 preview")
    image_url = url.rstrip("/") + driver.execute_script("return '/frame.png?' + query(50, 30, false)")
    with urllib.request.urlopen(image_url, timeout=60) as r:
        saved_png = r.read()
    if saved_png[16:24] != (50).to_bytes(4, "big") + (30).to_bytes(4, "big"):
        fail("the saved image is not 50x30")
    # At full quality (antialiasing and shadows) the server renders another picture of that size.
    driver.execute_script("""document.getElementById('save-quality').value = 'full';
                             document.getElementById('save-png').click();""")
    wait.until(lambda d: d.find_element(By.ID, "save-png").get_attribute("data-saved") == "50x30 full")
    with urllib.request.urlopen(url.rstrip("/") + driver.execute_script("return '/frame.png?' + query(50, 30, true)"),
                                timeout=60) as r:
        if idat(r.read()) == idat(saved_png):
            fail("the full-quality saved image is the preview's")

    # A bad equation: the error under the column the command line reports, and the last good image stays.
    n = frames()
    src = driver.execute_script("return document.getElementById('frame').src")
    driver.execute_script("""const e = document.getElementById('equation');
                             e.value = 'x^2+*y'; e.dispatchEvent(new Event('change'));""")
    wait.until(lambda d: d.find_element(By.ID, "error").text != "")
    box = driver.find_element(By.ID, "error")
    lines = box.get_attribute("textContent").split("\n")
    if box.get_attribute("data-column") != "5" or lines[0] != "x^2+*y" or lines[1] != " " * 4 + "^" \
            or "at character 5 of the equation" not in lines[2]:
        fail(f"error box: {lines!r}")
    if frames() != n or driver.execute_script("return document.getElementById('frame').src") != src:
        fail("the image changed with a bad equation")

    # Back to the good equation; then the saved scene renders to the last full-size frame.
    n = frames()
    driver.execute_script("""const e = document.getElementById('equation');
                             e.value = arguments[0]; e.dispatchEvent(new Event('change'));""", original)
    last = settle(n)
    if driver.find_element(By.ID, "error").text != "":
        fail("the error stayed after a good equation")
    toml_url = url.rstrip("/") + driver.execute_script("return '/scene.toml?' + query(view.width, view.height, false)")
    with urllib.request.urlopen(toml_url, timeout=60) as r:
        saved = r.read()
    with open(os.path.join(WORK, "saved.toml"), "wb") as f:
        f.write(saved)
    out = os.path.join(WORK, "saved.png")
    subprocess.run([BINARY, "render", os.path.join(WORK, "saved.toml"), "-o", out], check=True)
    with open(out, "rb") as f:
        if idat(f.read()) != idat(last):
            fail("the saved scene does not render to the view's last full-size frame")

    # An equation alone, clipped by a box: the page keeps the box (it sends a box's keys, not a radius) and its
    # light slider reaches algray's default key and fill lights.
    other = subprocess.Popen([BINARY, "view", "--port", "0", "-e", "x^2+y^2-z^2-0.25", "--set", "extent.type=box",
                              "--width", "96", "--height", "72"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    other_url = other.stdout.readline().strip()
    if not other_url.startswith("http://127.0.0.1:"):
        fail(f"expected the second server's URL, got {other_url!r}")
    driver.get(other_url)
    boxed = settle(0)
    if driver.find_element(By.ID, "error").text != "" or \
            driver.execute_script("return document.getElementById('extent-type').value") != "box":
        fail(f"an equation in a box: error {driver.find_element(By.ID, 'error').text!r}")
    picture = control("""const e = document.getElementById('light'); e.value = '0.3';
                         e.dispatchEvent(new Event('input'));""")
    if driver.find_element(By.ID, "error").text != "" or picture == boxed:
        fail(f"the light slider on an equation's default lights: error {driver.find_element(By.ID, 'error').text!r}")
finally:
    if driver is not None:
        driver.quit()
    for process in (server, other):
        if process is not None:
            process.terminate()
            process.wait(timeout=30)
print("test_view_browser: first frame, hint, fps while moving, drag, slider, zoom, colours, lights, transparency, "
      "axis views, clip shape and radius, sections, clipping planes, reset, saved image at both qualities, JPEG and WebP frames while moving, located error, saved scene "
      "and an equation in a box all hold in Chromium")
