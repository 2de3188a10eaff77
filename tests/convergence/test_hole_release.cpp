// The singular start (issue 24 item 6; docs/shocks.md, "A release from rest at a hole"): a chain released at
// rest with its hanging part tilted 40 degrees (cases/scenes/hole_release_at_rest.toml: 0.4 m hanging, heap
// at the hole, f = 0.83) converges at first order in its stop time, and the cause is the tilt, not the rest
// start: the same chain hanging straight down, released at rest from the same heap and hole (the front speed
// starts from 0, the first crossing comes after a time ~ sqrt(h), the heap's partial link is the same), meets
// the reduced model's exact quadrature on every mesh.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"

using namespace chainsim;

namespace {

double stop_time(const std::vector<std::string>& overrides, int nodes) {
  const std::string file = std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/hole_release_at_rest.toml";
  std::vector<std::string> o = overrides;
  o.push_back("string.nodes=" + std::to_string(nodes));
  o.push_back("solver.rtol=1e-11");  // the time integration's share stays below 1e-10 of t_stop
  o.push_back("solver.atol=1e-13");
  const RunSummary run = run_front_scene<2>(parse_scene(file, o));
  INFO("N = " << nodes << ": " << run.status << " " << run.stop_reason << run.error);
  REQUIRE(run.status == "stopped");
  return run.t_stop;
}

}  // namespace

TEST_CASE("a chain released at rest through a hole, tilted, converges at first order: the start's corner, not "
          "the rest start", "[convergence][shocks][general]") {
  // Tilted 40 degrees: observed order of the stop time from 41, 81, 161 nodes. Measured 1.01 here and 1.05,
  // 1.00 on 81 - 641 nodes (docs/shocks.md): order 1, with t_stop(h) - t* = 6.8e-3 s x (h / 1 m).
  std::vector<double> t;
  for (int nodes : {41, 81, 161}) t.push_back(stop_time({}, nodes));
  const double order = std::log2(std::abs(t[0] - t[1]) / std::abs(t[1] - t[2]));
  std::printf("\nhole release at rest, 40 degrees: t_stop = %.12f, %.12f, %.12f s on 41, 81, 161 nodes; order %.3f\n",
              t[0], t[1], t[2], order);
  CHECK(order >= 0.9);
  CHECK(order <= 1.3);  // not second order: the documented cause below is what limits it
  // The first-order term: t(N) - t(2N) = C h / 2 with C = 6.8e-3 s per metre of link (measured 6.8e-3 on
  // 41/81 and 6.7e-3 on 81/161): its size, not only its rate.
  const double c = 2 * (t[1] - t[2]) / (1.0 / 80);
  CHECK(c > 5e-3);
  CHECK(c < 9e-3);

  // The same chain hanging straight down: the reduced sliding chain from rest at eta0 = 0.4 (f = 0.83), whose
  // stop time (the heap empty) is the exact quadrature t0 * xi(1), t0 = sqrt(2 l / g).
  const std::vector<std::string> vertical = {"shape.points=[[-0.6, 0.0], [0.0, 0.0], [0.0, -0.4]]"};
  const double exact = std::sqrt(2 * 1.0 / 9.81) * exact::sliding_fall_time(0.83, 0.4);
  for (int nodes : {41, 81}) {
    const double tv = stop_time(vertical, nodes);
    std::printf("vertical, N = %d: t_stop = %.12f s, exact %.12f s, relative error %.2e\n", nodes, tv, exact,
                std::abs(tv - exact) / exact);
    CHECK(std::abs(tv - exact) / exact < 1e-9);
  }
}
