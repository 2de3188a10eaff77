// The frames' files written while the run goes on (StringSolver::stream_outputs; issue 24, item 5: the
// outputs no longer follow the integration, they overlap it).
#include <chrono>
#include <filesystem>
#include <thread>
#include <string>

#include <catch2/catch.hpp>

#include "cases/scene/scene_run.hpp"
#include "solver/output.hpp"
#include "test_scene_support.hpp"

namespace {

/// Bytes of the temporary files (AtomicFile's hidden ".NAME.*.tmp") of `name` in `dir`.
std::uintmax_t temporary_bytes(const std::filesystem::path& dir, const std::string& name) {
  std::uintmax_t bytes = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (file.rfind("." + name + ".", 0) == 0) bytes += entry.file_size(ec);
  }
  return bytes;
}

}  // namespace

TEST_CASE("a streamed run writes its frames while it runs, the same files as written after it", "[output][stream]") {
  using namespace chainsim;
  // The chain of the scene tests released horizontally, 101 nodes, 401 frames: nodes.csv holds about 4 MB.
  std::string text = test::edit(test::kSceneBase, "nodes = 11", "nodes = 101");
  text = test::edit(text, "[[0.0, 0.0], [0.0, -1.0]]", "[[0.0, 0.0], [1.0, 0.0]]");
  text = test::edit(text, "[shape]", "[output]\ninterval = 0.0005\n\n[shape]");
  const SceneSpec spec = parse_scene_text(text, "stream.toml");
  const auto dir = test::temp_dir("output_stream");
  SceneRun<2> streamed(spec);
  {
    const RunDirectory run_dir(dir / "streamed");
    streamed.stream(run_dir);
    // Near the end of the run the rows of the frames recorded so far reach the disk (a writer thread
    // formats them during the run): nodes.csv's temporary file grows past its first 1 MiB buffer
    // while the run waits at a step after 0.9 t_end (for at most 20 s, on a loaded machine).
    std::uintmax_t during = 0;
    bool waited = false;
    const double t_end = streamed.solver_options().t_end;
    REQUIRE_FALSE(streamed
                      .run([&](double t) {
                        if (waited || t < 0.9 * t_end) return;
                        waited = true;
                        const auto start = std::chrono::steady_clock::now();
                        while ((during = temporary_bytes(run_dir.path(), "nodes.csv")) <= (1u << 20) &&
                               std::chrono::steady_clock::now() - start < std::chrono::seconds(20))
                          std::this_thread::sleep_for(std::chrono::milliseconds(10));
                      })
                      .has_value());
    REQUIRE(waited);
    INFO("nodes.csv's temporary file during the run: " << during << " bytes");
    CHECK(during > (1u << 20));
    streamed.write(run_dir, streamed.summary());
  }
  // Written after the run by a scene that did not stream: byte for byte the same files.
  SceneRun<2> after(spec);
  REQUIRE_FALSE(after.run().has_value());
  after.write(dir / "after", after.summary());
  for (const char* name : {"nodes.csv", "tension.csv", "energy.csv", "string.pvd", "frames/frame_0000.vtp",
                           "frames/frame_0400.vtp"}) {
    INFO(name);
    REQUIRE(std::filesystem::exists(dir / "streamed" / name));
    CHECK(test::read(dir / "streamed" / name) == test::read(dir / "after" / name));
  }
  // Nothing of the stream is left behind: no temporary file.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir / "streamed"))
    CHECK(entry.path().extension() != ".tmp");
}
