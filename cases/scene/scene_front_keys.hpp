#pragma once
/// @file scene_front_keys.hpp
/// The scene's keys of the fronts' input (shocks/front_checks.hpp): the fronts' physical checks
/// name "effects.heap[0].s0", print the value as the file wrote it, and refuse it at its
/// file:line:column. Used by the parser (parse_effects.cpp) and the builder (front_scene.cpp).
#include <string>

#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "shocks/front_checks.hpp"

namespace chainsim {

class SceneFrontKeys final : public FrontKeys {
 public:
  explicit SceneFrontKeys(const SceneSpec& spec) : spec_(spec) {}

  std::string heap(std::size_t k, const std::string& field) const override {
    return fmt::format("effects.heap[{}]{}{}", k, field.empty() ? "" : ".", field);
  }
  std::string fold(const std::string& field) const override { return field.empty() ? "effects.fold" : "effects.fold." + field; }
  std::string plane_normal() const override { return "effects.plane.normal"; }
  std::string declared(bool heaps) const override { return heaps ? "[[effects.heap]]" : "[effects.fold]"; }
  std::string end(bool after) const override { return after ? "ends.end" : "ends.start"; }
  std::string side(bool after) const override { return after ? "side = \"end\"" : "side = \"start\""; }
  std::string text(const std::string& key, const std::string& shown) const override {
    const auto it = spec_.locations.find(key);
    return it != spec_.locations.end() && !it->second.text.empty() ? it->second.text : shown;
  }
  bool hints() const override { return true; }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const override {
    throw InputError(fmt::format("{}: {}", spec_.where(key), message));
  }

 private:
  const SceneSpec& spec_;
};

}  // namespace chainsim
