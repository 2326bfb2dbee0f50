"""algray from Python: scenes, renders into numpy arrays, probes and batches on any OpenCL device.

    import algray
    scene = algray.Scene.load("scenes/torus.toml")
    scene.set("camera.fov_y", 30)
    image = algray.Renderer().render(scene, width=640, height=480, preview=True)
    image.rgba.shape            # (480, 640, 4), float32, linear colour
    image.save("torus.png")

It is the renderer the command line runs (the compiled module algray._algray over its C++ API), not a second
implementation. Errors raise SceneError (with .file, .line, .column), DeviceError or OutputError.
"""
import json
import os

from . import _toml
from ._algray import DeviceError, Image, OutputError, Scene, SceneError, _Renderer, _Video
from ._algray import __version__
from ._algray import devices

__all__ = ["Scene", "Renderer", "Image", "Animation", "SceneError", "DeviceError", "OutputError", "devices", "explore",
           "__version__"]


def _scene_set(self, key, value):
    """Changes this scene in place, and returns it for chaining: sets a dotted scene key, or a parameter by its
    bare name, as `algray render --set key=value` does; a bare name that is no parameter but a table sets the table
    or list whole ("section", []), the key "--section" adds a plane section and "--clip" a clipping plane (the
    side of it kept: "z<0.5"), as the flags. The value may be a
    Python number, bool, string or list (written as TOML). Use copy.copy(scene) first to keep the original.

    >>> scene = algray.Scene.from_equation("x^2+y^2+z^2-r^2", parameters={"r": 1})
    >>> scene.set("r", 0.5).set("camera.azimuth", 90) is scene
    True
    >>> scene.parameters
    {'r': 0.5}
    >>> try:
    ...     scene.set("q", 1)
    ... except algray.SceneError as e:
    ...     print(e.message)
    the scene has no parameter 'q'; its parameters: r (--set parameters.q=VALUE adds one)
    >>> scene.set("section", [{"plane": [0, 0, 1, -0.5]}]).to_dict()["section"][0]["plane"]
    [0.0, 0.0, 1.0, -0.5]
    >>> scene.set("--section", "x=0").set("section.1.colour", [1, 0, 0]).to_dict()["section"][1]["plane"]
    [1.0, 0.0, 0.0, 0.0]
    >>> scene.set("--clip", "z>0.25").to_dict()["clip"][0]["plane"]
    [0.0, 0.0, -1.0, 0.25]
    """
    self._set(key, _toml.value(value))
    return self


def _scene_from_dict(data, name="<dict>"):
    """A scene from a dict laid out as the TOML file: {"surface": {"equation": ...}, "camera": {...}, ...}."""
    return Scene.from_toml(_toml.document(data), name)


def _scene_from_equation(equation, parameters=None, extent=None, camera=None, name="<equation>", **tables):
    """A scene from an equation alone, with algray's defaults for everything else (README, "An equation is a
    scene"): a sphere extent of radius 2, the camera framing it from 3R through 45 degrees, a key and a fill light
    that follow the camera, 2x2 antialiasing. `equation` is a string ("x^4+y^4+z^4-1", with ^ or **) or anything
    whose str() is one, such as a sympy expression. parameters={"r": 1} names the equation's constants; extent=,
    camera= and further tables (image=, material=, light=[...], antialias=, render=) are as in a TOML file. The
    camera's keys are set on the framed camera, as --set does, so the default lights stay.

    >>> scene = algray.Scene.from_equation("x^4+y^4+z^4-1")
    >>> scene.to_dict()["extent"]["radius"], scene.to_dict()["antialias"]["samples"], len(scene.to_dict()["light"])
    (2.0, 2, 2)
    >>> import sympy
    >>> x, y, z = sympy.symbols("x y z")
    >>> algray.Scene.from_equation(x**4 - sympy.Rational(3, 2)*x*y*z + y**4 + z**4 - 1).equations
    ['x**4 - 3*x*y*z/2 + y**4 + z**4 - 1']
    """
    data = {"surface": {"equation": str(equation)}}
    if parameters:
        data["parameters"] = {str(k): float(v) for k, v in parameters.items()}
    if extent:
        data["extent"] = extent
    data.update(tables)
    scene = _scene_from_dict(data, name)
    for key, value in (camera or {}).items():
        scene.set("camera." + key, value)
    return scene


def _scene_to_dict(self):
    """The scene as the dict its TOML reads to."""
    return _toml.loads(self.to_toml())


Scene.set = _scene_set
Scene.from_dict = staticmethod(_scene_from_dict)
Scene.from_equation = staticmethod(_scene_from_equation)
Scene.to_dict = _scene_to_dict


def _image_stats(self):
    """The --stats dict of the render: passes, kernels (built or from the cache), rays, timings."""
    return json.loads(self.stats_json)


def _image_to_pil(self):
    """The image as a PIL image (RGBA, 8-bit sRGB: the pixels a PNG of it holds). Needs Pillow (python3-pil).

    >>> image = algray.Renderer().render(algray.Scene.from_equation("x^2+y^2+z^2-1"), width=32, height=24,
    ...                                  preview=True)
    >>> image.srgb().shape, image.srgb().dtype.name, image.to_pil().size
    ((24, 32, 4), 'uint8', (32, 24))
    """
    from PIL import Image as PilImage
    return PilImage.fromarray(self.srgb(), "RGBA")


Image.stats = property(_image_stats)
Image.to_pil = _image_to_pil
Image._repr_png_ = Image.png  # Jupyter shows an Image by its PNG bytes
Image.__repr__ = lambda self: f"<algray.Image {self.width}x{self.height}>"


class Renderer:
    """One OpenCL device, its context and its program cache, kept for every render, probe and batch.

    device: None for the first GPU, else the first device; an index of devices(); or a substring of the device
    or platform name. precision: "auto" (double where the device's fp64 is fast, else adaptive; previews, where
    that is double, race double against adaptive over their first frames of a surface and keep the faster:
    image.stats["solver"]["precision_reason"] says which), "double", "float", "mixed" or "adaptive".
    cache: keep built kernels on disk between processes."""

    def __init__(self, device=None, precision="auto", cache=True):
        self._renderer = _Renderer("" if device is None else str(device), cache)
        self.precision = precision

    @property
    def device(self):
        return self._renderer.device()

    def render(self, scene, width=0, height=0, preview=False, aov=(), reference=False, depth=True, progress=None):
        """Renders into memory and returns an Image. width/height 0 keep the scene's size; aov lists solver
        channels ("iterations", "isolation", "classification", "flags"), found in image.aov; depth=False leaves
        out depth and normals (image.depth and .normal are None), halving the film, as for a PNG; progress(done,
        total) is called after each tile. The GIL is released while rendering; Ctrl-C stops the render."""
        precision = "" if self.precision == "auto" else self.precision
        return self._renderer.render(scene, width, height, preview, precision, list(aov), reference, depth, progress)

    def probe(self, scene, pixel=None, ray=None, all_solvers=False):
        """The probe report as a dict: pixel=(x, y) for that pixel's centre ray, or ray=(origin, direction)."""
        if (pixel is None) == (ray is None):
            raise ValueError("probe needs pixel=(x, y) or ray=(origin, direction)")
        if pixel is not None:
            return json.loads(self._renderer.probe_pixel(scene, int(pixel[0]), int(pixel[1]), all_solvers))
        origin, direction = ray
        return json.loads(self._renderer.probe_ray(scene, list(origin), list(direction), all_solvers))

    def batch(self, jobs, progress=None, message=None, resume=False, shard=(0, 1), **render_options):
        """A jobs file (a path, as `algray batch` takes) run on this device: returns "done", "frames failed",
        "bad input" or "stopped"; progress(frame_dict) after each frame, message(text) for warnings and
        failures; shard=(k, n) renders frames k, k+n, ... as `--shard k/n` does. Or an iterable of scenes:
        returns their images, calling progress(index, image) after each."""
        if isinstance(jobs, (str, os.PathLike)):
            return self._renderer.batch(os.fspath(jobs), resume, progress, message, tuple(shard))
        images = []
        for index, scene in enumerate(jobs):
            images.append(self.render(scene, **render_options))
            if progress:
                progress(index, images[-1])
        return images


class Animation:
    """A video that Renderer.animate wrote: its path, frames and fps; Jupyter shows it inline (a <video> element,
    or an <img> for a GIF, holding the file's bytes)."""

    def __init__(self, path, frames, fps):
        self.path, self.frames, self.fps = path, frames, fps

    def _repr_html_(self):
        import base64
        data = base64.b64encode(open(self.path, "rb").read()).decode("ascii")
        kind = os.path.splitext(self.path)[1].lower().lstrip(".")
        if kind == "gif":
            return f'<img src="data:image/gif;base64,{data}"/>'
        return f'<video controls autoplay loop muted src="data:video/{kind};base64,{data}"></video>'

    def __repr__(self):
        return f"<algray.Animation {self.path}: {self.frames} frames at {self.fps} fps>"


def _animate(self, scene, sweep, seconds=5, fps=30, path=None, width=0, height=0, preview=False, progress=None):
    """Renders `scene` with each key of `sweep` ({"a": (0, 1)}: a parameter or dotted key, from, to) going
    evenly from its first value to its last over seconds x fps frames, both ends included, into a video at `path`
    (.mp4, .webm or .gif; None: a temporary .mp4) through the same writer as `algray batch --video`, and returns
    an Animation, which Jupyter shows inline. progress(index, frames) after each frame."""
    frames = max(1, round(seconds * fps))
    if path is None:
        import tempfile
        handle, path = tempfile.mkstemp(prefix="algray-", suffix=".mp4")
        os.close(handle)
        os.unlink(path)
    video = _Video(os.fspath(path), float(fps))
    for index in range(frames):
        t = index / (frames - 1) if frames > 1 else 0.0
        frame_scene = scene.__copy__()
        for key, (start, end) in sweep.items():
            frame_scene.set(key, start + (end - start) * t)
        video.add(self.render(frame_scene, width, height, preview=preview, depth=False))
        if progress:
            progress(index, frames)
    video.finish()
    return Animation(os.fspath(path), frames, fps)


Renderer.animate = _animate


def explore(scene, renderer=None, width=480, height=360, **sliders):
    """Sliders for the scene's parameters, the camera's orbit angles and its zoom in Jupyter, re-rendering a
    preview as they move (ipywidgets). Returns the widget box; see algray.explorer.Explorer."""
    from .explorer import Explorer
    return Explorer(scene, renderer or Renderer(), width, height, **sliders).widget
