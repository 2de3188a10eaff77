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
#include "shocks/edge_front.hpp"
#include "shocks/kink_front.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/contact_module.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

/// A scene with fronts, ready to run: the one scene type (scene.hpp), its fronts described.
template <int dim>
using FrontScene = StringScene<dim>;

namespace scene_build {
template <int dim>
struct SceneParts;
}

/// The fronts' part of build_string_scene (scene.hpp), for a scene with fronts: checks the fronts
/// against the string, builds the model with front tracking from `parts` (moved from), sets
/// scene.front_names, the fronts' description (fronts, num_fronts, stop_events) and record_steps.
template <int dim>
std::unique_ptr<StringModel<dim>> build_front_model(const SceneSpec& spec, scene_build::SceneParts<dim>& parts,
                                                    StringScene<dim>& scene);

/// The scene's obstacles ([[effects.surface]], [[effects.cylinder]], [effects.plane] with surface =
/// true; solver/contact_module.hpp), each checked at its key, in that order; and what they do not meet
/// (quadratic elements, implicit methods) refused at the key at fault. A surface's `edge` is left to
/// build_front_model, which bounds it at its edge front.
template <int dim>
std::vector<Obstacle<dim>> contact_obstacles(const SceneSpec& spec);

/// Builds the model of a scene with fronts (spec.has_fronts(), dim = spec.dimension): build_string_scene.
template <int dim>
FrontScene<dim> build_front_scene(const SceneSpec& spec);

/// The run's summary (any scene, with or without fronts): to_json(run) and the scene's description;
/// with fronts also "t_end" (the scene's end time), "fronts_final_s0" (each front's s0 at the stop, m)
/// and a stop_reason that names the fronts ("the heap_end front reached s0 = 0.01 m", "the heap has
/// run empty", "t_end reached").
template <int dim>
nlohmann::json front_summary(const FrontScene<dim>& scene, const RunSummary& run);

/// Builds the scene and runs it; a numerical failure ends the run with status "failed" (no throw).
template <int dim>
RunSummary run_front_scene(const SceneSpec& spec);

}  // namespace chainsim
