// Hard cases of the string solver and the integrator's watchdog (docs/stability.md): runs that must
// end (step budget, step-size collapse, wall clock, a drifting loose-tolerance run), long and large
// runs, slack at a pushed end, the whip with the slack check off, extreme units, and every method at
// the edges of the tolerance range. References: closed forms (static tension, rigid motion of a
// driven straight string, a blow-up time), conservation laws and a tight-tolerance reference run.
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "tests/problems/string_test_support.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string scene_file(const std::string& name) {
  std::ifstream in(std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A hanging chain scene (2D, fixed top end, gravity −y): `links` links of total length ℓ, density λ,
/// tilted by `tilt` rad, at rest; [solver] and [output]/[stop] as given.
std::string hanging_scene(int links, double l, double lam, double g, double tilt, const std::string& solver,
                          double interval, double t_end) {
  return fmt::format(
      "[string]\nlength = {0:.17g}\ndensity = {1:.17g}\nnodes = {2}\n"
      "[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [{3:.17g}, {4:.17g}]]\n"
      "[ends]\nstart = \"fixed\"\n[effects.gravity]\ng = [0.0, {5:.17g}]\n"
      "[solver]\n{6}\n[output]\ninterval = {7:.17g}\n[stop]\nt_end = {8:.17g}\n",
      l, lam, links + 1, l * std::sin(tilt), -l * std::cos(tilt), -g, solver, interval, t_end);
}

StringScene<2> build(const std::string& text) { return build_string_scene<2>(parse_scene_text(text, "hard.toml")); }

/// Runs a scene; returns the NumericalError's message ("" if the run completed).
std::string run_scene(StringSolver<2>& solver) {
  try {
    solver.run();
    return "";
  } catch (const NumericalError& e) {
    return e.what();
  }
}

void require_frames_finite(const StringSolver<2>& solver) {
  for (const auto& f : solver.frames()) {
    REQUIRE(f.x.allFinite());
    REQUIRE(f.v.allFinite());
    REQUIRE(f.tension.allFinite());
    REQUIRE(std::isfinite(f.drift));
  }
}

/// y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
class BlowUp : public OdeSystem {
 public:
  int size() const override { return 1; }
  void rhs(double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) override {
    ydot[0] = y[0] * y[0];
  }
  double time_scale() const override { return 1.0; }
};

}  // namespace

TEST_CASE("watchdog: max_steps bounds the whole run, also when the runner takes one step per call",
          "[hard][integrator]") {
  // The whip scene with max_steps = 1: before, the runner's one-step calls never met ARKODE's
  // per-call limit and the run took 758 steps.
  std::string text = scene_file("whip_crack.toml");
  const std::string key = "check_slack = true";
  text.replace(text.find(key), key.size(), key + "\nmax_steps = 1");
  auto scene = build(text);
  StringSolver<2> solver(*scene.model, scene.solver);
  const std::string error = run_scene(solver);
  CHECK_THAT(error, Contains("ARK_TOO_MUCH_WORK") && Contains("max_steps = 1 ") && Contains("ARKODE_FEHLBERG_13_7_8"));
  CHECK(solver.summary().stats.steps == 1);
  CHECK(solver.summary().status == "failed");
}

TEST_CASE("watchdog: a step size that collapses at a blow-up ends the run there, naming time and step",
          "[hard][integrator]") {
  BlowUp system;
  IntegratorOptions options;
  options.rtol = 1e-10;
  Integrator integrator(system, 0.0, Eigen::VectorXd::Ones(1), options);
  try {
    while (integrator.time() < 2.0) integrator.advance(2.0, /*one_step=*/true);
    FAIL("the integration went past the blow-up at t = 1");
  } catch (const NumericalError& e) {
    // Steps below 1e-14 max(|t|, 1) s can only be taken within ~1e-14·(1−t)^0 of t = 1 for this
    // solution (the local error of a step h scales like h^9 y^10): the run ends just before t = 1.
    CHECK_THAT(e.time(), WithinAbs(1.0, 1e-6));
    CHECK_THAT(std::string(e.what()), Contains("stalled") && Contains("step-size floor") && Contains("last step h"));
  }
  CHECK(integrator.stats().steps < 5000);
}

TEST_CASE("watchdog: max_wall_s ends a long run after that wall-clock time", "[hard][integrator]") {
  auto scene = build(hanging_scene(40, 1, 0.1, 9.81, 0.05, "rtol = 1e-12\natol = 1e-14", 1.0, 1e5));
  scene.solver.integrator.max_wall_s = 0.3;
  StringSolver<2> solver(*scene.model, scene.solver);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = run_scene(solver);
  const double wall = seconds_since(start);
  CHECK_THAT(error, Contains("wall-clock budget max_wall_s = 0.3 s"));
  CHECK(wall > 0.3);
  CHECK(wall < CHAINSIM_WALL_FACTOR * 5);
  CHECK(solver.summary().t_stop < 1e5);
}

TEST_CASE("ARK437L2SA ERK at rtol 1e-2 on a 111-link hanging chain without constraint stabilization ends with a "
          "diagnostic, and with it runs to the end",
          "[hard][integrator]") {
  // Without Baumgarte stabilization the link lengths are held only by the integration error; at
  // rtol = 1e-2 this embedded pair lets them drift (max violation 0.65 by t = 2.9 s) until a link
  // collapses near t = 2.97 s: the tensions diverge, the steps shrink to below the round-off of t,
  // and the run used to go on for ever. The watchdog ends it there. (slack = "ignore": the slack the
  // drifting string shows on the way would otherwise stop it first, which is also a located diagnostic.)
  const std::string solver_keys =
      "method = \"ARKODE_ARK437L2SA_ERK_7_3_4\"\nrtol = 1e-2\natol = 1e-10\nstabilization_time = {}\nslack = \"ignore\"";
  auto scene = build(hanging_scene(111, 1, 0.1, 9.81, 0.05, fmt::format(solver_keys, 0), 0.05, 10));
  StringSolver<2> solver(*scene.model, scene.solver);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = run_scene(solver);
  CHECK(seconds_since(start) < 20);
  CHECK_THAT(error, Contains("stalled") && Contains("ARKODE_ARK437L2SA_ERK_7_3_4") && Contains("rtol = 0.01"));
  CHECK(solver.summary().t_stop < 10);
  CHECK(solver.summary().max_constraint_violation > 0.5);  // the cause: the links no longer have their length
  require_frames_finite(solver);

  // With the default stabilization (0.1 t_char) the same method and tolerance reach t_end.
  auto stabilized = build(hanging_scene(111, 1, 0.1, 9.81, 0.05,
                                        "method = \"ARKODE_ARK437L2SA_ERK_7_3_4\"\nrtol = 1e-2\natol = 1e-10", 0.05,
                                        10));
  StringSolver<2> solver2(*stabilized.model, stabilized.solver);
  CHECK(run_scene(solver2).empty());
  require_frames_finite(solver2);
  CHECK(solver2.summary().max_constraint_violation < 1e-2);  // held to the tolerance, rtol = 1e-2
  CHECK(solver2.summary().relative_energy_drift() < 0.05);
}

TEST_CASE("the implicit ARK437L2SA DIRK at rtol 1e-2 on the 111-link chain without stabilization finishes or "
          "stops with the watchdog's diagnostic",
          "[hard][integrator][implicit]") {
  // The implicit partner of the case above, on the string's own Newton solver: a Newton iteration
  // that fails is a step failure to ARKODE, and a run of them ends in the same located diagnostics
  // (time, step size, method), never in a hang.
  const std::string solver_keys =
      "method = \"ARKODE_ARK437L2SA_DIRK_7_3_4\"\nrtol = 1e-2\natol = 1e-10\nstabilization_time = 0\n"
      "slack = \"ignore\"\nmax_wall_s = 20";
  auto scene = build(hanging_scene(111, 1, 0.1, 9.81, 0.05, solver_keys, 0.05, 10));
  StringSolver<2> solver(*scene.model, scene.solver);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = run_scene(solver);
  CHECK(seconds_since(start) < 30);
  if (!error.empty()) {
    CHECK_THAT(error, Contains("t = ") && Contains("h = ") && Contains("ARKODE_ARK437L2SA_DIRK_7_3_4"));
  } else {
    CHECK(solver.summary().t_stop == 10);
  }
  require_frames_finite(solver);
}

TEST_CASE("1000 periods of a small hanging chain's small oscillation: energy and constraint drift stay bounded",
          "[hard][string][convergence]") {
  // 6 links, 0.01 rad; period of the first mode 2π/ω1, ω1 = 1.2024 sqrt(g/ℓ) for the continuous chain.
  const double period = 2 * M_PI / (1.2024 * std::sqrt(9.81));
  auto run_for = [&](double periods) {
    auto scene = build(hanging_scene(6, 1, 0.1, 9.81, 0.01, "rtol = 1e-10\natol = 1e-12", 10 * period,
                                     periods * period));
    StringSolver<2> solver(*scene.model, scene.solver);
    REQUIRE(run_scene(solver).empty());
    require_frames_finite(solver);
    return solver.summary();
  };
  const RunSummary s100 = run_for(100), s1000 = run_for(1000);
  // The error per step is held below rtol relative to the state, and an explicit Runge-Kutta
  // method's energy error grows at most linearly with the number of steps (here ~1e5): the
  // measured drift is 4e-10 of the energy scale after 1000 periods (errors of both signs partly
  // cancel). Bounds: 1e-8, and at most 20 times the drift after 100 periods (linear growth would
  // give 10; an instability would grow exponentially).
  CHECK(s1000.relative_energy_drift() < 1e-8);
  CHECK(s1000.relative_energy_drift() < 20 * std::max(s100.relative_energy_drift(), 1e-12));
  // Baumgarte stabilization returns each link to its length on τ_b: the violation stays at the
  // integration error (measured 1e-13).
  CHECK(s1000.max_constraint_violation < 1e-10);
}

TEST_CASE("50,000 links: a hanging chain at rest keeps the static tension g (mass below) and stays at rest",
          "[hard][string]") {
  const int links = 50000;
  auto scene = build(hanging_scene(links, 1, 0.1, 9.81, 0.0, "rtol = 1e-8\natol = 1e-12", 5e-4, 1e-3));
  StringSolver<2> solver(*scene.model, scene.solver);
  REQUIRE(run_scene(solver).empty());
  require_frames_finite(solver);
  const auto& chain = scene.model->chain();
  for (const auto& frame : solver.frames()) {
    // Link j holds up the nodes j+1..N: T_j = g Σ_{i>j} m_i, exactly for the discrete chain at rest.
    double below = 0, worst = 0;
    for (int j = links - 1; j >= 0; --j) {
      below += chain.masses()[j + 1];
      worst = std::max(worst, std::abs(frame.tension[j] - 9.81 * below) / (9.81 * 0.1));
    }
    CHECK(worst < 1e-9);
    CHECK(frame.v.cwiseAbs().maxCoeff() < 1e-9);
  }
  // Round-off of the positions (~1e-16 m) relative to a link of 2e-5 m.
  CHECK(solver.summary().max_constraint_violation < 1e-10);
}

TEST_CASE("a string pushed at an end: slack is detected at the first link, when the push begins",
          "[hard][string]") {
  // A straight string along +x, no gravity, its start driven along the string by x0 + A sin ωt and
  // moving with it: it moves rigidly, so link j carries T_j = (mass beyond j) · (−ẍ0) =
  // m_j⁺ A ω² sin ωt. For t > π/ω the end pushes: every tension turns negative, link 0 (the largest)
  // first in magnitude. Analytic slack time: t* = π/ω.
  const double A = 0.1, omega = 5;
  const std::string text = fmt::format(
      "[string]\nlength = 1.0\ndensity = 0.1\nnodes = 21\n[shape]\nkind = \"polyline\"\n"
      "points = [[0.0, 0.0], [1.0, 0.0]]\n[velocity]\nkind = \"uniform\"\nvalue = [{0}, 0.0]\n"
      "[ends]\nstart = {{ kind = \"driven\", path = \"sine\", amplitude = [{1}, 0.0], omega = {2} }}\n"
      "[solver]\ncheck_slack = true\nmax_step = 1e-4\n[output]\ninterval = 0.01\n[stop]\nt_end = 2.0\n",
      A * omega, A, omega);
  auto scene = build(text);
  StringSolver<2> solver(*scene.model, scene.solver);
  try {
    solver.run();
    FAIL("a pushed string must go slack");
  } catch (const NumericalError& e) {
    const double t_star = M_PI / omega;
    CHECK(e.time() >= t_star);
    CHECK(e.time() <= t_star + 1e-4);  // the first accepted step past t* (max_step = 1e-4 s)
    CHECK_THAT(std::string(e.what()), Contains("slack") && Contains("link 0 "));
  }
  // Before t*, the tension of link 0 follows the rigid-motion law.
  for (const auto& f : solver.frames()) {
    if (f.t <= 0) continue;
    const double beyond = 0.1 * (1.0 - 0.5 / 20);  // mass of nodes 1..20 (end node: half a link)
    CHECK_THAT(f.tension[0], WithinAbs(beyond * A * omega * omega * std::sin(omega * f.t), 1e-7));
  }
}

TEST_CASE("the chain pendulum through its whip with the slack check off: finite, energy kept", "[hard][string]") {
  // pendulum_release.toml stops at 0.49 s because the discrete chain needs a negative tension near
  // its tip at ~0.51 s. With the check off the model goes on (a link may push); the ledger of this
  // conservative system must still close.
  std::string text = scene_file("pendulum_release.toml");
  text.replace(text.find("check_slack = true"), 18, "check_slack = false");
  text.replace(text.find("t_end = 0.49"), 12, "t_end = 0.7");
  auto scene = build(text);
  StringSolver<2> solver(*scene.model, scene.solver);
  double max_tip_speed = 0;
  Points<2> x, v;
  solver.on_step = [&](double t, const Eigen::VectorXd& y) {
    scene.model->unpack(t, y, x, v);
    max_tip_speed = std::max(max_tip_speed, v.col(v.cols() - 1).norm());
  };
  REQUIRE(run_scene(solver).empty());
  require_frames_finite(solver);
  double min_tension = 0;
  for (const auto& f : solver.frames()) min_tension = std::min(min_tension, f.tension.minCoeff());
  CHECK(min_tension < 0);  // it went through the regime the slack check refuses
  CHECK(max_tip_speed > 2 * std::sqrt(2 * 9.81));  // the whip: ~3x a dropped particle's speed
  CHECK(solver.summary().relative_energy_drift() < 1e-8);  // measured 9e-11 at rtol 1e-8
  CHECK(solver.summary().max_constraint_violation < 1e-6);
}

TEST_CASE("extreme but valid units give the same scaled answer to 1e-9 (string scene)", "[hard][string]") {
  // A 10-link hanging chain over 2 time units sqrt(ℓ/g): positions/ℓ, velocities/sqrt(gℓ) and
  // tensions/(λgℓ) at the same scaled times. rtol 1e-12 so that each run is accurate to ~1e-11.
  auto scaled = [](double l, double lam, double g) {
    const double tu = std::sqrt(l / g);
    auto scene = build(hanging_scene(10, l, lam, g, 0.3, fmt::format("rtol = 1e-12\natol = {:.17g}", 1e-14 * l),
                                     0.5 * tu, 2 * tu));
    StringSolver<2> solver(*scene.model, scene.solver);
    REQUIRE(run_scene(solver).empty());
    require_frames_finite(solver);
    const auto& f = solver.frames().back();
    Eigen::VectorXd out(f.x.size() + f.v.size() + f.tension.size());
    out << Eigen::Map<const Eigen::VectorXd>(f.x.data(), f.x.size()) / l,
        Eigen::Map<const Eigen::VectorXd>(f.v.data(), f.v.size()) / std::sqrt(g * l), f.tension / (lam * g * l);
    return out;
  };
  const Eigen::VectorXd ref = scaled(1, 1, 9.81);
  const double units[][3] = {{1e-3, 1, 9.81}, {1e3, 1, 9.81}, {1, 1e-6, 9.81},
                             {1, 1e6, 9.81},  {1, 1, 1e-3},   {1, 1, 1e3}};
  for (const auto& u : units) {
    INFO("length " << u[0] << ", density " << u[1] << ", gravity " << u[2]);
    CHECK((scaled(u[0], u[1], u[2]) - ref).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("every method alias at rtol 1e-14 and 1e-2 on one short scene finishes or stops with a diagnostic",
          "[hard][integrator]") {
  constexpr double kWall = 20;
  auto run_with = [](const std::string& method, double rtol, std::string& error) {
    auto scene = build(hanging_scene(10, 1, 0.1, 9.81, 0.3,
                                     fmt::format("method = \"{}\"\nrtol = {:g}\natol = {:g}", method, rtol, rtol * 1e-2),
                                     0.25, 0.25));
    // SDIRK 2 at rtol 1e-14 would need ~1e6 steps here (15 s): 5000 steps, then a diagnostic.
    scene.solver.integrator.max_steps = 5000;
    scene.solver.integrator.max_wall_s = kWall;  // the watchdog's last resort: no run may hang
    StringSolver<2> solver(*scene.model, scene.solver);
    error = run_scene(solver);
    require_frames_finite(solver);
    return solver.frames().back().x;
  };
  std::string error;
  const Points<2> ref = run_with("erk8", 1e-12, error);
  REQUIRE(error.empty());
  std::vector<std::string> methods;
  for (const auto& [alias, what] : method_aliases()) methods.push_back(alias);
  methods.push_back("ARKODE_ARK437L2SA_ERK_7_3_4");
  for (const auto& method : methods) {
    for (double rtol : {1e-14, 1e-2}) {
      INFO(method << " at rtol " << rtol);
      const auto start = std::chrono::steady_clock::now();
      const Points<2> x = run_with(method, rtol, error);
      CHECK(seconds_since(start) < kWall + 5);  // ends within its wall budget (one step is milliseconds)
      if (!error.empty()) {
        CHECK_THAT(error, Contains("t = ") && Contains("method"));  // a diagnostic: when, with what
        continue;
      }
      // Completed: at rtol 1e-14 every method agrees with the reference to 1e-6 m (measured
      // 1e-9 for the low orders); at 1e-2 only a gross bound is meaningful.
      CHECK((x - ref).cwiseAbs().maxCoeff() < (rtol < 1e-10 ? 1e-6 : 0.2));
    }
  }
}
