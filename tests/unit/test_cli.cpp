// The chainsim executable: exit codes, error messages and the --json summary.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <chrono>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tests/unit/test_scene_support.hpp"

extern char** environ;

namespace {

struct Result {
  int status;
  std::string output;  // stdout and stderr
};

/// Runs chainsim with `args`; stdout and stderr are captured together unless stdout_only.
Result run(const std::string& args, bool stdout_only = false) {
  const std::string cmd = std::string(CHAINSIM_BINARY) + " " + args + (stdout_only ? " 2>/dev/null" : " 2>&1");
  FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe);
  std::string out;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

/// A fresh path for one test's outputs (not created: the commands make it).
std::string temp_dir(const std::string& name) { return chainsim::test::temp_path(name).string(); }

}  // namespace

TEST_CASE("chainsim reduced --json prints the summary keys", "[unit][cli]") {
  const std::string out = temp_dir("cli_json");
  const Result r = run("reduced falling --json --out " + out);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.output);
  for (const char* key : {"t_stop_over_t0", "eta_stop", "P_stop_over_P0", "t_fall_over_t0", "energy_residual"})
    CHECK(j.contains(key));
  CHECK(std::filesystem::exists(out + "/series.csv"));
  CHECK(std::filesystem::exists(out + "/summary.json"));
  // No temporary files are left behind.
  for (const auto& entry : std::filesystem::directory_iterator(out))
    CHECK(entry.path().extension() != ".tmp");
}

TEST_CASE("bad command lines exit non-zero naming the option, the value and the range", "[unit][cli]") {
  const std::string out = " --out " + temp_dir("cli_bad");
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"reduced falling --f 1.5", "chainsim: error: --f = 1.5 is out of range: allowed 0 <= f <= 1"},
      {"reduced falling --f -0.1", "chainsim: error: --f = -0.1 is out of range: allowed 0 <= f <= 1"},
      {"reduced folded --length -2", "chainsim: error: --length = -2 is out of range: allowed length > 0"},
      {"reduced falling --eps 0", "chainsim: error: --eps = 0 is out of range: allowed 0 < eps < 1"},
      {"reduced falling --eps 1.2", "chainsim: error: --eps = 1.2 is out of range: allowed 0 < eps < 1"},
      {"reduced hanging",
       "chainsim: error: problem = \"hanging\" is not a known problem: allowed falling, folded, sliding"},
      {"reduced sliding --force 1", "chainsim: error: --force = 1 applies to the folded chain only"},
      {"reduced falling --method rk99", "chainsim: error: method = \"rk99\" is not a known integration method"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Result r = run(std::string(c.args) + out);
    CHECK(r.status == 2);
    CHECK_THAT(r.output, Catch::Matchers::StartsWith(c.message));
  }
  // A malformed number is caught by the parser with the option's name.
  const Result r = run("reduced falling --f abc" + out);
  CHECK(r.status != 0);
  CHECK_THAT(r.output, Catch::Matchers::Contains("--f"));
}

TEST_CASE("every command has --help", "[unit][cli]") {
  for (const char* cmd : {"", "reduced", "canonical", "run"}) {
    CAPTURE(cmd);
    const Result r = run(std::string(cmd) + " --help");
    CHECK(r.status == 0);
    CHECK_THAT(r.output, Catch::Matchers::Contains("Usage"));
  }
}

TEST_CASE("chainsim run: a numerical failure exits 3, says what and when, and writes complete outputs", "[unit][cli]") {
  // A straight string at rest, fixed at one end, its free end pushed back towards the fixed end with
  // 1 N: the tension would be −1 N everywhere, which an inextensible string cannot carry.
  const std::string dir = temp_dir("cli_slack");
  std::filesystem::create_directories(dir);
  const std::string scene = dir + "/pushed.toml";
  {
    std::FILE* f = std::fopen(scene.c_str(), "w");
    REQUIRE(f);
    std::fputs("[string]\nnodes = 11\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.0, 0.0]]\n"
               "[ends]\nstart = \"fixed\"\nend = { kind = \"loaded\", force = [-1.0, 0.0] }\n"
               "[solver]\ncheck_slack = true\n[stop]\nt_end = 1.0\n",
               f);
    std::fclose(f);
  }
  const Result r = run("run " + scene + " --out " + dir + "/out");
  CHECK(r.status == 3);
  CHECK_THAT(r.output, Catch::Matchers::StartsWith("chainsim: numerical failure: slack at t = 0 s"));
  std::ifstream stats(dir + "/out/stats.json");
  REQUIRE(stats);
  const auto j = nlohmann::json::parse(stats);
  CHECK(j["status"] == "failed");
  CHECK_THAT(j["error"].get<std::string>(), Catch::Matchers::Contains("slack"));
  // With --json the failure is one JSON object on stdout (the summary up to the failure); the
  // message still goes to stderr.
  const Result json = run("run " + scene + " --json --out " + dir + "/out", true);
  CHECK(json.status == 3);
  const auto failed = nlohmann::json::parse(json.output);
  CHECK(failed["status"] == "failed");
  CHECK(failed["exit_code"] == 3);
  CHECK_THAT(failed["error"].get<std::string>(), Catch::Matchers::StartsWith("slack at t = 0 s"));
  CHECK(failed["root_functions"] == 0);
}

TEST_CASE("every command-line parse error exits 2 with 'chainsim: error:' and what is allowed", "[unit][cli]") {
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"reduced falling --f abc",
       "chainsim: error: --f = 'abc' is not a number: allowed shock dissipation parameter f, 0 <= f <= 1"},
      {"compare folded --nodes 4.5",
       "chainsim: error: --nodes = '4.5' is not an integer: allowed nodes of the string, 4 <= N <= 200001"},
      {"reduced falling --bogus", "chainsim: error: unknown or extra argument --bogus for chainsim reduced; valid "
                                  "options: --help, --f, --eps,"},
      {"reduced falling --f", "chainsim: error: --f needs a value: shock dissipation parameter f, 0 <= f <= 1"},
      {"reduced", "chainsim: error: chainsim reduced needs the argument 'problem' (falling | folded | sliding)"},
      {"run", "chainsim: error: chainsim run needs the argument 'scene'"},
      {"plot", "chainsim: error: chainsim plot needs the argument 'run_dir'"},
      {"", "chainsim: error: a command is required: reduced, canonical, compare, run, plot"},
      {"frob --f 1", "chainsim: error: unknown command 'frob': allowed reduced, canonical, compare, run, plot"},
      {"canonical extra", "chainsim: error: unknown or extra argument extra for chainsim canonical"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Result r = run(c.args);
    CHECK(r.status == 2);
    CHECK_THAT(r.output, Catch::Matchers::StartsWith(c.message));
  }
}

TEST_CASE("with --json every failure of every command prints one error object", "[unit][cli]") {
  const std::string out = temp_dir("cli_json_errors");
  struct Case {
    const char* args;
    const char* command;
    const char* error;
  };
  const Case cases[] = {
      {"reduced falling --f 3 --json", "reduced", "--f = 3 is out of range: allowed 0 <= f <= 1"},
      {"reduced falling --f abc --json", "reduced", "--f = 'abc' is not a number"},
      {"compare falling --nodes 2 --json", "compare", "--nodes = 2 is out of range: allowed 4 <= nodes <= 200001"},
      {"canonical --out /proc/chainsim_no --json", "canonical", "--out = '/proc/chainsim_no' cannot be used"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Result r = run(c.args, true);
    CHECK(r.status == 2);
    const auto j = nlohmann::json::parse(r.output);  // exactly one object
    CHECK(j["status"] == "failed");
    CHECK(j["exit_code"] == 2);
    CHECK(j["command"] == c.command);
    CHECK_THAT(j["error"].get<std::string>(), Catch::Matchers::StartsWith(c.error));
    // The message on stderr is the same.
    const Result both = run(c.args);
    CHECK_THAT(both.output, Catch::Matchers::StartsWith(std::string("chainsim: error: ") + c.error));
  }
  // `run` prints its own object (with the scene), once.
  const Result r = run("run " + out + "/missing.toml --json", true);
  CHECK(r.status == 2);
  const auto j = nlohmann::json::parse(r.output);
  CHECK(j["scene"] == out + "/missing.toml");
  CHECK(j["exit_code"] == 2);
}

TEST_CASE("chainsim plot and compare have --help and plot refuses a missing run directory with exit code 2",
          "[unit][cli]") {
  for (const char* cmd : {"compare", "plot"}) {
    CAPTURE(cmd);
    const Result r = run(std::string(cmd) + " --help");
    CHECK(r.status == 0);
    CHECK_THAT(r.output, Catch::Matchers::Contains("Usage"));
  }
  const std::string missing = temp_dir("cli_plot_missing");
  const Result r = run("plot " + missing);
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Matchers::StartsWith("chainsim: error: RUN_DIR '" + missing + "' does not exist"));
}

// --- a run directory belongs to one run -------------------------------------------------------------

namespace {

/// Starts `chainsim ARGS...` in the background, its stdout and stderr into `log`; returns its pid.
pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<std::string> words = {"chainsim"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, CHAINSIM_BINARY, &actions, nullptr, argv.data(), environ) == 0);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  return WEXITSTATUS(status);
}

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::set<std::string> listing(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

/// A hanging chain of `nodes` nodes swinging for `t_end` s (taut throughout), frames every 0.05 s.
std::string swinging_chain(int nodes, double t_end) {
  return "[string]\nlength = 1.0\nnodes = " + std::to_string(nodes) +
         "\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [0.1, -0.994987437107]]\n[ends]\nstart = "
         "\"fixed\"\n[effects.gravity]\ng = [0.0, -9.81]\n[output]\ninterval = 0.05\n[stop]\nt_end = " +
         std::to_string(t_end) + "\n";
}

/// The run in `dir` is one complete set: nodes.csv's last time is stats.json's t_stop and, without
/// fronts (which hide the nodes in a heap), its rows are stats.json's frames times `nodes`; the files
/// are those of that run (no series.csv of a run with fronts beside a string run's, nothing of
/// another command).
void check_one_run(const std::filesystem::path& dir, int nodes, const std::set<std::string>& files) {
  CHECK(listing(dir) == files);
  const auto stats = nlohmann::json::parse(slurp(dir / "stats.json"));
  CHECK(stats["nodes"] == nodes);
  std::ifstream csv(dir / "nodes.csv");
  std::string line;
  std::getline(csv, line);
  long rows = 0;
  double last = -1;
  while (std::getline(csv, line)) {
    ++rows;
    last = std::stod(line.substr(0, line.find(',')));
  }
  if (stats["num_fronts"] == 0) CHECK(rows == stats["frames"].get<long>() * nodes);
  CHECK(last == stats["t_stop"].get<double>());
}

const std::set<std::string> kStringRunFiles = {"energy.csv", "forces.csv", "frames", "nodes.csv",
                                               "stats.json", "string.pvd", "tension.csv"};

}  // namespace

TEST_CASE("a second run into a directory in use is refused at once, naming the directory and the holder's pid",
          "[unit][cli][output]") {
  const std::filesystem::path dir = temp_dir("cli_lock");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "long.toml") << swinging_chain(101, 1000.0);
  std::ofstream(dir / "short.toml") << swinging_chain(11, 0.1);
  const auto out = dir / "d";
  const pid_t first = spawn({"run", (dir / "long.toml").string(), "--out", out.string(), "--quiet", "--max-wall", "60"},
                            (dir / "first.log").string());
  // Wait until the first run holds the directory (its pid in the lock file).
  const std::string pid = std::to_string(first);
  bool held = false;
  for (int k = 0; k < 1000 && !held; ++k) {
    held = slurp(out / ".chainsim.lock") == pid + "\n";
    if (!held) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!held) kill(first, SIGKILL);
  REQUIRE(held);
  // Every command that writes a run is refused, with exit 2, before touching anything.
  for (const std::string& cmd : {"run " + (dir / "short.toml").string(), std::string("compare falling --nodes 11"),
                                 std::string("reduced falling"), "sweep " + (dir / "short.toml").string() +
                                                                      " --grid string.nodes=11"}) {
    CAPTURE(cmd);
    const Result second = run(cmd + " --out " + out.string());
    CHECK(second.status == 2);
    CHECK_THAT(second.output, Catch::Matchers::StartsWith("chainsim: error: --out = '" + out.string() +
                                                          "' is in use by another chainsim process (pid " + pid + ")"));
  }
  REQUIRE(kill(first, SIGINT) == 0);
  CHECK(wait_exit(first) == 130);
  // The first run's set alone, complete; the lock released.
  check_one_run(out, 101, kStringRunFiles);
  CHECK(nlohmann::json::parse(slurp(out / "stats.json"))["status"] == "interrupted");
  // Free again: the short run now runs there and replaces the set.
  CHECK(run("run " + (dir / "short.toml").string() + " --out " + out.string()).status == 0);
  check_one_run(out, 11, kStringRunFiles);
}

TEST_CASE("two runs started together into one directory never mix: one is refused or they run one after the other",
          "[unit][cli][output]") {
  // A: a falling chain with a heap (writes series.csv); D: a hanging chain (does not). Before the lock
  // they both exited 0 leaving D's stats.json beside A's files, or failed on a shared write probe.
  const std::filesystem::path dir = temp_dir("cli_race");
  std::filesystem::create_directories(dir);
  const std::string source = CHAINSIM_SOURCE_DIR;
  const std::string a = source + "/cases/scenes/falling_chain.toml", d = source + "/cases/scenes/hanging_chain.toml";
  int refused = 0;
  for (int attempt = 0; attempt < 6; ++attempt) {
    CAPTURE(attempt);
    const auto out = dir / ("d" + std::to_string(attempt));
    const pid_t pa = spawn({"run", a, "--out", out.string(), "--quiet"}, (dir / "a.log").string());
    std::this_thread::sleep_for(std::chrono::milliseconds(5 * attempt));
    const pid_t pd = spawn({"run", d, "--out", out.string(), "--quiet"}, (dir / "d.log").string());
    const int code_a = wait_exit(pa), code_d = wait_exit(pd);
    for (const auto& [code, log] : {std::pair{code_a, "a.log"}, std::pair{code_d, "d.log"}}) {
      CHECK((code == 0 || code == 2));
      if (code == 2) {
        ++refused;
        CHECK_THAT(slurp(dir / log), Catch::Matchers::Contains("' is in use by another chainsim process (pid "));
      }
    }
    CHECK((code_a == 0 || code_d == 0));
    // The directory holds the set of the run that wrote last, whole.
    const auto stats = nlohmann::json::parse(slurp(out / "stats.json"));
    std::set<std::string> files = kStringRunFiles;
    if (stats["num_fronts"] == 1) files.insert("series.csv");
    check_one_run(out, stats["nodes"].get<int>(), files);
  }
  CHECK(refused > 0);  // the runs did overlap
}

TEST_CASE("every command that writes a run removes what any of them wrote there before, and nothing else",
          "[unit][cli][output]") {
  const std::filesystem::path dir = temp_dir("cli_clean");
  std::filesystem::create_directories(dir / "d" / "frames");
  const auto out = dir / "d";
  std::ofstream(out / "notes.txt") << "mine\n";
  std::ofstream(out / "frames" / "mine.txt") << "mine\n";
  std::ofstream(dir / "short.toml") << swinging_chain(11, 0.1);
  const std::string to = " --out " + out.string();
  const std::set<std::string> mine = {"notes.txt", "frames"};
  auto with_mine = [&](std::set<std::string> files) {
    files.insert(mine.begin(), mine.end());
    return files;
  };
  REQUIRE(run("compare falling --nodes 11" + to).status == 0);
  CHECK(listing(out) == with_mine({"reduced_series.csv", "string_series.csv", "summary.json"}));
  REQUIRE(run("run " + (dir / "short.toml").string() + to).status == 0);
  CHECK(listing(out) == with_mine(kStringRunFiles));  // frames/ holds both the run's and the user's
  CHECK(std::filesystem::exists(out / "frames" / "mine.txt"));
  REQUIRE(run("reduced falling" + to).status == 0);
  CHECK(listing(out) == with_mine({"series.csv", "summary.json"}));
  REQUIRE(run("sweep " + (dir / "short.toml").string() + " --grid string.nodes=11,12" + to).status == 0);
  CHECK(listing(out) == with_mine({"sweep.csv"}));
  REQUIRE(run("run " + (dir / "short.toml").string() + to).status == 0);
  REQUIRE(run("canonical --quick --nodes 11" + to).status == 0);
  CHECK(listing(out) ==
        with_mine({"falling", "figure_data", "folded", "sliding", "summary.csv", "summary.json"}));
  REQUIRE(run("compare folded --nodes 11" + to).status == 0);
  CHECK(listing(out) == with_mine({"reduced_series.csv", "string_series.csv", "summary.json"}));
  CHECK(slurp(out / "notes.txt") == "mine\n");
  CHECK(slurp(out / "frames" / "mine.txt") == "mine\n");
}

TEST_CASE("the summary lists the outputs the run wrote: no forces.csv where none was written", "[unit][cli][output]") {
  // A loop travelling along its own shape: no gravity, no end loads, so no force columns.
  const std::filesystem::path dir = temp_dir("cli_outputs_line");
  const std::string scene = std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/travelling_loop.toml";
  const Result r = run("run " + scene + " --t-end 0.01 --quiet --out " + (dir / "d").string());
  REQUIRE(r.status == 0);
  CHECK_THAT(r.output, Catch::Matchers::Contains("outputs    " + (dir / "d").string() +
                                                 ": nodes.csv tension.csv energy.csv string.pvd frames/ stats.json\n"));
  CHECK(listing(dir / "d") == std::set<std::string>{"energy.csv", "frames", "nodes.csv", "stats.json", "string.pvd",
                                                    "tension.csv"});
}

TEST_CASE("the printed summary says so when the run starts impulsively", "[unit][cli]") {
  // A chain at rest whose driven end moves at 2 m/s from t = 0: its velocities jump at t = 0. The
  // summary's text said nothing of it (stats.json did). The lifted 0.2 m (0.25 kg/m) moves at v but for
  // the half link lumped on the heap's end node: 1/2 (0.25) (0.2 - h/2) (2)^2 = 0.0875 J with h = 0.05 m.
  const std::filesystem::path dir = temp_dir("cli_impulsive");
  std::filesystem::create_directories(dir);
  const std::filesystem::path scene = dir / "pick_up.toml";
  std::ofstream(scene) << chainsim::test::pick_up(21, 2.0, 0.01, false);
  const Result r = run("run " + scene.string() + " --t-end 0.05 --quiet --out " + (dir / "d").string());
  REQUIRE(r.status == 0);
  CHECK_THAT(r.output, Catch::Matchers::Contains("start      the initial velocities are not compatible"));
  CHECK_THAT(r.output, Catch::Matchers::Contains("giving the string 0.0875 J of kinetic energy"));
  // A run that starts at rest says nothing of it.
  const std::string hanging = std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/hanging_chain.toml";
  const Result quiet = run("run " + hanging + " --t-end 0.01 --quiet --out " + (dir / "e").string());
  REQUIRE(quiet.status == 0);
  CHECK_THAT(quiet.output, !Catch::Matchers::Contains("start      "));
  // Without a driver: a closed square launched along itself at 1 m/s, whose corners turn the velocity; the
  // message named a driven end and the drivers' work, which this scene has not.
  const std::filesystem::path square = dir / "square.toml";
  std::ofstream(square) << "[string]\nclosed = true\nnodes = 40\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], "
                           "[0.25, 0.0], [0.25, 0.25], [0.0, 0.25]]\n[velocity]\nkind = \"tangential\"\nspeed = 1.0\n"
                           "[stop]\nt_end = 0.01\n";
  const Result corner = run("run " + square.string() + " --quiet --out " + (dir / "f").string());
  REQUIRE(corner.status == 0);
  CHECK_THAT(corner.output, Catch::Matchers::Contains("start      the initial velocities are not compatible") &&
                                Catch::Matchers::Contains("[velocity] values that would stretch or shorten links") &&
                                Catch::Matchers::Contains("booked at t = 0 in W_applied") &&
                                !Catch::Matchers::Contains("drivers' work"));
}

TEST_CASE("paths and --set keys that are not UTF-8 give JSON with U+FFFD and the run's own exit code",
          "[unit][cli]") {
  const std::filesystem::path dir = temp_dir("cli_not_utf8");
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "s\xff.toml").string(), out = (dir / "o\xff").string();
  std::ofstream(scene) << swinging_chain(11, 0.1);
  // A run that completes exits 0 and prints its summary (it printed a JSON type_error with exit 1).
  const Result ok = run("run '" + scene + "' --json --out '" + out + "'", true);
  CHECK(ok.status == 0);
  const auto summary = nlohmann::json::parse(ok.output);
  CHECK(summary["status"] == "completed");
  CHECK(summary["out"] == (dir / "o\xef\xbf\xbd").string());
  CHECK(summary["scene"] == (dir / "s\xef\xbf\xbd.toml").string());
  CHECK(std::filesystem::exists(std::filesystem::path(out) / "stats.json"));
  // A bad key is bad input: exit 2 and the error object.
  const Result bad = run("run '" + scene + "' --json --set 'string.\xff=1' --out '" + out + "'", true);
  CHECK(bad.status == 2);
  const auto error = nlohmann::json::parse(bad.output);
  CHECK(error["exit_code"] == 2);
  CHECK_THAT(error["error"].get<std::string>(), Catch::Matchers::Contains("'string.\xef\xbf\xbd' is not a scene key"));
}

TEST_CASE("chainsim compare pulley --json: the heavy Atwood chain over a pulley against exact::pulley_*, and bad "
          "input", "[unit][cli][pulley]") {
  // The command's defaults (101 nodes, u0 = 0.05 m, R = 0.1 m): the bounds of test_contact.cpp's
  // "compare pulley" on 101 nodes; u* from the quadratic 4u² + πRu − (ℓ ℓ_free/2 + 2u0²) = 0 solved here.
  const std::string out = temp_dir("cli_compare_pulley");
  const Result r = run("compare pulley --json --out " + out, true);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.output);
  CAPTURE(r.output);
  for (const char* key : {"t_lift_off", "t_lift_off_exact", "abs_err_t_lift_off", "x_lift_off", "x_lift_off_exact",
                          "abs_err_x_lift_off", "max_abs_err_x", "max_abs_err_tension_short", "max_abs_err_tension_long",
                          "mean_abs_err_tension_short", "mean_abs_err_tension_long", "mean_err_tension_short",
                          "mean_err_tension_long", "max_rel_err_tension",
                          "tension_steps", "u_lift_off_exact", "energy_residual", "momentum_residual", "nodes", "u0",
                          "R"})
    CHECK(j.contains(key));
  CHECK(j["problem"] == "pulley");
  const double pi = 3.141592653589793, free = 1 - pi * 0.1, c = 0.5 * free + 2 * 0.05 * 0.05;
  CHECK(j["u_lift_off_exact"].get<double>() == Approx((-pi * 0.1 + std::sqrt(pi * pi * 0.01 + 16 * c)) / 8).epsilon(1e-12));
  CHECK(j["x_lift_off_exact"].get<double>() == Approx(0.5 * free + j["u_lift_off_exact"].get<double>()).epsilon(1e-14));
  // Links along the arc (model.md §10): measured 3.3e-8 s, 2.8e-8 m, 5.4e-8 m, 6.3e-7 N, 2.4e-12.
  CHECK(j["abs_err_t_lift_off"].get<double>() < 1e-6);
  CHECK(j["abs_err_x_lift_off"].get<double>() < 1e-6);
  CHECK(j["max_abs_err_x"].get<double>() < 1e-6);
  CHECK(j["mean_abs_err_tension_short"].get<double>() < 1e-5);
  CHECK(j["energy_residual"].get<double>() < 1e-10);
  CHECK(j["momentum_residual"].get<double>() < 1e-12);
  for (const char* file : {"string_series.csv", "exact_series.csv", "summary.json"})
    CHECK(std::filesystem::exists(out + "/" + file));
  CHECK_THAT(chainsim::test::read(std::filesystem::path(out) / "exact_series.csv"),
             Catch::Matchers::StartsWith("t,x,x_dot,u,tension_short,tension_long,lift_off_margin\n"));
  const std::string bad = " --out " + temp_dir("cli_compare_pulley_bad");
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"compare pulley --u0 0", "chainsim: error: --u0 = 0 is out of range: allowed 0 < u0 < 0.34292"},
      {"compare pulley --u0 0.35", "chainsim: error: --u0 = 0.35 is out of range: allowed 0 < u0 < 0.34292"},
      {"compare pulley --R 0", "chainsim: error: --R = 0 is out of range: allowed 0 < R < 0.31830"},
      {"compare pulley --R 0.4", "chainsim: error: --R = 0.4 is out of range: allowed 0 < R < 0.31830"},
      {"compare pulley --x0 0.3", "chainsim: error: --x0 = 0.3: compare pulley starts from --u0"},
      {"compare pulley --f 0.5", "chainsim: error: --f = 0.5: compare pulley has no f"},
      // refused when given, at the default value too (they were taken silently)
      {"compare pulley --f 0.83", "chainsim: error: --f = 0.83: compare pulley has no f"},
      {"compare pulley --eps 0.01", "chainsim: error: --eps = 0.01: compare pulley stops at the lift-off and has no cutoff"},
      {"compare edge --eps 0.01", "chainsim: error: --eps = 0.01: compare edge stops at the lift-off and has no cutoff"},
      {"compare peg --eps 0.01", "chainsim: error: --eps = 0.01: compare peg stops at the lift-off and has no cutoff"},
      {"compare pulley --nodes 2", "chainsim: error: --nodes = 2 is out of range: allowed 3 <= nodes <= 200001"},
      {"compare edge --u0 0.1", "chainsim: error: --u0 = 0.1: only compare pulley takes --u0"},
      {"compare folded --R 0.1", "chainsim: error: --R = 0.1: only compare pulley takes --R"},
  };
  for (const Case& k : cases) {
    CAPTURE(k.args);
    const Result b = run(std::string(k.args) + bad);
    CHECK(b.status == 2);
    CHECK_THAT(b.output, Catch::Matchers::StartsWith(k.message));
  }
}

TEST_CASE("chainsim compare edge, peg, pulley: an implicit --method is refused at the option, as scenes refuse it",
          "[unit][cli][edge][pulley]") {
  // Scenes refuse implicit methods with an edge or an obstacle (their Newton systems know neither); the
  // comparisons build the same string over an edge or a pulley, so they refuse them too, before the run
  // (compare pulley used to run dirk4 with the contact module, and compare edge failed inside its first step).
  const std::string bad = " --out " + temp_dir("cli_compare_implicit");
  for (const char* problem : {"edge", "peg", "pulley"})
    for (const char* method : {"dirk4", "dirk2", "ARKODE_ARK324L2SA_DIRK_4_2_3"}) {
      const std::string args = std::string("compare ") + problem + " --method " + method;
      CAPTURE(args);
      const Result r = run(args + bad);
      CHECK(r.status == 2);
      CHECK_THAT(r.output, Catch::Matchers::StartsWith(std::string("chainsim: error: --method = ") + method +
                                                       " is implicit, and implicit methods do not meet") &&
                               Catch::Matchers::Contains("allowed an explicit method"));
    }
}

TEST_CASE("chainsim compare edge --json: the chain off a table's edge against exact::edge_*, and bad input",
          "[unit][cli][edge]") {
  // The bounds of test_edge_front.cpp ("a chain sliding off a table matches exact::edge_*"), here with the
  // command's defaults (101 nodes, x0 = 0.2, erk5 at rtol 1e-9).
  for (const char* f : {"0", "0.5"}) {
    CAPTURE(f);
    const std::string out = temp_dir(std::string("cli_compare_edge_") + f);
    const Result r = run(std::string("compare edge --json --f ") + f + " --out " + out, true);
    REQUIRE(r.status == 0);
    const auto j = nlohmann::json::parse(r.output);
    CAPTURE(r.output);
    for (const char* key : {"t_lift_off", "t_lift_off_exact", "abs_err_t_lift_off", "x_lift_off", "x_lift_off_exact",
                            "abs_err_x_lift_off", "max_abs_err_x", "max_abs_err_tension", "max_rel_err_tension",
                            "t_stop_over_t0", "t_stop_over_t0_exact", "rel_err_t_stop", "energy_residual",
                            "momentum_residual", "events", "nodes", "x0", "f"})
      CHECK(j.contains(key));
    CHECK(j["problem"] == "edge");
    CHECK(j["status"] == "stopped");
    REQUIRE(j["events"].size() == 1);
    CHECK(j["events"][0]["kind"] == "lift_off");
    // x* = (ℓ + √(ℓ² + 8 x0²))/4 at f = 0, independently of exact::edge_lift_off_x.
    if (std::string(f) == "0") CHECK(j["x_lift_off_exact"].get<double>() == Approx((1 + std::sqrt(1.32)) / 4));
    CHECK(j["abs_err_t_lift_off"].get<double>() < 1e-7);
    CHECK(j["abs_err_x_lift_off"].get<double>() < 1e-7);
    CHECK(j["max_abs_err_x"].get<double>() < 1e-7);
    CHECK(j["max_abs_err_tension"].get<double>() < 1e-6);
    CHECK(j["energy_residual"].get<double>() < 1e-8);
    CHECK(j["momentum_residual"].get<double>() < 1e-8);
    for (const char* file : {"string_series.csv", "exact_series.csv", "summary.json"})
      CHECK(std::filesystem::exists(out + "/" + file));
  }
  const std::string out = " --out " + temp_dir("cli_compare_edge_bad");
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"compare edge --f 1.5", "chainsim: error: --f = 1.5 is out of range: allowed 0 <= f <= 1"},
      {"compare edge --f -0.5", "chainsim: error: --f = -0.5 is out of range: allowed 0 <= f <= 1"},
      {"compare edge --x0 0", "chainsim: error: --x0 = 0 is out of range: allowed 0 < x0 < 1"},
      {"compare edge --x0 1", "chainsim: error: --x0 = 1 is out of range: allowed 0 < x0 < 1"},
      {"compare edge --nodes 2", "chainsim: error: --nodes = 2 is out of range: allowed 3 <= nodes <= 200001"},
      {"compare edge --eta0 0.3", "chainsim: error: --eta0 = 0.3: compare edge starts from --x0"},
      {"compare sliding --x0 0.3", "chainsim: error: --x0 = 0.3: only compare edge takes --x0"},
      {"compare hanging", "chainsim: error: problem = \"hanging\" is not a known problem: allowed falling, folded, "
                          "sliding, edge"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Result r = run(std::string(c.args) + out);
    CHECK(r.status == 2);
    CHECK_THAT(r.output, Catch::Matchers::StartsWith(c.message));
  }
}
