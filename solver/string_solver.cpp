// Drives a StringModel with the Integrator and writes its outputs: see string_solver.hpp.
#include "string_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"
#include "output.hpp"
#include "vtk_output.hpp"

namespace chainsim {

void StringSolverOptions::validate() const {
  integrator.validate();
  require_positive("stop.t_end", t_end);
  require_in_range("output.interval", output_interval, 0.0, INFINITY, Bound::kOpen);
}

void StringSolverOptions::check_frame_budget(int nodes) const {
  // About 40 bytes per node and frame, so the limit is under 1 GB: a typo must not exhaust the machine.
  constexpr double kMaxNodeFrames = 2e7;
  const double frames = std::floor(t_end / output_interval) + 2;
  const double node_frames = frames * nodes;
  if (node_frames > kMaxNodeFrames)
    throw InputError(fmt::format("output.interval = {:g} s with stop.t_end = {:g} s asks for {:.3g} frames of "
                                 "{} nodes ({:.3g} node-frames): allowed at most {:.0e}; raise output.interval",
                                 output_interval, t_end, frames, nodes, node_frames, kMaxNodeFrames));
}

nlohmann::json to_json(const RunSummary& s) {
  nlohmann::json j = {{"status", s.status},
                      {"t_end", s.t_end},
                      {"steps", s.stats.steps},
                      {"rhs_evals", s.stats.rhs_evals},
                      {"wall_s", s.wall_s},
                      {"energy_drift", s.energy_drift},
                      {"final_energy_drift", s.final_energy_drift},
                      {"energy_scale", s.energy_scale},
                      {"relative_energy_drift", s.relative_energy_drift()},
                      {"max_constraint_violation", s.max_constraint_violation},
                      {"tension_solves", s.tension_solves},
                      {"tension_backend", s.tension_backend},
                      {"frames", s.frames},
                      {"stop_reason", s.stop_reason},
                      {"dimension", s.dimension},
                      {"nodes", s.nodes},
                      {"links", s.links},
                      {"effects", s.effects},
                      {"prescribed", s.prescribed},
                      {"root_functions", s.root_functions},
                      {"tension_unknowns", s.tension_unknowns},
                      {"junction_unknowns", s.junction_unknowns},
                      {"stabilization_time", s.stabilization_time},
                      {"stats", to_json(s.stats)}};
  if (!s.error.empty()) j["error"] = s.error;
  return j;
}

template <int dim>
StringSolver<dim>::StringSolver(StringModel<dim>& model, const StringSolverOptions& options)
    : model_(model), options_(options) {
  options_.validate();
  options_.check_frame_budget(model_.chain().num_nodes());
  describe_model();
}

template <int dim>
void StringSolver<dim>::describe_model() {
  // What the model holds, read back from it (not from the scene that asked for it).
  const auto& chain = model_.chain();
  summary_.dimension = dim;
  summary_.nodes = chain.num_nodes();
  summary_.links = chain.num_links();
  summary_.effects.clear();
  for (const auto& force : model_.forces()) summary_.effects.push_back(force->name());
  summary_.prescribed.clear();
  for (const auto& p : model_.prescribed())
    summary_.prescribed.push_back(fmt::format("node {}: {}", p.node, p.path->description()));
  summary_.root_functions = model_.num_events();
  summary_.tension_unknowns = model_.tension_system().size();
  summary_.junction_unknowns = summary_.tension_unknowns - chain.num_links();
  summary_.stabilization_time = model_.options().stabilization_time;
  summary_.tension_backend = model_.tension_system().backend_name();
}

template <int dim>
void StringSolver<dim>::record(double t, const Eigen::VectorXd& y) {
  auto snap = model_.snapshot(t, y);
  Frame<dim> f;
  f.t = t;
  f.x = std::move(snap.x);
  f.v = std::move(snap.v);
  f.tension = std::move(snap.tension);
  f.kinetic = snap.kinetic;
  f.potential = snap.potential;
  f.work = snap.work;
  f.max_violation = snap.max_violation;
  if (frames_.empty()) {
    e0_ = snap.kinetic + snap.potential;
    v0_ = snap.potential;
  }
  f.drift = f.kinetic + f.potential - e0_ - f.work;
  if (!f.x.allFinite() || !f.v.allFinite() || !f.tension.allFinite() || !std::isfinite(f.drift))
    throw NumericalError(fmt::format("the solution is no longer finite at t = {:.9g} s", t), t);
  summary_.energy_drift = std::max(summary_.energy_drift, std::abs(f.drift));
  summary_.final_energy_drift = f.drift;
  summary_.energy_scale =
      std::max(summary_.energy_scale, f.kinetic + std::abs(f.potential - v0_) + std::abs(f.work));
  summary_.max_constraint_violation = std::max(summary_.max_constraint_violation, f.max_violation);
  frames_.push_back(std::move(f));
  summary_.frames = static_cast<long>(frames_.size());
}

template <int dim>
const RunSummary& StringSolver<dim>::run() {
  frames_.clear();
  summary_ = RunSummary{};
  describe_model();
  const auto start = std::chrono::steady_clock::now();
  const long solves_before = model_.tension_solves();
  const double t0 = 0.0;
  std::unique_ptr<Integrator> integrator;
  auto finish = [&](const std::string& status) {
    summary_.status = status;
    summary_.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary_.tension_solves = model_.tension_solves() - solves_before;
    if (integrator) {
      summary_.stats = integrator->stats();
      summary_.t_end = integrator->time();
      final_state_ = integrator->state();
    }
  };
  try {
    // 1. A consistent initial state.
    model_.make_consistent(t0);
    const Eigen::VectorXd y0 = model_.state_from_chain();
    integrator = std::make_unique<Integrator>(model_, t0, y0, options_.integrator);
    record(t0, y0);
    if (model_.options().check_slack) model_.check_slack(t0, y0);
    // 2. Step by step to each output time: constraints (and slack) are checked at accepted steps.
    const auto n_out = static_cast<long>(std::ceil(options_.t_end / options_.output_interval - 1e-9));
    for (long k = 1; k <= n_out; ++k) {
      const double t_out = std::min(options_.t_end, k * options_.output_interval);
      while (integrator->time() < t_out) {
        integrator->advance(t_out, /*one_step=*/true);
        const double t = integrator->time();
        const Eigen::VectorXd& y = integrator->state();
        summary_.max_constraint_violation =
            std::max(summary_.max_constraint_violation, model_.max_constraint_violation(t, y));
        if (model_.options().check_slack) model_.check_slack(t, y);
        if (on_step) on_step(t, y);
      }
      record(t_out, integrator->state());
    }
  } catch (const RecoverableError& e) {
    // Only a trial stage may be retried: at an accepted state the model cannot go on.
    finish("failed");
    const double t = integrator ? integrator->time() : t0;
    summary_.error = fmt::format("the string degenerated at t = {:.9g} s: {}", t, e.what());
    throw NumericalError(summary_.error, t);
  } catch (const Error& e) {
    finish("failed");
    summary_.error = e.what();
    throw;
  }
  finish("completed");
  summary_.stop_reason = "t_end";
  return summary_;
}

template <int dim>
void StringSolver<dim>::write_outputs(const std::filesystem::path& dir, const OutputSelection& select) const {
  CHAINSIM_VERIFY(!select.vtk || select.nodes, "the ParaView frames need the nodes field");
  ensure_directory(dir);
  // 1. Remove every output of an earlier run first: the directory then holds this run's files or
  //    none, never a mix; stats.json, written last, marks a complete set.
  std::error_code ec;
  for (const char* name : {"stats.json", "nodes.csv", "tension.csv", "energy.csv", "string.pvd"})
    std::filesystem::remove(dir / name, ec);
  std::filesystem::remove_all(dir / "frames", ec);
  const auto& chain = model_.chain();
  const int n = chain.num_nodes(), L = chain.num_links();
  // 2. CSV tables.
  if (select.csv) {
    const char* axes[] = {"x", "y", "z"};
    std::vector<std::string> columns = {"t", "node"};
    for (int d = 0; d < dim; ++d) columns.emplace_back(axes[d]);
    for (int d = 0; d < dim; ++d) columns.push_back(std::string("v") + axes[d]);
    CsvTable nodes(columns);
    CsvTable tension({"t", "link", "s_mid", "T"});
    CsvTable energy({"t", "K", "V", "W_applied", "drift"});
    std::vector<double> s_mid(static_cast<std::size_t>(L));
    for (int j = 0; j < L; ++j) s_mid[static_cast<std::size_t>(j)] = chain.link_midpoint(j);
    std::vector<double> row;
    for (const auto& f : frames_) {
      for (int i = 0; select.nodes && i < n; ++i) {
        row = {f.t, static_cast<double>(i)};
        for (int d = 0; d < dim; ++d) row.push_back(f.x(d, i));
        for (int d = 0; d < dim; ++d) row.push_back(f.v(d, i));
        nodes.add_row(row);
      }
      for (int j = 0; select.tension && j < L; ++j)
        tension.add_row({f.t, static_cast<double>(j), s_mid[static_cast<std::size_t>(j)], f.tension[j]});
      energy.add_row({f.t, f.kinetic, f.potential, f.work, f.drift});
    }
    if (select.nodes) nodes.write(dir / "nodes.csv");
    if (select.tension) tension.write(dir / "tension.csv");
    if (select.energy) energy.write(dir / "energy.csv");
  }
  // 3. ParaView frames, then their index.
  if (select.vtk) {
    ensure_directory(dir / "frames");
    std::vector<std::pair<double, std::string>> index;
    VtkPolyline line;
    for (int j = 0; j < L; ++j) line.segments.emplace_back(chain.link_start(j), chain.link_end(j));
    Eigen::MatrixXd mass = chain.masses().transpose();
    for (std::size_t k = 0; k < frames_.size(); ++k) {
      const auto& f = frames_[k];
      line.points = Eigen::Matrix3Xd::Zero(3, n);
      line.points.topRows(dim) = f.x;
      Eigen::MatrixXd velocity = Eigen::MatrixXd::Zero(3, n);
      velocity.topRows(dim) = f.v;
      line.point_data = {{"velocity", velocity}, {"mass", mass}};
      line.cell_data.clear();
      if (select.tension) line.cell_data.emplace_back("tension", f.tension.transpose());
      const std::string name = fmt::format("frame_{:04d}.vtp", k);
      write_vtp(dir / "frames" / name, line);
      index.emplace_back(f.t, "frames/" + name);
    }
    write_pvd(dir / "string.pvd", index);
  }
  // 4. stats.json, last.
  if (select.stats) write_json(dir / "stats.json", to_json(summary_));
}

template class StringSolver<2>;
template class StringSolver<3>;

}  // namespace chainsim
