// The outputs of a run, judged before it: their size priced from the real bytes per node-frame
// (StringSolverOptions::estimate_outputs, checked here against the bytes runs write), an earlier
// run's outputs removed before the integration starts, and a name the run writes that is taken by
// something else refused before the run.
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/cli/run_command.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::read;
using test::temp_dir;

namespace {

/// A chain released horizontal from a pivot: every node moves, so its numbers print at full length.
std::string pendulum_scene(int nodes, double t_end, const std::string& output) {
  return fmt::format(R"([string]
length = 1.0
density = 0.1
nodes = {}

[shape]
kind = "polyline"
points = [[0.0, 0.0], [1.0, 0.0]]

[ends]
start = "fixed"

[effects.gravity]
g = [0.0, -9.81]

[stop]
t_end = {}

[output]
{}
)",
                     nodes, t_end, output);
}

/// Bytes under `dir` (files only, recursively).
double bytes_under(const std::filesystem::path& dir) {
  double total = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) total += static_cast<double>(entry.file_size());
  return total;
}

}  // namespace

TEST_CASE("the output budget prices a run's files from their real sizes", "[unit][scene][output]") {
  const auto dir = temp_dir("output_budget");
  struct Case {
    std::string name, output;
  };
  // Every output, the ParaView files binary or as text, and the CSV files alone.
  const Case cases[] = {{"binary", "interval = 0.01"},
                        {"ascii", "interval = 0.01\nvtk_encoding = \"ascii\""},
                        {"csv", "interval = 0.01\nformats = [\"csv\"]"}};
  for (const Case& c : cases) {
    INFO(c.name);
    const auto scene_file = dir / (c.name + ".toml");
    std::ofstream(scene_file) << pendulum_scene(201, 0.3, c.output);
    const SceneSpec spec = parse_scene(scene_file);
    StringSolverOptions options;
    options.t_end = spec.stop.t_end;
    options.output_interval = spec.output.interval;
    const OutputEstimate estimate = options.estimate_outputs(201, 2, false, spec.output.select);
    RunCommandOptions run;
    run.scene = scene_file.string();
    run.out = (dir / c.name).string();
    run.quiet = true;
    std::ostringstream summary;
    REQUIRE(run_scene_command(run, summary) == 0);
    // The estimate bounds the bytes written from above, and not by more than 2x.
    const double written = bytes_under(dir / c.name);
    CHECK(estimate.node_frames == 201 * 32);
    CHECK(written <= estimate.disk_bytes);
    CHECK(written >= 0.5 * estimate.disk_bytes);
  }
}

TEST_CASE("an earlier run's outputs are gone before the integration starts, so a run killed then leaves none",
          "[unit][scene][output][cli]") {
  const auto dir = temp_dir("stale_outputs");
  const auto out = dir / "out";
  std::filesystem::create_directories(out / "frames");
  for (const char* name : {"stats.json", "nodes.csv", "tension.csv", "energy.csv", "string.pvd", "frames/frame_0000.vtp"})
    std::ofstream(out / name) << "from an earlier run\n";
  // A run of many seconds (a long chain for a long time, explicit steps), started in the background.
  const auto scene_file = dir / "long.toml";
  std::ofstream(scene_file) << pendulum_scene(2001, 100.0, "interval = 1.0\nformats = [\"csv\"]");
  const auto pid_file = dir / "pid";
  const std::string cmd = fmt::format("{} run {} --out {} --quiet --max-wall 60 > /dev/null 2>&1 & echo $! > {}",
                                      CHAINSIM_BINARY, scene_file.string(), out.string(), pid_file.string());
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const pid_t pid = std::stoi(read(pid_file));
  // The earlier outputs disappear while the run integrates: poll, then kill the run (SIGKILL: no
  // chance to write anything).
  bool cleared = false;
  for (int k = 0; k < 3000 && !cleared; ++k) {
    cleared = !std::filesystem::exists(out / "stats.json");
    if (!cleared) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const bool was_running = ::kill(pid, SIGKILL) == 0;
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  CHECK(cleared);
  CHECK(was_running);  // it was still integrating when the outputs were already gone
  for (const char* name : {"stats.json", "nodes.csv", "tension.csv", "energy.csv", "string.pvd", "frames"})
    CHECK_FALSE(std::filesystem::exists(out / name));
}

TEST_CASE("an output name taken by a directory or a file is refused before the run, and nothing is removed",
          "[unit][scene][output]") {
  const auto dir = temp_dir("taken_outputs");
  const auto scene_file = dir / "s.toml";
  std::ofstream(scene_file) << pendulum_scene(21, 0.1, "interval = 0.05");
  auto run_into = [&](const std::filesystem::path& out) {
    RunCommandOptions run;
    run.scene = scene_file.string();
    run.out = out.string();
    run.quiet = true;
    std::ostringstream summary;
    return run_scene_command(run, summary);
  };
  const auto a = dir / "a";
  std::filesystem::create_directories(a / "stats.json");
  std::ofstream(a / "nodes.csv") << "earlier\n";
  CHECK_THROWS_WITH(run_into(a), fmt::format("--out = '{}': '{}' is a directory, where a run writes a file; remove or "
                                             "rename it, or choose another --out",
                                             a.string(), (a / "stats.json").string()));
  CHECK(read(a / "nodes.csv") == "earlier\n");
  const auto b = dir / "b";
  std::filesystem::create_directories(b);
  std::ofstream(b / "frames") << "a file\n";
  CHECK_THROWS_WITH(run_into(b), fmt::format("--out = '{}': '{}' is a file, where a run writes a directory of "
                                             "ParaView frames; remove or rename it, or choose another --out",
                                             b.string(), (b / "frames").string()));
  // A free directory runs.
  CHECK(run_into(dir / "c") == 0);
  CHECK(std::filesystem::exists(dir / "c" / "stats.json"));
}
