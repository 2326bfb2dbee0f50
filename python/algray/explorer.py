"""Live exploration in Jupyter: sliders for a scene's parameters, the camera's orbit and zoom, re-rendering a
preview as they move, as SURFER does. The camera sliders are the scene keys camera.azimuth, camera.elevation and
camera.distance, which the command line's --set and the view page use too."""
import copy


class Explorer:
    """The state behind the sliders: `values` maps each slider's name to its value; update(name, value) sets one
    and re-renders into `png` (the preview's bytes) and, where ipywidgets is there, into the image widget."""

    def __init__(self, scene, renderer, width=480, height=360, **ranges):
        self.scene = scene
        self.renderer = renderer
        self.width, self.height = width, height
        # The camera by the scene keys camera.azimuth, .elevation and .distance, as the view page sets them.
        angles = scene.camera_angles
        self.values = dict(angles)
        distance = angles["distance"]
        self.ranges = {"azimuth": (-180.0, 180.0), "elevation": (-90.0, 90.0),
                       "distance": (distance / 4, distance * 4)}
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
        for key in ("azimuth", "elevation", "distance"):
            s.set("camera." + key, float(self.values[key]))
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
