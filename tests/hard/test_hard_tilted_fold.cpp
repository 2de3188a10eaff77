// The folded chain released from a line tilted from the vertical (docs/shocks.md, "A fold whose arms
// turn apart"): the fold front comes apart within its first crossings, at every tilt and f, and the
// run stops there with a located diagnostic. The stop is checked against laws the code does not
// contain: the self-similarity of the release (early on, the only lengths are g t² and h, so the
// stop happens at the same s0/h and at a time ∝ √h on every mesh), the geometry of the folded link
// at the stop (its chord, from the nodes, against h / cos 10°), and the energy and momentum ledgers.
// The run the diagnostic recommends for f = 0 (the string resolving the kink, no fold front) is the
// example scene cases/scenes/tilted_folded_chain.toml, run with its energy ledger by test_scene.cpp.
#include <cmath>
#include <string>

#include <catch2/catch.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "../convergence/canonical_test_support.hpp"

using namespace chainsim;
using test::setup_for;
using Catch::Matchers::Contains;

TEST_CASE("a folded chain released tilted comes apart within its first crossings, at the same s0/h on every mesh",
          "[hard][shocks]") {
  for (double tilt : {5.0, 15.0, 20.0, 30.0})
    for (double f : {0.0, 0.5, 1.0}) {
      INFO("tilt " << tilt << " deg, f = " << f);
      double t_stop[2] = {}, s0_over_h[2] = {}, rel_energy[2] = {};
      long transfers[2] = {};
      const int meshes[2] = {41, 161};
      for (int m = 0; m < 2; ++m) {
        StringCaseSetup s = setup_for(Problem::kFolded, f, meshes[m]);
        s.tilt_deg = tilt;
        s.frame_interval = 1.0;  // the frames at t = 0 and at the stop
        const StringCaseRun out = solve_string_case(s);
        const RunSummary& run = out.run;
        const double h = 1.0 / (meshes[m] - 1);
        REQUIRE(run.status == "stopped");
        const int a = static_cast<int>(run.transfers), b = a + 1;  // the folded link (a, b)
        CHECK_THAT(run.stop_reason, Contains("has come apart") &&
                                        Contains("nodes " + std::to_string(a) + " and " + std::to_string(b)) &&
                                        Contains("For f = 0 run the scene without [effects.fold]"));
        // The stop is where the folded link's chord |x_b − x_a| passes h / cos(10°), the most a fold
        // whose arms are within 20° of antiparallel needs to cross a node.
        const Frame<2>& last = out.frames.back();
        CHECK(last.t == Approx(run.t_stop).epsilon(1e-12));
        CHECK((last.x.col(b) - last.x.col(a)).norm() / h == Approx(1 / std::cos(10 * kPi / 180)).epsilon(1e-9));
        // Momentum closes to the integrator's tolerance; the energy ledger to O(h) of its scale.
        CHECK(run.relative_momentum_residual() < 1e-9);
        t_stop[m] = run.t_stop;
        s0_over_h[m] = run.samples.back().s0[0] / h;
        rel_energy[m] = run.relative_energy_drift();
        transfers[m] = run.transfers;
      }
      CHECK(transfers[0] == transfers[1]);  // 1 at 5 degrees, 0 from 15 degrees up
      // Self-similar: h = ℓ/40 and ℓ/160 stop at one s0/h, at times in the ratio √4 = 2. The free arm's
      // tension (1 − f) λ ṡ0² decelerates an arm of length ℓ, which breaks the similarity at
      // O((1 − f) h/ℓ) per crossing: measured |Δ(s0/h)| / (s0/h) ≤ 1.2e-3 and ratios 1.9938–1.9994
      // for f < 1 (1.9938: 5 degrees, f = 0, one crossing before the stop), 4.3e-5 and 1.99996–2.00001
      // for f = 1 (a tension-free arm: no length but g t² and h).
      const double similarity = f == 1.0 ? 1e-4 : 4e-3;
      CHECK(s0_over_h[0] == Approx(s0_over_h[1]).epsilon(similarity));
      CHECK(t_stop[0] / t_stop[1] == Approx(2.0).epsilon(similarity));
      CHECK(s0_over_h[1] < transfers[1] + 1.0);  // before the next crossing
      CHECK(rel_energy[0] < 1e-3);                 // measured 1.1e-5 (5 deg) to 7.5e-4 (30 deg)
      CHECK(rel_energy[1] < 0.3 * rel_energy[0]);  // measured ratio 0.25: first order in h
    }
}

TEST_CASE("a tilted folded chain makes more crossings before it comes apart as the tilt goes to zero",
          "[hard][shocks]") {
  // s0/h at the stop against the tilt (41 nodes, f = 0.5): it falls as the tilt grows (measured 17.0,
  // 10.0, 5.0, 2.0, 0.94, 0.76 for 0.5 to 30 degrees); the paper's vertical fold crosses every node
  // and runs to its cutoff (test_hard_fronts.cpp).
  double previous = 40;
  for (double tilt : {0.5, 1.0, 2.0, 5.0, 15.0, 30.0}) {
    INFO("tilt " << tilt << " deg");
    StringCaseSetup s = setup_for(Problem::kFolded, 0.5, 41);
    s.tilt_deg = tilt;
    const StringCaseRun out = solve_string_case(s);
    REQUIRE(out.run.status == "stopped");
    const double s0_over_h = out.run.samples.back().s0[0] * 40;
    CHECK(s0_over_h < previous);
    previous = s0_over_h;
  }
  CHECK(previous > 0.5);
}

