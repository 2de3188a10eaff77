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
