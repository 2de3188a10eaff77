// chainsim_bench_scene: what a scene costs (not a test; not registered with CTest).
//
// The same motion — a chain hanging from a fixed point, released from rest 0.5 rad off the vertical
// under gravity (erk8, rtol 1e-8, atol 1e-10, τ_b = 0.03 s) — run three ways:
//   (i)   from a minimal scene: [effects.gravity] and a fixed end, nothing else;
//   (ii)  from a scene that also declares effects at zero strength: [effects.drag] coefficient = 0
//         and a zero load on the free end (declared effects are built, so they are evaluated at
//         every right-hand side although they change nothing);
//   (iii) the bare StringModel / StringSolver built in C++, no scene.
// Repetitions are interleaved (i, ii, iii, i, …) so that drifts of the machine hit all three alike.
// Reported: the median wall time of the integration (StringSolver::run) and of the whole set-up +
// run (parse, build, project, integrate), their ratios, and the step counts and final tip
// positions, which show that the three runs compute the same motion.
//
// With --slack: what [solver] slack = "allow" costs (docs/model.md "Slack and snap-taut"), the same
// scenes with slack = "stop" and "allow", interleaved: (a) the minimal scene above, a taut run that
// never goes slack; (b) the swinging U (cases/scenes/swinging_u.toml) to t = 0.4 s, before its first
// slack, and with "allow" to t = 1 s.
//
// Usage: chainsim_bench_scene [--quick] [--slack]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/discretize.hpp"
#include "solver/forces.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

constexpr double kAngle = 0.5;          // rad off the vertical
constexpr double kTau = 0.03;           // s, Baumgarte time (declared in the scenes too)
constexpr double kG = 9.81;             // m/s^2

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::string minimal_scene(int links, double t_end) {
  return fmt::format(R"([string]
length = 1.0
density = 0.1
nodes = {}
[shape]
kind = "polyline"
points = [[0.0, 0.0], [{:.17g}, {:.17g}]]
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -{}]
[solver]
stabilization_time = {}
[output]
interval = {}
[stop]
t_end = {}
)",
                     links + 1, std::sin(kAngle), -std::cos(kAngle), kG, kTau, t_end, t_end);
}

std::string zero_effects_scene(int links, double t_end) {
  std::string text = minimal_scene(links, t_end);
  const std::string ends = "start = \"fixed\"\n";
  text.replace(text.find(ends), ends.size(), ends + "end = { kind = \"loaded\", force = [0.0, 0.0] }\n");
  return text + "[effects.drag]\ncoefficient = 0.0\n";
}

struct Sample {
  double run = 0, total = 0;  // s
  long steps = 0;
  Vec<2> tip = Vec<2>::Zero();
  std::vector<std::string> effects;
};

/// Runs a solver whose set-up began at wall time t0; times the integration and the whole.
Sample measure(double t0, StringSolver<2>& solver) {
  Sample s;
  const double t1 = now();
  const RunSummary& summary = solver.run();
  const double t2 = now();
  s.run = t2 - t1;
  s.total = t2 - t0;
  s.steps = summary.stats.steps;
  s.tip = solver.frames().back().x.col(solver.frames().back().x.cols() - 1);
  s.effects = summary.effects;
  return s;
}

Sample from_scene(const std::string& text) {
  const double t0 = now();
  const SceneSpec spec = parse_scene_text(text, "bench.toml");
  StringScene<2> scene = build_string_scene<2>(spec);
  StringSolver<2> solver(*scene.model, scene.solver);
  return measure(t0, solver);
}

Sample bare(int links, double t_end) {
  const double t0 = now();
  // The nodes placed on the same straight line as the scenes' polyline, by the same mesh function.
  Points<2> line(2, 2);
  line << 0.0, std::sin(kAngle), 0.0, -std::cos(kAngle);
  Chain<2> chain = discretize(*polyline_curve<2>(line), 1.0, 0.1, links, false);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0, -kG)));
  std::vector<PrescribedNode<2>> top = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}};
  StringModelOptions mo;
  mo.stabilization_time = kTau;
  StringModel<2> model(std::move(chain), std::move(forces), top, mo);
  model.make_consistent(0.0);
  StringSolverOptions so;
  so.integrator.method = "erk8";
  so.integrator.rtol = 1e-8;
  so.integrator.atol = 1e-10;
  so.t_end = t_end;
  so.output_interval = t_end;
  StringSolver<2> solver(model, so);
  return measure(t0, solver);
}


/// The U of cases/scenes/swinging_u.toml (101 nodes) with the given slack policy, to t_end.
std::string swinging_u(const char* slack, double t_end) {
  return fmt::format(R"([string]
density = 0.1
nodes = 101
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.3, -0.4], [0.6, -0.4], [0.3, 0.0]]
corner_radius = 0.12
[ends]
start = "fixed"
end = "fixed"
[effects.gravity]
g = [0.0, -9.81]
[solver]
slack = "{}"
[output]
interval = {}
[stop]
t_end = {}
)",
                     slack, t_end, t_end);
}

int slack_bench(bool quick) {
  const int repeats = quick ? 3 : 11;
  const double t_end = quick ? 0.5 : 2.0;
  auto with_slack = [](std::string text, const char* policy) {
    return text.replace(text.find("[solver]\n"), 9, fmt::format("[solver]\nslack = \"{}\"\n", policy));
  };
  const std::vector<std::pair<std::string, std::string>> scenes = {
      {"(a) hanging chain, slack = stop", with_slack(minimal_scene(100, t_end), "stop")},
      {"(a) hanging chain, slack = allow", with_slack(minimal_scene(100, t_end), "allow")},
      {"(b) swinging U to 0.4 s, stop", swinging_u("stop", 0.4)},
      {"(b) swinging U to 0.4 s, allow", swinging_u("allow", 0.4)},
      {"(b) swinging U to 1 s, allow", swinging_u("allow", 1.0)}};
  std::vector<std::vector<Sample>> runs(scenes.size());
  for (int r = 0; r < repeats; ++r)
    for (std::size_t k = 0; k < scenes.size(); ++k) runs[k].push_back(from_scene(scenes[k].second));
  std::printf("chainsim_bench_scene --slack%s: median of %d\n\n", quick ? " --quick" : "", repeats);
  std::printf("  %-36s %10s %8s\n", "", "run (ms)", "steps");
  std::vector<double> run(scenes.size());
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    std::vector<double> a;
    for (const auto& s : runs[k]) a.push_back(s.run);
    run[k] = median(a);
    std::printf("  %-36s %10.2f %8ld\n", scenes[k].first.c_str(), 1e3 * run[k], runs[k].front().steps);
  }
  std::printf("\n  ratios allow/stop: (a) %.3f   (b) %.3f\n", run[1] / run[0], run[3] / run[2]);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, slack = false;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--quick") == 0) quick = true;
    if (std::strcmp(argv[k], "--slack") == 0) slack = true;
  }
  if (slack) return slack_bench(quick);
  const int links = 100;
  const double t_end = quick ? 0.5 : 2.0;
  const int repeats = quick ? 3 : 11;
  const std::string scene_i = minimal_scene(links, t_end), scene_ii = zero_effects_scene(links, t_end);
  std::vector<Sample> runs[3];
  for (int r = 0; r < repeats; ++r) {
    runs[0].push_back(from_scene(scene_i));
    runs[1].push_back(from_scene(scene_ii));
    runs[2].push_back(bare(links, t_end));
  }
  const char* names[3] = {"(i) minimal scene", "(ii) + zero drag, zero end load", "(iii) bare C++ (no scene)"};
  double run[3], total[3];
  std::printf("chainsim_bench_scene%s: hanging chain, %d links, 0.5 rad, t_end = %g s, erk8 rtol 1e-8; median of %d\n\n",
              quick ? " --quick" : "", links, t_end, repeats);
  std::printf("  %-34s %10s %12s %8s  %-28s %s\n", "", "run (ms)", "total (ms)", "steps", "tip at t_end (m)", "effects");
  for (int k = 0; k < 3; ++k) {
    std::vector<double> a, b;
    for (const auto& s : runs[k]) {
      a.push_back(s.run);
      b.push_back(s.total);
    }
    run[k] = median(a);
    total[k] = median(b);
    const Sample& s = runs[k].front();
    std::string effects;
    for (const auto& e : s.effects) effects += (effects.empty() ? "" : ", ") + e;
    std::printf("  %-34s %10.2f %12.2f %8ld  (%.12f, %.12f) %s\n", names[k], 1e3 * run[k], 1e3 * total[k], s.steps,
                s.tip[0], s.tip[1], effects.c_str());
  }
  std::printf("\n  ratios (run, total): (ii)/(i) = %.3f, %.3f   (i)/(iii) = %.3f, %.3f   (ii)/(iii) = %.3f, %.3f\n",
              run[1] / run[0], total[1] / total[0], run[0] / run[2], total[0] / total[2], run[1] / run[2],
              total[1] / total[2]);
  std::printf("  tip difference (i) vs (iii): %.3g m; (ii) vs (i): %.3g m\n",
              (runs[0].front().tip - runs[2].front().tip).norm(), (runs[1].front().tip - runs[0].front().tip).norm());
  return 0;
}
