#pragma once
/// @file scene_build.hpp
/// What every model built from a scene shares (internal to cases/scene/: scene_parts.cpp, string_scene.cpp,
/// front_scene.cpp, reduced_scene.cpp): errors located at the key at fault, vectors checked against the dimension,
/// and the string itself — the shape discretized, the initial velocity, the force effects and
/// the held ends, exactly as the scene declares them.
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "solver/forces.hpp"
#include "solver/integrator.hpp"
#include "solver/string_solver.hpp"

namespace chainsim::scene_build {

/// The largest number of nodes a scene may ask for (memory: a few hundred bytes per node).
inline constexpr long long kMaxNodes = 10000000;

/// Throws InputError "<file:line:column of key>: <message>".
[[noreturn]] inline void fail_at(const SceneSpec& spec, const std::string& key, const std::string& message) {
  throw InputError(fmt::format("{}: {}", spec.where(key), message));
}

/// Runs f(); an InputError it throws without a location gets the location of `key` in front.
template <class F>
auto at_key(const SceneSpec& spec, const std::string& key, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (spec.located(message)) throw;
    throw InputError(fmt::format("{}: {}", spec.where(key), message));
  }
}

/// The value of `key` as written in the file ("" if it was not written).
inline std::string text_of(const SceneSpec& spec, const std::string& key) {
  const auto it = spec.locations.find(key);
  return it != spec.locations.end() ? it->second.text : "";
}

/// A vector key as a Vec<dim>; throws (located) if it has another number of components.
template <int dim>
Vec<dim> as_vec(const SceneSpec& spec, const std::vector<double>& v, const std::string& key) {
  if (static_cast<int>(v.size()) != dim)
    fail_at(spec, key, fmt::format("{} = {} has {} components but string.dimension = {}", key, text_of(spec, key),
                                   v.size(), spec.dimension));
  Vec<dim> out;
  for (int d = 0; d < dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

/// A vector key that must be a direction (`what`: "a normal", "an axis"), normalized; throws (located) if it is
/// zero or not finite.
template <int dim>
Vec<dim> as_unit_vec(const SceneSpec& spec, const std::vector<double>& v, const std::string& key,
                     const std::string& what) {
  const Vec<dim> u = as_vec<dim>(spec, v, key);
  // Scaled before the norm (Eigen's stable norm): [0, 1e300] and [0, 1e-300] are directions too, whose plain norm
  // overflows or underflows.
  if (!u.allFinite() || !(u.cwiseAbs().maxCoeff() > 0))
    fail_at(spec, key, fmt::format("{} = {} is not {}: allowed a finite nonzero vector", key, text_of(spec, key), what));
  return Vec<dim>(u.stableNormalized());
}

/// The string of a scene before a model is made of it.
template <int dim>
struct SceneParts {
  std::unique_ptr<Curve<dim>> curve;  ///< the shape, parametrized by arc length = material coordinate
  Chain<dim> chain;                   ///< nodes on the shape, with the initial velocities
  double length = 0;                  ///< ℓ (m)
  Vec<dim> gravity = Vec<dim>::Zero();  ///< g (m/s²); zero without [effects.gravity]
  std::vector<std::unique_ptr<Force<dim>>> forces;  ///< gravity, drag, end loads: those declared
  std::vector<PrescribedNode<dim>> prescribed;      ///< fixed and driven ends
  double characteristic_time = 0;     ///< t_char (s), see build_string_scene
  /// The string's options from [solver]: stabilization_time (or 0.1 t_char), backend, slack policy
  /// and tolerance.
  StringModelOptions model;
  /// The run's options from [solver], [output] and [stop], checked (the frame budget too).
  StringSolverOptions solver;
};

/// Builds the string of a scene (dim must equal spec.dimension) with the effects and ends it
/// declares, checking what does not depend on the model: dimensions, lengths, closed/open, ends,
/// the solver options. Throws InputError located at the key at fault.
template <int dim>
SceneParts<dim> build_scene_parts(const SceneSpec& spec);

/// The fronts of a scene in FrontModel's order (the order of s): "heap_start", "fold", "heap_end",
/// each present only if declared.
std::vector<std::string> front_names(const SceneSpec& spec);

/// The index (in front_names order) of the front each [[stop.front]] names; throws InputError at
/// stop.front[k].front if the scene has no such front.
std::vector<int> front_stop_indices(const SceneSpec& spec);

}  // namespace chainsim::scene_build
