// What every string run writes, with or without fronts: frames at the exact multiples of
// [output] interval plus the state at the stop, the fronts as a second ParaView part, the VTK
// encoding chosen by the scene, and slack reported by default (stop) or recorded (warn).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/cli/run_command.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::read;
using test::temp_dir;

namespace {

/// Runs `text` with `chainsim run --json` into dir/out; returns (exit code, printed summary).
std::pair<int, nlohmann::json> run_json(const std::filesystem::path& dir, const std::string& text) {
  std::ofstream(dir / "scene.toml") << text;
  RunCommandOptions options;
  options.scene = (dir / "scene.toml").string();
  options.out = (dir / "out").string();
  options.json = true;
  options.quiet = true;
  std::ostringstream out;
  int code = 0;
  try {
    code = run_scene_command(options, out);
  } catch (const NumericalError&) {
    code = 3;
  }
  return {code, nlohmann::json::parse(out.str())};
}

/// The distinct times of the first column of a CSV file, in order.
std::vector<double> times(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<double> t;
  while (std::getline(in, line)) {
    const double value = std::stod(line.substr(0, line.find(',')));
    if (t.empty() || value != t.back()) t.push_back(value);
  }
  return t;
}

}  // namespace

TEST_CASE("a run with fronts writes frames at the exact output times and the state at the stop",
          "[unit][scene]") {
  const auto dir = temp_dir("outputs_fronts");
  const auto [code, j] = run_json(dir, test::kFallingBase + "[output]\ninterval = 0.05\n");
  REQUIRE(code == 0);
  REQUIRE(j["status"] == "stopped");
  const double t_stop = j["t_stop"].get<double>();
  const std::vector<double> t = times(dir / "out" / "nodes.csv");
  // 0, 0.05, ..., then the stop (0.38 s for this chain): every multiple below the stop, exactly.
  const auto multiples = static_cast<std::size_t>(std::floor(t_stop / 0.05)) + 1;
  REQUIRE(t.size() == multiples + 1);
  for (std::size_t k = 0; k < multiples; ++k) CHECK(t[k] == static_cast<double>(k) * 0.05);
  CHECK(t.back() == t_stop);
  CHECK(times(dir / "out" / "energy.csv") == t);
  CHECK(times(dir / "out" / "forces.csv") == t);
  // ParaView: the string (part 0) and its fronts (part 1) at every frame, binary by default.
  const std::string pvd = read(dir / "out" / "string.pvd");
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::string frame = "frames/frame_" + fmt::format("{:04d}", k) + ".vtp";
    const std::string fronts = "frames/fronts_" + fmt::format("{:04d}", k) + ".vtp";
    CHECK(pvd.find("part=\"0\" file=\"" + frame + "\"") != std::string::npos);
    CHECK(pvd.find("part=\"1\" file=\"" + fronts + "\"") != std::string::npos);
    CHECK(std::filesystem::exists(dir / "out" / fronts));
  }
  const std::string last = read(dir / "out" / "frames" / fmt::format("fronts_{:04d}.vtp", t.size() - 1));
  CHECK(last.find("NumberOfVerts=\"1\"") != std::string::npos);
  CHECK(last.find("Name=\"plane_normal\"") != std::string::npos);
  CHECK(last.find("format=\"appended\"") != std::string::npos);
  // [output] vtk_encoding = "ascii": the same files as text.
  const auto [code_ascii, j_ascii] =
      run_json(dir, test::kFallingBase + "[output]\ninterval = 0.05\nvtk_encoding = \"ascii\"\n");
  REQUIRE(code_ascii == 0);
  CHECK(read(dir / "out" / "frames" / "frame_0000.vtp").find("format=\"ascii\"") != std::string::npos);
}

TEST_CASE("slack is found by default and stops the run, and with slack = warn it is recorded and the run goes on",
          "[unit][scene]") {
  // A straight string at rest, fixed at its start and pushed along itself at its free end by 1 N
  // (no gravity): the exact tension is −1 N in every link from t = 0.
  const std::string pushed = "[string]\nnodes = 11\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.0, 0.0]]\n"
                             "[ends]\nstart = \"fixed\"\nend = { kind = \"loaded\", force = [-1.0, 0.0] }\n"
                             "[stop]\nt_end = 0.1\n";
  const auto dir = temp_dir("outputs_slack");
  const auto [code, j] = run_json(dir, pushed);  // no slack key: the default, stop
  CHECK(code == 3);
  CHECK(j["status"] == "failed");
  CHECK(j["slack"]["policy"] == "stop");
  CHECK(j["slack"]["detected"] == true);
  CHECK(j["slack"]["t"] == 0.0);
  CHECK_THAT(j["slack"]["T"].get<double>(), Catch::Matchers::WithinRel(-1.0, 1e-9));
  CHECK(nlohmann::json::parse(read(dir / "out" / "stats.json"))["slack"]["detected"] == true);

  const auto [code_warn, warn] = run_json(dir, pushed + "[solver]\nslack = \"warn\"\n");
  CHECK(code_warn == 0);
  CHECK(warn["status"] == "completed");
  CHECK(warn["slack"]["policy"] == "warn");
  CHECK(warn["slack"]["detected"] == true);
  CHECK(warn["slack"]["t"] == 0.0);
  const double s = warn["slack"]["s"].get<double>();
  CHECK(s > 0);
  CHECK(s < 1);
  CHECK_THAT(warn["slack"]["T"].get<double>(), Catch::Matchers::WithinRel(-1.0, 1e-9));
  CHECK(warn["slack"]["message"].get<std::string>().rfind("slack at t = 0 s: link ", 0) == 0);

  const auto [code_ignore, ignore] = run_json(dir, pushed + "[solver]\nslack = \"ignore\"\n");
  CHECK(code_ignore == 0);
  CHECK(ignore["slack"]["detected"] == false);
}

TEST_CASE("with slack = allow the summary counts the snaps and gives what they dissipated (issue 27)", "[unit][scene][slack]") {
  // The chain thrown up over its fixed end (cases/scenes/thrown_chain.toml, 21 nodes): it goes slack and is
  // caught. The summary's "slack" had only {policy, detected: false}, and the text said "allowed: links go slack"
  // whether any did or not; it now has the count and W_snap, W_snap_supports at the last frame (energy.csv's last
  // row).
  const std::string thrown = "[string]\nlength = 1.0\ndensity = 0.1\nnodes = 21\n[shape]\nkind = \"polyline\"\n"
                             "points = [[0.0, 0.0], [1.0, 0.0]]\n[velocity]\nkind = \"rotation\"\nomega = 7.0\n"
                             "center = [0.0, 0.0]\n[ends]\nstart = \"fixed\"\n[effects.gravity]\ng = [0.0, -9.81]\n"
                             "[solver]\nslack = \"allow\"\n[output]\ninterval = 0.25\n[stop]\nt_end = 1.0\n";
  const auto dir = temp_dir("outputs_snaps");
  const auto [code, j] = run_json(dir, thrown);
  REQUIRE(code == 0);
  const nlohmann::json& slack = j["slack"];
  CHECK(slack["policy"] == "allow");
  CHECK(slack["snaps"].get<long long>() >= 1);
  CHECK(slack["ledger_t"] == 1.0);
  // energy.csv's last row: t, K, V, W_applied, drift, W_snap, W_snap_supports, W_links.
  std::ifstream in(dir / "out" / "energy.csv");
  std::string line, last;
  while (std::getline(in, line)) last = line;
  std::vector<double> row;
  std::stringstream cells(last);
  for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
  REQUIRE(row.size() == 8);
  CHECK(slack["W_snap"].get<double>() == row[5]);
  CHECK(slack["W_snap"].get<double>() < 0);  // perfectly inelastic snaps dissipate
  CHECK(slack["W_snap_supports"].get<double>() == row[6]);
  CHECK(nlohmann::json::parse(read(dir / "out" / "stats.json"))["slack"]["snaps"] == slack["snaps"]);
  // Without allow there is no count.
  const auto [code_stop, stop] = run_json(dir, thrown.substr(0, thrown.find("[solver]")) + "[stop]\nt_end = 0.1\n");
  CHECK(code_stop == 0);
  CHECK_FALSE(stop["slack"].contains("snaps"));
}

TEST_CASE("[solver] max_wall_s ends a scene's run after that wall-clock time, with its outputs", "[unit][scene]") {
  const auto dir = temp_dir("outputs_max_wall");
  // A hanging chain asked for 1e4 s of motion at rtol 1e-12: minutes of work, cut at 0.2 s of wall time.
  const std::string text = test::kSceneBase.substr(0, test::kSceneBase.find("[stop]")) +
                           "[solver]\nrtol = 1e-12\natol = 1e-14\nmax_wall_s = 0.2\n[stop]\nt_end = 1e4\n";
  const auto start = std::chrono::steady_clock::now();
  const auto [code, j] = run_json(dir, text);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(code == 3);
  CHECK(j["status"] == "failed");
  CHECK_THAT(j["error"].get<std::string>(), Catch::Matchers::Contains("wall-clock budget max_wall_s = 0.2 s"));
  CHECK(j["t_stop"].get<double>() > 0);
  CHECK(j["t_stop"].get<double>() < 1e4);
  CHECK(wall < 10);
  CHECK(std::filesystem::exists(dir / "out" / "stats.json"));
}
