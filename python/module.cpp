// The compiled module algray._algray: pybind11 bindings of the public C++ API (include/algray/algray.h).
#include <Python.h>
#include <algray/algray.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;
namespace api = algray::api;

namespace {

// A read-only numpy view of one of the image's vectors, keeping the image alive as long as the array.
template <typename T>
py::array_t<T> view(const api::Image& image, const std::vector<T>& values, std::vector<py::ssize_t> shape) {
  auto* owner = new api::Image(image);
  py::capsule keep(owner, [](void* p) { delete static_cast<api::Image*>(p); });
  py::array_t<T> array(shape, values.data(), keep);
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

py::dict solver_channels(const api::Image& image) {
  py::dict out;
  const std::vector<py::ssize_t> shape{image.height(), image.width()};
  for (const std::string& name : image.channel_names()) {
    // "solver.class" is aov["class"]: the prefix names the group, every channel here is a solver's.
    const std::string key = name.rfind("solver.", 0) == 0 ? name.substr(7) : name;
    if (auto u = image.uint_channel(name))
      out[py::str(key)] = py::array_t<std::uint32_t>(shape, u->data());
    else if (auto f = image.float_channel(name))
      out[py::str(key)] = py::array_t<float>(shape, f->data());
  }
  return out;
}

// A device as algray.devices() lists it and Renderer.device describes it.
py::dict device_dict(const api::Device& d) {
  return py::dict(py::arg("index") = d.index, py::arg("platform") = d.platform,
                  py::arg("platform_version") = d.platform_version, py::arg("name") = d.name,
                  py::arg("vendor") = d.vendor, py::arg("version") = d.version, py::arg("driver") = d.driver,
                  py::arg("type") = d.type, py::arg("compute_units") = d.compute_units, py::arg("fp64") = d.fp64,
                  py::arg("global_mem_bytes") = d.global_mem_bytes, py::arg("max_alloc_bytes") = d.max_alloc_bytes);
}

// Whether to stop: a signal Python must handle (Ctrl-C), or an exception a callback raised. Asked between tiles,
// with the GIL held only for the question; the Python error stays set, and is raised once the render has stopped.
bool python_interrupted() {
  py::gil_scoped_acquire gil;
  return PyErr_Occurred() != nullptr || PyErr_CheckSignals() != 0;
}

// Calls a Python callback from a library callback. What it raises is kept as Python's pending error instead of
// unwinding through the renderer; the render stops at its next check, and the error is raised then.
template <typename F>
void call_python(F&& f) {
  py::gil_scoped_acquire gil;
  if (PyErr_Occurred()) return;
  try {
    f();
  } catch (py::error_already_set& e) {
    e.restore();
  }
}

}  // namespace

PYBIND11_MODULE(_algray, m) {
  m.doc() = "algray: ray tracing of real algebraic surfaces on any OpenCL device (compiled part)";
  m.attr("__version__") = api::version();
  // The library's warnings (a kernel cache that cannot be used) to sys.stderr, where a notebook shows them.
  api::set_warning_handler([](const std::string& text) {
    if (!Py_IsInitialized()) return;
    py::gil_scoped_acquire gil;
    PyObject* pending_type = nullptr;
    PyObject* pending_value = nullptr;
    PyObject* pending_trace = nullptr;
    PyErr_Fetch(&pending_type, &pending_value, &pending_trace);  // a Ctrl-C waiting to be raised stays pending
    try {
      py::module_::import("sys").attr("stderr").attr("write")(text);
    } catch (py::error_already_set&) {
    }
    PyErr_Restore(pending_type, pending_value, pending_trace);
  });

  // Exceptions: SceneError carries where the input went wrong.
  static py::exception<api::SceneError> scene_error(m, "SceneError", PyExc_ValueError);
  static py::exception<api::DeviceError> device_error(m, "DeviceError", PyExc_RuntimeError);
  static py::exception<api::OutputError> output_error(m, "OutputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const api::SceneError& e) {
      py::object error = py::reinterpret_borrow<py::object>(scene_error.ptr())(e.what());
      error.attr("file") = e.file;
      error.attr("line") = e.line;
      error.attr("column") = e.column;
      error.attr("message") = e.message;
      error.attr("excerpt") = e.excerpt;
      PyErr_SetObject(scene_error.ptr(), error.ptr());
    } catch (const api::DeviceError& e) {
      PyErr_SetString(device_error.ptr(), e.what());
    } catch (const api::OutputError& e) {
      PyErr_SetString(output_error.ptr(), e.what());
    }
  });

  m.def("devices", [] {
    py::list out;
    for (const api::Device& d : api::devices()) out.append(device_dict(d));
    return out;
  });

  py::class_<api::Scene>(m, "Scene")
      .def_static("load", &api::Scene::load, py::arg("path"))
      .def_static("from_toml", &api::Scene::from_toml, py::arg("text"), py::arg("name") = "<string>")
      .def_static("from_jsurf", &api::Scene::from_jsurf, py::arg("text"), py::arg("name") = "<string>")
      .def_static("default", &api::Scene::default_scene)
      .def("_set", [](api::Scene& s, const std::string& key, const std::string& value) { s.set(key, value); })
      .def("to_toml", &api::Scene::to_toml)
      .def_property_readonly("name", &api::Scene::name)
      .def_property_readonly("source", &api::Scene::source)
      .def_property_readonly("width", &api::Scene::width)
      .def_property_readonly("height", &api::Scene::height)
      .def_property_readonly("equations", &api::Scene::equations)
      .def_property_readonly("parameters",
                             [](const api::Scene& s) {
                               py::dict out;
                               for (const auto& [name, value] : s.parameters()) out[py::str(name)] = value;
                               return out;
                             })
      .def_property_readonly("warnings", &api::Scene::warnings)
      .def_property_readonly(
          "camera_angles",
          [](const api::Scene& s) {
            const std::array<double, 3> a = s.camera_angles();
            return py::dict(py::arg("azimuth") = a[0], py::arg("elevation") = a[1], py::arg("distance") = a[2]);
          },
          "the camera as the keys camera.azimuth, camera.elevation (degrees) and camera.distance about look_at")
      .def("__copy__", [](const api::Scene& s) { return api::Scene(s); })
      .def("__repr__", [](const api::Scene& s) { return "<algray.Scene " + s.name() + " from " + s.source() + ">"; });

  py::class_<api::Image>(m, "Image")
      .def_property_readonly("width", &api::Image::width)
      .def_property_readonly("height", &api::Image::height)
      .def_property_readonly("rgba",
                             [](const api::Image& i) {
                               return view(i, i.rgba(), {i.height(), i.width(), 4});
                             })
      // None for a render without depth and normals (render(..., depth=False)).
      .def_property_readonly("depth",
                             [](const api::Image& i) -> py::object {
                               if (i.depth().empty()) return py::none();
                               return view(i, i.depth(), {i.height(), i.width()});
                             })
      .def_property_readonly("normal",
                             [](const api::Image& i) -> py::object {
                               if (i.normal().empty()) return py::none();
                               return view(i, i.normal(), {i.height(), i.width(), 3});
                             })
      .def_property_readonly("aov", &solver_channels)
      .def_property_readonly("stats_json", &api::Image::stats_json)
      .def(
          "srgb",
          [](const api::Image& i) {
            const std::vector<std::uint8_t> bytes = i.srgba();
            py::array_t<std::uint8_t> out({static_cast<py::ssize_t>(i.height()), static_cast<py::ssize_t>(i.width()),
                                           static_cast<py::ssize_t>(4)});
            std::copy(bytes.begin(), bytes.end(), out.mutable_data());
            return out;
          },
          "8-bit sRGB RGBA as a numpy uint8 array (height, width, 4): the pixels of png(), for imshow")
      .def("save", &api::Image::save, py::arg("path"), py::call_guard<py::gil_scoped_release>())
      .def(
          "png",
          [](const api::Image& i) {
            std::string bytes;
            {
              py::gil_scoped_release released;
              bytes = i.png();
            }
            return py::bytes(bytes);
          },
          "the bytes save(\"x.png\") writes, the scene included, without a file");

  py::class_<api::Video>(m, "_Video")
      .def(py::init<const std::string&, double>(), py::arg("path"), py::arg("fps"))
      .def("add", &api::Video::add, py::arg("image"))
      .def("finish", &api::Video::finish, py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("frames", &api::Video::frames);

  py::class_<api::Renderer>(m, "_Renderer")
      .def(py::init<const std::string&, bool>(), py::arg("device") = "", py::arg("cache") = true)
      .def("device", [](api::Renderer& r) { return device_dict(r.device()); })
      .def(
          "render",
          [](api::Renderer& r, const api::Scene& scene, int width, int height, bool preview,
             const std::string& precision, const std::vector<std::string>& aovs, bool reference, bool depth,
             const std::function<void(int, int)>& progress) {
            api::RenderSettings settings;
            settings.width = width;
            settings.height = height;
            settings.preview = preview;
            settings.precision = precision;
            settings.aovs = aovs;
            settings.reference = reference;
            settings.depth_and_normal = depth;
            if (progress)
              settings.on_progress = [&](const api::Progress& p) {
                call_python([&] { progress(p.tiles_done, p.tiles_total); });
              };
            settings.cancelled = python_interrupted;
            try {
              py::gil_scoped_release released;
              return r.render(scene, settings);
            } catch (const api::Cancelled&) {
              // Ctrl-C, or a callback's exception: it is set already; raise it now that the render has stopped.
              if (PyErr_Occurred()) throw py::error_already_set();
              throw;
            }
          },
          py::arg("scene"), py::arg("width") = 0, py::arg("height") = 0, py::arg("preview") = false,
          py::arg("precision") = "", py::arg("aov") = std::vector<std::string>{}, py::arg("reference") = false,
          py::arg("depth") = true, py::arg("progress") = nullptr)
      .def(
          "probe_pixel",
          [](api::Renderer& r, const api::Scene& s, int x, int y, bool all) { return r.probe_pixel(s, x, y, all); },
          py::arg("scene"), py::arg("x"), py::arg("y"), py::arg("all_solvers") = false,
          py::call_guard<py::gil_scoped_release>())
      .def(
          "probe_ray",
          [](api::Renderer& r, const api::Scene& s, const std::array<double, 3>& o, const std::array<double, 3>& d,
             bool all) { return r.probe_ray(s, o, d, all); },
          py::arg("scene"), py::arg("origin"), py::arg("direction"), py::arg("all_solvers") = false,
          py::call_guard<py::gil_scoped_release>())
      .def(
          "batch",
          [](api::Renderer& r, const std::string& jobs, bool resume, const std::function<void(py::dict)>& progress,
             const std::function<void(const std::string&)>& message, std::pair<int, int> shard) {
            api::BatchSettings settings;
            settings.jobs_path = jobs;
            settings.resume = resume;
            settings.shard_index = shard.first;
            settings.shard_count = shard.second;
            if (progress)
              settings.on_frame = [&](const api::BatchFrame& f) {
                call_python([&] {
                  progress(py::dict(py::arg("done") = f.done, py::arg("total") = f.total, py::arg("job") = f.job,
                                    py::arg("frame") = f.frame, py::arg("frames") = f.frames,
                                    py::arg("status") = f.status, py::arg("frame_ms") = f.frame_ms));
                });
              };
            if (message) settings.on_message = [&](const std::string& text) { call_python([&] { message(text); }); };
            // Ctrl-C (or a callback's exception) stops the batch before its next frame, as render stops before
            // its next tile; the error is raised once the batch has stopped.
            settings.cancelled = python_interrupted;
            api::BatchResult result;
            {
              py::gil_scoped_release released;
              result = r.batch(settings);
            }
            if (PyErr_Occurred()) throw py::error_already_set();
            switch (result) {
              case api::BatchResult::Done:
                return std::string("done");
              case api::BatchResult::FramesFailed:
                return std::string("frames failed");
              case api::BatchResult::BadInput:
                return std::string("bad input");
              case api::BatchResult::Stopped:
                break;
            }
            return std::string("stopped");
          },
          py::arg("jobs"), py::arg("resume") = false, py::arg("progress") = nullptr, py::arg("message") = nullptr,
          py::arg("shard") = std::pair<int, int>{0, 1});
}
