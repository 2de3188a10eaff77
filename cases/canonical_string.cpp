// The canonical problems on the string solver: see canonical_string.hpp.
#include "cases/canonical_string.hpp"

#include <cmath>

#include <fmt/format.h>

#include "solver/errors.hpp"

namespace chainsim {

IntegratorOptions StringCaseSetup::default_integrator() {
  IntegratorOptions o;
  o.method = "erk5";
  o.rtol = 1e-9;
  o.atol = 1e-11;
  return o;
}

void StringCaseSetup::validate() const {
  chain.validate();
  if (nodes < 4 || nodes > 200001)
    throw InputError(fmt::format("--nodes = {} is out of range: allowed 4 <= nodes <= 200001", nodes));
  ReducedSetup reduced;
  reduced.problem = problem;
  reduced.chain = chain;
  reduced.eps = eps;
  reduced.eta0 = eta0;
  reduced.force = force;
  reduced.validate();
  require_in_range("--tilt", tilt_deg, -80.0, 80.0);
  require_in_range("t_max_over_t0", t_max_over_t0, 0.0, INFINITY, Bound::kOpen);
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
  ReducedSetup defaults;
  defaults.problem = setup.problem;
  defaults.eta0 = setup.eta0;
  double eta0 = defaults.initial_eta();
  Chain<2> chain = Chain<2>::uniform(lambda, ell, links, false);
  Points<2>& x = chain.positions();
  Points<2>& v = chain.velocities();
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -g)));
  std::vector<PrescribedNode<2>> prescribed;
  std::vector<HeapSpec<2>> heaps;
  std::optional<FoldSpec> fold;
  FrontModelOptions options;
  StringCaseRun out;
  const double t0 = setup.chain.t0();
  switch (setup.problem) {
    case Problem::kFalling: {
      // Free end (s = 0) on top; the material s <= y falls, the rest lies in the heap at x0 = 0.
      const double y0 = eta0 * ell;
      for (int i = 0; i <= links; ++i) x.col(i) = std::max(y0 - i * h, 0.0) * tilted;
      heaps.push_back({HeapSpec<2>::Side::kAfter, Vec<2>::Zero(), f, y0});
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
      heaps.push_back({HeapSpec<2>::Side::kBefore, Vec<2>::Zero(), f, s0});
      break;
    }
  }
  options.stabilization_time = 0.02 * t0;
  FrontModel<2> model(std::move(chain), std::move(forces), std::move(prescribed), std::move(heaps), fold, options);
  FrontRunOptions run_options;
  run_options.integrator = setup.integrator;
  run_options.t_end = setup.t_max_over_t0 * t0;
  out.run = run_fronts(model, run_options);
  // η, dη/dt and P per sample.
  for (const FrontSample& s : out.run.samples) {
    const double s0 = s.s0[0], sd = s.s0_dot[0];
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
  return out;
}

}  // namespace chainsim
