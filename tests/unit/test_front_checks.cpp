// The fronts' physical checks have one implementation (shocks/front_checks.hpp, issue 22 item 4): the
// front tracker refuses a bad HeapSpec or FoldSpec with the scene's wording, naming the spec's fields
// ("heap.s0", "fold.s0") where the scene names its keys (tests/unit/test_scene_errors.cpp).
#include <catch2/catch.hpp>

#include <memory>
#include <optional>
#include <vector>

#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "shocks/front_tracker.hpp"

using namespace chainsim;

namespace {

/// A straight 1 m string of 16 links (their sum exactly 1 m) from (0, 1) down to (0, 0) (or a closed square), with these fronts and ends.
void build(std::vector<HeapSpec<2>> heaps, std::optional<FoldSpec> fold, bool closed = false,
           std::vector<PrescribedNode<2>> prescribed = {}) {
  Points<2> vertices(2, closed ? 4 : 2);
  if (closed)
    vertices << 0.0, 0.25, 0.25, 0.0, 0.0, 0.0, 0.25, 0.25;  // a square of side 1/4
  else
    vertices << 0.0, 0.0, 1.0, 0.0;
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices, closed), 1.0, 1.0, 16, closed);
  make_front_model<2>(std::move(chain), {}, std::move(prescribed), std::move(heaps), fold, FrontOptions{});
}

HeapSpec<2> end_heap(double s0) {
  HeapSpec<2> heap;
  heap.side = HeapSpec<2>::Side::kAfter;
  heap.s0 = s0;
  heap.dissipation = 0.5;
  return heap;
}

}  // namespace

TEST_CASE("the tracker refuses bad fronts with the scene's wording, naming the spec's fields", "[unit][shocks]") {
  CHECK_THROWS_WITH(build({end_heap(1.5)}, std::nullopt),
                    "heap.s0 = 1.5 is outside the string: allowed 0 < s0 <= 1 for a heap the string runs into (the "
                    "string is 1 m long)");
  CHECK_THROWS_WITH(build({end_heap(1.0), end_heap(0.9)}, std::nullopt),
                    "heap.side = after: heap already holds that side of the string; allowed at most one heap per side");
  CHECK_THROWS_WITH(build({end_heap(0.8)}, FoldSpec{0.5, 0.9}),
                    "fold.s0 = 0.9 is not between the heaps: allowed 0 <= s0 < 0.8");
  CHECK_THROWS_WITH(build({}, FoldSpec{1.5, 0.5}), "fold.dissipation = 1.5 is out of range: allowed 0 <= dissipation <= 1");
  CHECK_THROWS_WITH(build({end_heap(1.0)}, std::nullopt, true),
                    "a heap on a closed string: fronts are tracked on open strings only (string.closed = true)");
  HeapSpec<2> table = end_heap(1.0);
  table.plane_normal = Vec<2>::Zero();
  CHECK_THROWS_WITH(build({table}, std::nullopt),
                    "the normal of a heap's plane = [0, 0] is zero: a plane needs a normal");
  std::vector<PrescribedNode<2>> fixed;
  fixed.push_back({16, std::make_shared<FixedPoint<2>>(Vec<2>(0.0, 0.0))});
  CHECK_THROWS_WITH(build({end_heap(1.0)}, std::nullopt, false, std::move(fixed)),
                    "the string's last node = prescribed is inside the heap of heap (a heap the string runs into, "
                    "s0 = 1 m): an end held by a heap cannot be fixed, loaded or driven");
}
