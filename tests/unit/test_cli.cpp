// The chainsim executable: exit codes, error messages and the --json summary.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

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

std::string temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("chainsim_test_" + name);
  std::filesystem::remove_all(dir);
  return dir.string();
}

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
