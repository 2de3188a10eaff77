// The run loop of a string with fronts: see front_solver.hpp.
#include "front_solver.hpp"

#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"

namespace chainsim {

void FrontRunOptions::validate() const {
  integrator.validate();
  require_in_range("t_end", t_end, 0.0, INFINITY, Bound::kOpen, Bound::kOpen);
  require_in_range("frame_interval", frame_interval, 0.0, INFINITY);
}

nlohmann::json to_json(const FrontRun& r) {
  nlohmann::json j = {{"status", r.status},
                      {"stop_reason", r.stop_reason},
                      {"t_stop", r.t_stop},
                      {"wall_s", r.wall_s},
                      {"steps", r.stats.steps},
                      {"rhs_evals", r.stats.rhs_evals},
                      {"transfers", r.transfers},
                      {"tension_solves", r.tension_solves},
                      {"energy_residual", r.relative_energy_residual()},
                      {"energy_residual_abs", r.max_energy_residual},
                      {"energy_scale", r.energy_scale},
                      {"momentum_residual", r.relative_momentum_residual()},
                      {"max_constraint_violation", r.max_violation},
                      {"samples", r.samples.size()},
                      {"stats", to_json(r.stats)}};
  if (!r.error.empty()) j["error"] = r.error;
  return j;
}

CsvTable samples_table(const FrontRun& run) {
  std::vector<std::string> cols = {"t"};
  const std::size_t nf = run.samples.empty() ? 0 : run.samples.front().s0.size();
  const std::size_t dim = run.samples.empty() ? 0 : run.samples.front().support.size();
  const char* axes[] = {"x", "y", "z"};
  for (std::size_t k = 0; k < nf; ++k) {
    cols.push_back("s0_" + std::to_string(k));
    cols.push_back("s0dot_" + std::to_string(k));
    for (std::size_t d = 0; d < dim; ++d) cols.push_back("front_" + std::to_string(k) + "_" + axes[d]);
  }
  for (const char* c : {"K", "V", "W_applied", "W_shocks", "W_heaps", "W_remesh", "energy_residual",
                        "momentum_residual"})
    cols.emplace_back(c);
  for (std::size_t d = 0; d < dim; ++d) cols.push_back(std::string("support_") + axes[d]);
  for (const char* c : {"moving_mass", "heap_mass", "max_violation", "moving_nodes"}) cols.emplace_back(c);
  CsvTable table(cols);
  for (const FrontSample& s : run.samples) {
    std::vector<double> row = {s.t};
    for (std::size_t k = 0; k < nf; ++k) {
      row.push_back(s.s0[k]);
      row.push_back(s.s0_dot[k]);
      for (std::size_t d = 0; d < dim; ++d) row.push_back(s.position[k * dim + d]);
    }
    for (double v : {s.kinetic, s.potential, s.w_applied, s.w_shocks, s.w_heaps, s.w_remesh, s.energy_residual,
                     s.momentum_residual})
      row.push_back(v);
    for (double v : s.support) row.push_back(v);
    for (double v : {s.moving_mass, s.heap_mass, s.max_violation, static_cast<double>(s.moving_nodes)})
      row.push_back(v);
    table.add_row(row);
  }
  return table;
}

template <int dim>
FrontRun run_fronts(FrontModel<dim>& model, const FrontRunOptions& options) {
  options.validate();
  FrontRun run;
  const auto start = std::chrono::steady_clock::now();
  model.make_consistent(0.0);
  Eigen::VectorXd y = model.state_from_chain();
  double e0 = 0, v0 = 0;
  Vec<dim> p0 = Vec<dim>::Zero();
  auto record = [&](double t, const Eigen::VectorXd& state) {
    const auto snap = model.snapshot(t, state);
    FrontSample s;
    s.t = t;
    for (const auto& f : snap.fronts) {
      s.s0.push_back(f.s0);
      s.s0_dot.push_back(f.s0_dot);
      for (int d = 0; d < dim; ++d) s.position.push_back(f.position[d]);
    }
    s.kinetic = snap.kinetic;
    s.potential = snap.potential;
    s.w_applied = snap.w_applied;
    s.w_shocks = snap.w_shocks;
    s.w_heaps = snap.w_heaps;
    s.w_remesh = snap.w_remesh;
    if (run.samples.empty()) {
      e0 = snap.kinetic + snap.potential;
      v0 = snap.potential;
      p0 = snap.momentum;
    }
    s.energy_residual = snap.kinetic + snap.potential - e0 - snap.w_applied - snap.w_shocks - snap.w_heaps -
                        snap.w_remesh;
    s.momentum_residual = (snap.momentum - p0 - snap.impulse).norm();
    for (int d = 0; d < dim; ++d) s.support.push_back(snap.support[d]);
    s.moving_mass = snap.moving_mass;
    s.heap_mass = snap.heap_mass;
    s.max_violation = snap.max_violation;
    s.moving_nodes = model.num_moving_nodes();
    run.max_energy_residual = std::max(run.max_energy_residual, std::abs(s.energy_residual));
    run.energy_scale = std::max(run.energy_scale, snap.kinetic + std::abs(snap.potential - v0) +
                                                      std::abs(snap.w_applied) + std::abs(snap.w_shocks) +
                                                      std::abs(snap.w_heaps));
    run.max_momentum_residual = std::max(run.max_momentum_residual, s.momentum_residual);
    run.momentum_scale = std::max(run.momentum_scale, snap.momentum.norm() + snap.impulse.norm());
    run.max_violation = std::max(run.max_violation, snap.max_violation);
    if (options.frame_interval > 0 &&
        (run.frame_times.empty() || t >= run.frame_times.back() + options.frame_interval * (1 - 1e-9))) {
      run.frame_times.push_back(t);
      run.frames.push_back(snap.x);
      std::vector<int> moving;
      for (const auto& arc : model.arcs())
        for (int i = arc.first; i <= arc.last; ++i) moving.push_back(i);
      run.frame_moving.push_back(moving);
    }
    run.samples.push_back(std::move(s));
  };
  try {
    record(0.0, y);
    Integrator integrator(model, 0.0, y, options.integrator);
    for (;;) {
      const auto outcome = integrator.advance(options.t_end, /*one_step=*/true);
      const double t = integrator.time();
      if (outcome == Integrator::Outcome::kEvent) {
        Eigen::VectorXd state = integrator.state();
        const auto action = model.handle_events(t, state, integrator.events_found());
        if (action.kind == FrontModel<dim>::EventAction::Kind::kStop) {
          record(t, state);
          run.status = "stopped";
          run.stop_reason = action.reason;
          break;
        }
        if (state.size() == integrator.state().size())
          integrator.restart(t, state);
        else
          integrator.resize(t, state);
        record(t, state);
        continue;
      }
      record(t, integrator.state());
      if (outcome == Integrator::Outcome::kReachedTarget) {
        run.status = "completed";
        run.stop_reason = "t_end reached";
        break;
      }
    }
    run.t_stop = run.samples.back().t;
    run.stats = integrator.stats();
  } catch (const Error& e) {  // NumericalError, or a RecoverableError outside a step (at a crossing)
    run.status = "failed";
    run.error = e.what();
    run.t_stop = run.samples.empty() ? 0 : run.samples.back().t;
  }
  run.transfers = model.transfers();
  run.tension_solves = model.tension_solves();
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

template FrontRun run_fronts<2>(FrontModel<2>&, const FrontRunOptions&);
template FrontRun run_fronts<3>(FrontModel<3>&, const FrontRunOptions&);

}  // namespace chainsim
