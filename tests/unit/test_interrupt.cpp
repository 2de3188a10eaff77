// Ctrl-C: a run stopped by SIGINT ends at its last accepted step with valid outputs, stats.json
// saying "interrupted" and the time reached, and exit code 130; no progress line is drawn when
// stderr is not a terminal. SIGTERM (what a batch scheduler sends) is treated the same way, and one
// that lands while the outputs are written lets them be finished: no half file, no temporary file.
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tests/unit/test_scene_support.hpp"
extern char** environ;

namespace {

std::string read(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Starts `chainsim run SCENE --out OUT`, stdout to /dev/null, stderr to `log`; returns its pid.
pid_t spawn_run(const std::string& scene, const std::string& out, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::string binary = CHAINSIM_BINARY;
  std::string a0 = "chainsim", a1 = "run", a3 = "--out";
  char* argv[] = {a0.data(), a1.data(), const_cast<char*>(scene.c_str()), a3.data(), const_cast<char*>(out.c_str()),
                  nullptr};
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv, environ) == 0);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

/// The files of `dir` (and frames/) whose names end in ".tmp".
std::vector<std::string> temporary_files(const std::filesystem::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() > 4 && name.substr(name.size() - 4) == ".tmp") found.push_back(e.path().string());
  }
  return found;
}

/// Rows of a CSV file after its header.
long data_rows(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  long rows = -1;
  while (std::getline(in, line)) ++rows;
  return rows;
}

/// A hanging chain swinging gently (taut throughout) asked to run for 1000 s: far longer than the
/// tests wait.
const char* kLongSwing = R"([string]
length = 1.0
nodes = 101
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.1, -0.994987437107]]
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -9.81]
[output]
interval = 0.05
[stop]
t_end = 1000.0
)";

}  // namespace

TEST_CASE("chainsim run stopped by SIGINT or SIGTERM leaves valid outputs marked interrupted", "[unit][cli]") {
  // SIGTERM (a batch scheduler) once killed the run: exit 143, the earlier outputs removed, nothing written.
  const auto [signal, cause] = GENERATE(std::pair{SIGINT, "the user"}, std::pair{SIGTERM, "SIGTERM"});
  CAPTURE(signal);
  const auto dir = chainsim::test::temp_dir("sigint");
  std::ofstream(dir / "long.toml") << kLongSwing;
  const std::string log = (dir / "stderr.txt").string();
  const pid_t pid = spawn_run((dir / "long.toml").string(), (dir / "out").string(), log);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  REQUIRE(kill(pid, signal) == 0);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);

  const nlohmann::json stats = nlohmann::json::parse(read(dir / "out" / "stats.json"));
  CHECK(stats["status"] == "interrupted");
  CHECK(stats["stop_reason"].get<std::string>().rfind(std::string("interrupted by ") + cause + " at t = ", 0) == 0);
  const double t_stop = stats["t_stop"].get<double>();
  CHECK(t_stop > 0);
  CHECK(t_stop < 1000.0);
  // The outputs are complete up to the stop: every frame has every node, the last frame is the stop.
  const long frames = stats["frames"].get<long>();
  std::ifstream nodes(dir / "out" / "nodes.csv");
  std::string line;
  long rows = 0;
  std::getline(nodes, line);
  double last_t = 0;
  while (std::getline(nodes, line)) {
    ++rows;
    last_t = std::stod(line.substr(0, line.find(',')));
  }
  CHECK(rows == frames * 101);
  CHECK(last_t == Approx(t_stop).epsilon(1e-9));
  CHECK(std::filesystem::exists(dir / "out" / "string.pvd"));
  // The energy ledger is closed up to the stop (the run is a plain swinging chain).
  CHECK(stats["relative_energy_drift"].get<double>() < 1e-6);
  // stderr was a file, not a terminal: no progress line was drawn.
  CHECK(read(log).find('\r') == std::string::npos);
  // Nothing left but the outputs: no temporary file, the lock released.
  CHECK(temporary_files(dir / "out").empty());
  CHECK_FALSE(std::filesystem::exists(dir / "out" / ".chainsim.lock"));
}

TEST_CASE("SIGTERM while the outputs are written: they are finished, whole, and no temporary file stays",
          "[unit][cli]") {
  // Before: the run died half-way through nodes.csv, leaving .nodes.csv.tmp and no stats.json.
  // 2001 nodes, 401 frames: nodes.csv of 800,000 rows takes a good fraction of a second to write.
  const auto dir = chainsim::test::temp_dir("sigterm_write");
  std::string scene = kLongSwing;
  scene.replace(scene.find("nodes = 101"), 11, "nodes = 2001");
  scene.replace(scene.find("interval = 0.05"), 15, "interval = 0.0005\nformats = [\"csv\"]\nmax_megabytes = 10000");
  scene.replace(scene.find("t_end = 1000.0"), 14, "t_end = 0.2");
  std::ofstream(dir / "big.toml") << scene;
  const auto out = dir / "out";
  const pid_t pid = spawn_run((dir / "big.toml").string(), out.string(), (dir / "stderr.txt").string());
  // Wait for the temporary file of nodes.csv, then send SIGTERM. No fixed time: the run reaches its
  // writing in ~1 s in a Release build and in more than 30 s under the sanitizers (CTest's timeout bounds
  // the wait); if the run ends before the file is seen, the test could not do what it is for.
  bool writing = false;
  while (!writing) {
    std::error_code ec;
    for (std::filesystem::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().filename().string().rfind(".nodes.csv.", 0) == 0) writing = true;
    if (writing) break;
    int early = 0;
    if (waitpid(pid, &early, WNOHANG) == pid) FAIL("the run ended before its nodes.csv was seen being written");
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  REQUIRE(kill(pid, SIGTERM) == 0);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  // `chainsim run` writes nodes.csv while it integrates (StringSolver::stream_outputs): the signal came
  // while the file was being written, during the integration (the run stops at its next accepted step:
  // exit 130, "interrupted") or after it (the run had reached t_end: exit 0, "completed"). Either way
  // the set is whole: every frame's rows, stats.json, no temporary file.
  const nlohmann::json stats = nlohmann::json::parse(read(out / "stats.json"));
  INFO("exit status " << WEXITSTATUS(status) << ", run " << stats["status"]);
  CHECK(((WEXITSTATUS(status) == 0 && stats["status"] == "completed") ||
         (WEXITSTATUS(status) == 130 && stats["status"] == "interrupted")));
  CHECK(data_rows(out / "nodes.csv") == stats["frames"].get<long>() * 2001);
  CHECK(temporary_files(out).empty());
}
