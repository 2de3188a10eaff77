// solver/vtk_output: the frames read back exactly with VTK's own reader (python3-vtk9), in both
// encodings; skipped (with a warning) where vtk is not importable.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"
#include "solver/vtk_output.hpp"
#include "tests/unit/test_scene_support.hpp"

using namespace chainsim;

namespace {

/// Values that a lossy writer would change: thirds, π, a subnormal, huge and tiny numbers, −0.
VtkPolyline awkward_polyline() {
  VtkPolyline line;
  const int n = 7;
  line.points = Eigen::Matrix3Xd::Zero(3, n);
  Eigen::MatrixXd velocity(3, n), s(1, n);
  for (int i = 0; i < n; ++i) {
    line.points.col(i) << i / 3.0, std::sin(1.0 + i) * M_PI, i % 2 ? -0.0 : 1e-310 * i;
    velocity.col(i) << 1e300 / (i + 1), -1.0 / (7.0 * (i + 1)), std::exp(-40.0 * i);
    s(0, i) = 0.1 * i;
  }
  // Two pieces, as a run with a heap inside the listed nodes writes: 0-1-2 and 4-5-6.
  line.segments = {{0, 1}, {1, 2}, {4, 5}, {5, 6}};
  line.point_data = {{"velocity", velocity}, {"s", s}};
  Eigen::MatrixXd tension(1, 4);
  tension << 2.0 / 3.0, -std::numeric_limits<double>::min(), 123456789.123456789, 0.0;
  line.cell_data = {{"tension", tension}};
  return line;
}

nlohmann::json as_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index r = 0; r < m.rows(); ++r) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("VTK frames read back exactly with VTK's reader, binary (default) and ascii", "[unit][vtk]") {
  const auto dir = chainsim::test::temp_dir("vtk_roundtrip");
  const VtkPolyline line = awkward_polyline();
  write_vtp(dir / "default.vtp", line);
  write_vtp(dir / "binary.vtp", line, VtkEncoding::kBinary);
  write_vtp(dir / "ascii.vtp", line, VtkEncoding::kAscii);

  // The expected values, written by nlohmann::json, which prints doubles so that they read back exactly.
  nlohmann::json expected;
  expected["points"] = as_json(line.points);
  expected["segments"] = line.segments;
  for (const auto& [name, data] : line.point_data) expected["point_data"][name] = as_json(data);
  for (const auto& [name, data] : line.cell_data) expected["cell_data"][name] = as_json(data);
  std::ofstream(dir / "expected.json") << expected.dump();

  const std::string cmd = std::string("/usr/bin/python3 ") + CHAINSIM_SOURCE_DIR + "/tests/python/vtk_roundtrip.py " +
                          (dir / "expected.json").string() + " " + (dir / "default.vtp").string() + " " +
                          (dir / "binary.vtp").string() + " " + (dir / "ascii.vtp").string() + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = pclose(pipe);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 77) {
    WARN("skipped: " << out);
    return;
  }
  INFO(out);
  CHECK(code == 0);
  CHECK_THAT(out, Catch::Matchers::StartsWith("ok: 3 files read back exactly"));

  // Binary is the default, and smaller.
  std::ifstream a(dir / "default.vtp", std::ios::binary), b(dir / "binary.vtp", std::ios::binary);
  CHECK(std::string(std::istreambuf_iterator<char>(a), {}) == std::string(std::istreambuf_iterator<char>(b), {}));
  CHECK(std::filesystem::file_size(dir / "binary.vtp") < std::filesystem::file_size(dir / "ascii.vtp"));
}

TEST_CASE("vtk_encoding is binary or ascii and anything else is an InputError naming the key", "[unit][vtk]") {
  CHECK(parse_vtk_encoding("binary") == VtkEncoding::kBinary);
  CHECK(parse_vtk_encoding("ascii") == VtkEncoding::kAscii);
  CHECK_THROWS_WITH(parse_vtk_encoding("base64", "output.vtk_encoding"),
                    "output.vtk_encoding = \"base64\" is not allowed; valid values: binary, ascii");
}
