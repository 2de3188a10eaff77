#pragma once
/// @file string_solver.hpp
/// Runs a StringModel with the ARKODE Integrator: records frames at the output times, checks the
/// link constraints (and slack, if asked) after every accepted step, keeps the energy ledger, and
/// writes the outputs.
///
/// Outputs (write_outputs, all through AtomicFile):
///   nodes.csv    t, node, x, y[, z], vx, vy[, vz]       at every output time
///   tension.csv  t, link, s_mid, T                       s_mid: material coordinate of the link midpoint
///   energy.csv   t, K, V, W_applied, drift               drift = K + V − (K0 + V0) − W_applied
///   stats.json   ARKODE statistics, tension solves, wall time, ledger, constraint violation
///   frames/frame_XXXX.vtp and string.pvd                 ParaView time series
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
  double t_end = 1.0;            ///< end time (s), > 0
  double output_interval = 0.1;  ///< time between frames (s); frames at 0, Δ, 2Δ, …, and t_end
  void validate() const;
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

  /// Writes the output files (see the file comment) into `dir` (created if needed).
  void write_outputs(const std::filesystem::path& dir, bool vtk = true) const;

 private:
  void record(double t, const Eigen::VectorXd& y);

  StringModel<dim>& model_;
  StringSolverOptions options_;
  std::vector<Frame<dim>> frames_;
  RunSummary summary_;
  Eigen::VectorXd final_state_;
  double e0_ = 0, v0_ = 0;
};

}  // namespace chainsim
