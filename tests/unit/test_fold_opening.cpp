// A fold is a tight bight: the jump conditions allow a dissipative kink only where its two arms are
// antiparallel (docs/shocks.md). the front tracker measures how far its arms are from that (the fold's
// "opening") and stops the run, through an ARKODE root, when it passes FoldFront::kMaxOpeningDeg; a fold
// that starts wider is refused.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/discretize.hpp"
#include "shocks/front_tracker.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;

namespace {

const double kDeg = kPi / 180;

/// A chain of 20 links folded at s0 = 0.2 m: arc A hangs straight down from the origin, arc B
/// leaves the fold at `opening` from straight up (antiparallel = 0).
StringModel<2> folded(double opening) {
  Points<2> vertices(2, 3);
  vertices << 0.0, 0.0, 0.8 * std::sin(opening), 0.0, -0.2, -0.2 + 0.8 * std::cos(opening);
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices), 1.0, 1.0, 20, false);
  FoldSpec fold;
  fold.s0 = 0.2;
  fold.dissipation = 0.5;
  return make_front_model<2>(std::move(chain), {}, {}, {}, fold, FrontOptions{});
}

}  // namespace

TEST_CASE("a fold's opening is the angle of its arms from antiparallel, and a fold that starts open is refused",
          "[unit][shocks]") {
  // The nodes lie on the polyline, so the fold's end links are the two arms' directions: the
  // opening equals the angle built in (to round-off).
  for (const double degrees : {0.0, 5.0, 19.0}) {
    StringModel<2> model = folded(degrees * kDeg);
    const auto snap = model.snapshot(0.0, model.state_from_chain());
    REQUIRE(snap.fronts.size() == 1);
    CHECK(front_tracker(model)->front_state(0).opening / kDeg == Approx(degrees).margin(1e-9));
  }
  try {
    folded(30 * kDeg);
    FAIL("a fold opened 30 degrees was accepted");
  } catch (const InputError& e) {
    const std::string what = e.what();
    CHECK(what.rfind("the fold at s0 = 0.2", 0) == 0);
    CHECK(what.find("has opened: its arms leave it 30 degrees from antiparallel (a tight bight allows at most 20;") !=
          std::string::npos);
  }
}

TEST_CASE("a fold whose arms swing apart stops the run when they are 20 degrees from antiparallel",
          "[unit][shocks][scene]") {
  // The folded chain of the scene tests (resting arm 0.2 m, antiparallel free arm) thrown sideways at 1 m/s: the resting
  // arm swings about the fixed start while the free arm flies on, so the arms turn apart at the
  // fold. The opening event (a root) ends the run before the cutoff, with the ledgers closed.
  const std::string text = test::kFoldedBase + "[velocity]\nkind = \"uniform\"\nvalue = [1.0, 0.0]\n";
  const SceneSpec spec = parse_scene_text(text, "thrown_fold.toml");
  FrontScene<2> scene = build_front_scene<2>(spec);
  CHECK(scene.model->num_events() == 4);  // 2 crossings + the cutoff + the opening
  const RunSummary run = test::run_front_spec(spec);
  CAPTURE(run.stop_reason, run.t_stop);
  CHECK(run.status == "stopped");
  CHECK(run.stop_reason.find(fmt::format("has opened at t = {:.9g} s: its arms leave it 20 degrees from antiparallel",
                                         run.t_stop)) != std::string::npos);
  REQUIRE(!run.samples.empty());
  CHECK(run.samples.back().fronts[0].s0 < 0.99);
  // The fold's forces carry the momentum flux of the material it moves (exact), and its energy
  // balance is W_s = −2 f λ |ṡ0|³ up to the bounded O(h²) term of V (midpoints vs lumped masses).
  CHECK(run.relative_momentum_residual() < 1e-12);
  CHECK(run.relative_energy_residual() < 1e-4);
}
