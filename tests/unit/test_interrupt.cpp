// Ctrl-C: a run stopped by SIGINT ends at its last accepted step with valid outputs, stats.json
// saying "interrupted" and the time reached, and exit code 130; no progress line is drawn when
// stderr is not a terminal.
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

extern char** environ;

namespace {

std::string read(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("chainsim run stopped by SIGINT leaves valid outputs marked interrupted", "[unit][cli]") {
  const auto dir = std::filesystem::temp_directory_path() / "chainsim_test_sigint";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // A hanging chain swinging gently (taut throughout) asked to run for 1000 s: far longer than the
  // test waits.
  std::ofstream(dir / "long.toml") << R"([string]
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
  const std::string out = (dir / "out").string(), log = (dir / "stderr.txt").string();
  const std::string scene = (dir / "long.toml").string();
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
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  REQUIRE(kill(pid, SIGINT) == 0);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);

  const nlohmann::json stats = nlohmann::json::parse(read(dir / "out" / "stats.json"));
  CHECK(stats["status"] == "interrupted");
  CHECK(stats["stop_reason"].get<std::string>().rfind("interrupted by the user at t = ", 0) == 0);
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
}
