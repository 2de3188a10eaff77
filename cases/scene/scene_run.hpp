#pragma once
/// @file scene_run.hpp
/// One run of a string scene (with or without fronts), exactly as `chainsim run` does it: the model
/// built and checked (build_string_scene, with the fronts when the scene has a heap or a fold),
/// the one runner (StringSolver), the summary that becomes stats.json, and the run directory
/// (StringSolver::write_outputs). `chainsim run`, `chainsim sweep` and the Python module
/// (python/chainsim) all run scenes through this class, so they give the same numbers.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

template <int dim>
class SceneRun {
 public:
  /// Builds the model of `spec` (spec.model = "string", dim = spec.dimension) and checks it.
  /// Throws InputError located at the key at fault.
  explicit SceneRun(const SceneSpec& spec);
  ~SceneRun();
  SceneRun(SceneRun&&) noexcept;
  SceneRun& operator=(SceneRun&&) noexcept;

  /// Integrates from t = 0 (StringSolver::run), calling `on_step(t)` after every accepted step.
  /// A numerical failure does not throw: it is returned, and the solver keeps the frames, samples
  /// and summary up to it (status "failed"); Ctrl-C (solver/interrupt.hpp) ends with "interrupted".
  std::optional<NumericalError> run(const std::function<void(double)>& on_step = {});

  const StringSolver<dim>& solver() const { return *solver_; }
  const StringModel<dim>& model() const { return *scene_.model; }
  const StringSolverOptions& solver_options() const { return scene_.solver; }
  const OutputSelection& output() const { return scene_.output; }
  bool has_fronts() const { return scene_.has_fronts(); }
  /// With fronts: what was built (front_scene.hpp's description: fronts, stop events); else null.
  nlohmann::json description() const;

  /// The run's summary as stats.json holds it: front_summary() (to_json(summary) and the scene's
  /// description; "model": "string", and "fronts": [] without fronts).
  nlohmann::json summary() const;
  /// Writes the run directory (the scene's [output] selection; stats.json = `summary`, last), after
  /// removing what any chainsim command wrote there before, holding its lock meanwhile (RunDirectory:
  /// InputError if another run holds it).
  void write(const std::filesystem::path& dir, const nlohmann::json& summary) const;
  /// The same into a directory this process already holds (`chainsim run` locks it for the whole run).
  void write(const RunDirectory& dir, const nlohmann::json& summary) const;
  /// Writes the frames' files into `dir` (held by this process) while the next run() runs
  /// (StringSolver::stream_outputs); write(dir, summary) then finishes them. Same files as write() alone.
  void stream(const RunDirectory& dir);

 private:
  StringScene<dim> scene_;  ///< the model, its options and description (build_string_scene)
  std::unique_ptr<StringSolver<dim>> solver_;
};

}  // namespace chainsim
