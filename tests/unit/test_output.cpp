// A run directory belongs to one run (solver/output.hpp): RunDirectory locks it (a second holder, in
// this process or another, is refused at once naming the pid; the lock dies with the process),
// temporary files have names no other writer uses, and the clean-up removes what any chainsim
// command may have written there, stray temporary files included, and never another file.
#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <random>
#include <set>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include "mesh/errors.hpp"
#include "solver/output.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using test::temp_dir;

namespace {

std::set<std::string> entries(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

std::string refusal(const std::filesystem::path& dir) {
  try {
    RunDirectory second(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a run directory is held by one RunDirectory at a time, and the lock dies with its holder",
          "[unit][output]") {
  const auto dir = temp_dir("run_directory_lock") / "out";
  const std::string pid = std::to_string(static_cast<long>(::getpid()));
  {
    const RunDirectory first(dir);
    CHECK(std::filesystem::is_directory(dir));
    CHECK(test::read(dir / RunDirectory::kLockName) == pid + "\n");
    // A second holder in this process is refused at once, naming the directory and the pid.
    const std::string message = refusal(dir);
    CHECK_THAT(message, Contains("--out = '" + dir.string() + "' is in use by another run in this process (pid " +
                                 pid + ")"));
    // ... and so is one in another process (a child: its own open file, its own pid).
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      const std::string m = refusal(dir);
      ::_exit(m.find("is in use by another chainsim process (pid " + pid + ")") != std::string::npos ? 0 : 1);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK((WIFEXITED(status) && WEXITSTATUS(status) == 0));
  }
  // Released: the lock file is gone and the directory can be held again.
  CHECK_FALSE(std::filesystem::exists(dir / RunDirectory::kLockName));
  CHECK_NOTHROW(RunDirectory(dir));
  // A holder that dies without releasing (no destructor: _exit) leaves a lock file that blocks nothing.
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    new RunDirectory(dir);  // never destroyed
    ::_exit(0);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  CHECK(std::filesystem::exists(dir / RunDirectory::kLockName));
  CHECK(test::read(dir / RunDirectory::kLockName) == std::to_string(child) + "\n");
  CHECK_NOTHROW(RunDirectory(dir));
}

TEST_CASE("temporary files are named for the process and the file, so no two writers share one",
          "[unit][output]") {
  const auto dir = temp_dir("atomic_names");
  AtomicFile a(dir / "nodes.csv"), b(dir / "nodes.csv");
  a.stream() << "a\n";
  b.stream() << "b\n";
  const std::set<std::string> names = entries(dir);
  REQUIRE(names.size() == 2);  // two temporary files, not one shared
  const std::string prefix = ".nodes.csv." + std::to_string(static_cast<long>(::getpid())) + ".";
  for (const std::string& name : names) {
    CHECK(name.rfind(prefix, 0) == 0);
    CHECK(name.substr(name.size() - 4) == ".tmp");
  }
  a.commit();
  CHECK(test::read(dir / "nodes.csv") == "a\n");
}

TEST_CASE("the clean-up removes what any chainsim command writes, stray temporary files included, and nothing else",
          "[unit][output]") {
  const auto dir = temp_dir("clean_up");
  auto touch = [&](const std::string& name) {
    std::filesystem::create_directories((dir / name).parent_path());
    std::ofstream(dir / name) << "x\n";
  };
  // What run, compare, reduced, canonical, sweep and plot write, and temporary files of killed writers.
  const std::vector<std::string> chainsim_files = {
      "stats.json", "nodes.csv", "tension.csv", "energy.csv", "forces.csv", "series.csv", "string.pvd",
      "frames/frame_0000.vtp", "frames/fronts_0000.vtp", "string_series.csv", "reduced_series.csv", "summary.json",
      "summary.csv", "sweep.csv", "figure_data/falling_f0_ode.csv", "falling/series.csv", "folded/summary.json",
      "sliding/series.csv", "figures/compare.png", "figures/animation.mp4", ".nodes.csv.123.4.tmp",
      ".nodes.csv.tmp", ".stats.json.99.0.tmp", "frames/.frame_0003.vtp.77.12.tmp",
      "falling/.series.csv.5.6.tmp", ".chainsim_write_probe.8.9.tmp"};
  // A user's own files, some inside chainsim's directories, some looking like temporary files.
  const std::vector<std::string> user_files = {"notes.txt", "my.csv", ".my.csv.1.2.tmp", "frames/readme.txt",
                                               "figures/sketch.svg", "falling/nodes.txt", ".tmp", "stats.json.bak"};
  for (const auto& name : chainsim_files) touch(name);
  for (const auto& name : user_files) touch(name);
  clear_run_outputs(dir);
  for (const auto& name : chainsim_files) CHECK_FALSE(std::filesystem::exists(dir / name));
  for (const auto& name : user_files) CHECK(std::filesystem::exists(dir / name));
  // chainsim's directories stay only where a user's file is left in them.
  CHECK(entries(dir) == std::set<std::string>{"notes.txt", "my.csv", ".my.csv.1.2.tmp", "frames", "figures",
                                              "falling", ".tmp", "stats.json.bak"});
  // What is left is no output (the summary's list of a run's outputs names none of it).
  CHECK(outputs_present(dir).empty());
  touch("frames/frame_0000.vtp");
  touch("falling/summary.json");
  touch("stats.json");
  CHECK(outputs_present(dir) == std::vector<std::string>{"frames/", "stats.json", "falling/"});
}

TEST_CASE("the clean-up refuses a directory whose problem subdirectory another run holds", "[unit][output]") {
  const auto dir = temp_dir("clean_up_nested");
  std::filesystem::create_directories(dir / "folded");
  std::ofstream(dir / "folded" / "series.csv") << "x\n";
  {
    const RunDirectory held(dir / "folded");
    CHECK_THROWS_WITH(clear_run_outputs(dir), Contains("is in use by"));
    CHECK(std::filesystem::exists(dir / "folded" / "series.csv"));
  }
  clear_run_outputs(dir);
  CHECK_FALSE(std::filesystem::exists(dir / "folded"));
}

TEST_CASE("JSON text replaces bytes that are not UTF-8 instead of failing", "[unit][output]") {
  const nlohmann::json j = {{"out", std::string("d\xff")}, {"ok", "caf\xc3\xa9"}};
  const std::string text = json_text(j);
  CHECK(text == "{\"ok\":\"caf\xc3\xa9\",\"out\":\"d\xef\xbf\xbd\"}");
  CHECK(nlohmann::json::parse(text)["out"] == "d\xef\xbf\xbd");
}

TEST_CASE("CSV numbers over the whole double range are fmt's shortest text and read back exactly", "[unit][output]") {
  // The writer lays out the shortest digits itself (fmt's "{}" rules): every finite double, random bit
  // patterns and the edges of fmt's switch between plain and exponent notation (1e-5, 1e16), must give
  // fmt::format("{}")'s text, and that text must read back (strtod) to the same bits.
  std::vector<double> values;
  std::mt19937_64 random(20261126);
  for (int k = 0; k < 60000; ++k) {
    std::uint64_t bits = random();
    double v = 0;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isfinite(v)) values.push_back(v);
  }
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 40000; ++k) values.push_back(unit(random) * std::pow(10.0, (k % 44) - 22));  // typical sizes
  for (const double edge : {1e-5, 1e-4, 1e15, 1e16, 1e17, 1e100, 1e-100, 1e300, 1e-300, 0.1, 123.456, 5e-324,
                            1.7976931348623157e308, 9007199254740993.0, 1e15 + 0.5, 0.000123456789012345})
    for (const double v : {edge, std::nextafter(edge, 0.0), std::nextafter(edge, 1e308)})
      for (const double signed_v : {v, -v}) values.push_back(signed_v);
  const auto dir = temp_dir("csv_number_range");
  const auto path = dir / "range.csv";
  std::string expected = "t,a\n";
  {
    CsvWriter csv(path, {"t", "a"});
    for (const double v : values) {
      csv.row({0.0, v});  // the second column: the writer's general path
      expected += "0," + fmt::format("{}", v) + "\n";
    }
    csv.commit();
  }
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(written.size() == expected.size());
  CHECK(written == expected);
  // Read back: every value's text gives its bits.
  std::size_t at = written.find('\n') + 1, bad = 0;  // the first row
  for (const double v : values) {
    at += 2;  // past "0,": the row's second column
    const std::size_t line_end = written.find('\n', at);
    const double back = std::strtod(written.substr(at, line_end - at).c_str(), nullptr);
    if (std::memcmp(&back, &v, sizeof v) != 0) ++bad;
    at = line_end + 1;
  }
  CHECK(bad == 0);
}

TEST_CASE("CSV numbers are written as fmt's shortest text, whatever path formats them", "[unit][output]") {
  // The writer formats integers and a repeated first column by faster paths: the text must stay the
  // one fmt::format("{}") (or "{:.Ng}") gives, byte for byte, across the rows and a buffer flush.
  const auto dir = temp_dir("csv_number_text");
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 7.0, 250.0, 1e6, 123456789012345.0, 999999999999999.0,
                                1e15, -1e15, 1e16, 3e17, 0.5, -2.5, 0.1, 1.0 / 3.0, 5e-324, 2.2250738585072014e-308,
                                1e-5, 1e-4, 6.02214076e23, std::nan(""), INFINITY, -INFINITY, 4503599627370496.5,
                                9007199254740993.0, -123.0};
  const std::size_t rows = 3 * CsvWriter::kFlushBytes / (values.size() * 8) + 7;  // past a few flushes
  for (const int digits : {0, 6, 17, 40}) {
    const auto path = dir / fmt::format("numbers_{}.csv", digits);
    std::string expected = "t,a,b\n";
    {
      CsvWriter csv(path, {"t", "a", "b"}, "", digits);
      for (std::size_t r = 0; r < rows; ++r) {
        const double t = values[(r / 5) % values.size()];  // the first column repeats, as a frame's time
        const double a = values[r % values.size()], b = values[(r * 7 + 3) % values.size()];
        csv.row({t, a, b});
        const double row[] = {t, a, b};
        for (int j = 0; j < 3; ++j) {
          expected += digits ? fmt::format("{:.{}g}", row[j], digits) : fmt::format("{}", row[j]);
          expected += j == 2 ? '\n' : ',';
        }
      }
      csv.commit();
    }
    std::ifstream in(path, std::ios::binary);
    const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    REQUIRE(written.size() == expected.size());
    CHECK(written == expected);
  }
}
