#pragma once
/// @file scene_sweep.hpp
/// Sweeps: many short runs of one scene, each with some of its keys set (`chainsim sweep`, and
/// chainsim.sweep in Python, which sends the same points to a Dask cluster).
///
/// A grid is a list of axes KEY = [values]; its points are the Cartesian product (the last axis
/// varies fastest). A point is a list of "KEY=VALUE" overrides applied to the scene exactly as
/// `chainsim run --set KEY=VALUE` applies them (cases/scene/scene_overrides.hpp): the same keys,
/// the same checks, the same located messages. One key more: `f`, the dissipation of the scene's
/// only front (effects.heap[0].f, or effects.fold.f).
///
/// Each point is one SceneRun (or, for model = "reduced", one reduced run): it never throws; it
/// gives a row (JSON object) with
///   status        "completed" | "stopped" | "interrupted" (Ctrl-C) | "failed" (numerical failure)
///                 | "error" (the point's scene was refused: bad key or value, inconsistent scene)
///   error         the message ("" when none)
///   wall_time_s   wall-clock time of the whole point: parsing, building, running (s)
///   and the run's summary (stats.json) flattened: top-level numbers, strings and booleans as they
///   are, nested objects as "parent.child", arrays of numbers as "name[k]" (other arrays left out).
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace chainsim {

struct SceneSpec;

/// The scene a sweep varies: its TOML text (a file's content, with `source` naming the file in
/// messages), overrides applied to every point first, and an optional end time for every run.
struct SweepScene {
  std::string text;
  std::string source;
  std::vector<std::string> overrides;  ///< "KEY=VALUE", before each point's own
  std::optional<double> t_end;         ///< replaces [stop] t_end (s), > 0
  std::string t_end_origin = "--t-end";  ///< how the user gave t_end, for messages
};

/// One axis of a grid: a key (dotted, as for --set, or `f`) and its values as TOML values ("0.5", "101").
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

/// Parses "KEY=V1,V2,..." (`chainsim sweep --grid`); a value may be a TOML array or inline table
/// ("shape.end=[1,0],[0,1]": commas inside brackets and braces do not split). Throws InputError.
SweepAxis parse_grid_axis(const std::string& argument);

/// The grid's points, each a list of "KEY=VALUE" (KEY as written in the grid). Throws InputError for
/// an empty grid, an axis without values, or a key given twice.
std::vector<std::vector<std::string>> sweep_points(const std::vector<SweepAxis>& grid);

/// The scene key a grid key sets: `f` is the key of the scene's only front's dissipation, an index
/// is read as a number (effects.heap[00].f is effects.heap[0].f). Throws InputError for `f` in a
/// scene without exactly one front.
std::string canonical_sweep_key(const SweepScene& scene, const std::string& key);

/// Refuses, before anything runs, points whose keys set one scene key twice: two grid keys that name
/// the same key (an alias and its full key: f and effects.heap[0].f), or a grid key stop.t_end with
/// the sweep's own t_end. Each row is labelled with the values of its grid keys, so a key set twice
/// would label it with a value that did not run. Throws InputError naming both spellings.
void check_sweep_points(const SweepScene& scene, const std::vector<std::vector<std::string>>& points);

/// Runs one point (see the file comment for the row). Never throws for a bad point (a point that
/// sets a key twice is an "error" row: check_sweep_points).
nlohmann::json run_sweep_point(const SweepScene& scene, const std::vector<std::string>& point);

/// What runs a point's scene: its summary (stats.json, with "error" for a numerical failure); it may throw
/// InputError or NumericalError. The Python module passes one that keeps the run (chainsim.sweep(results=True)).
using PointRun = std::function<nlohmann::json(const SceneSpec&)>;
/// run_sweep_point with the scene of the point run by `run` (the row is made as above).
nlohmann::json run_sweep_point(const SweepScene& scene, const std::vector<std::string>& point, const PointRun& run);

/// Checks the points (check_sweep_points: throws InputError), then runs every point on `workers` threads
/// (the runs share nothing but the interrupt flag); the rows are in the order of the points. After Ctrl-C (solver/interrupt.hpp) the running points end
/// "interrupted" and the points not started yet are rows with status "interrupted".
/// `done`, if given, counts the points ended (a progress bar reads it from another thread).
std::vector<nlohmann::json> run_sweep(const SweepScene& scene, const std::vector<std::vector<std::string>>& points,
                                      int workers, std::atomic<std::size_t>* done = nullptr);

/// The summary flattened into a row's columns (see the file comment).
nlohmann::json flatten_summary(const nlohmann::json& summary);

}  // namespace chainsim
