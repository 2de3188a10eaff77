#pragma once
/// @file string_solver.hpp
/// Runs a StringModel with the ARKODE Integrator: records frames at the output times, checks the
/// link constraints (and slack, if asked) after every accepted step, keeps the energy ledger, and
/// writes the outputs.
///
/// Outputs (write_outputs, all through AtomicFile; which ones: OutputSelection):
///   nodes.csv    t, node, x, y[, z], vx, vy[, vz]       at every output time
///   tension.csv  t, link, s_mid, T                       s_mid: material coordinate of the link midpoint
///   energy.csv   t, K, V, W_applied, drift               drift = K + V − (K0 + V0) − W_applied
///   frames/frame_XXXX.vtp and string.pvd                 ParaView time series
///   stats.json   ARKODE statistics, tension solves, wall time, ledger, constraint violation, the
///                effects built, root functions and junction unknowns; written last, so its
///                presence means the set of files is complete
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "integrator.hpp"
#include "string_model.hpp"

namespace chainsim {

struct StringSolverOptions {
  IntegratorOptions integrator;
  double t_end = 1.0;            ///< end time (s), > 0 ([stop] t_end)
  double output_interval = 0.1;  ///< time between frames (s); frames at 0, Δ, 2Δ, …, and t_end ([output] interval)
  void validate() const;
  /// Frames are kept in memory until the outputs are written: throws InputError if t_end and
  /// output_interval ask for more than 2·10⁷ node-frames of a string with `nodes` nodes.
  void check_frame_budget(int nodes) const;
};

/// Which outputs write_outputs() produces: fields × formats. A CSV file per field (nodes, tension,
/// energy), the ParaView frames (geometry and velocities, plus the tension as cell data if the
/// tension field is selected; they need the nodes field), and stats.json.
struct OutputSelection {
  bool nodes = true, tension = true, energy = true, stats = true;  ///< fields
  bool csv = true, vtk = true;                                     ///< formats
};

/// One recorded output time.
template <int dim>
struct Frame {
  double t = 0;
  Points<dim> x, v;
  Eigen::VectorXd tension;
  double kinetic = 0, potential = 0, work = 0, drift = 0;
  double max_violation = 0;
};

/// What a run did.
struct RunSummary {
  std::string status = "not run";  ///< "completed" or "failed"
  std::string error;               ///< the failure's message
  double t_end = 0;                ///< time reached (s)
  double wall_s = 0;               ///< wall-clock time of the integration (s)
  double energy_drift = 0;         ///< max over frames of |K + V − (K0 + V0) − W_applied| (J)
  double final_energy_drift = 0;   ///< the signed drift at the last frame (J)
  double energy_scale = 0;         ///< max over frames of K + |V − V0| + |W_applied| (J)
  double max_constraint_violation = 0;  ///< max over accepted steps of | |Δx_j| − h_j | / h_j
  long tension_solves = 0;
  long frames = 0;
  std::string tension_backend;
  std::string stop_reason;         ///< "t_end" when completed
  // What the model holds (observable proof that a scene pays only for what it declares):
  int dimension = 0;               ///< 2 or 3: the instantiation that ran
  int nodes = 0, links = 0;
  std::vector<std::string> effects;     ///< names of the force effects built (Force::name())
  std::vector<std::string> prescribed;  ///< prescribed nodes, e.g. "node 0: fixed"
  int root_functions = 0;          ///< event functions registered with the integrator (OdeSystem::num_events)
  int tension_unknowns = 0;        ///< size of the tension system
  int junction_unknowns = 0;       ///< tension_unknowns − links: unknowns junctions (shocks) add
  double stabilization_time = 0;   ///< Baumgarte time scale used (s)
  IntegratorStats stats;
  /// energy_drift / energy_scale (0 if the scale is 0).
  double relative_energy_drift() const { return energy_scale > 0 ? energy_drift / energy_scale : 0.0; }
};

/// The summary as JSON: t_end, steps, rhs_evals, wall_s, energy_drift, max_constraint_violation, …
nlohmann::json to_json(const RunSummary& summary);

template <int dim>
class StringSolver {
 public:
  StringSolver(StringModel<dim>& model, const StringSolverOptions& options);

  /// Called after every accepted step with (t, y).
  std::function<void(double, const Eigen::VectorXd&)> on_step;

  /// Projects the initial state onto the constraints (StringModel::make_consistent) and integrates
  /// from t = 0 to t_end. Throws NumericalError on failure (slack, singular system, ARKODE failure);
  /// frames() and summary() then hold what was done up to the failure.
  const RunSummary& run();

  const std::vector<Frame<dim>>& frames() const { return frames_; }
  const RunSummary& summary() const { return summary_; }
  /// The integrator's final state.
  const Eigen::VectorXd& final_state() const { return final_state_; }

  /// Writes the selected output files (see the file comment) into `dir` (created if needed). Outputs
  /// of an earlier run in `dir` are removed first, so the directory never mixes two runs; stats.json
  /// is written last.
  void write_outputs(const std::filesystem::path& dir, const OutputSelection& select = {}) const;

 private:
  void record(double t, const Eigen::VectorXd& y);
  void describe_model();

  StringModel<dim>& model_;
  StringSolverOptions options_;
  std::vector<Frame<dim>> frames_;
  RunSummary summary_;
  Eigen::VectorXd final_state_;
  double e0_ = 0, v0_ = 0;
};

}  // namespace chainsim
