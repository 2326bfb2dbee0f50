// `algray view`: a local web server that shows a scene live in the browser (its page, frames and saved scenes).
#include <algray/algray.h>
#include <httplib.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <memory>
#include <cstdlib>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <stdexcept>

#include "algray/math/polynomial.h"
#include "algray/scene/solver_options.h"
#include "algray/util/embedded_files.h"
#include "algray/util/json_text.h"
#include "commands.h"
#include "exit_codes.h"
#include "view_query.h"
#include "view_server.h"
#include "view_stream.h"

namespace algray {
// The page and its script (apps/algray/view/), embedded at build time.
const std::vector<EmbeddedFile>& embedded_view_files();
}  // namespace algray

namespace algray::cli {
namespace {

using nlohmann::json;

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

// Why a request's work stops early, asked between steps: its client left, its time ran out, or (a frame) a newer
// frame of its page came. Throws the answer; a client that left never reads it.
void check_going_on(const ViewLimits& limits, const std::function<bool()>& superseded = {}) {
  if (ViewServer::client_gone()) throw BadRequest("the client closed the connection", {}, 0, 408);
  if (ViewClock::now() > ViewServer::deadline())
    throw BadRequest("the request took longer than --request-timeout (" + format_number(limits.request_timeout_s) +
                         " s)",
                     {}, 0, 408, "--request-timeout");
  if (superseded && superseded()) throw BadRequest("a newer frame of this page replaced this one", {}, 0, 409);
}

// The request's settings applied to `base` in order. `before`: the settings of the page's last state, each with
// the scene after it; a state whose first settings are those starts from the scene after them rather than
// applying them again (each set() reads the scene again: the page's 21 settings took 4 ms for the Barth sextic and
// 6-11 ms for the decic). `applied`, where given, gets this request's. `size_in_scene`: the frame's size and
// preview mode are set on the scene too (image.width, image.height, render.preview), so that the render reads
// the scene no more.
FrameQuery parse_query(const api::Scene& base, const httplib::Request& req, const ViewLimits& limits,
                       const AppliedSettings* before = nullptr, AppliedSettings* applied = nullptr,
                       bool size_in_scene = false) {
  FrameQuery q{base};
  q.width = int_param(req, "width", base.width(), 1, kMaxViewSide);
  q.height = int_param(req, "height", base.height(), 1, kMaxViewSide);
  const std::string full = req.has_param("full") ? req.get_param_value("full") : "0";
  if (full != "0" && full != "1") throw BadRequest("full must be 0 or 1, not '" + full + "'");
  q.full = full == "1";
  std::vector<std::string> items;
  for (std::size_t i = 0, n = req.get_param_value_count("set"); i < n; ++i)
    items.push_back(req.get_param_value("set", i));
  std::vector<Setting> settings = parse_settings(items, limits.max_settings);
  // First, so that they are among the settings a page's states share while only its camera moves.
  if (size_in_scene) {
    std::vector<Setting> size{{"image.width", std::to_string(q.width)}, {"image.height", std::to_string(q.height)}};
    if (!q.full) size.push_back({"render.preview", "true"});
    settings.insert(settings.begin(), size.begin(), size.end());
  }
  std::size_t kept = 0;
  if (before)
    while (kept < before->size() && kept < settings.size() && (*before)[kept].setting.key == settings[kept].key &&
           (*before)[kept].setting.value == settings[kept].value)
      ++kept;
  if (kept > 0) q.scene = (*before)[kept - 1].scene;
  if (applied) applied->assign(before ? before->begin() : applied->end(), before ? before->begin() + kept : applied->end());
  // One equation's expansion is bounded by the parser's own budget, and stops when its client leaves (below); what a
  // request may add up is bounded here.
  const auto parse_deadline = ViewClock::now() + std::chrono::duration_cast<ViewClock::duration>(
                                                     std::chrono::duration<double, std::milli>(limits.max_parse_ms));
  for (std::size_t i = kept; i < settings.size(); ++i) {
    const Setting& s = settings[i];
    check_going_on(limits);
    const auto too_long = [&] {
      return BadRequest("applying the request's set= items took longer than --max-parse-ms (" +
                            format_number(limits.max_parse_ms) + " ms)",
                        s.key, 0, 413, "--max-parse-ms");
    };
    if (ViewClock::now() > parse_deadline) throw too_long();
    try {
      // One equation the parser's budget admits can still take seconds to expand: it stops too when the client
      // leaves or the time runs out.
      const ExpansionWatch watch([&] {
        return !ViewServer::client_gone() && ViewClock::now() <= std::min(parse_deadline, ViewServer::deadline());
      });
      q.scene.set(s.key, s.value);
    } catch (const api::SceneError& e) {
      throw BadRequest(e.what(), s.key, equation_column(e.what()));
    } catch (const ExpansionStopped&) {
      check_going_on(limits);  // the client left or the request's time ran out: that is the answer
      throw too_long();
    }
    if (applied) applied->push_back({s, q.scene});
  }
  return q;
}

// A frame over --max-frame-samples is refused before it starts (413).
void check_frame_cost(const FrameQuery& q, const ViewLimits& limits) {
  const std::uint64_t samples = frame_samples(q.scene.to_toml(), q.width, q.height, q.full);
  if (samples > limits.max_frame_samples)
    throw BadRequest("the frame needs " + std::to_string(samples) +
                         " samples (camera rays x (1 + shadow points) x (1 + bounces)); --max-frame-samples allows " +
                         std::to_string(limits.max_frame_samples),
                     {}, 0, 413, "--max-frame-samples");
}

// The page's name for its stream (`page`): 1 to 64 letters, digits, '-' or '_', as the page makes it.
std::string page_name(const httplib::Request& req) {
  const std::string page = req.get_param_value("page");
  const bool ok = !page.empty() && page.size() <= 64 && std::all_of(page.begin(), page.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_';
  });
  if (!ok) throw BadRequest("page must be 1 to 64 letters, digits, '-' or '_'", "page");
  return page;
}

// A state's place in its page's order (`seq`): a whole number from 1 to 2^53 (a JavaScript number's exact range).
std::uint64_t state_seq(const httplib::Request& req) {
  const std::string text = req.get_param_value("seq");
  std::uint64_t seq = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seq);
  if (ec != std::errc() || end != text.data() + text.size() || seq < 1 || seq > (std::uint64_t{1} << 53))
    throw BadRequest("seq must be a whole number from 1 to 2^53, not '" + text + "'", "seq");
  return seq;
}

// The state a page posts to /state: its settings as /frame.png takes them, its stage and how to encode the frame.
std::shared_ptr<const StreamState> stream_state(const api::Scene& base, const httplib::Request& req,
                                                const ViewLimits& limits, StreamHub& streams) {
  const std::uint64_t seq = state_seq(req);
  const std::string stage = req.has_param("stage") ? req.get_param_value("stage") : "still";
  if (stage != "moving" && stage != "still" && stage != "full")
    throw BadRequest("stage must be moving, still or full, not '" + stage + "'", "stage");
  const FrameEncoding encoding = parse_encoding(req.has_param("encoding") ? req.get_param_value("encoding") : "png");
  const int quality = int_param(req, "quality", 80, 1, 100);
  const std::string page_id = page_name(req);
  // Its page's last settings, for those this state repeats (404 when the page has no stream).
  const std::shared_ptr<const AppliedSettings> before = streams.applied_settings(page_id);
  auto applied = std::make_shared<AppliedSettings>();
  FrameQuery q = parse_query(base, req, limits, before.get(), applied.get(), true);
  check_frame_cost(q, limits);
  streams.remember_settings(page_id, applied);
  auto state = std::make_shared<StreamState>(std::move(q.scene));
  state->seq = seq;
  state->stage = stage;
  state->encoding = encoding;
  state->quality = quality;
  state->width = q.width;
  state->height = q.height;
  state->full = q.full;
  state->arrived = StreamClock::now();
  return state;
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

// The first surface's material prefix for --set: "surface.material", or "surface.0.material" where the scene's
// surfaces are a [[surface]] list, whatever its length (the key that fails is the other one).
std::string material_prefix(const api::Scene& scene, const toml::table& t) {
  api::Scene probe = scene;
  const double transparency = t["surface"]["material"]["front"]["transparency"].value_or(0.0);
  try {
    probe.set("surface.material.front.transparency", format_number(transparency));
    return "surface.material";
  } catch (const api::SceneError&) {
    return "surface.0.material";
  }
}

// What the page starts from: the scene's equation, parameters, camera, extent and solver, and the choices.
json scene_summary(const api::Scene& scene, const std::string& device) {
  const toml::table t = toml::parse(scene.to_toml());
  // The first surface's sides, as scene_to_toml writes a single surface ([[surface]] for several).
  const toml::node_view<const toml::node> surface =
      t["surface"].is_array() ? t["surface"][0] : toml::node_view<const toml::node>(t["surface"]);
  json lights = json::array();
  if (const toml::array* list = t["light"].as_array())
    for (const toml::node& l : *list) lights.push_back(l.as_table()->get("intensity")->value_or(1.0));
  const std::array<double, 3> angles = scene.camera_angles();
  // The extent as its kind has it, the plane sections and the clipping planes, for the page's clip, section and
  // cut controls.
  const toml::node_view<const toml::node> e = t["extent"];
  json extent{{"type", e["type"].value_or(std::string("sphere"))}};
  for (const char* key : {"centre", "min", "max"})
    if (e[key]) extent[key] = numbers(e[key].node());
  for (const char* key : {"radius", "half_height"})
    if (e[key]) extent[key] = e[key].value_or(1.0);
  if (e["axis"]) extent["axis"] = e["axis"].value_or(std::string("z"));
  json sections = json::array();
  if (const toml::array* list = t["section"].as_array())
    for (const toml::node& section : *list) {
      const toml::table& st = *section.as_table();
      json one{{"plane", numbers(st.get("plane"))}, {"colour", numbers(st.get("colour"))}};
      // The one surface it cuts and its width (surf's cut_with_plane) go back as they came.
      if (const toml::node* n = st.get("surface")) one["surface"] = n->value_or(std::int64_t{0});
      if (const toml::node* n = st.get("width")) one["width"] = n->value_or(1.0);
      sections.push_back(one);
    }
  json clips = json::array();
  if (const toml::array* list = t["clip"].as_array())
    for (const toml::node& clip : *list) clips.push_back({{"plane", numbers(clip.as_table()->get("plane"))}});
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
            {"up", numbers(t["camera"]["up"].node())},
            {"azimuth", angles[0]},
            {"elevation", angles[1]},
            {"distance", angles[2]}}},
          {"material_prefix", material_prefix(scene, t)},
          {"front_colour", numbers(surface["material"]["front"]["colour"].node())},
          {"back_colour", numbers(surface["material"]["back"]["colour"].node())},
          {"transparency", surface["material"]["front"]["transparency"].value_or(0.0)},
          {"background", numbers(t["image"]["background"].node())},
          {"light_intensities", lights},
          {"extent_radius", t["extent"]["radius"].value_or(1.0)},
          {"extent", extent},
          {"sections", sections},
          {"clips", clips},
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
  res.status = e.status;
  json body{{"error", e.what()}, {"key", e.key}, {"column", e.column}};
  if (!e.limit.empty()) body["limit"] = e.limit;
  // Replaced rather than thrown on: a message may quote bytes of the request.
  res.set_content(algray::dump_json(body), "application/json");
}

// Every handler's errors become a response: bad input and limits 4xx, anything else 500; the server goes on.
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
      res.set_content(error_json(e.what()), "application/json");
    }
  };
}

// A token as Jupyter's: 24 random bytes in hex, from the system's entropy source.
std::string random_token() {
  std::random_device entropy;
  std::string token;
  static const char hex[] = "0123456789abcdef";
  for (int i = 0; i < 24; ++i) {
    const unsigned byte = entropy() & 0xFF;
    token += hex[byte >> 4];
    token += hex[byte & 15];
  }
  return token;
}

}  // namespace

int run_view(const ViewRequest& request, std::ostream& out, std::ostream& err) {
  std::optional<api::Scene> loaded;
  try {
    loaded = request.equation      ? api::Scene::from_equation(*request.equation)
             : request.scene_path ? api::Scene::load(*request.scene_path)
                                  : api::Scene::default_scene();
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
  const ViewLimits& limits = request.limits;
  FrameQueue frames;
  // The pages' streams, and the thread that renders their frames on the same queue as /frame.png's.
  StreamHub streams(*renderer, frames, limits);
  const bool loopback = is_loopback(request.host);
  // Off loopback anyone who can reach the port could use it: a token in the URL, as Jupyter's, keeps them out.
  const std::string token = !request.token.empty() ? request.token : loopback ? std::string() : random_token();

  const std::string page_html = [] {
    for (const EmbeddedFile& f : embedded_view_files())
      if (std::string(f.name) == "index.html") return std::string(f.text);
    throw std::logic_error("the view page was not embedded");
  }();

  ViewServer server(limits);
  // A page posts a small state for each input, on connections it keeps: cpp-httplib's default of 5 requests per
  // connection would make it connect anew every fifth. Each request keeps its own limits.
  server.set_keep_alive_max_count(1000);
  // Before any route: the token, the Host header (a page of another site that rebinds its name to 127.0.0.1
  // sends its own name, and must not read the scene, which names its file), and parameters that are text.
  server.set_pre_routing_handler([&](const httplib::Request& req, httplib::Response& res) {
    const auto refuse = [&](int status, const std::string& message) {
      res.status = status;
      res.set_content(error_json(message), "application/json");
      return httplib::Server::HandlerResponse::Handled;
    };
    if (!token.empty() && !token_matches(req.get_param_value("token"), token))
      return refuse(403, "this server needs the token it printed at its start: add ?token=... to the URL");
    if (token.empty() && !is_loopback_host_header(req.get_header_value("Host")))
      return refuse(403, "the Host header '" + req.get_header_value("Host") +
                             "' is not a loopback address or localhost, so the page is not this machine's");
    for (const auto& [name, value] : req.params) {
      if (const auto problem = text_problem(name)) return refuse(400, "a parameter name " + *problem);
      if (const auto problem = text_problem(value)) return refuse(400, "the value of " + name + " " + *problem);
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server.Get("/", [&](const httplib::Request&, httplib::Response& res) { res.set_content(page_html, "text/html"); });
  server.Get("/scene.json", guarded([&](const httplib::Request&, httplib::Response& res) {
               res.set_content(algray::dump_json(scene_summary(base, device)), "application/json");
             }));
  server.Get("/frame.png", guarded([&](const httplib::Request& req, httplib::Response& res) {
               const FrameQueue::Ticket ticket = frames.arrive(req.get_param_value("page"));
               struct Leave {
                 FrameQueue& frames;
                 const FrameQueue::Ticket& ticket;
                 ~Leave() { frames.leave(ticket); }
               } leave{frames, ticket};
               const auto superseded = [&] { return frames.superseded(ticket); };
               const FrameQuery q = parse_query(base, req, limits);
               api::RenderSettings settings;
               settings.width = q.width;
               settings.height = q.height;
               settings.preview = !q.full;
               settings.depth_and_normal = false;
               check_frame_cost(q, limits);
               // Asked between tiles: the render stops, and gives the queue to the next frame, as soon as this
               // one is not wanted.
               std::optional<BadRequest> stopped;
               settings.cancelled = [&] {
                 try {
                   check_going_on(limits, superseded);
                   return false;
                 } catch (const BadRequest& e) {
                   stopped = e;
                   return true;
                 }
               };
               std::string png, stats;
               frames.take([&] { check_going_on(limits, superseded); });
               try {
                 const api::Image image = renderer->render(q.scene, settings);
                 png = image.png();
                 stats = image.stats_json();
               } catch (const api::Cancelled&) {
                 frames.give_back();
                 throw stopped ? *stopped : BadRequest("the frame was cancelled", {}, 0, 408);
               } catch (...) {
                 frames.give_back();
                 throw;
               }
               frames.give_back();
               const FrameFacts facts = frame_facts(stats);
               // Programs built or loaded from disk for this frame, rather than kept in memory.
               res.set_header("X-Algray-New-Programs", std::to_string(facts.new_programs));
               res.set_header("X-Algray-Kernel-Ms", std::to_string(facts.kernel_ms));
               res.set_header("X-Algray-Degree", std::to_string(facts.degree));
               res.set_header("Cache-Control", "no-store");
               res.set_content(png, "image/png");
             }));
  // The page's frames: one long-lived response per page, whose messages (StreamHub::next_message) this
  // connection's thread encodes and sends while the stream thread renders the next frame.
  server.Get("/stream", guarded([&](const httplib::Request& req, httplib::Response& res) {
               const std::string page_id = page_name(req);
               const std::shared_ptr<StreamSession> session = streams.open(page_id);
               // 256 KiB (the kernel doubles it): a 512^2 JPEG frame is some 30 KB, a 1024^2 PNG some 200 KB.
               ViewServer::limit_send_buffer(256 << 10);
               res.set_header("Cache-Control", "no-store");
               res.set_header("X-Content-Type-Options", "nosniff");
               auto hello = std::make_shared<bool>(true);
               auto last_send_ms = std::make_shared<double>(0);
               res.set_chunked_content_provider(
                   "application/octet-stream",
                   [&streams, &server, session, page_id, hello, last_send_ms](std::size_t, httplib::DataSink& sink) {
                     std::optional<std::string> message;
                     if (*hello) {
                       *hello = false;
                       message = StreamHub::hello_message(page_id);
                     } else {
                       message = streams.next_message(
                           session, [&server] { return ViewServer::client_gone() || !server.is_running(); },
                           *last_send_ms);
                     }
                     if (!message) return false;
                     const auto started = ViewClock::now();
                     // A client that stops reading fails this write after the server's write timeout, which
                     // ends the stream: its page holds one frame, never more, until then.
                     const bool sent = sink.write(message->data(), message->size());
                     *last_send_ms = std::chrono::duration<double, std::milli>(ViewClock::now() - started).count();
                     return sent;
                   },
                   [&streams, session](bool) { streams.close(session); });
             }));
  // A page's newest state, for its stream's next frame. Refused as /frame.png refuses a frame (a bad equation
  // with its column, a limit); 404 when the page has no stream open.
  server.Post("/state", guarded([&](const httplib::Request& req, httplib::Response& res) {
                const std::string page_id = page_name(req);
                const std::shared_ptr<const StreamState> state = stream_state(base, req, limits, streams);
                const bool accepted = streams.post(page_id, state);
                res.set_header("Cache-Control", "no-store");
                res.set_content(algray::dump_json(json{{"seq", state->seq}, {"accepted", accepted}}),
                                "application/json");
              }));
  server.Get("/scene.toml", guarded([&](const httplib::Request& req, httplib::Response& res) {
               FrameQuery q = parse_query(base, req, limits);
               q.scene.set("image.width", std::to_string(q.width));
               q.scene.set("image.height", std::to_string(q.height));
               q.scene.set("render.preview", q.full ? "false" : "true");
               res.set_header("Content-Disposition", "attachment; filename=\"scene.toml\"");
               res.set_content(q.scene.to_toml(), "application/toml");
             }));
  server.Get("/orbit.toml", guarded([&](const httplib::Request& req, httplib::Response& res) {
               const int frames_wanted = int_param(req, "frames", 36, 2, 3600);
               (void)parse_query(base, req, limits);  // the same settings as scene.toml, checked alike
               res.set_header("Content-Disposition", "attachment; filename=\"orbit.toml\"");
               res.set_content(
                   "# An orbit about the look-at point of the scene as `algray view` showed it. With scene.toml "
                   "beside this file\n# (the page saves both): algray batch orbit.toml\n[[job]]\nname = \"orbit\"\n"
                   "scene = \"scene.toml\"\noutput = \"orbit_{frame:03}.png\"\norbit = { frames = " +
                       std::to_string(frames_wanted) + ", degrees = 360 }\n",
                   "application/toml");
             }));
  server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
    res.status = 500;
    res.set_content(R"({"error":"internal error"})", "application/json");
  });

  if (!loopback)
    err << "algray view: warning: listening on " << request.host
        << ", so other machines can reach this server; only URLs with its token are answered\n";
  const int port = request.port == 0 ? server.bind_to_any_port(request.host) : request.port;
  if (request.port != 0 && !server.bind_to_port(request.host, port)) {
    err << "algray view: cannot listen on " << request.host << ":" << port
        << " (in use by another server, or not an address of this machine)\n";
    return kExitBadInput;
  }
  if (port < 0) {
    err << "algray view: cannot listen on " << request.host << "\n";
    return kExitBadInput;
  }
  const std::string shown_host = request.host.find(':') != std::string::npos ? "[" + request.host + "]" : request.host;
  const std::string url =
      "http://" + shown_host + ":" + std::to_string(port) + "/" + (token.empty() ? "" : "?token=" + token);
  out << url << std::endl;
  if (request.open) {
    const std::string command = "xdg-open '" + url + "' >/dev/null 2>&1 &";
    if (std::system(command.c_str()) != 0) err << "algray view: could not open a browser; visit " << url << "\n";
  }
  server.listen_after_bind();
  streams.stop();
  return kExitOk;
}

}  // namespace algray::cli
