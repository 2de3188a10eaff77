// cases/scene/parse_scene.cpp and scene_text.cpp on hard input: a very long one-line array (parsed in
// time linear in its length), files too large to be a scene (refused at a size limit without reading
// them whole, also from a device or a FIFO).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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

namespace {

/// The message of the InputError parse_scene(file) throws, or "" if none.
std::string read_error(const std::filesystem::path& file) {
  try {
    parse_scene(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// A FIFO at `path` that a background shell command fills with the output of `writer`.
void fifo_from(const std::filesystem::path& path, const std::string& writer) {
  REQUIRE(mkfifo(path.c_str(), 0600) == 0);
  REQUIRE(std::system(("(" + writer + " > '" + path.string() + "') 2>/dev/null &").c_str()) == 0);
}

/// Releases a writer still blocked on opening the FIFO (it then dies of SIGPIPE) and removes it.
void close_fifo(const std::filesystem::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK);
  if (fd >= 0) close(fd);
  std::filesystem::remove(path);
}

}  // namespace

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

TEST_CASE("a scene file larger than 64 MiB is refused without being read whole, from a file, a device or a FIFO",
          "[unit][scene]") {
  const auto dir = temp_dir("scene_input");
  const std::string limit = "the scene file is larger than 64 MiB (67108864 bytes), the most a scene may have";
  // A regular file: measured, not read (a sparse file of 100 MiB).
  const auto big = dir / "big.toml";
  std::ofstream(big).close();
  std::filesystem::resize_file(big, std::uintmax_t{100} << 20);
  CHECK(read_error(big) == big.string() + ":1:1: " + limit);
  // One byte over the limit is too many.
  std::filesystem::resize_file(big, (std::uintmax_t{64} << 20) + 1);
  CHECK(read_error(big) == big.string() + ":1:1: " + limit);
  std::filesystem::remove(big);
  // A device without end (/dev/zero): chainsim run's test below. A FIFO without end (an endless writer): the same.
  const auto endless = dir / "endless.toml";
  fifo_from(endless, "yes 'a = 1'");
  CHECK(read_error(endless) == endless.string() + ":1:1: " + limit);
  close_fifo(endless);
  // A FIFO that carries a scene (e.g. a shell's <(...)) is read like a file.
  const auto good = dir / "scene.toml";
  std::ofstream(good) << test::kSceneBase;
  const auto piped = dir / "piped.toml";
  fifo_from(piped, "cat '" + good.string() + "'");
  const SceneSpec spec = parse_scene(piped);
  CHECK(spec.nodes == 11);
  CHECK(spec.where("string.nodes") == piped.string() + ":4:9");
  close_fifo(piped);
  // A directory and a missing file.
  CHECK(read_error(dir) == "cannot read the scene file '" + dir.string() + "': it is a directory");
  CHECK(read_error(dir / "missing.toml") == "cannot read the scene file '" + (dir / "missing.toml").string() + "'");
}

TEST_CASE("chainsim run /dev/zero ends at once with the size limit and exit code 2", "[unit][scene][cli]") {
  const auto dir = temp_dir("scene_input_cli");
  const std::string cmd = std::string(CHAINSIM_BINARY) + " run /dev/zero --json --out " + (dir / "o").string() +
                          " > " + (dir / "stdout").string() + " 2>/dev/null";
  CHECK(WEXITSTATUS(std::system(cmd.c_str())) == 2);
  CHECK_THAT(test::read(dir / "stdout"),
             Contains("/dev/zero:1:1: the scene file is larger than 64 MiB (67108864 bytes), the most a scene may have"));
}
