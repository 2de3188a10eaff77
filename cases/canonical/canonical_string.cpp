// The canonical problems on the string solver: see canonical_string.hpp.
#include "cases/canonical/canonical_string.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim {

IntegratorOptions StringCaseSetup::default_integrator() {
  IntegratorOptions o;
  o.method = defaults::kCanonicalString.method;
  o.rtol = defaults::kCanonicalString.rtol;
  o.atol = defaults::kCanonicalString.atol;
  return o;
}

ReducedSetup StringCaseSetup::reduced() const {
  ReducedSetup r;
  r.problem = problem;
  r.chain = chain;
  r.eps = eps;
  r.eta0 = eta0;
  r.force = force;
  r.t_max_over_t0 = t_max_over_t0;
  return r;
}

void StringCaseSetup::validate() const {
  chain.validate();
  if (nodes < 4 || nodes > 200001)
    throw InputError(fmt::format("--nodes = {} is out of range: allowed 4 <= nodes <= 200001", nodes));
  reduced().validate();
  require_in_range("--tilt", tilt_deg, -80.0, 80.0);
  require_in_range("--bend", bend_deg, -80.0, 80.0);
  if (bend_deg != 0 && problem != Problem::kFalling)
    throw InputError("--bend: only the falling chain has a curved variant");
  if (std::abs(tilt_deg + bend_deg) > 80.0)
    throw InputError(fmt::format("--tilt + --bend = {:g} degrees: the top of the falling chain must stay within 80 "
                                 "degrees of the vertical (its height must grow along the string)",
                                 tilt_deg + bend_deg));
  require_in_range("--t-max", t_max_over_t0, 0.0, INFINITY, Bound::kOpen);
  require_in_range("frame_interval", frame_interval, 0.0, INFINITY);
  integrator.validate();
}

StringCaseRun solve_string_case(const StringCaseSetup& setup) {
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double f = setup.chain.dissipation;
  const int links = setup.nodes - 1;
  const double h = ell / links;
  const double tilt = setup.tilt_deg * kPi / 180.0;
  const Vec<2> up(0.0, 1.0);
  const Vec<2> tilted(std::sin(tilt), std::cos(tilt));  // unit vector tilt away from up
  const double eta0 = setup.reduced().initial_eta();
  Chain<2> chain = Chain<2>::uniform(lambda, ell, links, false);
  Points<2>& x = chain.positions();
  Points<2>& v = chain.velocities();
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -g)));
  std::vector<PrescribedNode<2>> prescribed;
  std::vector<HeapSpec<2>> heaps;
  std::optional<FoldSpec> fold;
  FrontOptions options;
  StringCaseRun out;
  const double t0 = setup.chain.t0();
  switch (setup.problem) {
    case Problem::kFalling: {
      // Free end (s = 0) on top; the material s <= y falls, the rest lies in the heap on the table.
      // σ = y0 − s is the distance from the contact along the string; the tangent turns from `tilt`
      // at the table to `tilt + bend` at the top (a straight line when bend = 0).
      const double y0 = eta0 * ell;
      const double bend = setup.bend_deg * kPi / 180.0;
      for (int i = 0; i <= links; ++i) {
        const double sigma = std::max(y0 - i * h, 0.0);
        if (bend == 0) {
          x.col(i) = sigma * tilted;
        } else {
          // The arc of radius R = y0/bend turning by delta = sigma/R, written without the cancellation of
          // cos(tilt) - cos(tilt + delta) (bend = 2e-14 degrees put the heap point 1.6 cm off the shape).
          const double R = y0 / bend, delta = sigma / R, chord = 2 * R * std::sin(delta / 2);
          x.col(i) = chord * Vec<2>(std::sin(tilt + delta / 2), std::cos(tilt + delta / 2));
        }
      }
      heaps.push_back({HeapSpec<2>::Side::kAfter, Vec<2>::Zero(), f, y0, up});
      options.stop_at.push_back({0, setup.eps * ell});
      break;
    }
    case Problem::kFolded: {
      // Node 0 fixed at the origin; resting arm down to the fold at depth y0, moving arm back up.
      const double y0 = eta0 * ell;
      for (int i = 0; i <= links; ++i) {
        const double s = i * h;
        // Both arms lie on one line, tilted by tilt_deg: the fold stays a fold, the ends are apart.
        x.col(i) = s <= y0 ? Vec<2>(-s * tilted) : Vec<2>(-y0 * tilted + (s - y0) * tilted);
      }
      prescribed.push_back({0, std::make_shared<FixedPoint<2>>(Vec<2>::Zero())});
      fold = FoldSpec{f, y0};
      if (setup.force > 0) forces.push_back(std::make_unique<EndLoad<2>>(links, Vec<2>(0.0, setup.force)));
      options.stop_at.push_back({0, (1 - setup.eps) * ell});
      break;
    }
    case Problem::kSliding: {
      // The heap holds s < ℓ − y; the hanging part hangs from the hole x0 = 0 down to the free end s = ℓ.
      double y0 = eta0 * ell;
      double speed = 0;
      if (eta0 == 0) {
        // The exact branch y = a t²/2 from y = 0, joined at y = 2h.
        const double a = g / (3 + 2 * f);
        y0 = 2 * h;
        out.t_offset = std::sqrt(2 * y0 / a);
        speed = a * out.t_offset;
      }
      if (y0 < 0.5 * h * 1.0000001)
        throw InputError(fmt::format("--eta0 = {:g} is too small for {} nodes: the hanging part must be at least "
                                     "half a link long (eta0 >= {:g}), or start from eta0 = 0",
                                     eta0, setup.nodes, 0.5 * h / ell));
      const double s0 = ell - y0;
      for (int i = 0; i <= links; ++i) {
        const double s = i * h;
        x.col(i) = -std::max(s - s0, 0.0) * tilted;
        if (s > s0) v.col(i) = -speed * tilted;
      }
      heaps.push_back({HeapSpec<2>::Side::kBefore, Vec<2>::Zero(), f, s0, std::nullopt});
      break;
    }
  }
  StringModelOptions string_options;
  string_options.stabilization_time = 0.02 * t0;
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), std::move(prescribed),
                                             std::move(heaps), fold, options, string_options);
  StringSolverOptions run_options;
  run_options.integrator = setup.integrator;
  // The safety stop on the reduced model's clock, on which the string starts at t_offset (sliding
  // from η0 = 0): both models then end at the same instant.
  run_options.t_end = setup.t_max_over_t0 * t0 - out.t_offset;
  if (!(run_options.t_end > 0))
    throw InputError(fmt::format("--t-max = {:g} ends before the string starts (t/t0 = {:.6g} on the reduced "
                                 "solution, sliding from eta0 = 0): raise it",
                                 setup.t_max_over_t0, out.t_offset / t0));
  // The samples after every step are what is compared; frames only when asked for.
  run_options.output_interval = setup.frame_interval > 0 ? setup.frame_interval : run_options.t_end;
  run_options.record_steps = true;
  StringSolver<2> solver(model, run_options);
  try {
    solver.run();
  } catch (const NumericalError&) {  // the run's status says "failed" and why
  }
  out.run = solver.summary();
  out.frames = solver.frames();
  // η, dη/dt and P per sample.
  for (const StepSample& s : out.run.samples) {
    const double s0 = s.fronts[0].s0, sd = s.fronts[0].s0_dot;
    double eta = s0 / ell, eta_dot = sd / ell;
    if (setup.problem == Problem::kSliding) {
      eta = (ell - s0) / ell;
      eta_dot = -sd / ell;
    }
    out.t.push_back(s.t + out.t_offset);
    out.eta.push_back(eta);
    out.eta_dot.push_back(eta_dot);
    out.P.push_back(s.support[1]);
  }
  out.summary = to_json(out.run);
  out.summary["problem"] = to_string(setup.problem);
  out.summary["nodes"] = setup.nodes;
  out.summary["t_stop_over_t0"] = (out.run.t_stop + out.t_offset) / t0;
  out.summary["eta_stop"] = out.eta.empty() ? 0.0 : out.eta.back();
  out.summary["tilt_deg"] = setup.tilt_deg;
  if (setup.problem == Problem::kFalling) out.summary["bend_deg"] = setup.bend_deg;
  return out;
}

namespace {

/// A solution known at increasing times t_k with values q_k and derivatives dq_k: cubic Hermite.
struct Hermite {
  std::vector<double> t, q, dq;
  double operator()(double x) const {
    if (x <= t.front()) return q.front();
    if (x >= t.back()) return q.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    const double h = t[k + 1] - t[k], u = (x - t[k]) / h;
    const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
    const double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
    return h00 * q[k] + h10 * h * dq[k] + h01 * q[k + 1] + h11 * h * dq[k + 1];
  }
};

/// The time at which the (monotone) reduced η takes the value `eta`, by bisection on the Hermite
/// interpolant, then P there.
double time_at_eta(const Hermite& eta, double value, bool increasing) {
  double lo = eta.t.front(), hi = eta.t.back();
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    ((eta(mid) < value) == increasing ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

Comparison compare_with_reduced(const StringCaseSetup& setup) {
  Comparison c;
  c.string = solve_string_case(setup);
  ReducedSetup rs = setup.reduced();
  const double t0 = setup.chain.t0(), P0 = setup.chain.P0(), ell = setup.chain.length;
  rs.integrator.max_step = t0 / 5000;
  const auto start = std::chrono::steady_clock::now();
  c.reduced = solve_reduced(rs);
  const double wall_reduced = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Hermite eta{c.reduced.series.column("t"), c.reduced.series.column("y"), c.reduced.series.column("ydot")};
  for (double& y : eta.q) y /= ell;
  for (double& yd : eta.dq) yd /= ell;
  // P of the reduced model from the paper's closed forms in (y, ẏ), with ẏ interpolated from (ẏ, ÿ).
  Hermite ydot{eta.t, c.reduced.series.column("ydot"), c.reduced.series.column("yddot")};
  const double lambda = setup.chain.density, g = setup.chain.gravity, f = setup.chain.dissipation;
  auto reduced_P_at = [&](double t) {
    const double y = eta(t) * ell, yd = ydot(t);
    const double sg = (yd > 0) - (yd < 0);
    switch (setup.problem) {
      case Problem::kFolded: return lambda * (1 + f * sg) * yd * yd + lambda * g * y;
      default: return f * lambda * yd * yd + lambda * g * (ell - y);  // falling and sliding
    }
  };
  bool monotone = true;
  for (std::size_t k = 1; k < eta.q.size(); ++k)
    if ((eta.q[k] - eta.q[k - 1]) * (eta.q.back() - eta.q.front()) < 0) monotone = false;
  const bool increasing = eta.q.back() > eta.q.front();
  const StringCaseRun& s = c.string;
  double err_eta = 0, err_P = 0;
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    err_eta = std::max(err_eta, std::abs(s.eta[k] - eta(s.t[k])));
    const double t_ref = monotone ? time_at_eta(eta, s.eta[k], increasing) : s.t[k];
    const double P_ref = reduced_P_at(t_ref);
    err_P = std::max(err_P, std::abs(s.P[k] - P_ref) / std::max(std::abs(P_ref), P0));
  }
  const double ts = c.string.summary["t_stop_over_t0"].get<double>();
  const double tr = c.reduced.summary["t_stop_over_t0"].get<double>();
  c.summary = c.string.summary;
  c.summary["t_stop_over_t0_reduced"] = tr;
  c.summary["rel_err_t_stop"] = std::abs(ts - tr) / tr;
  c.summary["max_abs_err_eta"] = err_eta;
  c.summary["max_rel_err_P"] = err_P;
  c.summary["P_compared_at"] = monotone ? "equal eta" : "equal t";
  c.summary["wall_s_reduced"] = wall_reduced;
  c.summary["f"] = setup.chain.dissipation;
  c.summary["eps"] = setup.eps;
  c.summary["force"] = setup.force;
  c.summary["eta0"] = rs.initial_eta();
  return c;
}

}  // namespace chainsim
