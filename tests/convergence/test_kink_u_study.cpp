// Study (hidden, [.kink_u]; docs/model.md §9 "Inserting a kink front into the U"): the swinging U
// (cases/scenes/swinging_u.toml, slack = "allow") run to t_ins, its state restarted with a kink front
// (shocks/kink_front.hpp) in the link whose neighbours turn most, and run on to t_end; prints where it
// stops. KU_NODES (101), KU_TINS (0.40 s), KU_TEND (1 s) set the mesh and the times; KU_OUT names a file for
// the frames (t, s, x, y rows).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "shocks/front_tracker.hpp"
#include "shocks/kink_front.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

double env(const char* name, double fallback) {
  const char* v = std::getenv(name);
  return v ? std::atof(v) : fallback;
}

}  // namespace

TEST_CASE("study: the swinging U with a kink front inserted at t_ins", "[.kink_u]") {
  const int nodes = static_cast<int>(env("KU_NODES", 101));
  const double t_ins = env("KU_TINS", 0.40), t_end = env("KU_TEND", 1.0);
  SceneSpec spec = parse_scene(std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/swinging_u.toml");
  spec.nodes = nodes;
  spec.stop.t_end = t_ins;
  spec.output.interval = t_ins;
  StringScene<2> scene = build_string_scene<2>(spec);
  StringSolver<2> first(*scene.model, scene.solver);
  first.run();
  const Frame<2>& at = first.frames().back();
  const Chain<2>& c0 = scene.model->chain();
  const double h = c0.link_length(0);
  // The link whose neighbours turn most, with the kink inside it.
  int best = -1;
  double best_turn = 0, best_l = 0;
  for (int j = 1; j + 2 < c0.num_nodes(); ++j) {
    const Vec<2> tA = (at.x.col(j) - at.x.col(j - 1)).normalized(), tB = (at.x.col(j + 2) - at.x.col(j + 1)).normalized();
    const Vec<2> d = tA - tB;
    const double lA = (at.x.col(j + 1) - at.x.col(j) - h * tB).dot(d) / d.squaredNorm();
    const double turn = std::acos(std::clamp(tA.dot(tB), -1.0, 1.0));
    if (turn > best_turn && lA > 0.05 * h && lA < 0.95 * h) best = j, best_turn = turn, best_l = lA;
  }
  REQUIRE(best > 0);
  fmt::print("N = {}: kink inserted at t = {} in link {} (s0 = {:.5f} m), turn {:.1f} deg over 3 links\n", nodes, at.t,
             best, c0.node_coordinate(best) + best_l, best_turn * 180 / kPi);
  Chain<2> chain = c0;
  chain.positions() = at.x;
  chain.velocities() = at.v;
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -9.81)));
  std::vector<PrescribedNode<2>> fixed;
  fixed.push_back({0, std::make_shared<FixedPoint<2>>(Vec<2>(at.x.col(0)))});
  fixed.push_back({nodes - 1, std::make_shared<FixedPoint<2>>(Vec<2>(at.x.col(nodes - 1)))});
  std::vector<std::unique_ptr<FrontKind<2>>> kinds;
  kinds.push_back(std::make_unique<KinkFront<2>>(KinkSpec{c0.node_coordinate(best) + best_l}));
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), std::move(fixed), std::move(kinds),
                                             FrontOptions{}, scene.model->options());
  StringSolverOptions so = scene.solver;
  so.t_end = t_end - t_ins;
  so.output_interval = 0.05;
  so.record_steps = true;
  StringSolver<2> second(model, so);
  try {
    second.run();
  } catch (const Error& e) {
    fmt::print("  failed: {}\n", e.what());
  }
  // KU_OUT: the frames (every 0.05 s from t_ins) as t, s, x, y rows, for a self-convergence study.
  if (const char* out = std::getenv("KU_OUT")) {
    std::FILE* f = std::fopen(out, "w");
    REQUIRE(f != nullptr);
    for (const Frame<2>& frame : second.frames())
      for (int i = 0; i < frame.x.cols(); ++i)
        std::fprintf(f, "%.6f,%.17g,%.17g,%.17g\n", t_ins + frame.t, model.chain().node_coordinate(i), frame.x(0, i),
                     frame.x(1, i));
    std::fclose(f);
  }
  const RunSummary& r = second.summary();
  fmt::print("  {} at t = {:.4f} s ({}): {} transfers, W_snap {:.3g} J, W_shocks {:.3g}, energy residual {:.2e}\n",
             r.status, t_ins + r.t_stop, r.stop_reason, r.transfers,
             r.samples.empty() ? 0.0 : r.samples.back().terms["W_snap"],
             r.samples.empty() ? 0.0 : r.samples.back().terms["W_shocks"], r.relative_energy_residual());
  for (const StepSample& s : r.samples)
    if (&s == &r.samples.back() || static_cast<int>((s.t) / 0.02) != static_cast<int>((s.t - 1e-12) / 0.02))
      fmt::print("    t = {:.4f}: s0 = {:.5f}, ds0/dt = {:.4f}, pos = ({:.4f}, {:.4f})\n", t_ins + s.t, s.fronts[0].s0,
                 s.fronts[0].s0_dot, s.fronts[0].position[0], s.fronts[0].position[1]);
}
