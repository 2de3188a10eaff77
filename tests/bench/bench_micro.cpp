// chainsim_bench_micro: micro-benchmarks of the string solver's inner pieces, with Google Benchmark
// (not a timed test: CTest runs it once with one iteration per case, as a smoke test).
//
//   BM_StringRhs/<backend>/<links>     one right-hand side of a 2D hanging chain released 0.5 rad off
//                                      the vertical (unpack, forces, link geometry, tension assembly
//                                      and solve, accelerations); counter node_time = time per node
//   BM_TensionSolve/<backend>/<links>  the factor-and-solve alone of that chain's tension system (the
//                                      matrix and right-hand side of the state above)
//   BM_NewtonSetupSolve/<solver>/<links>
//                                      one Newton set-up and solve of an implicit method on the hanging
//                                      chain's first mode (tests/problems/string_test_support.hpp,
//                                      amplitude 1e-5, at rest on the mode shape): StringModel::
//                                      newton_setup (linearisation and factorisation of the augmented
//                                      system, γ = 0.01 s) then one newton_solve; solver 0 = banded, 1 = klu
//   BM_NewtonSolve/<solver>/<links>    one newton_solve alone, with the factorisation above
//   BM_ImplicitStep/<solver>/<links>   dirk5 (rtol 1e-5, atol 1e-10) over one period of that mode,
//                                      without the integrator's construction; counters steps and
//                                      step_time = time per accepted step
//   BM_FrontCrossing/<nodes>           one heap crossing of the falling chain (cases/scenes/
//                                      falling_chain.toml, f = 0.5): StringModel::handle_events at the
//                                      polished root of the first crossing (material moved into the
//                                      heap, arcs rebuilt, the state re-projected)
//
// Backends: 0 = tridiagonal, 1 = klu, 2 = eigen (a backend not built is skipped with a message).
// Usage: chainsim_bench_micro [--benchmark_filter=REGEX] [--benchmark_repetitions=N] ...
//        tests/bench/micro_compare.sh OLD_REV runs it side by side with an older revision's build.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "../problems/string_test_support.hpp"
#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "solver/integrator.hpp"
#include "solver/string_model.hpp"

using namespace chainsim;

namespace {

const char* const kBackends[] = {"tridiagonal", "klu", "eigen"};

/// A chain of `links` links hanging from a fixed point, released at rest 0.5 rad off the vertical
/// (the motion of chainsim_bench and chainsim_bench_scene), projected onto the constraints.
std::unique_ptr<StringModel<2>> swinging_chain(int links, const std::string& backend) {
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, links, false);
  for (int i = 0; i <= links; ++i)
    chain.positions().col(i) = Vec<2>(std::sin(0.5) * i / links, -std::cos(0.5) * i / links);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0, -9.81)));
  std::vector<PrescribedNode<2>> top = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}};
  StringModelOptions options;
  options.stabilization_time = 0.03;
  options.backend = backend;
  auto model = std::make_unique<StringModel<2>>(std::move(chain), std::move(forces), top, options);
  model->make_consistent(0.0);
  return model;
}

/// The swinging chain of state.range(1) links with backend state.range(0), at (t, y) a little after the
/// release (20 steps of erk5), so that the velocity terms of the tension equation are not zero. No model
/// (the benchmark marked skipped) when the backend is not built.
struct MovingChain {
  std::unique_ptr<StringModel<2>> model;
  double t = 0;
  Eigen::VectorXd y;
};

MovingChain moving_chain_or_skip(benchmark::State& state) {
  const std::string backend = kBackends[state.range(0)];
  MovingChain c;
  try {
    c.model = swinging_chain(static_cast<int>(state.range(1)), backend);
  } catch (const InputError& e) {
    state.SkipWithError(("backend " + backend + " not built: " + e.what()).c_str());
    return c;
  }
  IntegratorOptions io;
  io.method = "erk5";
  io.rtol = 1e-8;
  io.atol = 1e-10;
  Integrator integrator(*c.model, 0.0, c.model->state_from_chain(), io);
  for (int k = 0; k < 20; ++k) integrator.advance(10.0, true);
  c.t = integrator.time();
  c.y = integrator.state();
  return c;
}

void BM_StringRhs(benchmark::State& state) {
  MovingChain c = moving_chain_or_skip(state);
  if (!c.model) return;
  Eigen::VectorXd ydot(c.y.size());
  for (auto _ : state) {
    c.model->rhs(c.t, c.y, ydot);
    benchmark::DoNotOptimize(ydot.data());
    benchmark::ClobberMemory();
  }
  const double nodes = static_cast<double>(state.range(1) + 1);
  state.counters["node_time"] = benchmark::Counter(nodes, benchmark::Counter::kIsIterationInvariantRate |
                                                              benchmark::Counter::kInvert);
  state.SetLabel(kBackends[state.range(0)]);
}

void BM_TensionSolve(benchmark::State& state) {
  MovingChain c = moving_chain_or_skip(state);
  if (!c.model) return;
  Eigen::VectorXd ydot(c.y.size());
  c.model->rhs(c.t, c.y, ydot);  // assembles the system of this state
  const double t = c.t;
  TensionSystem& system = c.model->tension_system();
  const Eigen::VectorXd rhs = system.rhs_vector();
  for (auto _ : state) {
    for (int u = 0; u < system.size(); ++u) system.rhs(u) = rhs[u];  // the solve overwrites it
    benchmark::DoNotOptimize(system.solve(t).data());
    benchmark::ClobberMemory();
  }
  state.counters["unknown_time"] = benchmark::Counter(static_cast<double>(system.size()),
                                                      benchmark::Counter::kIsIterationInvariantRate |
                                                          benchmark::Counter::kInvert);
  state.SetLabel(kBackends[state.range(0)]);
}

const char* const kLinearSolvers[] = {"banded", "klu"};

/// The hanging chain's first mode (amplitude 1e-5 of ℓ = 1 m, at rest on the mode shape) with the
/// Newton solver of state.range(0), and its state.
std::unique_ptr<StringModel<2>> first_mode_chain(benchmark::State& state) {
  const double j = boost::math::cyl_bessel_j_zero(0.0, 1);
  auto model = testing::hanging_chain(
      static_cast<int>(state.range(1)), 1.0,
      [&](double sigma) { return 1e-5 * boost::math::cyl_bessel_j(0, j * std::sqrt(std::max(sigma, 0.0))); },
      0.1 / std::sqrt(testing::kG), 0.0, "links", kLinearSolvers[state.range(0)]);
  state.SetLabel(kLinearSolvers[state.range(0)]);
  return model;
}

void BM_NewtonSetupSolve(benchmark::State& state) {
  auto model = first_mode_chain(state);
  const Eigen::VectorXd y = model->state_from_chain();
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(y.size());
  Eigen::VectorXd z(y.size());
  for (auto _ : state) {
    model->newton_setup(0.0, y, true, 0.01);
    model->newton_solve(r, z);
    benchmark::DoNotOptimize(z.data());
    benchmark::ClobberMemory();
  }
}

void BM_NewtonSolve(benchmark::State& state) {
  auto model = first_mode_chain(state);
  const Eigen::VectorXd y = model->state_from_chain();
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(y.size());
  Eigen::VectorXd z(y.size());
  model->newton_setup(0.0, y, true, 0.01);
  for (auto _ : state) {
    model->newton_solve(r, z);
    benchmark::DoNotOptimize(z.data());
    benchmark::ClobberMemory();
  }
}

void BM_ImplicitStep(benchmark::State& state) {
  auto model = first_mode_chain(state);
  const Eigen::VectorXd y0 = model->state_from_chain();
  IntegratorOptions io;
  io.method = "dirk5";
  io.rtol = 1e-5;
  io.atol = 1e-10;
  const double period = 4 * kPi / (boost::math::cyl_bessel_j_zero(0.0, 1) * std::sqrt(testing::kG));
  long steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto integrator = std::make_unique<Integrator>(*model, 0.0, y0, io);
    state.ResumeTiming();
    integrator->advance(period);
    state.PauseTiming();
    steps += integrator->stats().steps;
    integrator.reset();
    state.ResumeTiming();
  }
  state.counters["steps"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kAvgIterations);
  state.counters["step_time"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// The falling chain of cases/scenes/falling_chain.toml with `nodes` nodes.
FrontScene<2> falling_chain(int nodes) {
  const SceneSpec spec = parse_scene(std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/falling_chain.toml",
                                     {"string.nodes=" + std::to_string(nodes)});
  return build_front_scene<2>(spec);
}

void BM_FrontCrossing(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  // The polished root of the first crossing, found once.
  double t_event = 0;
  Eigen::VectorXd y_event;
  std::vector<int> found;
  {
    FrontScene<2> scene = falling_chain(nodes);
    IntegratorOptions io;
    io.method = "erk5";
    io.rtol = 1e-9;
    io.atol = 1e-11;
    Integrator integrator(*scene.model, 0.0, scene.model->state_from_chain(), io);
    while (integrator.advance(2.0) != Integrator::Outcome::kEvent) {
      if (integrator.time() >= 2.0) {
        state.SkipWithError("the falling chain reached no crossing");
        return;
      }
    }
    t_event = integrator.time();
    y_event = integrator.state();
    found = integrator.events_found();
  }
  for (auto _ : state) {
    state.PauseTiming();
    FrontScene<2> scene = falling_chain(nodes);  // the model before the crossing, anew
    Eigen::VectorXd y = y_event;
    state.ResumeTiming();
    benchmark::DoNotOptimize(scene.model->handle_events(t_event, y, found));
    benchmark::ClobberMemory();
    state.PauseTiming();
    if (y.size() >= y_event.size()) {
      state.SkipWithError("handle_events did not move a node into the heap");
      state.ResumeTiming();
      break;
    }
    scene = FrontScene<2>{};  // destroyed outside the timing
    state.ResumeTiming();
  }
}

}  // namespace

BENCHMARK(BM_StringRhs)->ArgsProduct({{0, 1, 2}, {64, 512, 4096}});
BENCHMARK(BM_TensionSolve)->ArgsProduct({{0, 1, 2}, {64, 512, 4096}});
BENCHMARK(BM_NewtonSetupSolve)->ArgsProduct({{0, 1}, {250, 1000, 10000}});
BENCHMARK(BM_NewtonSolve)->ArgsProduct({{0, 1}, {250, 1000, 10000}});
BENCHMARK(BM_ImplicitStep)->ArgsProduct({{0, 1}, {250, 1000, 10000}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrontCrossing)->Arg(101)->Arg(1001);

BENCHMARK_MAIN();
