// `chainsim sweep SCENE --grid KEY=V1,V2,... [--grid ...] [--set KEY=VALUE] [--t-end T] [--jobs N] --out DIR`:
// runs the scene at every point of the grid (cases/scene/scene_sweep.hpp) on N threads and writes
// DIR/sweep.csv, one row per point: the grid keys (values as written), status, error, wall_time_s
// and the run's summary (stats.json, flattened). A failed point is a row with its error; the sweep
// goes on. Ctrl-C stops the running points ("interrupted"), writes the rows and exits 130.
//
//   $ chainsim sweep cases/scenes/falling_chain.toml --grid f=0,0.5,1.5 --grid string.nodes=51,101 --out results/sw
//   sweep      cases/scenes/falling_chain.toml: 6 points on 2 threads in 0.321 s
//   status     2 error, 4 stopped
//   outputs    results/sw/sweep.csv
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <ostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/cli/commands.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_sweep.hpp"
#include "mesh/errors.hpp"
#include "solver/interrupt.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

/// One CSV field: numbers and booleans as JSON writes them (numbers: the shortest text that reads back
/// to the same double), text quoted when it holds a comma, a quote or a line break.
std::string csv_field(const nlohmann::json& value) {
  if (value.is_null()) return "";
  if (!value.is_string()) return value.dump();
  const std::string text = value.get<std::string>();
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

int run_sweep_command(const SweepCommandOptions& options, std::ostream& out) {
  std::vector<SweepAxis> grid;
  for (const std::string& g : options.grid) grid.push_back(parse_grid_axis(g));
  const std::vector<std::vector<std::string>> points = sweep_points(grid);
  if (options.jobs < 0)
    throw InputError(fmt::format("--jobs = {} is out of range: allowed jobs >= 1 (0: every core)", options.jobs));
  const int jobs = options.jobs > 0 ? options.jobs : std::max(1u, std::thread::hardware_concurrency());
  // The scene is read once and checked with the fixed overrides before any point runs: a bad file is
  // the command's error (exit 2), a bad point is a row.
  const SweepScene scene{read_scene_file(options.scene), options.scene, options.overrides, options.t_end};
  parse_scene_text(scene.text, scene.source, scene.overrides);  // the file's own errors, located
  check_sweep_points(scene, points);                             // a key set twice, before any output
  const std::filesystem::path dir = options.out.empty()
                                        ? std::filesystem::path("results") / "sweep" /
                                              std::filesystem::path(options.scene).stem()
                                        : std::filesystem::path(options.out);
  install_sigint_handler();  // SIGINT, SIGTERM: the running points stop, the rows are written
  const RunDirectory run_dir(dir);  // held until sweep.csv is written
  run_dir.clear();

  const auto start = std::chrono::steady_clock::now();
  const std::vector<nlohmann::json> rows = run_sweep(scene, points, jobs);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Columns: the grid keys, status, error, wall_time_s, then every summary key in order of appearance.
  std::vector<std::string> columns;
  for (const SweepAxis& axis : grid) columns.push_back(axis.key);
  const std::size_t fixed = columns.size();
  for (const char* c : {"status", "error", "wall_time_s"}) columns.emplace_back(c);
  for (const nlohmann::json& row : rows)
    for (const auto& [key, value] : row.items())
      if (std::find(columns.begin() + static_cast<long>(fixed), columns.end(), key) == columns.end())
        columns.push_back(key);
  AtomicFile file(dir / "sweep.csv");
  std::ostream& csv = file.stream();
  for (std::size_t c = 0; c < columns.size(); ++c) csv << (c ? "," : "") << csv_field(columns[c]);
  csv << '\n';
  std::map<std::string, int> statuses;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      csv << (c ? "," : "");
      if (c < fixed)
        csv << csv_field(points[k][c].substr(points[k][c].find('=') + 1));
      else if (rows[k].contains(columns[c]))
        csv << csv_field(rows[k][columns[c]]);
    }
    csv << '\n';
    ++statuses[rows[k]["status"].get<std::string>()];
  }
  file.commit();

  std::string counts;
  for (const auto& [status, n] : statuses) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, status);
  if (options.json) {
    out << json_text({{"points", rows.size()}, {"jobs", jobs}, {"wall_s", wall}, {"statuses", statuses},
                      {"out", (dir / "sweep.csv").string()}})
        << '\n';
  } else {
    out << fmt::format("sweep      {}: {} points on {} thread{} in {:.3g} s\n", options.scene, rows.size(), jobs,
                       jobs == 1 ? "" : "s", wall);
    out << fmt::format("status     {}\n", counts);
    out << fmt::format("outputs    {}\n", (dir / "sweep.csv").string());
  }
  return statuses.count("interrupted") ? 130 : 0;
}

}  // namespace chainsim
