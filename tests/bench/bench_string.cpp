// chainsim_bench: cost of the string solver (not a test; not registered with CTest).
//
//   1. Tension solve, one factor-and-solve per call, for one open arc, one closed loop (cyclic), and
//      8 arcs (a string cut by fronts): tridiagonal (Thomas / Sherman–Morrison), KLU (klu_refactor),
//      Eigen SparseLU. Median over repeats of the time per call, and the ratio to tridiagonal.
//   2. Cost per step against the number of nodes: a swinging hanging chain integrated with ERK5 for
//      a fixed number of steps; time per step and per right-hand side per node (flat = linear cost).
//
// Usage: chainsim_bench [--quick]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mesh/errors.hpp"
#include "solver/integrator.hpp"
#include "solver/string_model.hpp"
#include "solver/tension_system.hpp"

using namespace chainsim;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// Median over `repeats` of the mean time (s) of `calls` invocations of f.
double time_per_call(const std::function<void()>& f, int calls, int repeats) {
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int c = 0; c < calls; ++c) f();
    samples.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / calls);
  }
  return median(samples);
}

/// Values like a string's: diagonal −(w_a + w_b) with random masses, couplings w cosθ.
void fill(TensionSystem& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.5, 1.5), c(-1.0, 1.0);
  s.zero();
  for (const ArcBlock& arc : s.arcs())
    for (int i = 0; i < arc.num_links; ++i) {
      const int j = arc.first_unknown + i;
      s.add_diagonal(j, -2.0 * u(rng));
      if (i + 1 < arc.num_links || arc.closed) s.set_coupling(j, 0.9 * c(rng));
      s.rhs(j) = c(rng);
    }
}

void bench_tension(bool quick) {
  std::printf("1. tension solve: median time per factor-and-solve (microseconds), ratio to tridiagonal\n\n");
  std::printf("  %-12s %9s  %12s %12s %12s   %8s %8s\n", "system", "unknowns", "tridiagonal", "klu", "eigen",
              "klu/tri", "eig/tri");
  const std::vector<int> sizes = quick ? std::vector<int>{100, 1000, 10000} : std::vector<int>{100, 1000, 10000, 100000};
  for (const char* kind : {"open arc", "closed loop", "8 arcs"}) {
    for (int n : sizes) {
      std::vector<double> us;
      for (const std::string backend : {"tridiagonal", "klu", "eigen"}) {
        const bool arcs = std::strcmp(kind, "8 arcs") == 0;
        std::vector<int> links;
        std::vector<bool> closed;
        if (arcs) {
          for (int k = 0; k < 8; ++k) {
            links.push_back(n / 8);
            closed.push_back(false);
          }
        } else {
          links = {n};
          closed = {std::strcmp(kind, "closed loop") == 0};
        }
        std::unique_ptr<TensionSystem> s;
        try {
          s = std::make_unique<TensionSystem>(links, closed, backend);
        } catch (const InputError&) {
          us.push_back(NAN);  // backend not built
          continue;
        }
        std::mt19937 rng(1);
        fill(*s, rng);
        const int calls = std::max(1, 200000 / n);
        us.push_back(1e6 * time_per_call([&] { s->solve(0.0); }, calls, quick ? 5 : 11));
      }
      std::printf("  %-12s %9d  %12.3f %12.3f %12.3f   %8.2f %8.2f\n", kind, n, us[0], us[1], us[2], us[1] / us[0],
                  us[2] / us[0]);
    }
  }
  std::printf("\n");
}

void bench_steps(bool quick) {
  std::printf("2. cost per step of a swinging hanging chain (ERK5 Dormand-Prince, 7 stages, tridiagonal)\n\n");
  std::printf("  %8s  %8s  %12s  %14s  %18s\n", "links", "steps", "ms/step", "us/rhs", "ns/(rhs*node)");
  const std::vector<int> sizes =
      quick ? std::vector<int>{64, 256, 1024} : std::vector<int>{64, 128, 256, 512, 1024, 2048, 4096, 8192};
  for (int n : sizes) {
    Chain<2> chain = Chain<2>::uniform(1.0, 1.0, n, false);
    for (int i = 0; i <= n; ++i) chain.positions().col(i) = Vec<2>(std::sin(0.5) * i / n, -std::cos(0.5) * i / n);
    std::vector<std::unique_ptr<Force<2>>> forces;
    forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0, -9.81)));
    std::vector<PrescribedNode<2>> top = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}};
    StringModelOptions mo;
    mo.stabilization_time = 0.03;
    StringModel<2> model(std::move(chain), std::move(forces), top, mo);
    model.make_consistent(0.0);
    IntegratorOptions io;
    io.method = "erk5";
    io.rtol = 1e-8;
    io.atol = 1e-11;
    std::vector<double> per_step, per_rhs;
    const int steps = quick ? 100 : 200;
    long total_steps = 0;
    for (int r = 0; r < (quick ? 3 : 5); ++r) {
      Integrator integrator(model, 0.0, model.state_from_chain(), io);
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < steps; ++k) integrator.advance(1e3, true);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto st = integrator.stats();
      per_step.push_back(wall / st.steps);
      per_rhs.push_back(wall / st.rhs_evals);
      total_steps = st.steps;
    }
    const double rhs = median(per_rhs);
    std::printf("  %8d  %8ld  %12.4f  %14.3f  %18.2f\n", n, total_steps, 1e3 * median(per_step), 1e6 * rhs,
                1e9 * rhs / (n + 1));
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("chainsim_bench%s: backends built: ", quick ? " --quick" : "");
  for (const auto& b : tension_backend_names()) std::printf("%s ", b.c_str());
  std::printf("\n\n");
  bench_tension(quick);
  bench_steps(quick);
  return 0;
}
