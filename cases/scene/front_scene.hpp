#pragma once
/// @file front_scene.hpp
/// A scene with shocks: a scene that declares a heap ([[effects.heap]]) or a fold ([effects.fold])
/// runs on FrontModel (shocks/front_model.hpp) instead of StringModel; one that declares neither
/// never gets here, so it has no fronts and no root functions (docs/scenes.md).
///
/// The shape lays out the whole string, s = 0 … ℓ; the material held by a heap may lie anywhere on
/// it (a heap is shapeless: only the moving part's nodes are used), but the shape must put the
/// material point s0 of each heap at the heap's point, and fold back on itself at a fold's s0.
/// Before any run the builder refuses, located at the key at fault: a closed string with fronts, a
/// front outside the string, a heap point the shape does not reach at s0, a heap point off its plane
/// or a plane whose normal points away from the string, a fold where the shape does not fold back
/// or outside the heaps, an end held, loaded or driven inside a heap, a stop event on a front the
/// scene lacks, and solver or output keys that apply to scenes without fronts only.
///
/// Outputs (write_front_outputs, every file through AtomicFile, stats.json last), by field:
///   nodes   nodes.csv (t, node, s, x, y[, z]: the moving nodes at each frame) and/or the ParaView
///           frames string.pvd + frames/frame_XXXX.vtp (the moving part, point data s)
///   energy  series.csv: samples_table() — front positions and speeds, K, V, the work ledgers,
///           residuals, the supports' force, moving and heap masses, after every step
///   stats   stats.json: front_summary()
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/scene/scene.hpp"
#include "shocks/front_model.hpp"
#include "shocks/front_solver.hpp"

namespace chainsim {

/// A scene with fronts, ready to run.
template <int dim>
struct FrontScene {
  std::unique_ptr<FrontModel<dim>> model;
  FrontRunOptions run;
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
nlohmann::json front_summary(const FrontScene<dim>& scene, const FrontRun& run);

/// Writes the selected outputs (see the file comment) into `dir`, stats.json (= `summary`) last.
template <int dim>
void write_front_outputs(const std::filesystem::path& dir, const FrontScene<dim>& scene, const FrontRun& run,
                         const nlohmann::json& summary);

}  // namespace chainsim
