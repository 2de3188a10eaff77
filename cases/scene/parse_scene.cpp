// String scenes, step 1: TOML -> SceneSpec (scene.hpp). The file is read here and each section is
// checked by its own parse function (parse_sections.hpp) through a checked view of its table
// (checked_table.hpp), after the command line's overrides (scene_overrides.hpp); every key read is
// located in the scene text (scene_text.hpp).
// See docs/scenes.md for every key.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include "cases/scene/toml.hpp"

#include "cases/scene/parse_sections.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_overrides.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

using scene_parse::Context;
using scene_parse::Section;
using scene_text::SourceText;

namespace {

/// The largest scene file read (bytes): far above any scene (a 100001-point polyline is 2 MB), far
/// below what would exhaust memory.
constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{64} << 20;

SceneSpec parse_table(const toml::table& root, const SourceText& text) {
  SceneSpec spec;
  spec.source = text.name();
  Context ctx{text, spec};
  // An effect written as a section of its own is pointed to [effects.NAME].
  Section::Moved effects;
  for (const EffectTable& table : effect_tables())
    effects.emplace_back(table.name, fmt::format(table.array ? "[[effects.{}]]" : "[effects.{}]", table.name));
  const Section top(root, "", ctx,
                    {"string", "shape", "velocity", "ends", "effects", "solver", "output", "stop", "model"}, effects,
                    "section");
  scene_parse::parse_model(top, ctx);
  scene_parse::parse_string(top, ctx);
  scene_parse::parse_shape(top, ctx);
  scene_parse::parse_velocity(top, ctx);
  scene_parse::parse_ends(top, ctx);
  scene_parse::parse_effects(top, ctx);
  scene_parse::parse_solver(top, ctx);
  scene_parse::parse_output(top, ctx);
  scene_parse::parse_stop(top, ctx);
  return spec;
}

}  // namespace

const std::vector<EffectTable>& effect_tables() {
  static const std::vector<EffectTable> tables = {
      {"gravity", false}, {"drag", false}, {"heap", true}, {"fold", false}, {"plane", false}, {"edge", true},
      {"surface", true}, {"cylinder", true}, {"kink", true}};
  return tables;
}

std::string SceneSpec::where(const std::string& key) const {
  for (std::string k = key; !k.empty();) {
    if (const auto it = locations.find(k); it != locations.end()) return it->second.where;
    const auto cut = k.find_last_of(".[");
    k = cut == std::string::npos ? "" : k.substr(0, cut);
  }
  return source + ":1:1";
}

bool SceneSpec::located(const std::string& message) const {
  if (message.rfind(source + ":", 0) == 0) return true;
  for (const auto& [key, location] : locations)
    if (!location.where.empty() && message.rfind(location.where + ":", 0) == 0) return true;
  return false;
}

void replace_t_end(SceneSpec& spec, double t_end, const std::string& origin) {
  if (!(t_end > 0 && std::isfinite(t_end)))
    throw InputError(fmt::format("{} = {} is out of range: allowed t_end > 0 (s)", origin, t_end));
  spec.stop.t_end = t_end;
  spec.locations["stop.t_end"] = {origin, fmt::format("{}", t_end)};
}

SceneSpec parse_scene_text(std::string_view text, const std::string& source) { return parse_scene_text(text, source, {}); }

SceneSpec parse_scene_text(std::string_view text, const std::string& source, const std::vector<std::string>& overrides) {
  SourceText src(source, text);
  try {
    toml::table root = toml::parse(text, source);
    scene_parse::apply_overrides(root, overrides, src);
    return parse_table(root, src);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", src.where(e.source()), e.description()));
  }
}

SceneSpec parse_scene(const std::filesystem::path& file) { return parse_scene(file, {}); }

std::string read_scene_file(const std::filesystem::path& file) {
  const std::string name = file.string();
  auto too_large = [&] {
    return InputError(fmt::format("{}:1:1: the scene file is larger than {} MiB ({} bytes), the most a scene may have",
                                  name, kMaxSceneBytes >> 20, kMaxSceneBytes));
  };
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(fmt::format("cannot read the scene file '{}': it is a directory", name));
  // A regular file is measured first; anything else (a FIFO, a device such as /dev/zero) is read up
  // to the limit and no further.
  if (std::filesystem::is_regular_file(file, ec) && std::filesystem::file_size(file, ec) > kMaxSceneBytes && !ec)
    throw too_large();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read the scene file '{}'", name));
  std::string text;
  std::vector<char> chunk(std::size_t{1} << 16);
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount());
    if (text.size() + n > kMaxSceneBytes) throw too_large();
    text.append(chunk.data(), n);
  }
  if (in.bad()) throw InputError(fmt::format("cannot read the scene file '{}'", name));
  return text;
}

SceneSpec parse_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  return parse_scene_text(read_scene_file(file), file.string(), overrides);
}

}  // namespace chainsim
