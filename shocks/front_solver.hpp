#pragma once
/// @file front_solver.hpp
/// Runs a FrontModel with the ARKODE Integrator: records a sample after every accepted step, moves
/// nodes across fronts at the root events (then resizes the integrator), stops at a stop event or
/// t_end, and closes the energy and momentum ledgers.
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "shocks/front_model.hpp"
#include "solver/integrator.hpp"
#include "solver/output.hpp"

namespace chainsim {

struct FrontRunOptions {
  IntegratorOptions integrator;
  double t_end = 1.0;        ///< s; the run ends here unless a stop event comes first
  bool record_nodes = false;  ///< keep node positions at every `frame_interval`
  double frame_interval = 0;  ///< s (0: no frames)
  void validate() const;
};

/// One recorded instant (after an accepted step, a crossing, or the stop).
struct FrontSample {
  double t = 0;
  std::vector<double> s0, s0_dot;  ///< per front (m, m/s)
  std::vector<double> position;    ///< per front, its point x0 (dim components, m)
  double kinetic = 0, potential = 0, w_applied = 0, w_shocks = 0, w_heaps = 0, w_remesh = 0;
  double energy_residual = 0;      ///< K + V − K0 − V0 − W_applied − W_shocks − W_heaps − W_remesh (J)
  double momentum_residual = 0;    ///< |p − p0 − impulse| (N s)
  std::vector<double> support;     ///< force of the supports on the system (N), dim components
  double moving_mass = 0, heap_mass = 0, max_violation = 0;
  int moving_nodes = 0;
};

struct FrontRun {
  std::string status = "not run";  ///< "stopped" (a stop event), "completed" (t_end) or "failed"
  std::string stop_reason, error;
  double t_stop = 0, wall_s = 0;
  long transfers = 0, tension_solves = 0;
  double max_energy_residual = 0, energy_scale = 0, max_momentum_residual = 0, momentum_scale = 0;
  double max_violation = 0;
  IntegratorStats stats;
  std::vector<FrontSample> samples;
  std::vector<double> frame_times;
  std::vector<Eigen::MatrixXd> frames;  ///< node positions (dim × nodes) at frame_times, moving nodes only valid
  std::vector<std::vector<int>> frame_moving;  ///< which nodes moved at each frame
  double relative_energy_residual() const { return energy_scale > 0 ? max_energy_residual / energy_scale : 0; }
  double relative_momentum_residual() const {
    return momentum_scale > 0 ? max_momentum_residual / momentum_scale : 0;
  }
};

/// Summary keys: status, stop_reason, t_stop, wall_s, steps, rhs_evals, transfers, energy_residual
/// (relative), momentum_residual (relative), max_constraint_violation, …
nlohmann::json to_json(const FrontRun& run);
/// The samples as a table (columns t, s0_k, s0dot_k, front_k_x.., K, V, W_applied, W_shocks, W_heaps, W_remesh,
/// energy_residual, momentum_residual, support_x.., moving_mass, heap_mass, max_violation).
CsvTable samples_table(const FrontRun& run);

/// Integrates from t = 0 (after projecting the initial state onto the constraints). A numerical
/// failure is caught: the run then has status "failed" and the message in `error`, with the samples
/// up to the failure.
template <int dim>
FrontRun run_fronts(FrontModel<dim>& model, const FrontRunOptions& options);

}  // namespace chainsim
