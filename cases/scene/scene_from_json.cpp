// A scene given as JSON, written as TOML (scene_json.hpp: scene_toml_text).
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include "cases/scene/toml.hpp"

#include "cases/scene/scene_json.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

namespace {

toml::table to_table(const nlohmann::json& object, const std::string& at);

toml::array to_array(const nlohmann::json& array, const std::string& at);

/// Appends or assigns one JSON value converted to TOML through `put`.
template <class Put>
void convert(const nlohmann::json& value, const std::string& at, Put&& put) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: put(to_table(value, at)); break;
    case nlohmann::json::value_t::array: put(to_array(value, at)); break;
    case nlohmann::json::value_t::string: put(value.get<std::string>()); break;
    case nlohmann::json::value_t::boolean: put(value.get<bool>()); break;
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned: put(value.get<std::int64_t>()); break;
    case nlohmann::json::value_t::number_float: put(value.get<double>()); break;
    default:
      throw InputError(fmt::format("{} = {} cannot be written in a scene: allowed a number, a string, true or "
                                   "false, a list or a dict",
                                   at, value.dump()));
  }
}

toml::table to_table(const nlohmann::json& object, const std::string& at) {
  toml::table table;
  for (const auto& item : object.items()) {
    const std::string key = item.key();  // a named copy: a lambda may not capture a structured binding in C++17
    const std::string name = at.empty() ? key : at + "." + key;
    convert(item.value(), name, [&](auto&& v) { table.insert_or_assign(key, std::forward<decltype(v)>(v)); });
  }
  return table;
}

toml::array to_array(const nlohmann::json& array, const std::string& at) {
  toml::array out;
  for (std::size_t k = 0; k < array.size(); ++k)
    convert(array[k], fmt::format("{}[{}]", at, k), [&](auto&& v) { out.push_back(std::forward<decltype(v)>(v)); });
  return out;
}

}  // namespace

std::string scene_toml_text(const nlohmann::json& scene) {
  if (!scene.is_object())
    throw InputError(fmt::format("a scene is a dict of sections (string, shape, stop, ...), not {}", scene.dump()));
  std::ostringstream text;
  text << toml::toml_formatter(to_table(scene, ""));
  return text.str();
}

}  // namespace chainsim
