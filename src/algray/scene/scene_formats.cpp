// Scene file types by extension, and the words that name them.
#include "algray/scene/scene_formats.h"

#include "algray/util/file_names.h"

namespace algray {

std::optional<SceneFormat> scene_format_of(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (ext.empty()) return SceneFormat::Toml;
  for (const SceneFormatInfo& f : kSceneFormats)
    if (ext == f.extension) return f.format;
  return std::nullopt;
}

std::string readable_scene_types() {
  std::string out;
  for (const SceneFormatInfo& f : kSceneFormats) {
    if (!out.empty()) out += ", ";
    out += std::string(f.extension) + " (" + f.what + ")";
  }
  return out;
}

std::string unknown_scene_type_message(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  return "algray does not read " + (ext.empty() ? std::string("this kind of") : "'" + ext + "'") +
         " files; it reads " + readable_scene_types() + ", or - for a TOML or .jsurf scene on standard input";
}

}  // namespace algray
