// chainsim_bench_micro: micro-benchmarks of the string solver's inner pieces, with Google Benchmark
// (not a timed test: CTest runs it once with one iteration per case, as a smoke test).
//
//   BM_StringRhs/<backend>/<links>     one right-hand side of a 2D hanging chain released 0.5 rad off
//                                      the vertical (unpack, forces, link geometry, tension assembly
//                                      and solve, accelerations); counter node_time = time per node
//   BM_TensionSolve/<backend>/<links>  the factor-and-solve alone of that chain's tension system (the
//                                      matrix and right-hand side of the state above)
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
BENCHMARK(BM_FrontCrossing)->Arg(101)->Arg(1001);

BENCHMARK_MAIN();
