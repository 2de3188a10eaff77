// cases/scene/parse_scene.cpp and scene_text.cpp on hard input: a very long one-line array (parsed in
// time linear in its length), files too large to be a scene (refused at a size limit without reading
// them whole, also from a device or a FIFO).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::temp_dir;
using Catch::Matchers::Contains;

TEST_CASE("a polyline of 100001 points on one line parses, every point in place and located", "[unit][scene]") {
  // Points x_k = k / 100000 along a unit segment, all on line 5 of the file.
  constexpr int kPoints = 100001;
  std::string points;
  points.reserve(static_cast<std::size_t>(kPoints) * 24);
  for (int k = 0; k < kPoints; ++k)
    points += fmt::format("{}[{:.5f}, {}]", k == 0 ? "" : ", ", k / double(kPoints - 1), k % 2 == 0 ? "0.0" : "-0.0");
  const std::string text = "[string]\nnodes = 11\n[shape]\nkind = \"polyline\"\npoints = [" + points +
                           "]\n[stop]\nt_end = 0.1\n";
  const SceneSpec spec = parse_scene_text(text, "long.toml");
  REQUIRE(spec.shape.points.size() == static_cast<std::size_t>(kPoints));
  for (int k : {0, 1, 2, 50000, 99999, 100000}) {
    INFO(k);
    CHECK(spec.shape.points[k] == std::vector<double>{k / 100000.0, 0.0});
  }
  // Each point's location is its column on line 5: "points = [" is 10 characters, then
  // "[0.00000, 0.0], " etc.; point k = 100000 is "[1.00000, 0.0]", after 50000 "…, 0.0], " and
  // 50000 "…, -0.0], " (16 and 17 characters).
  CHECK(spec.where("shape.points[0]") == "long.toml:5:11");
  CHECK(spec.where("shape.points[100000]") == fmt::format("long.toml:5:{}", 11 + 50000 * 16 + 50000 * 17));
  CHECK(spec.locations.at("shape.points[100000]").text == "[1.00000, 0.0]");
  // The whole array is quoted cut to 60 characters.
  CHECK(spec.locations.at("shape.points").text == "[[0.00000, 0.0], [0.00001, -0.0], [0.00002, 0.0], [0.0000...");
  // And it builds: 11 nodes on the segment, 0.1 m apart.
  StringScene<2> scene = build_string_scene<2>(spec);
  const auto& x = scene.model->chain().positions();
  REQUIRE(x.cols() == 11);
  for (int i = 0; i < 11; ++i) {
    CHECK(x(0, i) == Approx(i / 10.0).margin(1e-12));
    CHECK(x(1, i) == Approx(0.0).margin(1e-12));
  }
}
