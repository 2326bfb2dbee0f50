// `algray view`: a local web server that shows a scene live in the browser (its page, frames and saved scenes).
#include <algray/algray.h>
#include <httplib.h>
#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <mutex>
#include <nlohmann/json.hpp>
#include <regex>
#include <stdexcept>

#include "algray/scene/solver_options.h"
#include "algray/util/embedded_files.h"
#include "commands.h"
#include "exit_codes.h"

namespace algray {
// The page and its script (apps/algray/view/), embedded at build time.
const std::vector<EmbeddedFile>& embedded_view_files();
}  // namespace algray

namespace algray::cli {
namespace {

using nlohmann::json;

// A request the page should not have sent, or a scene setting the scene refuses: answered 400 with its reason,
// never a crash. key: the setting at fault, if one; column: where in its value (the command line's "character").
struct BadRequest : std::runtime_error {
  BadRequest(const std::string& what, std::string key_ = {}, int column_ = 0)
      : std::runtime_error(what), key(std::move(key_)), column(column_) {}
  std::string key;
  int column;
};

// The largest frame the view renders: a poster is a job for `algray render`.
constexpr int kMaxViewSide = 4096;

int int_param(const httplib::Request& req, const char* name, int fallback, int lo, int hi) {
  if (!req.has_param(name)) return fallback;
  const std::string text = req.get_param_value(name);
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi)
    throw BadRequest(std::string(name) + " must be a whole number from " + std::to_string(lo) + " to " +
                     std::to_string(hi) + ", not '" + text + "'");
  return value;
}

// What one frame asks for: the scene as loaded, with the page's settings applied in order.
struct FrameQuery {
  api::Scene scene;
  int width = 0, height = 0;
  bool full = false;  // the scene's own mode (antialiasing, shadows) rather than preview
};

// The character of the equation a parse error names ("at character N of the equation"), else 0.
int equation_column(const std::string& message) {
  static const std::regex at(R"(at character (\d+) of the equation)");
  std::smatch m;
  return std::regex_search(message, m, at) ? std::atoi(m[1].str().c_str()) : 0;
}

FrameQuery parse_query(const api::Scene& base, const httplib::Request& req) {
  FrameQuery q{base};
  const std::size_t sets = req.get_param_value_count("set");
  for (std::size_t i = 0; i < sets; ++i) {
    const std::string item = req.get_param_value("set", i);
    const std::size_t eq = item.find('=');
    if (eq == 0 || eq == std::string::npos) throw BadRequest("a setting is key=value, not '" + item + "'");
    const std::string key = item.substr(0, eq);
    try {
      q.scene.set(key, item.substr(eq + 1));
    } catch (const api::SceneError& e) {
      throw BadRequest(e.what(), key, equation_column(e.what()));
    }
  }
  q.width = int_param(req, "width", base.width(), 1, kMaxViewSide);
  q.height = int_param(req, "height", base.height(), 1, kMaxViewSide);
  const std::string full = req.has_param("full") ? req.get_param_value("full") : "0";
  if (full != "0" && full != "1") throw BadRequest("full must be 0 or 1, not '" + full + "'");
  q.full = full == "1";
  return q;
}

std::vector<double> numbers(const toml::node* node) {
  std::vector<double> out;
  if (const toml::array* a = node ? node->as_array() : nullptr)
    for (const toml::node& x : *a) out.push_back(x.value_or(0.0));
  return out;
}

// The names of one list of solver choices (solver_options.h), as the page's selectors offer them.
template <class Choices>
json choice_names(const Choices& choices) {
  json names = json::array();
  for (const auto& c : choices) names.push_back(c.name);
  return names;
}

// What the page starts from: the scene's equation, parameters, camera, extent and solver, and the choices.
json scene_summary(const api::Scene& scene, const std::string& device) {
  const toml::table t = toml::parse(scene.to_toml());
  json parameters = json::object();
  for (const auto& [name, value] : scene.parameters()) parameters[name] = value;
  json precisions = choice_names(kPrecisions);
  precisions.insert(precisions.begin(), "auto");
  const std::vector<std::string> equations = scene.equations();
  return {{"name", scene.name()},
          {"equation", equations.empty() ? "" : equations.front()},
          {"parameters", parameters},
          {"camera",
           {{"eye", numbers(t["camera"]["eye"].node())},
            {"look_at", numbers(t["camera"]["look_at"].node())},
            {"up", numbers(t["camera"]["up"].node())}}},
          {"extent_radius", t["extent"]["radius"].value_or(1.0)},
          {"precision", t["render"]["precision"].value_or(std::string("auto"))},
          {"isolation", t["render"]["isolation"].value_or(std::string("bernstein"))},
          {"refinement", t["render"]["refinement"].value_or(std::string("brent"))},
          {"width", scene.width()},
          {"height", scene.height()},
          {"precisions", precisions},
          {"isolations", choice_names(kIsolations)},
          {"refinements", choice_names(kRefinements)},
          {"device", device}};
}

void answer_bad_request(httplib::Response& res, const BadRequest& e) {
  res.status = 400;
  res.set_content(json{{"error", e.what()}, {"key", e.key}, {"column", e.column}}.dump(), "application/json");
}

// Every handler's errors become a response: bad input 400, anything else 500; the server goes on.
template <class F>
httplib::Server::Handler guarded(F handle) {
  return [handle](const httplib::Request& req, httplib::Response& res) {
    try {
      handle(req, res);
    } catch (const BadRequest& e) {
      answer_bad_request(res, e);
    } catch (const api::SceneError& e) {
      answer_bad_request(res, BadRequest(e.what()));
    } catch (const api::DeviceError& e) {
      answer_bad_request(res, BadRequest(e.what()));
    } catch (const std::exception& e) {
      res.status = 500;
      res.set_content(json{{"error", e.what()}}.dump(), "application/json");
    }
  };
}

}  // namespace

int run_view(const ViewRequest& request, std::ostream& out, std::ostream& err) {
  std::optional<api::Scene> loaded;
  try {
    loaded = request.scene_path ? api::Scene::load(*request.scene_path) : api::Scene::default_scene();
    for (const Override& o : request.overrides) loaded->set(o.key, o.value);
  } catch (const api::SceneError& e) {
    err << e.what() << "\n";
    return kExitBadInput;
  }
  const api::Scene& base = *loaded;
  // One context and program cache for as long as the server runs: only a new degree builds a kernel.
  std::optional<api::Renderer> renderer;
  std::string device;
  try {
    renderer.emplace(request.device_spec, request.use_cache);
    device = renderer->device().name;
  } catch (const api::DeviceError& e) {
    err << "algray: " << e.what() << "\n";
    return kExitBadInput;
  }
  std::mutex render_mutex;  // one OpenCL queue: frames render one at a time

  const std::string page = [] {
    for (const EmbeddedFile& f : embedded_view_files())
      if (std::string(f.name) == "index.html") return std::string(f.text);
    throw std::logic_error("the view page was not embedded");
  }();

  httplib::Server server;
  server.Get("/", [&](const httplib::Request&, httplib::Response& res) { res.set_content(page, "text/html"); });
  server.Get("/scene.json", guarded([&](const httplib::Request&, httplib::Response& res) {
               res.set_content(scene_summary(base, device).dump(), "application/json");
             }));
  server.Get("/frame.png", guarded([&](const httplib::Request& req, httplib::Response& res) {
               const FrameQuery q = parse_query(base, req);
               api::RenderSettings settings;
               settings.width = q.width;
               settings.height = q.height;
               settings.preview = !q.full;
               settings.depth_and_normal = false;
               std::string png, stats;
               {
                 const std::lock_guard<std::mutex> lock(render_mutex);
                 const api::Image image = renderer->render(q.scene, settings);
                 png = image.png();
                 stats = image.stats_json();
               }
               const json s = json::parse(stats);
               double kernel_ms = 0;
               for (const json& p : s["passes"]) kernel_ms += p.value("kernel_ms", 0.0);
               int new_programs = 0;  // built or loaded from disk for this frame, rather than kept in memory
               for (const json& p : s["programs"]) new_programs += p.value("origin", "") != "memory";
               res.set_header("X-Algray-New-Programs", std::to_string(new_programs));
               int degree = 0;
               for (const json& surface : s["surfaces"]) degree = std::max(degree, surface.value("degree", 0));
               res.set_header("X-Algray-Kernel-Ms", std::to_string(kernel_ms));
               res.set_header("X-Algray-Degree", std::to_string(degree));
               res.set_header("Cache-Control", "no-store");
               res.set_content(png, "image/png");
             }));
  server.Get("/scene.toml", guarded([&](const httplib::Request& req, httplib::Response& res) {
               FrameQuery q = parse_query(base, req);
               q.scene.set("image.width", std::to_string(q.width));
               q.scene.set("image.height", std::to_string(q.height));
               q.scene.set("render.preview", q.full ? "false" : "true");
               res.set_header("Content-Disposition", "attachment; filename=\"scene.toml\"");
               res.set_content(q.scene.to_toml(), "application/toml");
             }));
  server.Get("/orbit.toml", guarded([&](const httplib::Request& req, httplib::Response& res) {
               const int frames = int_param(req, "frames", 36, 2, 3600);
               (void)parse_query(base, req);  // the same settings as scene.toml, checked alike
               res.set_header("Content-Disposition", "attachment; filename=\"orbit.toml\"");
               res.set_content(
                   "# An orbit about the look-at point of the scene as `algray view` showed it. With scene.toml "
                   "beside this file\n# (the page saves both): algray batch orbit.toml\n[[job]]\nname = \"orbit\"\n"
                   "scene = \"scene.toml\"\noutput = \"orbit_{frame:03}.png\"\norbit = { frames = " +
                       std::to_string(frames) + ", degrees = 360 }\n",
                   "application/toml");
             }));
  server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
    res.status = 500;
    res.set_content(R"({"error":"internal error"})", "application/json");
  });

  if (request.host != "127.0.0.1" && request.host != "localhost")
    err << "algray view: warning: listening on " << request.host
        << ", so other machines can reach this server; it has no authentication\n";
  const int port = request.port == 0 ? server.bind_to_any_port(request.host) : request.port;
  if (request.port != 0 && !server.bind_to_port(request.host, port)) {
    err << "algray view: cannot listen on " << request.host << ":" << port << "\n";
    return kExitBadInput;
  }
  if (port < 0) {
    err << "algray view: cannot listen on " << request.host << "\n";
    return kExitBadInput;
  }
  const std::string url = "http://" + request.host + ":" + std::to_string(port) + "/";
  out << url << std::endl;
  if (request.open) {
    const std::string command = "xdg-open '" + url + "' >/dev/null 2>&1 &";
    if (std::system(command.c_str()) != 0) err << "algray view: could not open a browser; visit " << url << "\n";
  }
  server.listen_after_bind();
  return kExitOk;
}

}  // namespace algray::cli
