#pragma once
/// @file string_solver.hpp
/// Runs the one discrete string (StringModel, with or without fronts) with the ARKODE Integrator:
/// records frames at the exact output times, checks the link constraints (and slack, if asked)
/// after every accepted step, acts on the model's root functions (front crossings, stop events),
/// keeps the energy ledger (and, with fronts, the momentum ledger), and writes the outputs.
///
/// Outputs (write_outputs, all through AtomicFile; which ones: OutputSelection):
///   nodes.csv    t, node[, s], x, y[, z], vx, vy[, vz]   the moving nodes at every frame (s: with a module)
///   tension.csv  t, link, s_mid, T                       the links of the arcs; s_mid: material
///                                                        coordinate of the link midpoint
///   energy.csv   t, K, V, W_applied, drift[, the module's energy terms]    at every frame (front
///                tracking's: shocks/front_tracker.hpp, ledger_terms)
///   forces.csv   t and the forces people measure (RunSummary::force_columns) at every frame
///                drift = K + V − (K0 + V0) − W_applied − Σ the module's energy terms
///   series.csv   one row per accepted step (StringSolverOptions::record_steps, on for runs with
///                fronts): samples_table()
///   frames/frame_XXXX.vtp and string.pvd                 ParaView time series: the moving string (part 0)
///   frames/fronts_XXXX.vtp                               and, with a module, its fronts as points (part 1:
///                                                        s0, s0_dot and the module's front_fields())
///   stats.json   the summary (to_json); written last, so its presence means the set is complete
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "integrator.hpp"
#include "output.hpp"
#include "string_model.hpp"

namespace chainsim {

/// Which outputs write_outputs() produces: fields × formats. A CSV file per field (nodes, tension,
/// energy: energy.csv and, when steps are recorded, series.csv; forces: forces.csv when the run has
/// supports, drivers or fronts), the ParaView frames (geometry and
/// velocities, plus the tension as cell data if the tension field is selected; they need the nodes
/// field), and stats.json.
struct OutputSelection {
  bool nodes = true, tension = true, energy = true, forces = true, stats = true;  ///< fields
  bool csv = true, vtk = true;                                     ///< formats
  bool vtk_ascii = false;  ///< ParaView files as text instead of raw binary ([output] vtk_encoding)
  double max_megabytes = 4000;  ///< disk budget of the outputs (MB, [output] max_megabytes)
};

/// What a run's frames cost, estimated before the run from the real sizes: bytes per node and frame
/// held in memory until the outputs are written, and written to disk by the selected outputs
/// (measured, see docs/scenes.md "Output budget").
struct OutputEstimate {
  double frames = 0, node_frames = 0;
  double memory_bytes = 0, disk_bytes = 0;
};


struct StringSolverOptions {
  IntegratorOptions integrator;
  double t_end = 1.0;            ///< end time (s), > 0 ([stop] t_end)
  double output_interval = defaults::kLibraryOutputInterval;  ///< time between frames (s); frames at 0, Δ, 2Δ, …, t_end, and at a stop
  bool record_steps = false;     ///< a StepSample after every accepted step (series.csv)
  void validate() const;
  /// Largest memory the frames may take until the outputs are written (bytes).
  static constexpr double kMaxFrameMemory = 2.0 * (1u << 30);
  /// The frames' memory and the selected outputs' size on disk for a string of `nodes` nodes in `dim`
  /// dimensions (`fronts`: with front tracking, whose nodes.csv has the s column).
  OutputEstimate estimate_outputs(int nodes, int dim, bool fronts, const OutputSelection& select) const;
  /// Throws InputError, before the run, if the frames would take more than kMaxFrameMemory or the
  /// outputs more than select.max_megabytes on disk (the message names both, and what to change).
  void check_output_budget(int nodes, int dim, bool fronts, const OutputSelection& select) const;
};

/// The values of a module's ledger terms at one record (StringModule::ledger_terms: names and kinds,
/// shared by every record of a run); empty for a string without a module.
struct LedgerValues {
  std::shared_ptr<const std::vector<LedgerTerm>> names;
  std::vector<double> values;  ///< in the order of *names
  /// The value of the term `name` (e.g. "W_remesh" of front tracking); throws if the run has none.
  double operator[](const std::string& name) const;
};

/// A front in a record: the module's FrontRecord<dim> held without the dimension (z = 0 in 2D), so
/// that one record type serves runs in 2 and 3 dimensions.
struct FrontValues {
  double s0 = 0;      ///< material coordinate of the front (m)
  double s0_dot = 0;  ///< its speed in the material (m/s)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< x0 (m; dim components)
  Eigen::Vector3d reaction = Eigen::Vector3d::Zero();  ///< the force of its support on the string (N)
  std::vector<double> fields;  ///< the module's front_fields() values (FrontRecord::fields)
};

/// The state of a run at a recorded time, the one record type for frames (Frame, at the output
/// times) and steps (RunSummary::samples: after every accepted step, crossing and the stop, when
/// StringSolverOptions::record_steps). A new ledger quantity is a field here, filled in one place
/// (StringSolver::make_record), and written by the outputs that list it.
struct RunRecord {
  double t = 0;
  double kinetic = 0, potential = 0, work = 0;  ///< K, V, W_applied (J)
  LedgerValues terms;  ///< the module's ledger terms (energy.csv's and series.csv's last columns)
  /// The energy ledger's residual in joules: K + V − K0 − V0 − W_applied − the module's energy terms
  /// (energy.csv's drift and series.csv's energy_residual; the summary's energy_residual is relative,
  /// energy_residual_abs J).
  double drift = 0;
  double momentum_residual = 0;  ///< |p − p0 − impulse| (N s); 0 without a momentum ledger
  Eigen::Vector3d support = Eigen::Vector3d::Zero();  ///< force of all supports on the system (N; dim components)
  double moving_mass = 0;    ///< Σ m_i over the nodes in an arc (kg)
  double max_violation = 0;  ///< max_j | |Δx_j| − h_j | / h_j over the links of the arcs
  int moving_nodes = 0;      ///< nodes in an arc
  std::vector<double> forces;  ///< the forces people measure, in the order of RunSummary::force_columns
  std::vector<FrontValues> fronts;  ///< with a module that has fronts
};

/// One accepted step (or crossing, or the stop) of a run that records its steps.
using StepSample = RunRecord;

/// One recorded output time: the record and the nodes.
template <int dim>
struct Frame : RunRecord {
  Points<dim> x, v;
  Eigen::VectorXd tension;   ///< per link; NaN for a link in no arc
  std::vector<int> moving;   ///< the nodes in an arc (all of them without a module)
};

/// What a run did.
struct RunSummary {
  std::string status = "not run";  ///< "completed" (t_end), "stopped" (a stop event), "interrupted"
                                   ///< (Ctrl-C, interrupt.hpp) or "failed"
  std::string error;               ///< the failure's message
  /// Set when the absolute tolerance is coarser than rtol times the motion's size (the largest
  /// displacement of a node from its initial position over the frames): the run resolves the motion
  /// only to about atol, whatever rtol says ("" otherwise).
  std::string tolerance_warning;
  std::string stop_reason;         ///< "t_end" when completed
  double t_end = 0;                ///< the end time asked for (s)
  double t_stop = 0;               ///< the time reached (s)
  double wall_s = 0;               ///< wall-clock time of the integration (s)
  double energy_drift = 0;         ///< max over frames and samples of |drift| (J), see the file comment
  double final_energy_drift = 0;   ///< the signed drift at the last record (J)
  /// The physical energy scale (J): the max over frames and samples of K + |V − V0| + |W_applied| +
  /// Σ |the module's work terms| (LedgerTerm::Kind::kWork) and of
  /// ℓ (λ |g| ℓ + Σ |loads|) (StringModel::physical_scales), so that a
  /// string at rest is judged against its weight, never against the round-off of its energy.
  double energy_scale = 0;
  double max_momentum_residual = 0, momentum_scale = 0;  ///< with a momentum ledger (fronts)
  double max_constraint_violation = 0;  ///< max over accepted steps of | |Δx_j| − h_j | / h_j
  SlackPolicy slack_policy = SlackPolicy::kIgnore;
  std::optional<SlackReport> slack;  ///< the first slack found at an accepted step (checked unless ignored)
  /// An impulsive start (StringModel::ImpulsiveStart): the initial velocities were not compatible
  /// with the links (e.g. a string at rest whose driven end moves at t = 0) and jumped to the
  /// compatible ones, giving the string `impulsive_energy` (J). The energy ledger books it as work
  /// of the drivers at t = 0: W_applied starts at it, and K0 is the kinetic energy before the jump.
  bool impulsive_start = false;
  double impulsive_energy = 0;        ///< J
  double impulsive_speed_change = 0;  ///< the largest jump of a node's velocity (m/s)
  /// slack = allow: the start is a snap taut (docs/model.md §9, "The start"), and this is what its
  /// impulses dissipated (J, ≥ 0), booked at t = 0 in W_snap; W_applied starts at impulsive_energy
  /// plus it, the supports' work. Zero with slack = stop.
  double impulsive_dissipated = 0;
  long tension_solves = 0;
  long transfers = 0;              ///< the module's transfers (front tracking: nodes moved across fronts)
  long frames = 0;
  std::string tension_backend;
  // What the model holds (observable proof that a scene pays only for what it declares):
  int dimension = 0;               ///< 2 or 3: the instantiation that ran
  int nodes = 0, links = 0;
  std::vector<std::string> effects;     ///< names of the force effects built (Force::name())
  std::vector<std::string> prescribed;  ///< prescribed nodes, e.g. "node 0: fixed"
  int root_functions = 0;          ///< event functions registered with the integrator (OdeSystem::num_events)
  int tension_unknowns = 0;        ///< size of the tension system at the start
  double stabilization_time = 0;   ///< Baumgarte time scale used (s)
  IntegratorStats stats;
  std::vector<StepSample> samples;     ///< after every accepted step (StringSolverOptions::record_steps)
  /// The module's ledger terms (StringModule::ledger_terms), the columns they add to energy.csv and
  /// series.csv; empty without a module.
  std::vector<LedgerTerm> ledger_terms;
  /// Names of the measured forces (forces.csv, the end of series.csv): per prescribed node i,
  /// R_node{i}_x.. (its support's or driver's force on the string, N) and T_node{i} (the tension of the
  /// link at it, N); per front k, R_front{k}_x.. (the force of the front's support on the string at
  /// the front, N; zero for a front without one).
  std::vector<std::string> force_columns;
  /// The physical events the module located (StringModule::run_events), in the summary's `events`:
  /// one JSON object each, {"kind", "t", "front", "position", and the event's values}; empty without.
  std::vector<RunEvent> events;
  /// Per obstacle, its lift-offs (StringModule::lift_off_totals), listed in `events` or not: the summary's
  /// `contact_lift_offs` {obstacle: total} and `events_truncated` (some were not listed); empty (and neither
  /// key written) without obstacles.
  std::vector<LiftOffTotal> lift_off_totals;
  /// energy_drift / energy_scale (0 if the scale is 0).
  double relative_energy_drift() const { return energy_scale > 0 ? energy_drift / energy_scale : 0.0; }
  double relative_energy_residual() const { return relative_energy_drift(); }
  double relative_momentum_residual() const {
    return momentum_scale > 0 ? max_momentum_residual / momentum_scale : 0.0;
  }
};

/// The summary as JSON: status, stop_reason, t_end, t_stop, steps, rhs_evals, wall_s, energy_drift
/// (J) and relative_energy_drift, energy_residual (relative: the same number as relative_energy_drift;
/// energy_residual_abs is it in J, as series.csv's energy_residual column) and momentum_residual
/// (relative), max_constraint_violation, slack ({policy, detected, t, link, s, T, message}),
/// impulsive_start ({detected, kinetic_energy (J), max_speed_change (m/s), message}), transfers, tension_solves, frames, samples, the model's
/// description (dimension, nodes, links, effects, prescribed, root functions, tension unknowns,
/// stabilization time, backend) and ARKODE's statistics.
nlohmann::json to_json(const RunSummary& summary);
/// The model's part of the summary (to_json has it too): dimension, nodes, links, effects, prescribed,
/// root_functions, tension_unknowns, stabilization_time. A scene's description (cases/scene) is it.
nlohmann::json model_json(const RunSummary& summary);
/// Fills the model's fields of `summary` (those of model_json, the tension backend, the slack
/// policy, the force columns, the ledger terms), read back from the model: the one description of
/// a model, used by StringSolver and by the scenes.
template <int dim>
void describe_model(const StringModel<dim>& model, RunSummary& summary);
/// The samples as a table (columns t, s0_k, s0dot_k, front_k_x.., K, V, W_applied, the module's energy
/// terms, energy_residual, momentum_residual, support_x.., moving_mass, the module's other terms,
/// max_violation, moving_nodes; front tracking's terms: shocks/front_tracker.hpp).
CsvTable samples_table(const RunSummary& run);

template <int dim>
class StringSolver {
 public:
  StringSolver(StringModel<dim>& model, const StringSolverOptions& options);
  ~StringSolver();  ///< a streaming writer still at work is stopped; its unfinished files removed

  /// Called after every accepted step with (t, y).
  std::function<void(double, const Eigen::VectorXd&)> on_step;

  /// Projects the initial state onto the constraints (StringModel::make_consistent) and integrates
  /// from t = 0 to t_end or to a stop event. Throws NumericalError on failure (slack, singular
  /// system, ARKODE failure, a front crossing that cannot be completed); frames() and summary() then
  /// hold what was done up to the failure.
  const RunSummary& run();

  const std::vector<Frame<dim>>& frames() const { return frames_; }
  const RunSummary& summary() const { return summary_; }
  /// The integrator's final state.
  const Eigen::VectorXd& final_state() const { return final_state_; }

  /// Writes the selected output files (see the file comment) into `dir` (created if needed). Outputs
  /// of an earlier run in `dir` are removed first, so the directory never mixes two runs; stats.json
  /// (`summary`, or to_json(summary()) when null) is written last.
  void write_outputs(const std::filesystem::path& dir, const OutputSelection& select = {},
                     const nlohmann::json* summary = nullptr) const;
  /// Writes the next run()'s frame files (nodes, tension, energy and forces CSV; the ParaView frames)
  /// into `dir` while it runs: a thread of their own writes each frame as it is recorded, so that
  /// formatting the rows overlaps the integration instead of following it. write_outputs() with the
  /// same `dir` and selection then only finishes them (the frames still queued, the ParaView index,
  /// series.csv, stats.json last); any other call writes everything itself. The files are byte for byte
  /// those of write_outputs() alone. Earlier outputs in `dir` are removed when the run starts.
  void stream_outputs(const std::filesystem::path& dir, const OutputSelection& select = {});

 private:
  void record_frame(double t, const Eigen::VectorXd& y);
  /// Sets summary().tolerance_warning when atol is coarser than rtol times the motion's size.
  void check_tolerance();
  /// With `rates`: also the right-hand side at (t, y) (StringModel::snapshot).
  void record_sample(double t, const Eigen::VectorXd& y, Eigen::VectorXd* rates = nullptr);
  void check_slack(double t, const Eigen::VectorXd& y);
  /// The module's checks (a front's take-off, grazing, …) that are already negative at (t, y), the start or
  /// the state just after an event's handling: ARKODE finds only sign changes, so a check that starts below zero
  /// is never located. Returns the stop the module's handling makes of them, or nothing.
  /// `evaluated`: the model's last evaluation was at (t, y) (a record of it), and is read as it is.
  std::optional<EventAction> failed_checks(double t, const Eigen::VectorXd& y, bool after_event, bool evaluated);
  void book(double t, const typename StringModel<dim>::Snapshot& snap);
  void describe_model();
  std::vector<double> measured_forces(const typename StringModel<dim>::Snapshot& snap) const;
  /// Fills what every record holds (RunRecord) from the snapshot at t, after book().
  void fill_record(double t, const typename StringModel<dim>::Snapshot& snap, RunRecord& record) const;

  /// The files of the frames, written a frame at a time (string_solver.cpp).
  class FrameFiles;
  /// The writer thread of stream_outputs() (string_solver.cpp).
  class Stream;

  StringModel<dim>& model_;
  StringSolverOptions options_;
  std::vector<Frame<dim>> frames_;
  /// stream_outputs()'s request (applied by run()) and the writer of the run in progress or done.
  std::optional<std::pair<std::filesystem::path, OutputSelection>> stream_request_;
  mutable std::unique_ptr<Stream> stream_;
  RunSummary summary_;
  Eigen::VectorXd final_state_;
  Eigen::VectorXd restart_rates_;  // F at an event's new state, from its record (Integrator::provide_start_rhs)
  bool have_start_ = false;
  double e0_ = 0, v0_ = 0;
  Vec<dim> p0_ = Vec<dim>::Zero();
  std::shared_ptr<const std::vector<LedgerTerm>> term_names_;  ///< shared by the records' LedgerValues
};

}  // namespace chainsim
