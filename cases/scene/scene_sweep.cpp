// Sweeps of a scene: see scene_sweep.hpp.
#include "cases/scene/scene_sweep.hpp"

#include <atomic>
#include <cctype>
#include <map>
#include <chrono>
#include <cmath>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "cases/scene/reduced_scene.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_run.hpp"
#include "mesh/errors.hpp"
#include "solver/interrupt.hpp"

namespace chainsim {

namespace {

/// `f` -> the dotted key of the scene's only front's dissipation.
std::string front_f_key(const SceneSpec& spec) {
  const auto& fx = spec.effects;
  // The fronts with an f: heaps, a fold, edges and the touchdown fronts of surfaces that declare f (a kink's is 0).
  std::optional<std::size_t> touchdown;
  std::size_t touchdowns = 0;
  for (std::size_t k = 0; k < fx.surfaces.size(); ++k)
    if (fx.surfaces[k].f) touchdown = k, ++touchdowns;
  const std::size_t fronts = fx.heaps.size() + (fx.fold ? 1 : 0) + fx.edges.size() + touchdowns;
  if (fronts != 1)
    throw InputError(fmt::format("{}: the sweep key f names the dissipation of the scene's only front with an f, but "
                                 "the scene has {}: write effects.heap[K].f, effects.fold.f, effects.edge[K].f or "
                                 "effects.surface[K].f",
                                 spec.source, fronts == 0 ? "none" : fmt::format("{}", fronts)));
  if (touchdown) return fmt::format("effects.surface[{}].f", *touchdown);
  return fx.fold ? "effects.fold.f" : !fx.edges.empty() ? "effects.edge[0].f" : "effects.heap[0].f";
}

/// The key of an override "KEY=VALUE".
std::string key_of(const std::string& override_text) { return override_text.substr(0, override_text.find('=')); }

/// A dotted key with every index written without leading zeros ("heap[007]" -> "heap[7]").
std::string normalized_indices(const std::string& key) {
  std::string out;
  for (std::size_t i = 0; i < key.size(); ++i) {
    out += key[i];
    if (key[i] != '[') continue;
    std::size_t j = i + 1;
    while (j + 1 < key.size() && key[j] == '0' && std::isdigit(static_cast<unsigned char>(key[j + 1]))) ++j;
    i = j - 1;
  }
  return out;
}

/// The point's overrides with `f=` replaced by the key it stands for; throws InputError if two of them
/// (or one and the sweep's t_end) set one scene key. `canonical` caches the scene key of each grid key
/// (`f` parses the scene).
std::vector<std::string> resolve_keys(const SweepScene& scene, const std::vector<std::string>& point,
                                      std::map<std::string, std::string>& canonical) {
  std::vector<std::string> out;
  std::map<std::string, std::string> seen;  // scene key -> the grid key that sets it
  if (scene.t_end) seen["stop.t_end"] = scene.t_end_origin;
  for (const std::string& o : point) {
    const std::string key = key_of(o);
    auto it = canonical.find(key);
    if (it == canonical.end()) it = canonical.emplace(key, canonical_sweep_key(scene, key)).first;
    out.push_back(key == "f" ? it->second + o.substr(key.size()) : o);
    const auto [previous, fresh] = seen.emplace(it->second, key);
    if (fresh) continue;
    const bool t_end = scene.t_end && previous->second == scene.t_end_origin;
    throw InputError(fmt::format(
        "the grid key {} and {} {} both set {}: a row would show one value while the other ran; give one of them",
        t_end ? key : previous->second, t_end ? "the sweep's" : "the grid key", t_end ? previous->second : key,
        it->second));
  }
  return out;
}

template <int dim>
nlohmann::json run_string_point(const SceneSpec& spec) {
  SceneRun<dim> run(spec);
  const std::optional<NumericalError> failure = run.run();
  nlohmann::json summary = run.summary();
  if (failure) summary["error"] = failure->what();
  return summary;
}

nlohmann::json run_point(const SceneSpec& spec) {
  if (spec.model == "reduced") {
    ReducedRun run = solve_reduced(match_canonical_problem(spec));
    run.summary["t_end"] = spec.stop.t_end;
    run.summary["status"] = "completed";
    return run.summary;
  }
  return spec.dimension == 3 ? run_string_point<3>(spec) : run_string_point<2>(spec);
}

void flatten_into(nlohmann::json& row, const std::string& prefix, const nlohmann::json& value) {
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) flatten_into(row, prefix.empty() ? key : prefix + "." + key, item);
  } else if (value.is_array()) {
    // Numbers as name[k]; objects (the events, the fronts, the obstacles) as name[k].key, so that a row holds
    // an edge's lift-off time (events[0].t); other lists (of names) are left out.
    bool numbers = true, objects = true;
    for (const auto& item : value) {
      numbers = numbers && item.is_number();
      objects = objects && item.is_object();
    }
    if (!numbers && !objects) return;
    for (std::size_t k = 0; k < value.size(); ++k) flatten_into(row, fmt::format("{}[{}]", prefix, k), value[k]);
  } else if (!value.is_null()) {
    row[prefix] = value;
  }
}

}  // namespace

std::string canonical_sweep_key(const SweepScene& scene, const std::string& key) {
  if (key == "f") return front_f_key(parse_scene_text(scene.text, scene.source, scene.overrides));
  return normalized_indices(key);
}

void check_sweep_points(const SweepScene& scene, const std::vector<std::vector<std::string>>& points) {
  std::map<std::string, std::string> canonical;  // grid key as written -> scene key (f: parsed once)
  for (const auto& point : points) resolve_keys(scene, point, canonical);
}

SweepAxis parse_grid_axis(const std::string& argument) {
  const auto eq = argument.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--grid {}: expected KEY=V1,V2,..., e.g. --grid string.nodes=51,101", argument));
  SweepAxis axis{argument.substr(0, eq), {}};
  std::string value;
  int depth = 0;
  bool quoted = false;
  for (char c : argument.substr(eq + 1) + ",") {
    if (c == '"') quoted = !quoted;
    if (!quoted && (c == '[' || c == '{')) ++depth;
    if (!quoted && (c == ']' || c == '}')) --depth;
    if (c == ',' && depth == 0 && !quoted) {
      if (value.empty())
        throw InputError(fmt::format("--grid {}: an empty value (two commas, or a comma at an end)", argument));
      axis.values.push_back(value);
      value.clear();
    } else {
      value += c;
    }
  }
  return axis;
}

std::vector<std::vector<std::string>> sweep_points(const std::vector<SweepAxis>& grid) {
  if (grid.empty()) throw InputError("a sweep needs at least one grid axis KEY=V1,V2,...");
  std::set<std::string> keys;
  std::vector<std::vector<std::string>> points = {{}};
  for (const SweepAxis& axis : grid) {
    if (axis.values.empty()) throw InputError(fmt::format("the grid axis {} has no values", axis.key));
    if (!keys.insert(axis.key).second) throw InputError(fmt::format("the grid key {} is given twice", axis.key));
    std::vector<std::vector<std::string>> next;
    for (const auto& point : points)
      for (const std::string& value : axis.values) {
        next.push_back(point);
        next.back().push_back(axis.key + "=" + value);
      }
    points = std::move(next);
  }
  return points;
}

nlohmann::json run_sweep_point(const SweepScene& scene, const std::vector<std::string>& point) {
  return run_sweep_point(scene, point, run_point);
}

nlohmann::json run_sweep_point(const SweepScene& scene, const std::vector<std::string>& point, const PointRun& run) {
  const auto start = std::chrono::steady_clock::now();
  nlohmann::json row = nlohmann::json::object();
  nlohmann::json summary;
  std::string status, error;
  try {
    std::map<std::string, std::string> canonical;
    std::vector<std::string> overrides = scene.overrides;
    for (const std::string& o : resolve_keys(scene, point, canonical)) overrides.push_back(o);
    SceneSpec spec = parse_scene_text(scene.text, scene.source, overrides);
    if (scene.t_end) replace_t_end(spec, *scene.t_end, scene.t_end_origin);
    summary = run(spec);
    status = summary.value("status", "completed");
    error = summary.value("error", "");
  } catch (const InputError& e) {
    status = "error";
    error = e.what();
  } catch (const NumericalError& e) {  // the reduced model's failure
    status = "failed";
    error = e.what();
  } catch (const std::exception& e) {
    status = "error";
    error = e.what();
  }
  if (!summary.is_null()) row = flatten_summary(summary);
  row["status"] = status;
  row["error"] = error;
  row["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

std::vector<nlohmann::json> run_sweep(const SweepScene& scene, const std::vector<std::vector<std::string>>& points,
                                      int workers, std::atomic<std::size_t>* done) {
  check_sweep_points(scene, points);
  std::vector<nlohmann::json> rows(points.size());
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < points.size();) {
      rows[k] = interrupt_requested()
                    ? nlohmann::json{{"status", "interrupted"},
                                     {"error", fmt::format("not run: interrupted by {}", interrupt_cause())},
                                     {"wall_time_s", 0.0}}
                    : run_sweep_point(scene, points[k]);
      if (done) ++*done;
    }
  };
  const int n = std::max(1, std::min<int>(workers, static_cast<int>(points.size())));
  std::vector<std::thread> threads;
  for (int w = 1; w < n; ++w) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  return rows;
}

nlohmann::json flatten_summary(const nlohmann::json& summary) {
  nlohmann::json row = nlohmann::json::object();
  flatten_into(row, "", summary);
  return row;
}

}  // namespace chainsim
