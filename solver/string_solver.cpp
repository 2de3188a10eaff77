// Drives the one discrete string with the Integrator and writes its outputs: see string_solver.hpp.
#include "string_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <future>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"
#include "interrupt.hpp"
#include "vtk_output.hpp"

namespace chainsim {

namespace {
/// Frames are interpolated for methods up to this order (docs/string_solver.md, "The implicit path").
constexpr int kMaxDenseOrder = Integrator::kMaxDenseOrder;
/// A step of this fraction of the output interval or longer counts as longer than the frames: a step
/// that ARKODE shortened to end at a frame, one interval after the previous one, ends a few rounding
/// units short of the interval.
constexpr double kStepOfFrames = 1 - 1e-9;
/// A node that moves by less than this many units of round-off of the coordinates has not moved
/// (check_tolerance: a string at rest moves by about one, 1e-16 m on a 1 m chain).
constexpr double kRestMotion = 1e3;
/// An atol below this many units of round-off of the coordinates cannot be honoured (check_tolerance).
constexpr double kRoundoffUnits = 4;
/// A taut link whose length is off by more than this share of it (or kMaxViolationPerRtol × rtol, if larger)
/// at an accepted step stops the run (exit 3). Measured: 5.5e-3 on the driven catenary of the slack tests
/// (321 nodes, rtol 1e-8, the drift control's overshoot after releases), 0.025 and 0.14 on the swinging U at
/// rtol = atol = 1e-3 and 1e-2; a release taken back within a step had reached 0.155 (docs/model.md §9).
constexpr double kMaxViolation = 0.05, kMaxViolationPerRtol = 100;
}  // namespace

void StringSolverOptions::validate() const {
  integrator.validate_numbers();  // the method is checked by the Integrator that loads it
  require_positive("stop.t_end", t_end);
  require_in_range("output.interval", output_interval, 0.0, INFINITY, Bound::kOpen);
}

namespace {
// Bytes per node-frame of each output, measured on `chainsim run cases/scenes/hanging_chain.toml
// --set string.nodes=1001 --set output.interval=0.01 --set stop.t_end=1` (docs/scenes.md):
// nodes.csv 95 B for 6 values, tension.csv 49 B for 4, frames/ 85 B binary and 203 B ascii. A value
// of a moving string prints longer than one at rest (up to 17 digits, sign, exponent, comma): the
// estimate takes 20 B a value, so it bounds the CSV from above.
constexpr double kCsvBytesPerValue = 20;
// ParaView, per node: coordinates and velocity (3 doubles each), mass, s and the link's tension
// (1 double each), the link's two point indices (int32): 84 B raw; as text, the measured 203 B.
constexpr double kVtkBinaryBytes = 84, kVtkAsciiBytes = 210;
// Per frame: in memory, the Frame's own fields and vectors' bookkeeping; on disk, the ParaView files'
// headers, the .pvd entry, the energy and forces rows.
constexpr double kMemoryPerFrame = 512, kDiskPerFrame = 4096;

/// A module's obstacles as VTK polydata (frames/obstacles.vtp): the vertex cells and the segments, each
/// cell with its obstacle's index and its part (cell data "obstacle", "part": ObstacleDrawing::Part).
VtkPolyline obstacle_polydata(const ObstacleDrawing& d) {
  VtkPolyline out;
  const auto nv = static_cast<Eigen::Index>(d.points.size()), ns = static_cast<Eigen::Index>(d.segments.size());
  out.points.resize(3, nv + 2 * ns);
  Eigen::MatrixXd obstacle(1, nv + ns), part(1, nv + ns);
  for (Eigen::Index q = 0; q < nv; ++q) {
    out.points.col(q) = d.points[static_cast<std::size_t>(q)];
    out.vertex_cells.push_back(static_cast<int>(q));
    obstacle(0, q) = d.point_obstacle[static_cast<std::size_t>(q)];
    part(0, q) = d.point_part[static_cast<std::size_t>(q)];
  }
  for (Eigen::Index q = 0; q < ns; ++q) {
    const auto k = static_cast<std::size_t>(q);
    const auto a = static_cast<int>(nv + 2 * q);
    out.points.col(a) = d.segments[k].first;
    out.points.col(a + 1) = d.segments[k].second;
    out.segments.emplace_back(a, a + 1);
    obstacle(0, nv + q) = d.segment_obstacle[k];
    part(0, nv + q) = d.segment_part[k];
  }
  out.cell_data = {{"obstacle", obstacle}, {"part", part}};
  return out;
}
}  // namespace

OutputEstimate StringSolverOptions::estimate_outputs(int nodes, int dim, bool fronts,
                                                     const OutputSelection& select) const {
  OutputEstimate e;
  e.frames = std::floor(t_end / output_interval) + 2;
  e.node_frames = e.frames * nodes;
  // A Frame holds every node's position and velocity, a tension per link and the index of each
  // moving node.
  e.memory_bytes = e.node_frames * ((2.0 * dim + 1) * sizeof(double) + sizeof(int)) + e.frames * kMemoryPerFrame;
  double per_node_frame = 0;
  if (select.csv && select.nodes) per_node_frame += (2.0 + (fronts ? 1 : 0) + 2 * dim) * kCsvBytesPerValue;
  if (select.csv && select.tension) per_node_frame += 4 * kCsvBytesPerValue;
  if (select.vtk && select.nodes) per_node_frame += select.vtk_ascii ? kVtkAsciiBytes : kVtkBinaryBytes;
  e.disk_bytes = e.node_frames * per_node_frame + e.frames * kDiskPerFrame;
  return e;
}

void StringSolverOptions::check_output_budget(int nodes, int dim, bool fronts, const OutputSelection& select) const {
  const OutputEstimate e = estimate_outputs(nodes, dim, fronts, select);
  const std::string asks = fmt::format("output.interval = {:g} s with stop.t_end = {:g} s asks for {:.3g} frames of {} "
                                       "nodes ({:.3g} node-frames)",
                                       output_interval, t_end, e.frames, nodes, e.node_frames);
  if (e.memory_bytes > kMaxFrameMemory)
    throw InputError(fmt::format("{}: they would take {:.3g} GB of memory until written, allowed at most {:.3g} GB; "
                                 "raise output.interval",
                                 asks, e.memory_bytes / 1e9, kMaxFrameMemory / 1e9));
  if (e.disk_bytes > select.max_megabytes * 1e6)
    throw InputError(fmt::format("{}: the selected outputs would take about {:.3g} MB on disk, more than "
                                 "output.max_megabytes = {:g}; raise output.interval, select fewer fields or formats, "
                                 "or raise output.max_megabytes",
                                 asks, e.disk_bytes / 1e6, select.max_megabytes));
}

nlohmann::json model_json(const RunSummary& s) {
  nlohmann::json j = {{"dimension", s.dimension}, {"nodes", s.nodes}, {"links", s.links}};
  j["effects"] = s.effects;
  j["prescribed"] = s.prescribed;
  j["root_functions"] = s.root_functions;
  j["tension_unknowns"] = s.tension_unknowns;
  j["stabilization_time"] = s.stabilization_time;
  return j;
}

nlohmann::json to_json(const RunSummary& s) {
  nlohmann::json j = {{"status", s.status},
                      {"stop_reason", s.stop_reason},
                      {"t_end", s.t_end},
                      {"t_stop", s.t_stop},
                      {"steps", s.stats.steps},
                      {"rhs_evals", s.stats.rhs_evals},
                      {"wall_s", s.wall_s},
                      {"energy_drift", s.energy_drift},
                      {"final_energy_drift", s.final_energy_drift},
                      {"energy_scale", s.energy_scale},
                      {"relative_energy_drift", s.relative_energy_drift()},
                      {"energy_residual", s.relative_energy_residual()},
                      {"energy_residual_abs", s.energy_drift},
                      {"momentum_residual", s.relative_momentum_residual()},
                      {"max_constraint_violation", s.max_constraint_violation},
                      {"transfers", s.transfers},
                      {"tension_solves", s.tension_solves},
                      {"tension_backend", s.tension_backend},
                      {"frames", s.frames},
                      {"samples", s.samples.size()},
                      {"stats", to_json(s.stats)}};
  j["events"] = nlohmann::json::array();
  for (const RunEvent& e : s.events) {
    nlohmann::json event = {{"kind", e.kind}, {"t", e.t}, {"front", e.front}, {"position", e.position}};
    if (!e.obstacle.empty()) {  // an obstacle's event: no front
      event["front"] = nullptr;
      event["obstacle"] = e.obstacle;
    }
    for (const auto& [name, value] : e.values) event[name] = value;
    for (const auto& [name, index] : e.indices) event[name] = index;
    j["events"].push_back(std::move(event));
  }
  if (!s.lift_off_totals.empty()) {
    nlohmann::json totals = nlohmann::json::object();
    bool truncated = false;
    for (const LiftOffTotal& total : s.lift_off_totals) {
      totals[total.obstacle] = total.total;
      const auto listed = std::count_if(s.events.begin(), s.events.end(), [&](const RunEvent& e) {
        return e.kind == "lift_off" && e.obstacle == total.obstacle;
      });
      truncated = truncated || listed < total.total;
    }
    j["contact_lift_offs"] = totals;
    j["events_truncated"] = truncated;
  }
  j.update(model_json(s));
  nlohmann::json slack = {{"policy", to_string(s.slack_policy)}, {"detected", s.slack.has_value()}};
  if (s.slack)
    slack.update({{"t", s.slack->t},
                  {"link", s.slack->link},
                  {"s", s.slack->s_mid},
                  {"T", s.slack->tension},
                  {"message", s.slack->message()}});
  j["slack"] = slack;
  nlohmann::json impulsive = {{"detected", s.impulsive_start},
                              {"kinetic_energy", s.impulsive_energy},
                              {"max_speed_change", s.impulsive_speed_change}};
  if (s.impulsive_start && s.slack_policy == SlackPolicy::kAllow) {
    impulsive["dissipated"] = s.impulsive_dissipated;
    impulsive["message"] = fmt::format(
        "the initial velocities lengthen taut links (slack = \"allow\"): the string snapped taut at t = 0 by the "
        "snap's law (links that shorten went slack); the velocities jumped by up to {:.6g} m/s, the kinetic energy "
        "changed by {:.6g} J: {:.6g} J dissipated (W_snap at t = 0) and {:.6g} J the rest of the jump, the supports' "
        "work and the normal velocities the obstacles took (W_applied at t = 0)",
        s.impulsive_speed_change, s.impulsive_energy, s.impulsive_dissipated, s.impulsive_energy + s.impulsive_dissipated);
  } else if (s.impulsive_start) {
    impulsive["message"] = fmt::format(
        "the initial velocities are not compatible with the inextensible string (a driven end moving at t = 0 "
        "while the string is at rest, or [velocity] values that would stretch or shorten links, e.g. a tangential "
        "speed through a corner of the shape): they jumped at t = 0 by up to {:.6g} m/s, giving the string {:.6g} J "
        "of kinetic energy, booked at t = 0 in W_applied",
        s.impulsive_speed_change, s.impulsive_energy);
  }
  j["impulsive_start"] = impulsive;
  if (!s.error.empty()) j["error"] = s.error;
  if (!s.tolerance_warning.empty()) j["tolerance_warning"] = s.tolerance_warning;
  return j;
}

double LedgerValues::operator[](const std::string& name) const {
  if (names)
    for (std::size_t k = 0; k < names->size(); ++k)
      if ((*names)[k].name == name) return values[k];
  throw Error(fmt::format("the run has no ledger term '{}'", name));
}

CsvTable samples_table(const RunSummary& run) {
  std::vector<std::string> cols = {"t"};
  const std::size_t nf = run.samples.empty() ? 0 : run.samples.front().fronts.size();
  const auto dim = static_cast<Eigen::Index>(run.samples.empty() ? 0 : run.dimension);
  const char* axes[] = {"x", "y", "z"};
  const std::vector<LedgerTerm>& terms = run.ledger_terms;
  for (std::size_t k = 0; k < nf; ++k) {
    cols.push_back("s0_" + std::to_string(k));
    cols.push_back("s0dot_" + std::to_string(k));
    for (Eigen::Index d = 0; d < dim; ++d) cols.push_back("front_" + std::to_string(k) + "_" + axes[d]);
  }
  for (const char* c : {"K", "V", "W_applied"}) cols.emplace_back(c);
  for (const LedgerTerm& term : terms)
    if (term.energy()) cols.push_back(term.name);
  for (const char* c : {"energy_residual", "momentum_residual"}) cols.emplace_back(c);
  for (Eigen::Index d = 0; d < dim; ++d) cols.push_back(std::string("support_") + axes[d]);
  cols.emplace_back("moving_mass");
  for (const LedgerTerm& term : terms)
    if (!term.energy()) cols.push_back(term.name);
  for (const char* c : {"max_violation", "moving_nodes"}) cols.emplace_back(c);
  cols.insert(cols.end(), run.force_columns.begin(), run.force_columns.end());
  CsvTable table(cols);
  for (const StepSample& s : run.samples) {
    std::vector<double> row = {s.t};
    for (const FrontValues& front : s.fronts) {
      row.push_back(front.s0);
      row.push_back(front.s0_dot);
      for (Eigen::Index d = 0; d < dim; ++d) row.push_back(front.position[d]);
    }
    for (double v : {s.kinetic, s.potential, s.work}) row.push_back(v);
    for (std::size_t k = 0; k < terms.size(); ++k)
      if (terms[k].energy()) row.push_back(s.terms.values[k]);
    for (double v : {s.drift, s.momentum_residual}) row.push_back(v);
    for (Eigen::Index d = 0; d < dim; ++d) row.push_back(s.support[d]);
    row.push_back(s.moving_mass);
    for (std::size_t k = 0; k < terms.size(); ++k)
      if (!terms[k].energy()) row.push_back(s.terms.values[k]);
    for (double v : {s.max_violation, static_cast<double>(s.moving_nodes)}) row.push_back(v);
    row.insert(row.end(), s.forces.begin(), s.forces.end());
    table.add_row(row);
  }
  return table;
}

template <int dim>
StringSolver<dim>::StringSolver(StringModel<dim>& model, const StringSolverOptions& options)
    : model_(model), options_(options) {
  options_.validate();
  // The frames' memory (the scene checks its outputs' disk budget with its own selection).
  OutputSelection memory_only;
  memory_only.csv = memory_only.vtk = false;
  options_.check_output_budget(model_.chain().num_nodes(), dim, model_.module() != nullptr, memory_only);
  describe_model();
}

template <int dim>
void describe_model(const StringModel<dim>& model, RunSummary& summary) {
  // What the model holds, read back from it (not from the scene that asked for it).
  const auto& chain = model.chain();
  summary.dimension = dim;
  summary.nodes = chain.num_nodes();
  summary.links = chain.num_links();
  summary.effects.clear();
  for (const auto& force : model.forces()) summary.effects.push_back(force->name());
  summary.prescribed.clear();
  for (const auto& p : model.prescribed())
    summary.prescribed.push_back(fmt::format("node {}: {}", p.node, p.path->description()));
  summary.root_functions = model.num_events();
  summary.tension_unknowns = model.has_tension_system() ? model.tension_system().size() : 0;
  summary.stabilization_time = model.options().stabilization_time;
  summary.tension_backend = model.quadratic()             ? "quadratic elements (block tridiagonal)"
                            : model.has_tension_system() ? model.tension_system().backend_name()
                                                         : "none";
  summary.slack_policy = model.options().slack;
  const char* axes[] = {"x", "y", "z"};
  summary.force_columns.clear();
  for (const auto& p : model.prescribed()) {
    for (int d = 0; d < dim; ++d) summary.force_columns.push_back(fmt::format("R_node{}_{}", p.node, axes[d]));
    summary.force_columns.push_back(fmt::format("T_node{}", p.node));
  }
  const int fronts = model.module() ? model.module()->num_fronts() : 0;
  summary.ledger_terms = model.module() ? model.module()->ledger_terms() : std::vector<LedgerTerm>{};
  for (int k = 0; k < fronts; ++k)
    for (int d = 0; d < dim; ++d) summary.force_columns.push_back(fmt::format("R_front{}_{}", k, axes[d]));
}

template <int dim>
void StringSolver<dim>::describe_model() {
  chainsim::describe_model(model_, summary_);
  summary_.t_end = options_.t_end;
  term_names_ = std::make_shared<const std::vector<LedgerTerm>>(summary_.ledger_terms);
}

template <int dim>
std::vector<double> StringSolver<dim>::measured_forces(const typename StringModel<dim>::Snapshot& snap) const {
  std::vector<double> out;
  for (std::size_t k = 0; k < snap.end_reactions.size(); ++k) {
    for (int d = 0; d < dim; ++d) out.push_back(snap.end_reactions[k][d]);
    out.push_back(snap.end_tensions[k]);
  }
  for (const auto& front : snap.fronts)
    for (int d = 0; d < dim; ++d) out.push_back(front.reaction[d]);
  return out;
}

template <int dim>
void StringSolver<dim>::book(double t, const typename StringModel<dim>::Snapshot& snap) {
  if (!have_start_) {
    // K0 + V0 before an impulsive start, whose energy W_applied holds at t = 0 (zero otherwise).
    e0_ = snap.kinetic + snap.potential - snap.work;
    // and before what a start by the snap's law dissipated (slack = allow), which W_snap holds at t = 0
    for (std::size_t k = 0; k < summary_.ledger_terms.size(); ++k)
      if (summary_.ledger_terms[k].energy() && snap.terms[k] != 0) e0_ -= snap.terms[k];
    v0_ = snap.potential;
    p0_ = snap.momentum - snap.impulse;  // before the impulses a module booked at t0 (its impacts at the start)
    have_start_ = true;
  }
  // The ledger K + V − (K0 + V0) − W_applied − the module's energy terms, and its physical scale.
  double drift = snap.kinetic + snap.potential - e0_ - snap.work;
  double moved = snap.kinetic + std::abs(snap.potential - v0_) + std::abs(snap.work);
  for (std::size_t k = 0; k < summary_.ledger_terms.size(); ++k) {
    const LedgerTerm& term = summary_.ledger_terms[k];
    if (term.energy()) drift -= snap.terms[k];
    if (term.kind == LedgerTerm::Kind::kWork) moved += std::abs(snap.terms[k]);
  }
  if (!snap.x.allFinite() || !snap.v.allFinite() || !std::isfinite(drift))
    throw NumericalError(fmt::format("the solution is no longer finite at t = {:.9g} s", t), t);
  summary_.energy_drift = std::max(summary_.energy_drift, std::abs(drift));
  summary_.final_energy_drift = drift;
  // The scale is physical, never the round-off of a state at rest: what the run moves (K, V − V0 and
  // the work booked) and the weight and loads over the string's length (StringModel::physical_scales).
  summary_.energy_scale = std::max({summary_.energy_scale, snap.energy_scale, moved});
  summary_.max_constraint_violation = std::max(summary_.max_constraint_violation, snap.max_violation);
  if (snap.has_momentum_ledger) {
    summary_.max_momentum_residual =
        std::max(summary_.max_momentum_residual, (snap.momentum - p0_ - snap.impulse).norm());
    // As the energy's, the scale is physical, never the round-off of zero: the momentum the run carries
    // and books, and the momentum sqrt(2 M E) that the string's mass M has at the energy scale E (a
    // string at rest on its supports, whose net momentum and impulse both stay zero, is judged against
    // it, not against the round-off of zero).
    const double mass = model_.chain().density() * model_.chain().length();
    summary_.momentum_scale = std::max({summary_.momentum_scale, snap.momentum.norm() + snap.impulse.norm(),
                                        std::sqrt(2 * mass * snap.energy_scale)});
    // slack = allow: a string whose net momentum stays zero (a loop running along itself) is judged
    // against the momentum its mass carries, sqrt(2 M K), not against the round-off of zero.
    if (model_.allows_slack())
      summary_.momentum_scale = std::max(summary_.momentum_scale, std::sqrt(2 * mass * snap.kinetic));
  }
}

template <int dim>
void StringSolver<dim>::check_tolerance() {
  // The motion's size: the largest displacement of a node from its initial position over the frames
  // (a small oscillation about a rest shape moves by about twice its amplitude).
  if (frames_.size() < 2) return;
  const Points<dim>& x0 = frames_.front().x;
  double size = 0;
  for (std::size_t k = 1; k < frames_.size(); ++k)
    if (frames_[k].x.cols() == x0.cols())
      for (Eigen::Index i = 0; i < x0.cols(); ++i)  // no temporary: this runs at the run's memory peak
        size = std::max(size, (frames_[k].x.col(i) - x0.col(i)).cwiseAbs().maxCoeff());
  // The absolute tolerance on a position: atol, times the state's scale of positions when it has one.
  const Eigen::VectorXd scale = model_.state_scale();
  const double position_scale = scale.size() > 0 ? scale[0] : 1.0;
  const double atol = options_.integrator.atol * position_scale, rtol = options_.integrator.rtol;
  // A string at rest moves by the round-off of its coordinates: there is no motion to resolve.
  const double extent = x0.size() > 0 ? x0.cwiseAbs().maxCoeff() : 0.0;
  if (!(size > kRestMotion * std::numeric_limits<double>::epsilon() * std::max(extent, position_scale))) return;
  if (atol <= rtol * size) return;
  // An atol below the round-off of the coordinates cannot be set: a motion that small against the string's extent
  // (a chain balanced over a peg drifting off by 1e-8 m) is not resolved to rtol by any tolerance, and the advice
  // would be a number the run cannot honour.
  if (rtol * size < kRoundoffUnits * std::numeric_limits<double>::epsilon() * extent) return;
  // The advice, rounded down to two significant digits so that a run given it does not warn again
  // (rtol × 1.9998e-5 m printed as 2e-9 did).
  const double advice = rtol * size / position_scale;
  const double unit = std::pow(10.0, std::floor(std::log10(advice)) - 1);
  summary_.tolerance_warning = fmt::format(
      "atol = {:.3g} m on positions is {:.3g} of the motion's size ({:.3g} m, the largest displacement of a node "
      "over the frames), coarser than rtol = {:.3g}: the run resolves the motion only to about atol; set "
      "solver.atol <= {:.2g}",
      atol, atol / size, size, rtol, std::floor(advice / unit) * unit);
}

template <int dim>
void StringSolver<dim>::fill_record(double t, const typename StringModel<dim>::Snapshot& snap,
                                    RunRecord& record) const {
  record.t = t;
  record.kinetic = snap.kinetic;
  record.potential = snap.potential;
  record.work = snap.work;
  record.terms = {term_names_, snap.terms};
  record.drift = summary_.final_energy_drift;  // book() has just set it for this snapshot
  record.momentum_residual = snap.has_momentum_ledger ? (snap.momentum - p0_ - snap.impulse).norm() : 0.0;
  record.support.template head<dim>() = snap.support;
  record.moving_mass = snap.moving_mass;
  record.max_violation = snap.max_violation;
  record.moving_nodes = model_.num_moving_nodes();
  record.forces = measured_forces(snap);
  record.fronts.clear();
  record.fronts.reserve(snap.fronts.size());
  for (const FrontRecord<dim>& front : snap.fronts) {
    FrontValues& r = record.fronts.emplace_back();
    r.s0 = front.s0;
    r.s0_dot = front.s0_dot;
    r.position.template head<dim>() = front.position;
    r.reaction.template head<dim>() = front.reaction;
    r.fields = front.fields;
  }
}

template <int dim>
void StringSolver<dim>::record_frame(double t, const Eigen::VectorXd& y) {
  auto snap = model_.snapshot(t, y);
  book(t, snap);
  Frame<dim> f;
  fill_record(t, snap, f);
  f.moving.reserve(static_cast<std::size_t>(model_.chain().num_nodes()));  // not grown by doubling
  for (int i = 0; i < model_.chain().num_nodes(); ++i)
    if (model_.in_arc(i)) f.moving.push_back(i);
  f.x = std::move(snap.x);
  f.v = std::move(snap.v);
  f.tension = std::move(snap.tension);
  if (stream_ && frames_.size() == frames_.capacity()) stream_->drain();  // frames_ moves: not while read
  frames_.push_back(std::move(f));
  summary_.frames = static_cast<long>(frames_.size());
  if (stream_) stream_->publish(frames_.size());
}

template <int dim>
std::optional<EventAction> StringSolver<dim>::failed_checks(double t, const Eigen::VectorXd& y, bool after_event,
                                                           bool evaluated) {
  if (model_.module() == nullptr || !model_.module()->checks_at_start() || model_.num_events() == 0) return {};
  Eigen::VectorXd g(model_.num_events());
  if (evaluated)
    model_.module()->events(model_, g);  // the model's last evaluation was at (t, y), its tensions solved
  else
    model_.events(t, y, g);
  const std::vector<int> found = after_event ? model_.module()->events_failed_after_event(g)
                                             : model_.module()->events_failed_at_start(g);
  if (found.empty()) return {};
  Eigen::VectorXd state = y;
  const EventAction action = model_.handle_events(t, state, found);
  CHAINSIM_VERIFY(action.kind == EventAction::Kind::kStop, "a check that has failed must stop the run");
  return action;
}

template <int dim>
void StringSolver<dim>::record_sample(double t, const Eigen::VectorXd& y, Eigen::VectorXd* rates) {
  const auto snap = model_.snapshot(t, y, rates);
  book(t, snap);
  fill_record(t, snap, summary_.samples.emplace_back());
}

template <int dim>
void StringSolver<dim>::check_slack(double t, const Eigen::VectorXd& y) {
  const SlackPolicy policy = model_.options().slack;
  if (policy == SlackPolicy::kIgnore || policy == SlackPolicy::kAllow || (policy == SlackPolicy::kWarn && summary_.slack))
    return;
  const std::optional<SlackReport> slack = model_.find_slack(t, y);
  if (!slack) return;
  summary_.slack = slack;
  if (policy == SlackPolicy::kStop) throw NumericalError(slack->message(), t);
}

template <int dim>
const RunSummary& StringSolver<dim>::run() {
  stream_.reset();  // an earlier run's writer: its unfinished files are removed
  frames_.clear();
  summary_ = RunSummary{};
  have_start_ = false;
  describe_model();
  // The frames' files written while the run goes on (stream_outputs()), into a cleared directory, when
  // some grow with the nodes times the frames (nodes.csv, tension.csv, the ParaView frames): the
  // others, a row per frame, are written after the run at no cost worth a thread during it.
  if (stream_request_ && (stream_request_->second.vtk ||
                          (stream_request_->second.csv && (stream_request_->second.nodes || stream_request_->second.tension)))) {
    const auto& [dir, select] = *stream_request_;
    ensure_directory(dir);
    clear_run_outputs(dir);
    frames_.reserve(static_cast<std::size_t>(
        std::min(1e5, std::ceil(options_.t_end / options_.output_interval) + 2)));  // fewer waits in record_frame()
    stream_ = std::make_unique<Stream>(dir, select, model_, summary_, frames_);
  }
  const auto start = std::chrono::steady_clock::now();
  const long solves_before = model_.tension_solves();
  const long transfers_before = model_.module() ? model_.module()->transfers() : 0;
  const double t0 = 0.0;
  std::unique_ptr<Integrator> integrator;
  auto finish = [&](const std::string& status) {
    summary_.status = status;
    summary_.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary_.tension_solves = model_.tension_solves() - solves_before;
    summary_.transfers = (model_.module() ? model_.module()->transfers() : 0) - transfers_before;
    summary_.events = model_.module() ? model_.module()->run_events() : std::vector<RunEvent>{};
    summary_.lift_off_totals = model_.module() ? model_.module()->lift_off_totals() : std::vector<LiftOffTotal>{};
    if (integrator) {
      summary_.stats = integrator->stats();
      summary_.t_stop = integrator->time();
      final_state_ = integrator->take_state();  // a copy would add a state's bytes at the run's peak
      integrator.reset();  // its vectors freed before anything else is computed
    }
    check_tolerance();
  };
  long events_handled = 0;  // events handled by the model (after the start)
  try {
    // 1. A consistent initial state.
    model_.make_consistent(t0);
    {
      // The initial state lives only until the integrator holds its own copy (a state's bytes per
      // node for the whole run otherwise).
      Eigen::VectorXd y0 = model_.state_from_chain();
      // An impulsive start: the energy the jump of the velocities gave is the drivers' work at t = 0.
      const auto& impulsive = model_.impulsive_start();
      summary_.impulsive_start = impulsive.detected();
      summary_.impulsive_speed_change = impulsive.max_speed_change;
      if (summary_.impulsive_start) {
        summary_.impulsive_energy = impulsive.kinetic_energy;
        y0[model_.work_index()] = impulsive.kinetic_energy;
        // slack = allow: the start is a snap taut; what its impulses dissipated is W_snap (booked by the
        // slack module's start, SlackModule::start), and W_applied holds the rest of the jump, the drivers'
        // (supports') work.
        if (impulsive.dissipated > 0) {
          summary_.impulsive_dissipated = impulsive.dissipated;
          y0[model_.work_index()] += impulsive.dissipated;
        }
      }
      // The module's start on the consistent state (the contact module's lift-offs and landings at t0), which
      // books what it does in the ledgers' initial values.
      if (model_.start_module(t0, y0.tail(y0.size() - model_.work_index() - 1)))
        y0.head(model_.work_index()) = model_.state_from_chain().head(model_.work_index());
      integrator = std::make_unique<Integrator>(model_, t0, y0, options_.integrator);
      record_frame(t0, y0);
      if (options_.record_steps) record_sample(t0, y0);
      check_slack(t0, y0);
      // A check of the module already failed at the start: the run stops at t0 as at that event.
      if (const std::optional<EventAction> stop = failed_checks(t0, y0, false, false)) {
        finish("stopped");
        summary_.stop_reason = stop->reason;
        return summary_;
      }
    }
    // 2. Step by step to each output time: constraints (and slack) are checked at accepted steps,
    //    root functions acted on where they vanish.
    // At least one: a t_end far below the output interval is still integrated to (the last frame is t_end).
    const auto n_out =
        std::max(1L, static_cast<long>(std::ceil(options_.t_end / options_.output_interval - 1e-9)));
    auto output_time = [&](long k) { return std::min(options_.t_end, k * options_.output_interval); };
    // At every accepted step: the constraints, slack, the caller's hook and the step record.
    auto after_step = [&](double t, const Eigen::VectorXd& y) {
      model_.accept_step(t, y);  // slack = allow: the links released at this step go slack
      const auto violation = model_.worst_constraint_violation(t, y);
      summary_.max_constraint_violation = std::max(summary_.max_constraint_violation, violation.relative);
      // A taut link far off its length is no drift of the integration: stop, located (docs/model.md §9,
      // "A release taken back within a step"). The bound grows with the tolerances (the U at rtol = atol = 1e-3
      // drifts 0.025 h): rtol, and atol on positions over the link's length.
      const auto bound_of = [&](int j) {
        const Eigen::VectorXd scale = model_.state_scale();
        const double atol = options_.integrator.atol * (scale.size() > 0 ? scale[0] : 1.0);
        return std::max(kMaxViolation, kMaxViolationPerRtol * std::max(options_.integrator.rtol,
                                                                       atol / model_.chain().link_length(j)));
      };
      double bound = kMaxViolation;
      if (violation.link >= 0 && violation.relative > kMaxViolation && violation.relative > (bound = bound_of(violation.link)))
        throw NumericalError(fmt::format("at t = {:.9g} s taut link {} (s = {:.6g} m) has length {:.6g} m, {:.3g} of its "
                                         "length {:.6g} m off it (the bound is {:.3g}): the constraints have drifted "
                                         "far beyond the integration tolerance",
                                         t, violation.link, model_.chain().link_midpoint(violation.link),
                                         violation.length, violation.relative,
                                         model_.chain().link_length(violation.link), bound),
                             t);
      check_slack(t, y);
      if (on_step) on_step(t, y);
      if (options_.record_steps) record_sample(t, y);
    };
    // Frames closer together than the integrator's steps come from ARKODE's dense output and never
    // shorten a step: the integrator runs towards t_end, and every output time inside an accepted
    // step is interpolated on that step, then projected onto the link constraints (projected_state).
    // Frames further apart than the steps are stop times (exact states; at most one shortened step
    // per frame), and so are all frames of methods of order above kMaxDenseOrder, whose steps are far
    // more accurate than ARKODE's Hermite interpolant (degree <= 5). With root functions, the frames
    // inside the step that holds a root are interpolated before the event's polish recomputes that
    // step (the interpolant no longer covers them afterwards), all of them up to the step's end (the
    // polish may move the event past ARKODE's root), and kept if they lie before the polished event;
    // those at or after it are taken after the event, on the steps that follow.
    // `step` is the last step that ended without an event: the polish's step ends at the event and
    // says nothing about the step size of the run.
    // An interpolated frame is also a row of the step record (series.csv), as a frame at a stop time
    // is: every frame's time is one of its rows.
    auto record_interpolated = [&](double t_out, const Eigen::VectorXd& y_interpolated) {
      const Eigen::VectorXd y_out = model_.projected_state(t_out, y_interpolated);
      record_frame(t_out, y_out);
      if (options_.record_steps) record_sample(t_out, y_out);
    };
    double step = 0;
    std::vector<std::pair<double, Eigen::VectorXd>> before_event;
    long k = 1;
    const Integrator::RootStepHook interpolate_before_event = [&](double, double t_step_end) {
      before_event.clear();  // (a root the polish refuted: the step is taken again, and may hold another)
      for (long j = k; j <= n_out && output_time(j) < t_step_end; ++j)
        before_event.emplace_back(output_time(j), integrator->interpolate(output_time(j)));
    };
    const bool interpolating_method = integrator->stats().order <= kMaxDenseOrder;  // fixed for the run
    // Events that come back at one time without end (a node that lands and is let go at once, over
    // and over) would spin here: each is handled, the integrator restarts and finds it again at the
    // same t. Every event at a new time resets the count; so many at one time end the run, located.
    const long max_events_at_one_time = std::max(1000L, 4L * model_.chain().num_nodes());
    long events_at_one_time = 0;
    double last_event_t = -INFINITY;
    while (k <= n_out) {
      const bool dense = interpolating_method && step > kStepOfFrames * options_.output_interval;
      before_event.clear();
      const Integrator::Outcome outcome =
          integrator->advance(dense ? options_.t_end : output_time(k), /*one_step=*/true, interpolate_before_event);
      const double t = integrator->time();
      if (outcome == Integrator::Outcome::kEvent) {
        for (const auto& [t_out, y_out] : before_event) {
          if (!(t_out < t)) break;
          record_interpolated(t_out, y_out);
          ++k;
        }
        Eigen::VectorXd state = integrator->state();
        events_at_one_time = t == last_event_t ? events_at_one_time + 1 : 0;
        last_event_t = t;
        if (events_at_one_time >= max_events_at_one_time) {
          std::string found;
          for (std::size_t e = 0; e < integrator->events_found().size(); ++e)
            if (integrator->events_found()[e] != 0) found += fmt::format("{}{}", found.empty() ? "" : ", ", e);
          throw NumericalError(
              fmt::format("events stalled at t = {:.12g} s: {} events in a row at this same time (root function {} of "
                          "{}), each handled and found again at once, the time not advancing (a Zeno point of the "
                          "model's contact or fronts: e.g. a node that lands and is let go at the same instant)",
                          t, events_at_one_time, found, integrator->events_found().size()),
              t);
        }
        const EventAction action = model_.handle_events(t, state, integrator->events_found());
        ++events_handled;
        if (action.kind == EventAction::Kind::kStop) {
          if (options_.record_steps) record_sample(t, state);
          record_frame(t, state);
          finish("stopped");
          summary_.stop_reason = action.reason;
          return summary_;
        }
        if (state.size() == integrator->state().size())
          integrator->restart(t, state);
        else
          integrator->resize(t, state);
        if (options_.record_steps) {
          // The record evaluates the model at the new state: ARKODE's first evaluation after the restart
          // (the same state) takes that right-hand side instead of evaluating it again.
          record_sample(t, state, &restart_rates_);
          integrator->provide_start_rhs(restart_rates_);
        }
        // A check that the event's handling (a front's crossing, its re-layout) has taken below zero at once: ARKODE
        // would find no sign change from here. Read from the record's evaluation of this state where there is one.
        if (action.kind == EventAction::Kind::kTransfer)
          if (std::optional<EventAction> stop = failed_checks(t, state, true, options_.record_steps)) {
            record_frame(t, state);
            finish("stopped");
            summary_.stop_reason = stop->reason;
            return summary_;
          }
        if (interrupt_requested()) {  // Ctrl-C between events too: a run whose events keep coming stops
          record_frame(t, state);
          finish("interrupted");
          summary_.stop_reason = fmt::format("interrupted by {} at t = {:.9g} s", interrupt_cause(), t);
          return summary_;
        }
        continue;
      }
      step = integrator->last_step();
      const Eigen::VectorXd& y = integrator->state();
      for (; k <= n_out && output_time(k) < t; ++k) record_interpolated(output_time(k), integrator->interpolate(output_time(k)));
      after_step(t, y);
      if (k <= n_out && output_time(k) == t) record_frame(output_time(k++), y);
      if (k <= n_out && interrupt_requested()) {  // Ctrl-C: stop at this accepted state, outputs valid
        record_frame(t, y);
        finish("interrupted");
        summary_.stop_reason = fmt::format("interrupted by {} at t = {:.9g} s", interrupt_cause(), t);
        return summary_;
      }
    }
  } catch (const RecoverableError& e) {
    // Only a trial stage may be retried: at an accepted state the model cannot go on.
    finish("failed");
    const double t = summary_.t_stop;  // the integrator's time (t0 if it was never made), set by finish()
    summary_.error = fmt::format("the string degenerated at t = {:.9g} s: {}", t, e.what());
    throw NumericalError(summary_.error, t);
  } catch (const NumericalError& e) {
    finish("failed");
    summary_.error = e.what();
    // A step budget used up by events (a crumpling chain's snaps, a front's crossings) says so: the advice on
    // the method and tolerance does not help there.
    if (events_handled == 0 || summary_.error.find("ARK_TOO_MUCH_WORK") == std::string::npos) throw;
    summary_.error += fmt::format(
        ". {} of the steps ended at events, each a restart of the integrator ({})", events_handled,
        model_.allows_slack() ? "slack = \"allow\": the snaps taut among them; a chain that crumples snaps link by "
                                "link, docs/model.md §9, \"Limits\""
                              : "the fronts' crossings and the obstacles' landings and lift-offs");
    throw NumericalError(summary_.error, e.time());
  } catch (const Error& e) {
    finish("failed");
    summary_.error = e.what();
    throw;
  }
  finish("completed");
  summary_.stop_reason = "t_end";
  return summary_;
}

/// The files of the frames: nodes.csv, tension.csv, energy.csv, forces.csv (the CSV format selected)
/// and the ParaView frames with their index string.pvd (the ParaView format), or a part of them,
/// written a frame at a time (add(), in the frames' order) and committed together (commit()). Each
/// file is its own AtomicFile; the rows of a frame are those of the frame alone, so the files are the
/// same whether the frames come one by one during the run or all at once after it.
template <int dim>
class StringSolver<dim>::FrameFiles {
 public:
  /// Which files: the ParaView frames, nodes.csv, the other CSV files (each as `select` allows).
  struct Part {
    bool vtk = true, nodes_csv = true, other_csv = true;
  };

  FrameFiles(const std::filesystem::path& dir, const OutputSelection& select, const StringModel<dim>& model,
             const RunSummary& summary, Part part)
      : dir_(dir), select_(select), chain_(model.chain()), terms_(summary.ledger_terms) {
    fronts_ = model.module() != nullptr;
    if (fronts_) front_fields_ = model.module()->front_fields();
    if (select.vtk && part.vtk) {
      CHAINSIM_VERIFY(select.nodes, "the ParaView frames need the nodes field");
      ensure_directory(dir / "frames");
      vtk_ = true;
      // The obstacles (fixed in space): one file, part 2 of the collection at every frame's time.
      if (fronts_) {
        const ObstacleDrawing obstacles = model.module()->obstacles();
        obstacles_ = !obstacles.empty();
        if (obstacles_)
          write_vtp(dir / "frames" / "obstacles.vtp", obstacle_polydata(obstacles),
                    select.vtk_ascii ? VtkEncoding::kAscii : VtkEncoding::kBinary);
      }
    }
    if (!select.csv) return;
    if (select.nodes && part.nodes_csv) {
      const char* axes[] = {"x", "y", "z"};
      std::vector<std::string> columns = {"t", "node"};
      if (fronts_) columns.emplace_back("s");
      for (int d = 0; d < dim; ++d) columns.emplace_back(axes[d]);
      for (int d = 0; d < dim; ++d) columns.push_back(std::string("v") + axes[d]);
      nodes_.emplace(dir / "nodes.csv", columns);
    }
    if (!part.other_csv) return;
    if (select.tension) tension_.emplace(dir / "tension.csv", std::vector<std::string>{"t", "link", "s_mid", "T"});
    if (select.energy) {
      std::vector<std::string> columns = {"t", "K", "V", "W_applied", "drift"};
      for (const LedgerTerm& term : terms_)
        if (term.energy()) columns.push_back(term.name);
      energy_.emplace(dir / "energy.csv", columns);
    }
    if (select.forces && !summary.force_columns.empty()) {
      std::vector<std::string> columns = {"t"};
      columns.insert(columns.end(), summary.force_columns.begin(), summary.force_columns.end());
      forces_.emplace(dir / "forces.csv", columns);
    }
  }

  /// The next frame's rows and ParaView files.
  void add(const Frame<dim>& f) {
    const std::size_t k = count_++;
    if (vtk_) add_vtk(f, k);
    if (nodes_)
      for (int i : f.moving) {
        row_ = {f.t, static_cast<double>(i)};
        if (fronts_) row_.push_back(chain_.node_coordinate(i));
        for (int d = 0; d < dim; ++d) row_.push_back(f.x(d, i));
        for (int d = 0; d < dim; ++d) row_.push_back(f.v(d, i));
        nodes_->row(row_);
      }
    if (tension_)
      for (int j = 0; j < chain_.num_links(); ++j)
        if (!std::isnan(f.tension[j])) tension_->row({f.t, static_cast<double>(j), chain_.link_midpoint(j), f.tension[j]});
    if (energy_) {
      row_ = {f.t, f.kinetic, f.potential, f.work, f.drift};
      for (std::size_t term = 0; term < terms_.size(); ++term)
        if (terms_[term].energy()) row_.push_back(f.terms.values[term]);
      energy_->row(row_);
    }
    if (forces_) {
      row_ = {f.t};
      row_.insert(row_.end(), f.forces.begin(), f.forces.end());
      forces_->row(row_);
    }
  }

  /// Moves every file to its name (the ParaView index written first).
  void commit() {
    if (vtk_) write_pvd(dir_ / "string.pvd", index_);
    for (auto* file : {&nodes_, &tension_, &energy_, &forces_})
      if (*file) (*file)->commit();
  }

 private:
  /// The moving nodes, a line cell per link of an arc; with fronts, a point per front.
  void add_vtk(const Frame<dim>& f, std::size_t k) {
    const VtkEncoding encoding = select_.vtk_ascii ? VtkEncoding::kAscii : VtkEncoding::kBinary;
    const auto count = static_cast<Eigen::Index>(f.moving.size());
    std::vector<int> point_of(static_cast<std::size_t>(chain_.num_nodes()), -1);
    VtkPolyline line;
    line.points = Eigen::Matrix3Xd::Zero(3, count);
    Eigen::MatrixXd velocity = Eigen::MatrixXd::Zero(3, count), mass(1, count), s(1, count);
    for (Eigen::Index q = 0; q < count; ++q) {
      const int i = f.moving[static_cast<std::size_t>(q)];
      point_of[static_cast<std::size_t>(i)] = static_cast<int>(q);
      line.points.col(q).head(dim) = f.x.col(i);
      velocity.col(q).head(dim) = f.v.col(i);
      mass(0, q) = chain_.mass(i);
      s(0, q) = chain_.node_coordinate(i);
    }
    std::vector<double> cell_tension;
    for (int j = 0; j < chain_.num_links(); ++j) {
      if (std::isnan(f.tension[j])) continue;
      line.segments.emplace_back(point_of[static_cast<std::size_t>(chain_.link_start(j))],
                                 point_of[static_cast<std::size_t>(chain_.link_end(j))]);
      cell_tension.push_back(f.tension[j]);
    }
    line.point_data = {{"velocity", velocity}, {"mass", mass}, {"s", s}};
    if (select_.tension)
      line.cell_data.emplace_back(
          "tension", Eigen::Map<const Eigen::MatrixXd>(cell_tension.data(), 1,
                                                        static_cast<Eigen::Index>(cell_tension.size())));
    const std::string name = fmt::format("frame_{:04d}.vtp", k);
    write_vtp(dir_ / "frames" / name, line, encoding);
    index_.push_back({f.t, "frames/" + name, 0});
    if (obstacles_) index_.push_back({f.t, "frames/obstacles.vtp", 2});
    if (!fronts_) return;
    // The fronts: a point each, with what a user looks for (the module's fields).
    const auto nf = static_cast<Eigen::Index>(f.fronts.size());
    VtkPolyline points;
    points.vertices = true;
    points.points = Eigen::Matrix3Xd::Zero(3, nf);
    Eigen::MatrixXd s0(1, nf), s0_dot(1, nf);
    for (Eigen::Index q = 0; q < nf; ++q) {
      const FrontValues& front = f.fronts[static_cast<std::size_t>(q)];
      points.points.col(q).head(dim) = front.position.head(dim);
      s0(0, q) = front.s0;
      s0_dot(0, q) = front.s0_dot;
    }
    points.point_data = {{"s0", s0}, {"s0_dot", s0_dot}};
    std::size_t offset = 0;  // of the field in FrontValues::fields
    for (const FrontField& field : front_fields_) {
      Eigen::MatrixXd values = Eigen::MatrixXd::Zero(field.vector ? 3 : 1, nf);
      const int components = field.vector ? dim : 1;
      for (Eigen::Index q = 0; q < nf; ++q)
        for (int c = 0; c < components; ++c)
          values(c, q) = f.fronts[static_cast<std::size_t>(q)].fields[offset + static_cast<std::size_t>(c)];
      points.point_data.emplace_back(field.name, values);
      offset += static_cast<std::size_t>(components);
    }
    const std::string fronts_name = fmt::format("fronts_{:04d}.vtp", k);
    write_vtp(dir_ / "frames" / fronts_name, points, encoding);
    index_.push_back({f.t, "frames/" + fronts_name, 1});
  }

  std::filesystem::path dir_;
  OutputSelection select_;
  const Chain<dim>& chain_;
  std::vector<LedgerTerm> terms_;
  std::vector<FrontField> front_fields_;
  bool fronts_ = false, vtk_ = false, obstacles_ = false;
  std::optional<CsvWriter> nodes_, tension_, energy_, forces_;
  std::vector<PvdEntry> index_;
  std::vector<double> row_;
  std::size_t count_ = 0;
};

/// stream_outputs()'s writers: threads that pass each recorded frame to FrameFiles, one for the ParaView
/// frames (whose cost is mostly the file system's: a file per frame) and one for the CSV files (mostly
/// formatting numbers). The frames stay in StringSolver::frames_; the threads read those published to
/// them (published_), which the solver never moves while a thread may read them (record_frame() waits
/// for them before frames_ grows beyond its capacity).
template <int dim>
class StringSolver<dim>::Stream {
 public:
  Stream(std::filesystem::path directory, const OutputSelection& selection, const StringModel<dim>& model,
         const RunSummary& summary, const std::vector<Frame<dim>>& frames)
      : dir(std::move(directory)), select(selection), frames_(frames) {
    using Part = typename FrameFiles::Part;
    if (select.vtk) lanes_.push_back(std::make_unique<Lane>(dir, select, model, summary, Part{true, false, false}));
    if (select.csv) lanes_.push_back(std::make_unique<Lane>(dir, select, model, summary, Part{false, true, true}));
    for (auto& lane : lanes_) lane->thread = std::thread([this, l = lane.get()] { loop(*l); });
  }
  ~Stream() { close(); }

  /// frames[0, count) may be written.
  void publish(std::size_t count) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      published_ = count;
    }
    wake_.notify_all();
  }
  /// Returns when every published frame is written (the frames may then move).
  void drain() {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [&] {
      return std::all_of(lanes_.begin(), lanes_.end(), [&](const auto& lane) { return lane->written == published_; });
    });
  }
  /// Writes what is published, stops the threads and commits the files; rethrows a thread's error.
  void finish() {
    close();
    for (auto& lane : lanes_)
      if (lane->error) std::rethrow_exception(lane->error);
    for (auto& lane : lanes_) lane->files.commit();
  }

  const std::filesystem::path dir;
  const OutputSelection select;

 private:
  struct Lane {
    Lane(const std::filesystem::path& directory, const OutputSelection& selection, const StringModel<dim>& model,
         const RunSummary& summary, typename FrameFiles::Part part)
        : files(directory, selection, model, summary, part) {}
    FrameFiles files;
    std::size_t written = 0;
    std::exception_ptr error;
    std::thread thread;
  };

  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
    }
    wake_.notify_all();
    for (auto& lane : lanes_)
      if (lane->thread.joinable()) lane->thread.join();
  }
  void loop(Lane& lane) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return lane.written < published_ || closing_; });
      if (lane.written == published_) return;  // closing, nothing left
      const std::size_t end = published_;
      const Frame<dim>* frames = frames_.data();
      lock.unlock();
      try {
        for (std::size_t k = lane.written; k < end && !lane.error; ++k) lane.files.add(frames[k]);
      } catch (...) {
        lane.error = std::current_exception();  // finish() rethrows it; the later frames are not written
      }
      lock.lock();
      lane.written = end;
      wake_.notify_all();
    }
  }

  const std::vector<Frame<dim>>& frames_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::size_t published_ = 0;
  bool closing_ = false;
  std::vector<std::unique_ptr<Lane>> lanes_;
};

template <int dim>
StringSolver<dim>::~StringSolver() = default;

template <int dim>
void StringSolver<dim>::stream_outputs(const std::filesystem::path& dir, const OutputSelection& select) {
  stream_request_.emplace(dir, select);
}

namespace {
bool same_selection(const OutputSelection& a, const OutputSelection& b) {
  return a.nodes == b.nodes && a.tension == b.tension && a.energy == b.energy && a.forces == b.forces &&
         a.stats == b.stats && a.csv == b.csv && a.vtk == b.vtk && a.vtk_ascii == b.vtk_ascii;
}
}  // namespace

template <int dim>
void StringSolver<dim>::write_outputs(const std::filesystem::path& dir, const OutputSelection& select,
                                      const nlohmann::json* summary) const {
  CHAINSIM_VERIFY(!select.vtk || select.nodes, "the ParaView frames need the nodes field");
  if (stream_ && stream_->dir == dir && same_selection(stream_->select, select)) {
    // 1.-3. Streamed during the run (the directory cleared when it started): the rest of the frames.
    stream_->finish();
  } else {
    stream_.reset();  // another directory or selection: its unfinished files are removed
    ensure_directory(dir);
    // 1. Remove every output of an earlier run first: the directory then holds this run's files or
    //    none, never a mix; stats.json, written last, marks a complete set.
    clear_run_outputs(dir);
    // 2. The ParaView frames and nodes.csv (half the numbers) each on a thread of their own while
    //    this one writes the other CSV files (all only read the frames; each file is its own
    //    AtomicFile), so that the outputs cost the longest of the three, not their sum.
    using Part = typename FrameFiles::Part;
    auto write = [&](Part part) {
      FrameFiles files(dir, select, model_, summary_, part);
      for (const auto& f : frames_) files.add(f);
      files.commit();
    };
    // Each future waits for its thread when it goes out of scope, before the frames it reads (an
    // error below still waits for them); get() rethrows a thread's error.
    std::future<void> frames_written, nodes_written;
    if (select.vtk) frames_written = std::async(std::launch::async, write, Part{true, false, false});
    if (select.csv && select.nodes) nodes_written = std::async(std::launch::async, write, Part{false, true, false});
    write(Part{false, false, true});
    if (nodes_written.valid()) nodes_written.get();
    if (frames_written.valid()) frames_written.get();
  }
  // 3. The step record (runs that record steps).
  if (select.csv && select.energy && !summary_.samples.empty()) samples_table(summary_).write(dir / "series.csv");
  // 4. stats.json, last.
  if (select.stats) write_json(dir / "stats.json", summary ? *summary : to_json(summary_));
}

template class StringSolver<2>;
template class StringSolver<3>;
template void describe_model<2>(const StringModel<2>&, RunSummary&);
template void describe_model<3>(const StringModel<3>&, RunSummary&);

}  // namespace chainsim
