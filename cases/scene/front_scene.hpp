#pragma once
/// @file front_scene.hpp
/// A scene with shocks: a scene that declares a heap ([[effects.heap]]) or a fold ([effects.fold])
/// runs on the string with front tracking (StringModel with a FrontTracker, shocks/front_tracker.hpp);
/// one that declares neither never gets here, so it has no fronts and no root functions
/// (docs/scenes.md).
///
/// The shape lays out the whole string, s = 0 … ℓ; the material held by a heap may lie anywhere on
/// it (a heap is shapeless: only the moving part's nodes are used), but the shape must put the
/// material point s0 of each heap at the heap's point, and fold back on itself at a fold's s0.
/// Before any run the builder refuses, located at the key at fault: a closed string with fronts, a
/// front outside the string, a heap point the shape does not reach at s0, a heap point off its plane
/// or a plane whose normal points away from the string, a fold where the shape does not fold back
/// or outside the heaps, an end held, loaded or driven inside a heap, and a stop event on a front the
/// scene lacks. Every solver and output key works as for a string without fronts.
///
/// Outputs: those of every string run (StringSolver::write_outputs), with series.csv (a row per
/// step: front positions and speeds, the ledgers, the supports' force) and stats.json =
/// front_summary().
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/scene/scene.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

/// A scene with fronts, ready to run.
template <int dim>
struct FrontScene {
  std::unique_ptr<StringModel<dim>> model;
  StringSolverOptions solver;  ///< record_steps on: series.csv
  OutputSelection output;
  std::vector<std::string> front_names;  ///< "heap_start", "fold", "heap_end": those built, in order of s
  /// What was built, read back from the model: dimension, nodes, links, effects, prescribed, fronts
  /// (name, kind, side, f, s0, point, on_plane, plane_normal), num_fronts, root_functions (2 per
  /// front + stop events), stop_events, stabilization_time.
  nlohmann::json description;
  double characteristic_time = 0;  ///< t_char (s), as for a string scene
};

/// Builds the model of a scene with fronts (spec.has_fronts(), dim = spec.dimension) with exactly
/// the effects it declares. Throws InputError naming the file:line:column of the key at fault.
template <int dim>
FrontScene<dim> build_front_scene(const SceneSpec& spec);

/// The run's summary: to_json(run), the scene's description, "model": "string", "t_end" (the
/// scene's end time), "fronts_final" (each front's s0 at the stop, m) and a stop_reason that names
/// the fronts ("the heap_end front reached s0 = 0.01 m", "the heap has run empty", "t_end reached").
template <int dim>
nlohmann::json front_summary(const FrontScene<dim>& scene, const RunSummary& run);

/// Builds the scene and runs it; a numerical failure ends the run with status "failed" (no throw).
template <int dim>
RunSummary run_front_scene(const SceneSpec& spec);

}  // namespace chainsim
