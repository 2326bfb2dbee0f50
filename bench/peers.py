#!/usr/bin/env python3
"""Against the peers (issue 14): algray timed beside POV-Ray 3.7 and jsurf-alggeo on the paper's seven surfaces.

For each surface the script reads algray's scene file and writes the same picture for each peer: the equation
expanded into monomials for POV-Ray's `polynomial { ... sturm }`, clipped by the scene's extent sphere, and a
.jsurf file for jsurf-alggeo, with the same camera and size. Preview (1024x1024, PNG): `algray --preview`
(one camera ray per pixel, whatever the scene's antialiasing) against POV-Ray with one
shadowless point light and no antialiasing, and against `jsurf-alggeo -q 0` (its lowest quality, one ray per
pixel). Full mode (1024x768, PNG; the Barth sextic and decic): algray's scene as shipped against
POV-Ray with the scene's two 5x5 area lights and 2x2 antialiasing. Every time is the whole process, warm (one
untimed run of each program first), and each (algray, peer) pair runs interleaved, so that load from other
users of the machine falls on both alike; ratios are per pair, reported as median and range, for wall time
and for CPU time. The silhouettes of the last images are compared, with a warning where a peer's differs.
With --results the tables replace their own sections of bench/RESULTS.md ("Against the peers": "Preview against
POV-Ray and jsurf", "Full mode against POV-Ray"), with the date, machine, commit and command.

Installs povray and jsurf-alggeo with apt-get when they are missing (as root). Standard library only.
"""
import argparse
import datetime
import json
import math
import os
import random
import re
import resource
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time
import tomllib
from fractions import Fraction
from pathlib import Path

from bench_common import RESULTS_MD, ROOT, command_line, commit, machine, replace_section
from jsurf_compare import mask, read_png

SURFACES = ["barth_sextic", "cusp_catastrophe", "torus", "tooth", "lemniscate", "tanglecube", "barth_decic"]
FULL_SURFACES = ["barth_sextic", "barth_decic"]
PREVIEW_SIZE = (1024, 1024)
FULL_SIZE = (1024, 768)
# Issue 14, goal 1: preview at most 0.10x the faster peer; full mode at most 0.03x POV-Ray.
PREVIEW_TARGET = 0.10
FULL_TARGET = 0.03
PEER_NAMES = {"povray": "POV-Ray", "jsurf": "jsurf"}
JSURF_JAR = Path("/usr/share/java/jsurf-alggeo.jar")
# README's defaults for a scene without [material] (none of the seven has one).
DEFAULT_MATERIAL = {
    "front": {"colour": [0.95, 0.65, 0.15], "ambient": 0.15, "diffuse": 0.75, "specular": 0.35, "exponent": 40},
    "back": {"colour": [0.25, 0.45, 0.9], "ambient": 0.15, "diffuse": 0.75, "specular": 0.35, "exponent": 40},
}
# How far the silhouettes may differ before the timing is called meaningless: relative area, bounding-box edges
# (as a fraction of the image side) and intersection over union with algray's.
AREA_TOLERANCE = 0.03
BOX_TOLERANCE = 0.02
IOU_TOLERANCE = 0.95
# bench/RESULTS.md: the area and the two sections this script writes.
AREA = "## Against the peers"
HEADINGS = {"preview": "### Preview against POV-Ray and jsurf", "full": "### Full mode against POV-Ray"}


# ---------------------------------------------------------------------------------------------------------------
# Installing the peers

def ensure_peers():
    missing = [p for p, present in (("povray", shutil.which("povray")), ("jsurf-alggeo", JSURF_JAR.exists()))
               if not present]
    if not missing:
        return
    if os.geteuid() != 0:
        sys.exit(f"needs {' '.join(missing)}: run as root, or apt-get install {' '.join(missing)}")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    install = ["apt-get", "install", "-y", "-qq", "--no-install-recommends"] + missing
    print(f"installing {' '.join(missing)}", file=sys.stderr)
    # The package lists may be stale or absent on a fresh machine: update once and retry before giving up.
    if subprocess.run(install, env=env).returncode != 0:
        subprocess.run(["apt-get", "update", "-qq"], env=env, check=True)
        subprocess.run(install, env=env, check=True)


def java_home():
    """The JDK that jsurf's launcher should use: JAVA_HOME, Debian's default-java, or the one /usr/bin/java is.

    The launcher falls back to /usr/lib/jvm/default-java, which not every machine has."""
    if os.environ.get("JAVA_HOME"):
        return os.environ["JAVA_HOME"]
    if Path("/usr/lib/jvm/default-java/bin/java").exists():
        return "/usr/lib/jvm/default-java"
    java = shutil.which("java")
    if java:
        return str(Path(os.path.realpath(java)).parent.parent)
    sys.exit("jsurf-alggeo needs a Java runtime (apt-get install default-jre-headless)")


# ---------------------------------------------------------------------------------------------------------------
# algray's equations, expanded into monomials. The grammar is README's: numbers (exact decimal fractions),
# x, y, z, parameters, + - * /, ^ or ** with a constant non-negative integer exponent, parentheses, and
# functions of constants. Polynomials are dicts {(i, j, k): Fraction}; exact arithmetic, so cancelling terms
# vanish and the degree is the true one, as algray's own expansion (GMP rationals) finds it.

TOKEN = re.compile(r"\s*(?:(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)|([A-Za-z_]\w*)|(\*\*|[-+*/^(),]))")
FUNCTIONS = {"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
             "acos": math.acos, "atan": math.atan, "exp": math.exp, "log": math.log, "abs": abs,
             "sign": lambda v: float((v > 0) - (v < 0)), "floor": math.floor, "ceil": math.ceil}


def tokenize(text):
    tokens, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise ValueError(f"equation: cannot read {text[pos:pos + 10]!r}")
        tokens.append(("num", m.group(1)) if m.group(1) else ("name", m.group(2)) if m.group(2) else
                      ("op", "^" if m.group(3) == "**" else m.group(3)))
        pos = m.end()
    return tokens


def parse(text):
    """The equation as a tree of tuples: ('num', Fraction), ('var', name), (op, a, b), ('neg', a), ('call', f, a)."""
    tokens = tokenize(text)
    pos = 0

    def peek():
        return tokens[pos] if pos < len(tokens) else ("end", None)

    def take(value=None):
        nonlocal pos
        token = peek()
        if value is not None and token[1] != value:
            raise ValueError(f"equation: expected {value!r}, found {token[1]!r}")
        pos += 1
        return token

    def expression():
        node = term()
        while peek() in (("op", "+"), ("op", "-")):
            node = (take()[1], node, term())
        return node

    def term():
        node = unary()
        while peek() in (("op", "*"), ("op", "/")):
            node = (take()[1], node, unary())
        return node

    def unary():
        # -x^2 is -(x^2), as in algray.
        if peek() == ("op", "-"):
            take()
            return ("neg", unary())
        if peek() == ("op", "+"):
            take()
            return unary()
        return power()

    def power():
        base = atom()
        if peek() == ("op", "^"):
            take()
            return ("^", base, unary())  # right-associative
        return base

    def atom():
        kind, value = take()
        if kind == "num":
            return ("num", Fraction(value))
        if kind == "name":
            if value in FUNCTIONS:
                take("(")
                argument = expression()
                take(")")
                return ("call", value, argument)
            return ("var", value)
        if value == "(":
            node = expression()
            take(")")
            return node
        raise ValueError(f"equation: unexpected {value!r}")

    tree = expression()
    if pos != len(tokens):
        raise ValueError(f"equation: unexpected {tokens[pos][1]!r}")
    return tree


def padd(a, b, sign=1):
    out = dict(a)
    for e, c in b.items():
        out[e] = out.get(e, 0) + sign * c
        if out[e] == 0:
            del out[e]
    return out


def pmul(a, b):
    out = {}
    for ea, ca in a.items():
        for eb, cb in b.items():
            e = (ea[0] + eb[0], ea[1] + eb[1], ea[2] + eb[2])
            out[e] = out.get(e, 0) + ca * cb
    return {e: c for e, c in out.items() if c != 0}


def constant_of(p, what):
    if any(e != (0, 0, 0) for e in p):
        raise ValueError(f"equation: {what} must be a constant")
    return p.get((0, 0, 0), Fraction(0))


def expand(tree, parameters):
    kind = tree[0]
    if kind == "num":
        return {(0, 0, 0): tree[1]} if tree[1] else {}
    if kind == "var":
        name = tree[1]
        if name in ("x", "y", "z"):
            return {tuple(int(name == v) for v in "xyz"): Fraction(1)}
        if name not in parameters:
            raise ValueError(f"equation: unknown name {name!r}")
        return {(0, 0, 0): Fraction(parameters[name])} if parameters[name] else {}
    if kind == "neg":
        return {e: -c for e, c in expand(tree[1], parameters).items()}
    if kind == "call":
        value = FUNCTIONS[tree[1]](float(constant_of(expand(tree[2], parameters), f"the argument of {tree[1]}")))
        return {(0, 0, 0): Fraction(value)} if value else {}
    a, b = expand(tree[1], parameters), expand(tree[2], parameters)
    if kind == "+":
        return padd(a, b)
    if kind == "-":
        return padd(a, b, -1)
    if kind == "*":
        return pmul(a, b)
    if kind == "/":
        divisor = constant_of(b, "a divisor")
        return {e: c / divisor for e, c in a.items()}
    exponent = constant_of(b, "an exponent")
    if exponent.denominator != 1 or exponent < 0:
        raise ValueError("equation: exponents are non-negative integers")
    out = {(0, 0, 0): Fraction(1)}
    for _ in range(int(exponent)):
        out = pmul(out, a)
    return out


def evaluate(tree, parameters, point):
    """The equation's own value at a point, in floating point, straight from the tree (not the expansion)."""
    kind = tree[0]
    if kind == "num":
        return float(tree[1])
    if kind == "var":
        return point["xyz".index(tree[1])] if tree[1] in ("x", "y", "z") else float(parameters[tree[1]])
    if kind == "neg":
        return -evaluate(tree[1], parameters, point)
    if kind == "call":
        return float(FUNCTIONS[tree[1]](evaluate(tree[2], parameters, point)))
    a, b = evaluate(tree[1], parameters, point), evaluate(tree[2], parameters, point)
    if kind == "+":
        return a + b
    if kind == "-":
        return a - b
    if kind == "*":
        return a * b
    if kind == "/":
        return a / b
    return a ** round(b)


def check_expansion(tree, parameters, poly, centre, radius, name):
    """Compares the expansion with the equation at random points of the extent's cube: a wrong monomial would
    give POV-Ray another surface. The tolerance is relative to the size of the terms, which cancel near P = 0."""
    rng = random.Random(14)
    for _ in range(200):
        p = [centre[i] + radius * rng.uniform(-1, 1) for i in range(3)]
        terms = [float(c) * p[0] ** e[0] * p[1] ** e[1] * p[2] ** e[2] for e, c in poly.items()]
        direct = evaluate(tree, parameters, p)
        if abs(direct - math.fsum(terms)) > 1e-9 * (math.fsum(abs(t) for t in terms) + 1):
            raise SystemExit(f"{name}: the expansion disagrees with the equation at {p}: "
                             f"{math.fsum(terms)} against {direct}")


# ---------------------------------------------------------------------------------------------------------------
# Scenes

def vsub(a, b):
    return [a[i] - b[i] for i in range(3)]


def vscale(a, s):
    return [a[i] * s for i in range(3)]


def vdot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def vcross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def vnorm(a):
    return vscale(a, 1 / math.sqrt(vdot(a, a)))


def num(v):
    """A float as a plain decimal, which every peer's parser reads (no exponent notation)."""
    text = repr(float(v))
    if "e" in text or "E" in text:
        text = f"{float(v):.20f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0.0", "0.0") else text.removesuffix(".0")


def read_scene(path):
    scene = tomllib.loads(Path(path).read_text())
    surface = scene["surface"]
    if "equation" not in surface:
        raise SystemExit(f"{path}: needs [surface] equation (a terms list is not supported here)")
    parameters = scene.get("parameters", {})
    extent = scene["extent"]
    if extent.get("type", "sphere") != "sphere":
        raise SystemExit(f"{path}: the peers are given a clip sphere; this extent is a {extent['type']}")
    camera = scene["camera"]
    if camera.get("projection", "perspective") != "perspective":
        raise SystemExit(f"{path}: only perspective cameras are translated")
    tree = parse(surface["equation"])
    poly = expand(tree, parameters)
    degree = max(sum(e) for e in poly)
    centre, radius = [float(v) for v in extent["centre"]], float(extent["radius"])
    check_expansion(tree, parameters, poly, centre, radius, path.stem)
    material = {side: dict(DEFAULT_MATERIAL[side], **scene.get("material", {}).get(side, {}))
                for side in ("front", "back")}
    lights = scene.get("light", [])
    if not lights:  # algray's headlight: a point light at the eye
        lights = [{"type": "point", "position": camera["eye"], "intensity": 1.0}]
    return {"name": surface.get("name", path.stem), "stem": path.stem, "equation": surface["equation"],
            "parameters": parameters, "poly": poly, "degree": degree, "centre": centre, "radius": radius,
            "eye": [float(v) for v in camera["eye"]], "look_at": [float(v) for v in camera["look_at"]],
            "up": [float(v) for v in camera.get("up", [0, 1, 0])], "fov_y": float(camera["fov_y"]),
            "background": scene.get("image", {}).get("background", [1, 1, 1])[:3], "material": material,
            "lights": lights}


def pov_vector(v):
    return "<" + ", ".join(num(c) for c in v) + ">"


def pov_texture(m):
    return (f"{{ pigment {{ rgb {pov_vector(m['colour'])} }} finish {{ ambient {num(m['ambient'])} "
            f"diffuse {num(m['diffuse'])} phong {num(m['specular'])} phong_size {num(m['exponent'])} }} }}")


def write_pov(scene, path, width, height, full):
    """POV-Ray 3.7 scene. algray's world is right-handed, POV-Ray's left-handed: keeping every coordinate and
    giving the camera a negative `right` (POV-Ray's documented way to render right-handed scenes) shows the same
    view; look_at keeps that handedness. `angle` is POV-Ray's horizontal field of view."""
    if scene["degree"] > 35:
        raise SystemExit(f"{scene['stem']}: POV-Ray's polynomial stops at degree 35")
    aspect = width / height
    angle = math.degrees(2 * math.atan(aspect * math.tan(math.radians(scene["fov_y"]) / 2)))
    lines = [
        "#version 3.7;",
        f"// {scene['name']}: {scene['equation']}, from algray's scenes/{scene['stem']}.toml",
        "global_settings { assumed_gamma 1.0 }  // algray's colours are linear",
        f"background {{ rgb {pov_vector(scene['background'])} }}",
        "camera {",
        "  perspective",
        f"  location {pov_vector(scene['eye'])}",
        f"  sky {pov_vector(scene['up'])}",
        "  up y",
        f"  right -x*{num(aspect)}  // negative: a right-handed world",
        f"  angle {num(angle)}  // horizontal; algray's fov_y is {num(scene['fov_y'])} degrees vertical",
        f"  look_at {pov_vector(scene['look_at'])}",
        "}",
    ]
    # Preview: algray shades without shadows, so POV-Ray gets one shadowless point light (the key light's
    # centre). Full mode: every light as algray has it, rectangles as POV-Ray area lights of as many points.
    for light in scene["lights"] if full else scene["lights"][:1]:
        colour = vscale(light.get("colour", [1, 1, 1]), float(light.get("intensity", 1.0)))
        text = f"light_source {{ {pov_vector(light['position'])} color rgb {pov_vector(colour)}"
        if not full:
            text += " shadowless"
        elif light.get("type") == "rectangle":
            n = int(light.get("samples", 5))
            text += f" area_light {pov_vector(light['edge_u'])}, {pov_vector(light['edge_v'])}, {n}, {n}"
        elif light.get("type", "point") != "point":
            raise SystemExit(f"{scene['stem']}: a {light['type']} light has no POV-Ray translation here")
        lines.append(text + " }")
    terms = [f"xyz({e[0]},{e[1]},{e[2]}):{num(c)}" for e, c in sorted(scene["poly"].items(), reverse=True)]
    lines.append(f"polynomial {{ {scene['degree']},")
    for i in range(0, len(terms), 4):
        lines.append("  " + ", ".join(terms[i:i + 4]) + ("," if i + 4 < len(terms) else ""))
    # POV-Ray's inside is P < 0, so its outer texture is algray's front (the side P > 0).
    lines += [
        "  sturm",
        f"  texture {pov_texture(scene['material']['front'])}",
        f"  interior_texture {pov_texture(scene['material']['back'])}",
        f"  clipped_by {{ sphere {{ {pov_vector(scene['centre'])}, {num(scene['radius'])} }} }}",
        "  bounded_by { clipped_by }",
        "}",
    ]
    Path(path).write_text("\n".join(lines) + "\n")


def srgb(v):
    """Linear to display value: jsurf's colours are display values, shaded without gamma."""
    v = min(max(float(v), 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055


def jsurf_equation(scene):
    """The equation for jsurf with the parameters' values written in (jsurf knows only its own parameter names).
    A clip sphere off the origin moves the surface instead: jsurf clips to a sphere about its origin."""
    if any(scene["centre"]):
        c = scene["centre"]
        shifted = {}
        for e, coefficient in scene["poly"].items():
            term = {(0, 0, 0): coefficient}
            for axis in range(3):
                linear = {tuple(int(a == axis) for a in range(3)): Fraction(1)}
                if c[axis]:
                    linear[(0, 0, 0)] = Fraction(c[axis])
                for _ in range(e[axis]):
                    term = pmul(term, linear)
            shifted = padd(shifted, term)
        return "+".join("*".join([f"({num(v)})"] + [f"{var}^{n}" for var, n in zip("xyz", e) if n])
                        for e, v in sorted(shifted.items())) or "0"

    def value(m):
        name = m.group(0)
        return f"({num(scene['parameters'][name])})" if name in scene["parameters"] else name

    return re.sub(r"[A-Za-z_]\w*", value, scene["equation"]).replace("**", "^")


def write_jsurf(scene, path):
    """jsurf's frame (src/algray/scene/jsurf.cpp reads it the same way): the surface is evaluated at 10^scale_factor times the
    clip-space point, the clip sphere is the unit sphere there, and camera_transform takes clip space to camera
    space (the camera at its origin looking down -z, y up). Lights sit in camera space."""
    r, c = scene["radius"], scene["centre"]
    eye = vscale(vsub(scene["eye"], c), 1 / r)
    forward = vnorm(vsub(scene["look_at"], scene["eye"]))
    right = vnorm(vcross(forward, scene["up"]))
    up = vcross(right, forward)
    back = vscale(forward, -1)
    # World-to-camera: the rows are the camera's axes; the translation puts the eye at the origin.
    rows = [right + [-vdot(right, eye)], up + [-vdot(up, eye)], back + [-vdot(back, eye)], [0, 0, 0, 1]]
    # jsurf-alggeo 0.4.1's perspective camera is off axis: its pixels span the camera-space directions
    # (x, y, -1) with x and y in [t, 3t] (t = tan(fov_y/2), rounded to float as jsurf does; images are square),
    # not in [-t, t], so a camera aimed at the surface looks past it and renders nothing at these distances.
    # Shearing jsurf's camera space against the true one, x -> x - 2t z and y -> y - 2t z (z = -1 on its image
    # plane), puts the picture back on the axis; the eye, the camera's origin, stays where it is.
    t = struct.unpack("f", struct.pack("f", math.tan(math.radians(scene["fov_y"]) / 2)))[0]
    rows[0] = [rows[0][i] - 2 * t * rows[2][i] for i in range(4)]
    rows[1] = [rows[1][i] - 2 * t * rows[2][i] for i in range(4)]

    def to_camera(p):
        # Into jsurf's (sheared) camera space, so that the light sits at the scene's point; angles there are
        # sheared too, so jsurf's shading is near algray's but not the same.
        q = vscale(vsub(p, c), 1 / r)
        return [vdot(rows[i][:3], q) + rows[i][3] for i in range(3)]

    def colour(v):
        return " ".join(num(round(srgb(x), 7)) for x in v)

    lines = [
        f"# {scene['name']}, from algray's scenes/{scene['stem']}.toml (bench/peers.py)",
        f"surface_equation={jsurf_equation(scene)}",
        "camera_type=PERSPECTIVE_CAMERA",
        f"camera_fov_y={num(scene['fov_y'])}",
        "camera_transform=" + " ".join(num(v) for row in rows for v in row),
        "rotation_matrix=1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1",
        f"scale_factor={num(math.log10(r))}",
        f"background_color={colour(scene['background'])}",
    ]
    for side in ("front", "back"):
        m = scene["material"][side]
        # Blinn's half-vector exponent near 4x Phong's gives about the same highlight (src/algray/scene/jsurf.cpp).
        lines += [f"{side}_material_color={colour(m['colour'])}",
                  f"{side}_material_ambient_intensity={num(m['ambient'])}",
                  f"{side}_material_diffuse_intensity={num(m['diffuse'])}",
                  f"{side}_material_specular_intensity={num(m['specular'])}",
                  f"{side}_material_shininess={num(4 * m['exponent'])}"]
    # One point light, the key light's centre, as POV-Ray's preview has; jsurf casts no shadows.
    light = scene["lights"][0]
    lines += ["light_status_0=ON", f"light_position_0={' '.join(num(v) for v in to_camera(light['position']))}",
              f"light_color_0={colour(light.get('colour', [1, 1, 1]))}",
              f"light_intensity_0={num(light.get('intensity', 1.0))}"]
    lines += [f"light_status_{i}=OFF" for i in range(1, 8)]
    Path(path).write_text("\n".join(lines) + "\n")


# ---------------------------------------------------------------------------------------------------------------
# Running and timing

def timed(command, cwd, env):
    """(wall seconds, CPU seconds) of the whole process. The CPU time (user + system, of the process and its
    threads) is recorded beside the wall time because on a shared machine the wall time also counts waiting
    for cores that other work holds; it is the children's total, so runs must not overlap."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode != 0:
        raise SystemExit(f"failed ({result.returncode}): {' '.join(map(str, command))}\n"
                         f"{result.stderr.decode(errors='replace')[-2000:]}")
    return seconds, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def commands(args, scene_path, stem, mode, work):
    """{program: command} for one surface; every image is a PNG in `work`. POV-Ray runs in `work` with relative
    names, as Debian's povray.conf restricts writing to the current directory and /tmp."""
    width, height = PREVIEW_SIZE if mode == "preview" else FULL_SIZE
    out = {}
    algray = [str(args.algray), "render", str(scene_path), "-o", str(work / f"{stem}_{mode}_algray.png"),
              "--width", str(width), "--height", str(height)]
    # --preview drops shadows, bounces and antialiasing: one camera ray per pixel, as the peers' previews.
    out["algray"] = algray + (["--preview"] if mode == "preview" else [])
    # POV-Ray: -D no display, +FN8 8-bit PNG; preview without antialiasing. Full mode: +AM1 +R2 traces one ray
    # and then 2x2 more in each pixel that differs from a neighbour by more than the threshold; at the default
    # 0.0 that is every pixel, the nearest POV-Ray comes to algray's 2x2 in every pixel. No jitter.
    pov = ["povray", f"+I{stem}_{mode}.pov", f"+O{stem}_{mode}_povray.png", f"+W{width}", f"+H{height}", "+FN8",
           "-D", "-V", "-GA"]
    out["povray"] = pov + (["-A"] if mode == "preview" else [f"+A{args.pov_threshold}", "+AM1", "+R2", "-J"])
    if mode == "preview":
        # -q 0 is jsurf's lowest quality (one ray per pixel); it renders square images only.
        out["jsurf"] = ["jsurf-alggeo", "-s", str(width), "-q", "0", str(work / f"{stem}.jsurf"),
                        str(work / f"{stem}_{mode}_jsurf.png")]
    return out


def spread(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def measure(args, scene_dir, stem, mode, work, env):
    scene_path = scene_dir / f"{stem}.toml"
    scene = read_scene(scene_path)
    width, height = PREVIEW_SIZE if mode == "preview" else FULL_SIZE
    write_pov(scene, work / f"{stem}_{mode}.pov", width, height, full=(mode == "full"))
    if mode == "preview":
        write_jsurf(scene, work / f"{stem}.jsurf")
    cmds = commands(args, scene_path, stem, mode, work)
    for program, command in cmds.items():  # warm-up: caches, page cache, the JIT's class data
        timed(command, work, env)
    times = {program: [] for program in cmds}
    cpu = {program: [] for program in cmds}
    load_before = os.getloadavg()[0]
    for rep in range(args.repeat):
        # ABAB...: algray, then each peer, then again, so a burst of load elsewhere hits neighbours alike.
        for program, command in cmds.items():
            wall, used = timed(command, work, env)
            times[program].append(wall)
            cpu[program].append(used)
        print(f"  {stem} {mode} {rep + 1}/{args.repeat}: " +
              "  ".join(f"{p} {t[-1]:.2f} s" for p, t in times.items()), file=sys.stderr, flush=True)
    peers = [p for p in cmds if p != "algray"]
    row = {"surface": stem, "name": scene["name"], "degree": scene["degree"], "monomials": len(scene["poly"]),
           "mode": mode, "size": [width, height], "times_s": times, "cpu_s": cpu,
           "commands": {p: " ".join(c) for p, c in cmds.items()},
           "load_average_1min": [load_before, os.getloadavg()[0]],
           "median_s": {p: statistics.median(t) for p, t in times.items()},
           "ratio": {p: spread([a / b for a, b in zip(times["algray"], times[p])]) for p in peers},
           "cpu_ratio": {p: spread([a / b for a, b in zip(cpu["algray"], cpu[p])]) for p in peers}}
    faster = min(peers, key=lambda p: row["median_s"][p])
    target = PREVIEW_TARGET if mode == "preview" else FULL_TARGET
    row.update(faster=faster, target=target, met=row["ratio"][faster]["median"] <= target)
    row["silhouettes"] = silhouettes(work, stem, mode, list(cmds), scene["background"])
    return row


# ---------------------------------------------------------------------------------------------------------------
# Do the pictures correspond?

def silhouettes(work, stem, mode, programs, background):
    """Area and bounding box of the pixels that are not background in each program's last image, and the
    intersection over union with algray's. Shading differs by design; the outline must not."""
    bg = tuple(round(255 * srgb(v)) for v in background)
    masks, out = {}, {}
    for program in programs:
        width, height, rows = read_png(work / f"{stem}_{mode}_{program}.png")
        m = mask(rows, bg)
        masks[program] = m
        cols = [x for x in range(width) if any(m[y][x] for y in range(height))]
        lines = [y for y in range(height) if any(m[y])]
        area = sum(map(sum, m)) / (width * height)
        box = [cols[0] / width, lines[0] / height, (cols[-1] + 1) / width, (lines[-1] + 1) / height] if cols else None
        out[program] = {"area": area, "box": box}
    for program in programs:
        a, b = masks["algray"], masks[program]
        both = sum(pa and pb for ra, rb in zip(a, b) for pa, pb in zip(ra, rb))
        either = sum(pa or pb for ra, rb in zip(a, b) for pa, pb in zip(ra, rb))
        out[program]["iou"] = both / either if either else 1.0
    warnings = []
    ours = out["algray"]
    for program in programs[1:]:
        theirs = out[program]
        problems = []
        if ours["area"] and abs(theirs["area"] / ours["area"] - 1) > AREA_TOLERANCE:
            problems.append(f"area {theirs['area']:.4f} against algray's {ours['area']:.4f}")
        if ours["box"] and theirs["box"] and \
                max(abs(p - q) for p, q in zip(ours["box"], theirs["box"])) > BOX_TOLERANCE:
            problems.append(f"bounding box {fmt_box(theirs['box'])} against algray's {fmt_box(ours['box'])}")
        if theirs["iou"] < IOU_TOLERANCE:
            problems.append(f"intersection over union {theirs['iou']:.3f}")
        if problems:
            warnings.append(f"{stem} {mode}: {program}'s picture does not match algray's ({'; '.join(problems)}): "
                            "the timing compares different views")
    for w in warnings:
        print("WARNING: " + w, file=sys.stderr, flush=True)
    return {"programs": out, "warnings": warnings}


def fmt_box(box):
    return "[" + ", ".join(f"{v:.3f}" for v in box) + "]"


# ---------------------------------------------------------------------------------------------------------------
# Report

def ratio_cell(r):
    return f"{r['median']:.3f} ({r['min']:.3f}-{r['max']:.3f})"


def table(rows):
    lines = []
    preview = [r for r in rows if r["mode"] == "preview"]
    full = [r for r in rows if r["mode"] == "full"]
    if preview:
        lines += [f"Preview, {PREVIEW_SIZE[0]}x{PREVIEW_SIZE[1]} PNG, whole process, median wall seconds; ratios "
                  "algray / peer per interleaved pair, median (min-max); CPU: the same ratio of CPU seconds:", ""]
        lines += preview_table(preview)
    if full:
        if preview:
            lines.append("")
        lines += [f"Full mode, {FULL_SIZE[0]}x{FULL_SIZE[1]} PNG (algray: the scene as shipped; POV-Ray: two 5x5 "
                  "area lights, 2x2 antialiasing), whole process, median wall seconds:", ""]
        lines += full_table(full)
    return "\n".join(lines)


def preview_table(preview):
    lines = ["| surface | degree | algray s | POV-Ray s | jsurf s | algray / POV-Ray | algray / jsurf "
             f"| / faster peer | target {PREVIEW_TARGET:.2f} | CPU / faster peer "
             "| silhouette IoU (POV-Ray, jsurf) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in preview:
        s = r["silhouettes"]["programs"]
        lines.append(f"| {r['name']} | {r['degree']} | {r['median_s']['algray']:.2f} | "
                     f"{r['median_s']['povray']:.2f} | {r['median_s']['jsurf']:.2f} | "
                     f"{ratio_cell(r['ratio']['povray'])} | {ratio_cell(r['ratio']['jsurf'])} | "
                     f"{r['ratio'][r['faster']]['median']:.3f} ({PEER_NAMES[r['faster']]}) | "
                     f"{'met' if r['met'] else '**missed**'} | {ratio_cell(r['cpu_ratio'][r['faster']])} | "
                     f"{s['povray']['iou']:.3f}, {s['jsurf']['iou']:.3f} |")
    return lines


def full_table(full):
    lines = [f"| surface | degree | algray s | POV-Ray s | algray / POV-Ray | target {FULL_TARGET:.2f} "
             "| CPU ratio | silhouette IoU |", "|---|---|---|---|---|---|---|---|"]
    for r in full:
        lines.append(f"| {r['name']} | {r['degree']} | {r['median_s']['algray']:.2f} | "
                     f"{r['median_s']['povray']:.2f} | {ratio_cell(r['ratio']['povray'])} | "
                     f"{'met' if r['met'] else '**missed**'} | {ratio_cell(r['cpu_ratio']['povray'])} | "
                     f"{r['silhouettes']['programs']['povray']['iou']:.3f} |")
    return lines


def write_results(path, rows, versions, revision, command, repeat):
    """Each mode's table in place of its section of RESULTS.md (under "Against the peers")."""
    about = {
        "preview": f"{PREVIEW_SIZE[0]}x{PREVIEW_SIZE[1]} PNG, one camera ray per pixel in all three programs, whole "
                   "process, warm, interleaved pairs; median wall seconds; ratios algray / peer per pair, median "
                   "(min-max); CPU: the same ratio of CPU seconds. Target (issue 14, goal 1): at most "
                   f"{PREVIEW_TARGET:.2f}x the faster peer.",
        "full": f"{FULL_SIZE[0]}x{FULL_SIZE[1]} PNG: algray's scene as shipped (2x2 antialiasing, two 5x5 area "
                "lights) against POV-Ray with the same two lights as 5x5 area lights and 2x2 antialiasing; whole "
                f"process, warm, interleaved pairs; median wall seconds. Target (issue 14, goal 1): at most "
                f"{FULL_TARGET:.2f}x POV-Ray.",
    }
    for mode, make in (("preview", preview_table), ("full", full_table)):
        mine = [r for r in rows if r["mode"] == mode]
        if not mine:
            continue
        lines = [HEADINGS[mode], "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; commit: {revision}",
                 f"- Command: `{command}` ({repeat} timed pairs per surface)",
                 f"- Peers: {versions['povray']}; jsurf-alggeo {versions['jsurf']}. {about[mode]}", ""]
        lines += make(mine)
        replace_section(path, HEADINGS[mode], "\n".join(lines) + "\n", under=AREA)


def peer_versions(env):
    versions = {}
    # povray --version also prints warnings (a missing user povray.conf); the version is the line that names it.
    for program, command, pattern in (("povray", ["povray", "--version"], r"^POV-Ray \d"),
                                      ("jsurf", ["jsurf-alggeo", "--version"], r"\d+\.\d+")):
        result = subprocess.run(command, env=env, capture_output=True, text=True)
        text = (result.stdout + result.stderr).splitlines()
        versions[program] = next((l.strip() for l in text if re.search(pattern, l.strip())), "unknown")
    return versions


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--algray", type=Path, default=ROOT / "build/apps/algray/algray", help="the algray binary")
    ap.add_argument("--scenes", type=Path, default=ROOT / "scenes", help="where the surfaces' .toml files are")
    ap.add_argument("--surfaces", nargs="+", default=SURFACES, help="scene names (default: the paper's seven); "
                    f"full mode runs those of them among {', '.join(FULL_SURFACES)}")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs of each program per surface (default 3)")
    ap.add_argument("--only", choices=["preview", "full"], help="one of the two comparisons")
    ap.add_argument("--keep", type=Path, help="write the peer scene files and every image here, and keep them")
    ap.add_argument("--json", type=Path, help="write the results as JSON here")
    ap.add_argument("--results", action="store_true", help="write each table into its section of bench/RESULTS.md")
    ap.add_argument("--results-file", type=Path, default=RESULTS_MD, help="the page --results writes "
                    "(default bench/RESULTS.md)")
    ap.add_argument("--pov-threshold", type=float, default=0.0, help="POV-Ray's antialiasing threshold in full "
                    "mode (default 0.0: every pixel supersampled, as algray's 2x2; POV-Ray's own default is 0.3)")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    args.algray = args.algray.resolve()
    if not args.algray.exists():
        sys.exit(f"{args.algray}: no algray binary (build it, or pass --algray)")
    for stem in args.surfaces:
        if not (args.scenes / f"{stem}.toml").exists():
            sys.exit(f"{args.scenes / stem}.toml: no such scene")
    ensure_peers()
    env = dict(os.environ, JAVA_HOME=java_home())

    jobs = [(s, "preview") for s in args.surfaces] if args.only != "full" else []
    if args.only != "preview":
        jobs += [(s, "full") for s in args.surfaces if s in FULL_SURFACES]
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(args.keep or tmp).resolve()
        work.mkdir(parents=True, exist_ok=True)
        rows = []
        for stem, mode in jobs:
            rows.append(measure(args, args.scenes.resolve(), stem, mode, work, env))

    print(table(rows))
    warnings = [w for r in rows for w in r["silhouettes"]["warnings"]]
    for w in warnings:
        print(f"\nWARNING: {w}")
    command = command_line()
    versions = peer_versions(env) if args.json or args.results else None
    revision = commit(args.algray)
    if args.json:
        args.json.write_text(json.dumps({
            "date": datetime.date.today().isoformat(), "machine": machine(), "commit": revision,
            "command": command, "algray": str(args.algray),
            "peers": versions, "repeat": args.repeat, "rows": rows, "warnings": warnings}, indent=1) + "\n")
    if args.results:
        write_results(args.results_file, rows, versions, revision, command, args.repeat)
        print(f"wrote {args.results_file}", file=sys.stderr)


if __name__ == "__main__":
    main()
