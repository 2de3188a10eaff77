// A second potential force on a string with fronts (issue 22, item 3): a conservative force declares
// its potential (Force::uniform_field), and the fronts book it at their partial links and in the
// material their heaps hold, so the energy ledger closes as it does with gravity alone.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

/// The sliding chain of the paper moved to a hole at (1, 0): 0.8 m in a heap fed through the hole,
/// 0.2 m hanging, with the given forces; 20 links, f = 0.5, run for 0.25 s.
RunSummary sliding(std::vector<std::unique_ptr<Force<2>>> forces) {
  Points<2> vertices(2, 3);
  vertices << 0.2, 1.0, 1.0, 0.0, 0.0, -0.2;
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices), 1.0, 1.0, 20, false);
  HeapSpec<2> heap;
  heap.side = HeapSpec<2>::Side::kBefore;
  heap.point = Vec<2>(1.0, 0.0);
  heap.s0 = 0.8;
  heap.dissipation = 0.5;
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), {}, {heap}, std::nullopt, FrontOptions{});
  StringSolverOptions options;
  options.t_end = 0.25;
  options.output_interval = 0.05;
  options.record_steps = true;
  StringSolver<2> solver(model, options);
  RunSummary run = solver.run();
  REQUIRE(run.status == "completed");
  REQUIRE(run.transfers > 0);  // nodes came out of the heap: its content and the partial link changed
  return run;
}

}  // namespace

TEST_CASE("a second uniform field on a string with a heap: the energy ledger closes as with gravity alone",
          "[unit][shocks]") {
  const Vec<2> g(0.0, -9.81), a(4.0, 0.0);  // a uniform field along x besides gravity
  // The same physics with gravity alone: one field g + a (gravity tilted). Its drift is the fronts'
  // discretization error for this motion (the hanging part swings: not a straight-line motion).
  std::vector<std::unique_ptr<Force<2>>> tilted;
  tilted.push_back(std::make_unique<Gravity<2>>(Vec<2>(g + a)));
  const RunSummary alone = sliding(std::move(tilted));
  std::vector<std::unique_ptr<Force<2>>> two;
  two.push_back(std::make_unique<Gravity<2>>(g));
  two.push_back(std::make_unique<UniformField<2>>(a, "uniform field"));
  const RunSummary both = sliding(std::move(two));
  INFO("relative energy drift: gravity alone (tilted) " << alone.relative_energy_drift() << ", gravity and the field "
                                                        << both.relative_energy_drift());
  // The field along x moves material into and out of the heap at x = 1 m, whose potential
  // −a·(first moment) must be booked, and acts on the partial link: with gravity alone in the fronts'
  // potential (the code before) the drift was 0.079 of the energy scale.
  CHECK(alone.relative_energy_drift() < 2e-4);  // the bound of the example front scenes (test_scene.cpp)
  CHECK(both.relative_energy_drift() < 2e-4);
  CHECK(both.relative_energy_drift() == Approx(alone.relative_energy_drift()).epsilon(1e-6));
  // The held mass is what left the arcs: the mass ledger, independent of the fields.
  for (const StepSample& s : both.samples) CHECK(s.moving_mass + s.terms["heap_mass"] == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("a conservative force the fronts cannot book is refused with fronts", "[unit][shocks]") {
  // A potential that is not a uniform field: the fronts book partial links and heaps in uniform fields
  // only, so a run would leave the energy ledger open.
  struct Spring final : Force<2> {
    std::string name() const override { return "spring"; }
    void add_force(const NodeState<2>& s, Points<2>& force) const override {
      for (int i = 0; i < force.cols(); ++i) force.col(i) -= s.mass[i] * s.x.col(i);
    }
    bool conservative() const override { return true; }
    double potential(const NodeState<2>& s) const override {
      double v = 0;
      for (int i = 0; i < s.x.cols(); ++i) v += 0.5 * s.mass[i] * s.x.col(i).squaredNorm();
      return v;
    }
  };
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Spring>());
  CHECK_THROWS_AS(sliding(std::move(forces)), InputError);
  std::vector<std::unique_ptr<Force<2>>> spring;
  spring.push_back(std::make_unique<Spring>());
  CHECK_THROWS_WITH(sliding(std::move(spring)), Catch::Contains("the spring effect is conservative but not a uniform field"));
}
