// The main job, `chainsim canonical` (run here with --quick: f = 0 and 0.83): each canonical problem on
// the string solver with front tracking, as the reduced ODE and as the exact quadrature. The stop times
// are checked against the quadrature computed here from the closed forms, and the figures are drawn.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "cases/reduced/exact_solutions.hpp"
#include "tests/unit/test_scene_support.hpp"

namespace {

namespace fs = std::filesystem;

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The exact scaled time t/t0 at which each problem stops: the falling chain at η = ε, the folded
/// chain at η = 1 − ε, the sliding chain at η = 1 (its whole length hanging).
double quadrature_stop(const std::string& problem, double f, double eta0, double eps) {
  using namespace chainsim::exact;
  if (problem == "falling") return falling_xi(f, eps, eta0);
  if (problem == "folded") return folded_xi(f, 1 - eps, eta0);
  REQUIRE(problem == "sliding");
  return sliding_fall_time(f, eta0);
}

/// A CSV file of numbers: the header, then the rows.
std::vector<std::vector<double>> read_numbers(const fs::path& path, std::vector<std::string>& header) {
  std::ifstream in(path);
  REQUIRE(in);
  std::string line, cell;
  std::getline(in, line);
  std::stringstream names(line);
  while (std::getline(names, cell, ',')) header.push_back(cell);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    rows.emplace_back();
    while (std::getline(cells, cell, ',')) rows.back().push_back(std::stod(cell));
    REQUIRE(rows.back().size() == header.size());
  }
  return rows;
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

}  // namespace

TEST_CASE("chainsim canonical: string solver, reduced ODE and quadrature agree, and the figures are drawn",
          "[problems][cli]") {
  const fs::path dir = chainsim::test::temp_dir("canonical_job");
  const std::string binary = CHAINSIM_BINARY;
  REQUIRE(shell(binary + " canonical --quick --out " + dir.string() + " > " + (dir / "log.txt").string() + " 2>&1") == 0);
  std::stringstream log;
  log << std::ifstream(dir / "log.txt").rdbuf();
  CAPTURE(log.str());
  CHECK_THAT(log.str(), Catch::Matchers::Contains((dir / "summary.csv").string()));
  CHECK_THAT(log.str(), Catch::Matchers::Contains((dir / "figures").string()));

  // 1. The stop times, per problem and f, three ways.
  nlohmann::json rows;
  std::ifstream(dir / "summary.json") >> rows;
  REQUIRE(rows.size() == 6);  // 3 problems x f = 0, 0.83
  for (const auto& r : rows) {
    const std::string problem = r["problem"];
    const double f = r["f"], eta0 = r["eta0"], eps = r["eps"];
    CAPTURE(problem, f);
    const double tq = quadrature_stop(problem, f, eta0, eps);
    const double ts = r["t_stop_over_t0_string"], tr = r["t_stop_over_t0_reduced"];
    CHECK(rel(ts, tr) <= 1e-9);
    CHECK(rel(tr, tq) <= 1e-10);
    CHECK(rel(ts, tq) <= 1e-9);
    // The string run closes its energy ledger (model.md: the shock's dissipation is booked as W_shocks).
    CHECK(r["energy_residual_string"].get<double>() <= 1e-7);
  }

  // 2. The string solver's points of the fall-time figure against the quadrature at the same cutoff.
  std::vector<std::string> header;
  const auto fall = read_numbers(dir / "figure_data" / "fall_time_string.csv", header);
  REQUIRE(fall.size() == 3);  // f = 0, 0.5, 1
  auto at = [&](const std::vector<double>& row, const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    return row[static_cast<std::size_t>(it - header.begin())];
  };
  const double eps_fall = 1e-4;  // falling and folded stop there (sliding: when the whole chain hangs)
  for (const auto& row : fall) {
    const double f = at(row, "f");
    CAPTURE(f);
    CHECK(rel(at(row, "falling_string"), quadrature_stop("falling", f, 1.0, eps_fall)) <= 1e-9);
    CHECK(rel(at(row, "folded_string"), quadrature_stop("folded", f, 0.0, eps_fall)) <= 1e-9);
    CHECK(rel(at(row, "sliding0_string"), quadrature_stop("sliding", f, 0.0, eps_fall)) <= 1e-9);
  }

  // 3. The per-problem outputs and the figure data.
  for (const char* p : {"falling", "folded", "sliding"}) {
    CHECK(fs::exists(dir / p / "series.csv"));
    CHECK(fs::exists(dir / p / "summary.json"));
    for (const char* kind : {"ode", "exact", "string", "string_series"})
      CHECK(fs::exists(dir / "figure_data" / (std::string(p) + "_f0.83_" + kind + ".csv")));
  }

  // 4. The figures, as scripts/quickstart.sh demo draws them (with the general scene).
  if (shell("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") != 0) {
    WARN("/usr/bin/python3 has no matplotlib: the figures are not drawn");
    return;
  }
  const std::string scene = std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/curved_falling_chain.toml";
  REQUIRE(shell(binary + " run " + scene + " --out " + (dir / "curved_falling_chain").string() + " > /dev/null") == 0);
  REQUIRE(shell("/usr/bin/python3 " + std::string(CHAINSIM_SOURCE_DIR) + "/scripts/plot_canonical.py " +
                dir.string() + " --scene " + scene + " > /dev/null") == 0);
  for (const char* name : {"fall_time_vs_f", "falling_chain", "folded_chain", "sliding_chain", "falling_snapshots",
                           "folded_snapshots", "sliding_snapshots", "agreement", "curved_falling_chain"}) {
    CAPTURE(name);
    const fs::path png = dir / "figures" / (std::string(name) + ".png");
    REQUIRE(fs::exists(png));
    CHECK(fs::file_size(png) > 10000);
  }
}
