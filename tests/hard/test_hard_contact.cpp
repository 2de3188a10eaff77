// Hard cases of contact along arcs (docs/model.md §10; issue 23 item 6), each run with solver.slack =
// "allow" (the landings push the links behind them, which go slack): a touchdown at grazing incidence,
// an arc that lifts off a table and lands again, contact on a coarse mesh (5 nodes) over a pulley. Each
// one finishes, or stops with a located diagnostic (exit 3's NumericalError naming the time), in
// seconds; never NaN, never a hang. References: the ledgers (energy with W_impacts and W_snap, momentum
// along a smooth table) and the motion's invariants (a chain on the table ends on it).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

struct HardRun {
  std::string status, error;
  double seconds = 0, t_last = 0, drift = 0, momentum = 0, impacts = 0, lift_offs = 0, snaps = 0;
  double highest = 0, lowest = 0, px0 = 0, px = 0, w_impacts = 0;
  bool finite = true;
};

HardRun run_spec(const SceneSpec& spec) {
  HardRun r;
  const auto start = std::chrono::steady_clock::now();
  StringScene<2> scene = build_string_scene<2>(spec);
  StringSolver<2> solver(*scene.model, scene.solver);
  try {
    const RunSummary& s = solver.run();
    r.status = s.status;
    r.drift = s.relative_energy_drift();
    r.momentum = s.relative_momentum_residual();
  } catch (const NumericalError& e) {
    r.status = "numerical error";
    r.error = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& frames = solver.frames();
  REQUIRE(!frames.empty());
  for (const auto& f : frames) r.finite = r.finite && f.x.allFinite() && f.v.allFinite() && std::isfinite(f.drift);
  const auto& first = frames.front();
  const auto& last = frames.back();
  r.t_last = last.t;
  r.impacts = last.terms["impacts"];
  r.lift_offs = last.terms["lift_offs"];
  for (const LedgerTerm& term : *last.terms.names)  // slack = "allow" only
    if (term.name == "snaps") r.snaps = last.terms["snaps"];
  r.w_impacts = last.terms["W_impacts"];
  r.highest = last.x.row(1).maxCoeff();
  r.lowest = last.x.row(1).minCoeff();
  const Eigen::VectorXd& m = scene.model->masses();
  for (int i = 0; i < first.v.cols(); ++i) {
    r.px0 += m[i] * first.v(0, i);
    r.px += m[i] * last.v(0, i);
  }
  return r;
}

HardRun run_text(const std::string& text) { return run_spec(parse_scene_text(text, "hard_contact.toml")); }

void print(const char* name, const HardRun& r) {
  std::printf("\n%s: %s%s%s in %.2f s of CPU, to t = %.6g s; impacts %g, lift-offs %g, snaps %g, energy residual "
              "%.3g, momentum residual %.3g, lowest node %.3g m\n",
              name, r.status.c_str(), r.error.empty() ? "" : ": ", r.error.c_str(), r.seconds, r.t_last, r.impacts,
              r.lift_offs, r.snaps, r.drift, r.momentum, r.lowest);
}

/// A hard case's verdict: finite outputs, and either completed with closed ledgers (the energy's relative
/// residual below drift_bound) or stopped with the time.
void finished_or_located(const HardRun& r, double drift_bound = 1e-6) {
  CHECK(r.finite);
  if (r.status == "completed") {
    CHECK(r.drift < drift_bound);
    CHECK(r.momentum < 1e-9);
  } else {
    CHECK_THAT(r.error, Catch::Matchers::Contains("t = "));
  }
}

const char* kTable = "[[effects.surface]]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n";

}  // namespace

TEST_CASE("hard contact: a chain touching down on a table at grazing incidence", "[hard][contact][slack]") {
  // 1 m of chain tilted by 1e-4 rad, sliding at 1 m/s and falling: its low end lands first and the
  // touchdown sweeps along it at ~g t/θ, 10⁴ times the chain's speed: 40 landings within 6 ms.
  const double theta = 1e-4, low = 0.01;
  const std::string text = fmt::format(
      "[string]\ndensity = 1.0\nnodes = 41\n[shape]\nkind = \"polyline\"\npoints = [[0.0, {0:.17g}], [{1:.17g}, "
      "{2:.17g}]]\n[velocity]\nkind = \"uniform\"\nvalue = [1.0, 0.0]\n[effects.gravity]\ng = [0.0, -9.81]\n{3}"
      "[solver]\nmethod = \"erk5\"\nrtol = 1e-9\natol = 1e-11\nslack = \"allow\"\n[output]\ninterval = 0.02\n"
      "[stop]\nt_end = 0.1\n",
      low, std::cos(theta), low + std::sin(theta), kTable);
  const HardRun r = run_text(text);
  print("grazing touchdown", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
  CHECK(r.finite);
  REQUIRE(r.status == "completed");
  CHECK(r.impacts >= 1);
  CHECK(std::abs(r.lowest) < 1e-9);  // every node on the table
  CHECK(std::abs(r.highest) < 1e-9);
  CHECK(std::abs(r.px - r.px0) < 1e-12);  // the smooth table takes no momentum along it
  CHECK(r.drift < 1e-7);
  CHECK(r.momentum < 1e-10);
}

TEST_CASE("hard contact: an arc that lifts off a table and lands again", "[hard][contact][slack]") {
  // A chain lying on the table, its last 0.3 m thrown up (the initial velocities rise linearly to 2 m/s at
  // the end; the run projects them onto the links): that arc lifts off, flies and lands again.
  const int nodes = 41;
  std::string values;
  for (int i = 0; i < nodes; ++i) {
    const double s = static_cast<double>(i) / (nodes - 1);
    values += fmt::format("{}[0.0, {:.17g}]", i == 0 ? "" : ", ", s > 0.7 ? 2.0 * (s - 0.7) / 0.3 : 0.0);
  }
  const std::string text = fmt::format(
      "[string]\ndensity = 1.0\nnodes = {0}\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.0, 0.0]]\n"
      "[velocity]\nkind = \"nodes\"\nvalues = [{1}]\n[effects.gravity]\ng = [0.0, -9.81]\n{2}"
      "[solver]\nmethod = \"erk5\"\nrtol = 1e-9\natol = 1e-11\nslack = \"allow\"\n[output]\ninterval = 0.05\n"
      "[stop]\nt_end = 0.8\n",
      nodes, values, kTable);
  const HardRun r = run_text(text);
  print("lift-off and landing again", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
  CHECK(r.finite);
  CHECK(r.lift_offs >= 1);
  if (r.status == "completed") {
    CHECK(r.impacts >= 1);
    CHECK(std::abs(r.lowest) < 1e-9);  // on or above the table
    CHECK(std::abs(r.px - r.px0) < 1e-12);
    CHECK(r.drift < 1e-7);
    CHECK(r.momentum < 1e-10);
  } else {
    CHECK_THAT(r.error, Catch::Matchers::Contains("t = "));
  }
}

TEST_CASE("hard contact: 5 nodes over a pulley", "[hard][contact][slack]") {
  // The Atwood scene on 5 nodes: links of 0.25 m over a pulley of radius 0.1 m, released at rest, run
  // past the lift-off of its shorter side (0.525 s) and its whip over the pulley.
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const HardRun r = run_spec(parse_scene(file, {"string.nodes=5", "solver.slack=allow", "stop.t_end=2.0",
                                                "output.interval=0.1"}));
  print("5 nodes over a pulley", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
  finished_or_located(r);
}

TEST_CASE("hard contact: 5 nodes over a pulley with links along the arc", "[hard][contact][slack]") {
  // The same with effects.cylinder[0].contact = "arc": one node on the pulley, its two links running round
  // it from free ends. The circle's sense of wrapping was taken from two consecutive held nodes only, so
  // here it kept its default, the wrong way round: the node was let go at once and the chain fell through
  // the pulley (energy ledger 1.65e-3 with slack = "allow"; with "stop", a pushing link at 0.0831 s). Now
  // it runs past the lift-off and the whip with the energy ledger closed (measured 2.7e-11), and up to
  // 0.5 s (bilateral links) never enters the pulley.
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const HardRun r = run_spec(parse_scene(file, {"effects.cylinder[0].contact=arc", "string.nodes=5", "solver.slack=allow",
                                                "stop.t_end=2.0", "output.interval=0.1"}));
  print("5 nodes over a pulley, links along the arc", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
  CHECK(r.finite);
  CHECK(r.status == "completed");
  CHECK(r.drift < 1e-9);
  CHECK(r.momentum < 1e-12);
  const SceneSpec spec = parse_scene(file, {"effects.cylinder[0].contact=arc", "string.nodes=5", "output.interval=0.01"});
  StringScene<2> scene = build_string_scene<2>(spec);
  StringSolver<2> solver(*scene.model, scene.solver);
  const RunSummary& s = solver.run();
  CHECK(s.status == "completed");
  CHECK(s.relative_energy_drift() < 1e-9);
  double closest = INFINITY;
  for (const auto& f : solver.frames())
    for (int i = 0; i < f.x.cols(); ++i) closest = std::min(closest, f.x.col(i).norm());
  std::printf("  with bilateral links to 0.5 s: %s, energy residual %.3g, closest node to the axis %.9g m (R = 0.1 m)\n",
              s.status.c_str(), s.relative_energy_drift(), closest);
  CHECK(closest > 0.1 - 1e-9);
}

TEST_CASE("hard contact: a closed loop running round over a pulley ends in seconds, completed or located",
          "[hard][contact]") {
  // A closed loop of 80 nodes hanging over a pulley of radius 0.1 m (a half circle on it, two sides 0.35 m
  // long and a bottom of 0.2 m), launched along itself at 3 m/s (slack = "allow", as the other cases here;
  // with "stop" the same happens at 0.4606 s). Near t = 0.3453 s a node of it landed and was let go at the
  // same instant over and over: events at one time until the step budget, a minute of wall time for 0.5 s,
  // deaf to SIGTERM between the events. The run now ends in a second: completed, or stopped at that time
  // with the events named. That node had not landed: ARKODE's interpolant put its landing root function
  // (started at +2e-7 when it was let go) below zero within the next step, the recomputed step put the
  // root back at the same instant, the node was caught there, and its contact force after the impact
  // pulled, so it was let go again. A node whose force pulls after its impact now passes (its velocity
  // projected, the impact booked in W_impacts) and its landing root restarts above the interpolant's
  // error: with slack = "stop" (1000 events at 0.460590 s) the loop runs round the pulley to t_end, its
  // energy ledger closed to 10⁻⁸. With "allow" it stopped, located, at 0.1697 s: "snap taut was not
  // located". A landing's impact projects the positions, and that carried a slack link 6e-10 past its root
  // (its snap function below zero at the restart, where ARKODE never finds a root): the link went on
  // stretching unseen. The slack module now snaps such a link at that instant; the loop runs to t_end with
  // its snaps and its energy ledger closed (measured 5.1e-8 with W_snap, W_impacts).
  for (const char* slack : {"allow", "stop"}) {
  CAPTURE(slack);
  std::string points;
  for (int i = 0; i <= 60; ++i) {
    const double a = 3.141592653589793 * i / 60, r = 0.1 * 1.0003;
    points += fmt::format("[{:.17g}, {:.17g}], ", r * std::cos(a), r * std::sin(a));
  }
  points += "[-0.10003, -0.35], [0.10003, -0.35]";
  const std::string text = fmt::format(
      "[string]\nclosed = true\nnodes = 80\n[shape]\nkind = \"points\"\npoints = [{}]\n[velocity]\n"
      "kind = \"tangential\"\nspeed = 3.0\n[effects.gravity]\ng = [0.0, -9.81]\n[[effects.cylinder]]\n"
      "center = [0.0, 0.0]\nradius = 0.1\n[solver]\nslack = \"{}\"\n[stop]\nt_end = 0.5\n",
      points, slack);
  const HardRun r = run_text(text);
  print("closed loop round a pulley", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 10);
  finished_or_located(r);
  if (std::string(slack) == "stop") {
    CHECK(r.status == "completed");
    CHECK(r.t_last == Approx(0.5));
    CHECK(r.impacts > 0);
    CHECK(r.w_impacts < 0);  // the landings' Carnot losses, booked
    CHECK(r.drift < 1e-7);
  } else {
    CHECK(r.status == "completed");
    CHECK(r.t_last == Approx(0.5));
    CHECK(r.snaps > 0);
    CHECK(r.drift < 1e-6);
  }
  }
}

TEST_CASE("hard contact: the Atwood pulley at loose tolerances ends in seconds, completed or located",
          "[hard][contact]") {
  // At rtol 1e-4 with atol 1e-2 the event polish looped for ever (deaf to SIGTERM): the model refused a trial
  // state on the way to the event, ARKODE returned without moving, and the polish called it again as it was.
  // At rtol = atol = 1e-2 the polish moved the event past ARKODE's root, beyond the frames taken before it:
  // an internal error ("the integrator only moves forward in time"). Now the refused step is taken again
  // smaller (as advance() does), the event stays inside the step that holds the root, and the frames are
  // taken up to that step's end. (Both runs then stopped, located: events came back at one time. Now the
  // run at rtol = atol = 1e-2 completes: its energy ledger closes to the accuracy asked for, a few rtol (1.04e-2
  // measured: a global error), not 1e-6.)
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  for (const char* rtol : {"1e-4", "1e-2"}) {
    CAPTURE(rtol);
    const HardRun r = run_spec(parse_scene(file, {fmt::format("solver.rtol={}", rtol), "solver.atol=1e-2"}));
    print("Atwood pulley at loose tolerances", r);
    CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
    finished_or_located(r, std::max(1e-6, 3 * std::stod(rtol)));
  }
}

TEST_CASE("hard contact: the Atwood pulley at loose tolerances with links along the arc completes or stops located",
          "[hard][contact]") {
  // effects.cylinder[0].contact = "arc" at rtol 1e-4 and 1e-2 with atol 1e-2 m, a link's length on the 1 m string: the
  // steps are set by atol, and which landings a run takes, and where, depends on its step sequence, which anything
  // moves (the output interval, one more ledger entry changing the error norm's weights): a chaotic draw. One run's
  // residual is no measure of the ledger at that tolerance (it was 1.1e-5, then 1.9e-3 with one more ledger entry,
  // 1.25e-2, then 2.4e-2 with a corrected landing root, at the same setting), so the test takes eight: the output
  // intervals 0.01, 0.02, 0.025 and 0.05 s at both rtols. Each run is finite and ends either completed or at a located
  // slack stop (at atol = h a trial tension can go negative: "slack at t = … link … T < 0", the model's own
  // diagnostic; one of the eight in the measurements below); at most two of the eight stop. The ledger of the runs
  // that complete: their median below 5e-3 and each below 5 atol/ℓ = 5e-2. Measured on the eight (relative energy
  // residual): before that correction 3.0e-3 median, 1.25e-2 worst, none stopped; with the landing root continuous past
  // the tangent point 2.3e-3 median, 2.4e-2 worst, one slack stop (rtol 1e-2, 0.01 s); over 40 settings (rtol 1e-4 …
  // 1e-2, intervals 0.005 … 0.05 s) 1.7e-3 and 4.0e-4 median, two of 40 above 2e-2 with either. Under the
  // sanitizers two of the eight (0.02 s) keep the run time down.
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const std::vector<const char*> intervals =
      CHAINSIM_WALL_FACTOR > 1 ? std::vector<const char*>{"0.02"} : std::vector<const char*>{"0.01", "0.02", "0.025", "0.05"};
  std::vector<double> residuals;
  int stopped = 0, runs = 0;
  for (const char* interval : intervals) {
    for (const char* rtol : {"1e-4", "1e-2"}) {
      CAPTURE(interval, rtol);
      const HardRun r = run_spec(parse_scene(file, {"effects.cylinder[0].contact=arc", fmt::format("solver.rtol={}", rtol),
                                                    "solver.atol=1e-2", fmt::format("output.interval={}", interval)}));
      print("Atwood pulley at loose tolerances, links along the arc", r);
      ++runs;
      CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
      CHECK(r.finite);
      if (r.status == "completed") {
        residuals.push_back(r.drift);
        CHECK(r.drift < 5e-2);
        // The momentum ledger closes to round-off at the steps' ends; a frame inside a step is interpolated and
        // projected onto the contacts, which moves its momentum by the integration error: 2.6e-3 and 3.2e-3 at the
        // interval 0.01 s (rtol 1e-4 and 1e-2), 3.1e-8 at rtol = atol = 1e-6, 5e-16 at rtol 1e-8, atol 1e-10; 4e-16 to
        // 7e-16 at the other intervals. Bound: the accuracy asked for, atol/ℓ, at 0.01 s; round-off elsewhere.
        CHECK(r.momentum < (std::string(interval) == "0.01" ? 1e-2 : 1e-12));
      } else {
        ++stopped;
        CHECK(r.status == "numerical error");
        CHECK_THAT(r.error, Catch::Matchers::Contains("slack at t =") && Catch::Matchers::Contains("an inextensible string cannot push"));
      }
    }
  }
  CHECK(stopped <= runs / 4);
  REQUIRE(!residuals.empty());
  std::sort(residuals.begin(), residuals.end());
  const double median = residuals[residuals.size() / 2];
  std::printf("Atwood pulley at loose tolerances: %d runs, %d stopped, median relative energy residual %.3g\n", runs, stopped,
              median);
  // The median of the eight; under the sanitizers (one interval, two runs: 1.2e-3 and 2.4e-2) there is no median to
  // speak of, and the runs are checked one by one above.
  if (CHAINSIM_WALL_FACTOR == 1) CHECK(median < 5e-3);
}

TEST_CASE("hard contact: a lift-off root that Newton overshoots or the recomputed step refutes is no event at "
          "the step's start", "[hard][contact]") {
  // The smallest normal force of the held nodes is a minimum over nodes: its rate jumps where another node
  // becomes the smallest. At loose tolerances the polish's Newton step from the recomputed state at ARKODE's
  // root (past the zero) pointed before the step's start; it was held there, where the force is 0.609 of the
  // weight scale (rough pulley, rtol = atol = 1e-2) or 0.544 (smooth pulley, rtol 1e-4, atol 1e-2), and the
  // event was reported there: nothing to let go, the same root found again, 1000 times, "events stalled" at
  // 0.04 s and 0.1325 s. Now the polish keeps the root's bracket (the last state before the zero, the first
  // past it) and halves it where Newton leaves it; a root that neither the accepted step's end nor any
  // recomputed state has passed is no event (the step is taken again without it). Both runs now go past
  // those times (their later stops, located, are the contact model's at that accuracy).
  const std::filesystem::path dir = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes";
  struct Case {
    const char* file;
    const char* rtol;
    double stalled_at;
  };
  for (const Case& c : {Case{"atwood_rough_pulley.toml", "1e-2", 0.04}, Case{"atwood_pulley.toml", "1e-4", 0.1325}}) {
    CAPTURE(c.file, c.rtol);
    const HardRun r = run_spec(parse_scene(dir / c.file, {fmt::format("solver.rtol={}", c.rtol), "solver.atol=1e-2"}));
    print("lift-off root at loose tolerances", r);
    CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
    finished_or_located(r);
    CHECK_THAT(r.error, !Catch::Matchers::Contains("events stalled"));
    CHECK(r.t_last > c.stalled_at + 0.01);
  }
}

TEST_CASE("hard contact: a node that an impact's projection carries through the pulley lands at that instant",
          "[hard][contact]") {
  // The Atwood pulley at rtol = atol = 1e-2: its links are off their lengths by up to a few % of h, and the
  // projection at a landing moved a free node (let go 0.01 s before) 0.003 h into the pulley. Its landing
  // function started below zero, where ARKODE never finds a root: it fell through the pulley, and the run
  // ended in a Zeno of events (main: "events stalled" at 0.2507 s; rtol 1e-4: steps below the floor at
  // 0.170 s). Now the nodes the projection puts through a surface land at that instant. Reference: the
  // obstacle, never entered (every node at least R from the axis up to the integration's accuracy).
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const SceneSpec spec = parse_scene(file, {"solver.rtol=1e-2", "solver.atol=1e-2"});
  StringScene<2> scene = build_string_scene<2>(spec);
  StringSolver<2> solver(*scene.model, scene.solver);
  const auto start = std::chrono::steady_clock::now();
  const RunSummary& s = solver.run();
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < CHAINSIM_WALL_FACTOR * 20);
  CHECK(s.status == "completed");
  double closest = INFINITY;
  for (const auto& f : solver.frames()) {
    REQUIRE(f.x.allFinite());
    for (int i = 0; i < f.x.cols(); ++i) closest = std::min(closest, f.x.col(i).norm());
  }
  std::printf("\nAtwood pulley at rtol = atol = 1e-2: %s to t = %.4g s, closest node to the axis %.6g m (R = 0.1 m)\n",
              s.status.c_str(), solver.frames().back().t, closest);
  CHECK(closest > 0.1 - 1e-3);  // R less 1e-3 m (h = 0.01 m, the links off their lengths by up to ~2 %)
}

TEST_CASE("hard contact: a landing root that the recomputed solution does not reach is no event and a node "
          "found inside the pulley at an event lands there", "[hard][contact]") {
  // ARKODE finds its roots on its interpolant; at loose tolerances that crossed zero where the method's own
  // solution, recomputed by the polish, did not: a node let go with no normal speed (its gap quadratic in t,
  // Newton's iterations spent before its zero) or let go at once after a landing (its landing function
  // restarting at +kPassGap, the probe at the step's start of no length: no slope). The polish reported
  // the event there anyway, the landing window found no node, nothing changed, and the same root came back
  // 1000 times: "events stalled" (main: smooth pulley at rtol = atol = 3e-3 at 0.3058 s; rough pulley at
  // rtol 1e-4, atol 1e-2 at 0.1341 s, and on 201 nodes at rtol = atol = 1e-2 at 0.0629 s). Now such a root is
  // no event without a state past the zero (refuted), and at the step's start with one the bracket is
  // halved to the zero. And a node whose landing crossing was not on the interpolant of a step that held
  // another event was inside the pulley at that event: its landing function restarted below zero, where
  // ARKODE finds no root, and it fell through (main: the smooth pulley on 201 nodes at rtol = atol = 1e-4
  // completed with a node 0.39 h inside it, 4.9 h at 1e-3). Now every event lands such nodes.
  // Each run completes, or stops later with a located slack stop (a tension of -1e-3 of its scale or less,
  // within the integration error of zero at that tolerance). Its energy ledger closes to the order of the tolerance
  // tau = max(rtol, atol) asked for (a global error; measured 2.21, 0.898, 0.289 and 0.135 tau, bounds about 3
  // times those), its momentum ledger to round-off, and no node enters the pulley beyond the landing
  // functions' offsets (a node let go and caught at one instant restarts at kPassGap = 1e-5 h: measured at most
  // 6.6e-6 h inside; bound 3 kPassGap h).
  const std::filesystem::path dir = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes";
  struct Case {
    const char* file;
    int nodes;
    double rtol, atol, stalled_at, drift_per_tau;  // stalled_at: main's stall (0.5: it completed)
  };
  for (const Case& c : {Case{"atwood_pulley.toml", 101, 3e-3, 3e-3, 0.3058, 6.0},
                        Case{"atwood_rough_pulley.toml", 101, 1e-4, 1e-2, 0.1341, 3.0},
                        Case{"atwood_rough_pulley.toml", 201, 1e-2, 1e-2, 0.0629, 1.0},
                        Case{"atwood_pulley.toml", 201, 1e-4, 1e-4, 0.5, 0.4}}) {
    CAPTURE(c.file, c.nodes, c.rtol, c.atol);
    const SceneSpec spec = parse_scene(dir / c.file, {fmt::format("string.nodes={}", c.nodes), fmt::format("solver.rtol={}", c.rtol),
                                                      fmt::format("solver.atol={}", c.atol)});
    StringScene<2> scene = build_string_scene<2>(spec);
    StringSolver<2> solver(*scene.model, scene.solver);
    const auto start = std::chrono::steady_clock::now();
    std::string error;
    try {
      solver.run();
    } catch (const NumericalError& e) {
      error = e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const RunSummary& s = solver.summary();
    double closest = INFINITY;
    for (const auto& f : solver.frames()) {
      REQUIRE(f.x.allFinite());
      REQUIRE(f.v.allFinite());
      for (int i = 0; i < f.x.cols(); ++i) closest = std::min(closest, f.x.col(i).norm());
    }
    const double tau = std::max(c.rtol, c.atol), h = 1.0 / (c.nodes - 1);
    std::printf("\n%s on %d nodes at rtol %g, atol %g: %s%s%s in %.2f s, to t = %.6g s; energy residual %.3g (%.3g tau), "
                "momentum residual %.3g, deepest node %.3g h inside the pulley (R = 0.1 m)\n",
                c.file, c.nodes, c.rtol, c.atol, s.status.c_str(), error.empty() ? "" : ": ", error.c_str(), seconds,
                s.t_stop, s.relative_energy_drift(), s.relative_energy_drift() / tau, s.relative_momentum_residual(),
                (0.1 - closest) / h);
    CHECK(seconds < CHAINSIM_WALL_FACTOR * 20);
    CHECK_THAT(error, !Catch::Matchers::Contains("events stalled"));
    if (s.status == "completed") {
      CHECK(s.t_stop == Approx(0.5));
    } else {  // a located physical stop, past the time the events stalled at
      CHECK_THAT(error, Catch::Matchers::StartsWith("slack at t = "));
      CHECK(s.t_stop > c.stalled_at + 0.01);
    }
    CHECK(s.relative_energy_drift() < c.drift_per_tau * tau);
    CHECK(s.relative_momentum_residual() < 1e-12);
    CHECK(closest > 0.1 - 3e-5 * h);  // 3 kPassGap h: a landing function restarts at most kPassGap h above zero
  }
}

TEST_CASE("hard contact: the Atwood pulley with slack allowed and elastic snaps runs to its end",
          "[hard][contact][slack]") {
  // atwood_pulley.toml with slack = "allow" and snap_restitution = 1 stopped at 0.27994 s (main), "snap taut
  // was not located": a landing's projection had carried a slack link past its root at the restart. The
  // short run to 0.285 s passes that time; reference: the energy ledger (elastic snaps: W_snap only from the
  // supports, the landings' Carnot losses in W_impacts).
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const HardRun r = run_spec(parse_scene(file, {"solver.slack=allow", "solver.snap_restitution=1", "stop.t_end=0.285"}));
  print("Atwood pulley, slack allowed, elastic snaps", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 30);
  CHECK(r.status == "completed");
  CHECK(r.t_last == Approx(0.285));
  CHECK(r.drift < 1e-6);
}

TEST_CASE("hard contact: a spinning loop dropped on a table with slack allowed stays on the table",
          "[hard][contact][slack]") {
  // A closed loop of 60 nodes (radius 0.1 m, its centre 0.3 m above a table) running along itself at 2 m/s,
  // dropped (slack = "allow"). main stops at 0.6128 s, located: "the tension system is singular ...
  // (Sherman-Morrison correction of the closed arc)"; this branch stops at 0.4785 s, located: "link 25 has
  // collapsed" (the root cause, a real limit or a defect, is not found yet). A step taken again after a
  // refuted landing root stopped at a snap's root, and the landing the hidden function had passed before it
  // was lost: a node fell through the table at 0.255 s. Now that landing comes first. References: finite
  // outputs, a located stop or the end with the ledger closed, and the table never entered.
  const std::string text =
      "[string]\ndensity = 1.0\nnodes = 60\nclosed = true\n[shape]\nkind = \"circle\"\ncenter = [0.0, 0.3]\n"
      "radius = 0.1\n[velocity]\nkind = \"tangential\"\nspeed = 2.0\n[effects.gravity]\ng = [0.0, -9.81]\n"
      "[[effects.surface]]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n[solver]\nslack = \"allow\"\n[output]\n"
      "interval = 0.01\n[stop]\nt_end = 1.0\n";
  const HardRun r = run_text(text);
  print("spinning loop dropped on a table", r);
  CHECK(r.seconds < CHAINSIM_WALL_FACTOR * 20);
  finished_or_located(r);
  CHECK(r.t_last > 0.3);
  CHECK(r.lowest > -1e-9);  // on or above the table
}

TEST_CASE("hard contact: a closed loop that starts all round a cylinder is refused as locked, a looser one runs",
          "[hard][contact][slack]") {
  // A loop of radius 0.15 m on 64 nodes, spun at 20 rad/s under gravity, drawn on a cylinder of the same radius
  // (tester's run, issue 23): every node is held and the loop wraps the axis, so it is locked and its uniform
  // tension indeterminate. It used to fail at t = 0 with the singular tension solve ("link 63 of arc 0 has pivot
  // -6.66e-16 …"), which did not name the cylinder; it is refused before the run with the cause. Round a cylinder
  // of 0.1499 m its nodes start 1e-4 m (7e-3 links) off it, not held: it runs.
  const std::string text = R"([string]
density = 0.1
nodes = 64
[shape]
kind = "circle"
center = [0.0, 0.0]
radius = 0.15
[velocity]
kind = "rotation"
omega = 20.0
center = [0.0, 0.0]
[effects.gravity]
g = [0.0, -9.81]
[[effects.cylinder]]
center = [0.0, 0.0]
radius = 0.15
[solver]
slack = "allow"
[output]
interval = 0.01
[stop]
t_end = 0.5
)";
  CHECK_THROWS_WITH(build_string_scene<2>(parse_scene_text(text, "locked_loop.toml")),
                    Catch::Matchers::StartsWith("locked_loop.toml:") &&
                        Catch::Matchers::Contains("all its 64 nodes held on effects.cylinder[0]") &&
                        Catch::Matchers::Contains("it is locked there, and its tension is indeterminate"));
  const HardRun looser = run_spec(parse_scene_text(text, "locked_loop.toml", {"effects.cylinder[0].radius=0.1499"}));
  print("a loop round a cylinder 0.1 mm thinner", looser);
  CHECK(looser.status == "completed");
  finished_or_located(looser, 1e-8);  // energy residual measured 2.5e-9
  // In 3D a loop round the cylinder at 30 degrees to its cross-section (an ellipse on it, every node on the surface)
  // is not locked: a uniform tension would push it along the cylinder, so it deforms and runs (review).
  std::string points;
  for (int k = 0; k <= 360; ++k) {
    const double phi = 2 * kPi * k / 360;
    points += fmt::format("{}[{:.17g}, {:.17g}, {:.17g}]", k ? ", " : "", 0.15 * std::cos(phi), 0.15 * std::sin(phi),
                          std::tan(kPi / 6) * 0.15 * std::cos(phi));
  }
  const std::string tilted = fmt::format(R"([string]
dimension = 3
density = 0.1
nodes = 64
closed = true
[shape]
kind = "points"
points = [{}]
[effects.gravity]
g = [0.0, -9.81, 0.0]
[[effects.cylinder]]
center = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
radius = 0.15
[solver]
slack = "allow"
[stop]
t_end = 0.5
)",
                                         points);
  StringScene<3> scene = build_string_scene<3>(parse_scene_text(tilted, "tilted_loop.toml"));
  StringSolver<3> solver(*scene.model, scene.solver);
  const RunSummary r = solver.run();
  CHECK(r.status == "completed");
  CHECK(std::abs(r.relative_energy_residual()) < 1e-8);  // measured 2.7e-9 (the review's 64-node ellipse)
}
