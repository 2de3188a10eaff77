// chainsim_bench_modes: steps, wall time and accuracy of the hanging chain's first mode per method
// and mesh (not a test; not registered with CTest). docs/string_solver.md, "The implicit path".
//
// The chain (ℓ = 1 m, g = 9.81 m/s², τ_b = 0.1 √(ℓ/g)) starts at rest on the first mode shape
// J0(j01 √(σ/ℓ)) with lateral amplitude 1e-5 ℓ and runs three periods; ω1 is measured from the zero
// crossings of the modal projection (tests/convergence/test_hanging_chain_modes.cpp) and compared with
// the exact ω1 = ½ j01 √(g/ℓ). Reported per run: steps, RHS evaluations, Newton and GMRES iterations,
// the median wall and CPU (process) time of the integration over the repeats, and the relative
// error of ω1. The absolute tolerance is rtol times the amplitude (1e-5 m).
//
// Usage: chainsim_bench_modes [--repeats R] [--periods P] METHOD:RTOL:LINKS[:ELEMENTS] ...
//   e.g. chainsim_bench_modes erk4:1e-4:201 dirk4:1e-5:201 dirk4:1e-5:10000 erk8:1e-8:20:quadratic
// ELEMENTS is the discretization (StringModelOptions::elements): links (default) or quadratic (LINKS
// even: two links per element; the nodes are LINKS + 1).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include <boost/math/special_functions/bessel.hpp>

#include "../problems/string_test_support.hpp"

using namespace chainsim;
using namespace chainsim::testing;

namespace {

struct Result {
  double error = 0, wall = 0, cpu = 0;  // cpu: process time, the fair measure on a loaded machine
  IntegratorStats stats;
};

Result run(const std::string& method, double rtol, int links, double periods, const std::string& elements) {
  IntegratorOptions options;
  options.method = method;
  options.rtol = rtol;
  options.atol = rtol * 1e-5;  // the 1e-5 amplitude of the lateral motion as the absolute scale
  Result r;
  const std::clock_t cpu_start = std::clock();
  const auto start = std::chrono::steady_clock::now();
  const ModeMeasurement m = measure_mode(links, 1, periods, options, 1e-5, elements);
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  r.stats = m.stats;
  r.error = m.crossings >= 2 ? m.relative_error() : NAN;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3;
  double periods = 3.0;
  std::vector<std::string> cases;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) {
      repeats = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--periods") && i + 1 < argc) {
      periods = std::atof(argv[++i]);
    } else {
      cases.emplace_back(argv[i]);
    }
  }
  if (cases.empty()) {
    std::fprintf(stderr, "usage: chainsim_bench_modes [--repeats R] [--periods P] METHOD:RTOL:LINKS ...\n");
    return 2;
  }
  std::printf("%-28s %8s %7s %8s %7s %8s %8s %8s %7s %7s %10s %9s %11s\n", "method", "rtol", "links", "steps", "fails",
              "rhs", "newton", "gmres", "ncfail", "setups", "wall (s)", "cpu (s)", "omega1 err");
  for (const std::string& c : cases) {
    std::vector<std::string> field;
    for (std::size_t at = 0;;) {
      const std::size_t next = c.find(':', at);
      field.push_back(c.substr(at, next == std::string::npos ? std::string::npos : next - at));
      if (next == std::string::npos) break;
      at = next + 1;
    }
    if (field.size() != 3 && field.size() != 4) {
      std::fprintf(stderr, "bad case '%s': METHOD:RTOL:LINKS[:ELEMENTS]\n", c.c_str());
      return 2;
    }
    const std::string method = field[0];
    const double rtol = std::atof(field[1].c_str());
    const int links = std::atoi(field[2].c_str());
    const std::string elements = field.size() == 4 ? field[3] : "links";
    std::vector<double> walls, cpus;
    Result r;
    for (int k = 0; k < repeats; ++k) {
      r = run(method, rtol, links, periods, elements);
      walls.push_back(r.wall);
      cpus.push_back(r.cpu);
    }
    std::sort(walls.begin(), walls.end());
    std::sort(cpus.begin(), cpus.end());
    std::printf("%-28s %8.0e %7d %8ld %7ld %8ld %8ld %8ld %7ld %7ld %10.4f %9.4f %11.3e\n", (method + (elements == "links" ? "" : ":" + elements)).c_str(), rtol, links,
                r.stats.steps, r.stats.error_test_fails, r.stats.rhs_evals, r.stats.nonlin_iters, r.stats.lin_iters,
                r.stats.nonlin_conv_fails, r.stats.lin_setups, walls[walls.size() / 2], cpus[cpus.size() / 2], r.error);
    std::fflush(stdout);
  }
  return 0;
}
