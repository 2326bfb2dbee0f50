"""Live exploration in Jupyter: sliders for a scene's parameters, the camera's orbit and zoom, re-rendering a
preview as they move, as SURFER does."""
import copy
import math


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


def _add(a, b):
    return [x + y for x, y in zip(a, b)]


def _scale(a, s):
    return [x * s for x in a]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _unit(a):
    n = math.sqrt(_dot(a, a))
    return _scale(a, 1 / n)


class Orbit:
    """The scene's camera as angles about its look-at point: azimuth about the up vector and elevation above the
    plane through the look-at point normal to it, both in degrees from the scene's own view, and a zoom that
    divides the eye's distance."""

    def __init__(self, camera):
        self.look_at = list(camera.get("look_at", [0, 0, 0]))
        eye = list(camera["eye"])
        self.up = _unit(list(camera.get("up", [0, 1, 0])))
        offset = _sub(eye, self.look_at)
        self.distance = math.sqrt(_dot(offset, offset))
        self.forward = _unit(_sub(offset, _scale(self.up, _dot(offset, self.up))))  # in the plane normal to up
        self.side = _cross(self.up, self.forward)
        self.elevation0 = math.degrees(math.asin(max(-1.0, min(1.0, _dot(offset, self.up) / self.distance))))

    def eye(self, azimuth, elevation, zoom):
        a = math.radians(azimuth)
        e = math.radians(max(-89.0, min(89.0, self.elevation0 + elevation)))
        horizontal = _add(_scale(self.forward, math.cos(a)), _scale(self.side, math.sin(a)))
        direction = _add(_scale(horizontal, math.cos(e)), _scale(self.up, math.sin(e)))
        return _add(self.look_at, _scale(direction, self.distance / zoom))


class Explorer:
    """The state behind the sliders: `values` maps each slider's name to its value; update(name, value) sets one
    and re-renders into `png` (the preview's bytes) and, where ipywidgets is there, into the image widget."""

    def __init__(self, scene, renderer, width=480, height=360, **ranges):
        self.scene = scene
        self.renderer = renderer
        self.width, self.height = width, height
        self.orbit = Orbit(scene.to_dict()["camera"])
        self.values = {"azimuth": 0.0, "elevation": 0.0, "zoom": 1.0}
        self.ranges = {"azimuth": (-180.0, 180.0), "elevation": (-85.0, 85.0), "zoom": (0.25, 4.0)}
        for name, value in scene.parameters.items():
            self.values[name] = value
            span = max(abs(value), 1.0)
            self.ranges[name] = (value - span, value + span)
        self.ranges.update(ranges)
        self.renders = 0
        self.png = None
        self.image = None
        self._widget = None
        self.render()

    def current_scene(self):
        s = copy.copy(self.scene)
        for name in self.scene.parameters:
            s.set(name, float(self.values[name]))
        s.set("camera.eye", self.orbit.eye(self.values["azimuth"], self.values["elevation"], self.values["zoom"]))
        return s

    def render(self):
        self.image = self.renderer.render(self.current_scene(), width=self.width, height=self.height, preview=True)
        self.png = self.image._repr_png_()
        self.renders += 1
        if self._widget is not None:
            self._picture.value = self.png

    def update(self, name, value):
        self.values[name] = value
        self.render()

    @property
    def widget(self):
        """A VBox of the preview and one slider per value (ipywidgets), made on first use."""
        if self._widget is None:
            import ipywidgets

            self._picture = ipywidgets.Image(value=self.png, format="png", width=self.width, height=self.height)
            self.sliders = {}
            for name, (lo, hi) in self.ranges.items():
                slider = ipywidgets.FloatSlider(value=self.values[name], min=lo, max=hi, step=(hi - lo) / 200,
                                                description=name, continuous_update=False)
                slider.observe(lambda change, name=name: self.update(name, change["new"]), names="value")
                self.sliders[name] = slider
            self._widget = ipywidgets.VBox([self._picture] + list(self.sliders.values()))
        return self._widget
