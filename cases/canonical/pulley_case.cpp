// The heavy Atwood chain over a smooth pulley on the string solver: see pulley_case.hpp.
#include "cases/canonical/pulley_case.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "solver/contact_module.hpp"

namespace chainsim {

void PulleyCaseSetup::validate() const {
  chain.validate();
  if (nodes < 3 || nodes > 200001)
    throw InputError(fmt::format("--nodes = {} is out of range: allowed 3 <= nodes <= 200001", nodes));
  require_in_range("--R", radius, 0.0, chain.length / kPi, Bound::kOpen, Bound::kOpen);  // πR < ℓ
  // u0 = 0: at rest (unstable); u0 = ℓ_free/2: no shorter side.
  require_in_range("--u0", u0, 0.0, 0.5 * (chain.length - kPi * radius), Bound::kOpen, Bound::kOpen);
  require_shape_length("--R", radius, chain.length, "the pulley's radius R", radius);
  require_shape_length("--u0", u0, chain.length, "the shorter side (l - pi R)/2 - u0",
                       0.5 * (chain.length - kPi * radius) - u0);
  require_safety_stop(t_max_over_t0, chain.t0());
  integrator.validate();
}

namespace {

/// The run goes on to this multiple of the exact lift-off time t*, so that the string's lift-off (the
/// zero of its margin) is in it. It ends there: past the lift-off the shorter side unwraps, which the
/// links along the arc do not yet follow with closed ledgers (docs/model.md §10).
constexpr double kPastLiftOff = 1.005;

}  // namespace

double tension_at_pulley(const Points<2>& x, const Eigen::VectorXd& tension, int end, int step) {
  const int links = static_cast<int>(tension.size());
  auto link_of = [&](int node) { return step > 0 ? node : node - 1; };  // the link from `node` up the side
  int top = -1;  // the node at the top of the highest wholly-below link
  for (int i = end + step; i >= 0 && i <= links && x(1, i) < 0; i += step) top = i;
  if (top < 0 || std::abs(top - end) < 2) return std::nan("");
  const int j = link_of(top - step), k = link_of(top - 2 * step);
  auto mid = [&](int link) { return 0.5 * (x(1, link) + x(1, link + 1)); };
  const double y1 = mid(j), y0 = mid(k);
  return tension[j] + (tension[j] - tension[k]) / (y1 - y0) * (0 - y1);
}

void PulleyLiftOff::add(double t_step, double margin, double u) {
  if (t) return;
  const Step& prev = last_[0];
  if (have_prev_ > 0 && prev.margin > 0 && margin <= 0) {
    const double w = prev.margin / (prev.margin - margin);
    t = prev.t + w * (t_step - prev.t);
    x = x_offset + prev.u + w * (u - prev.u);
  }
  last_ = {Step{t_step, margin, u}, last_[0], last_[1]};
  have_prev_ = std::min(have_prev_ + 1, 3);
}

void PulleyLiftOff::released() {
  if (t || have_prev_ == 0) return;
  // The margin's zero past the last step: on the parabola through the last three (Newton's method from the
  // line through the last two), or on that line; at the last step where the margins do not fall.
  const Step &s0 = last_[0], &s1 = last_[1], &s2 = last_[2];
  double at = s0.t;
  if (have_prev_ >= 2 && s1.margin > s0.margin) {
    at = s0.t + s0.margin * (s0.t - s1.t) / (s1.margin - s0.margin);
    if (have_prev_ == 3) {
      const double d01 = (s0.margin - s1.margin) / (s0.t - s1.t), d12 = (s1.margin - s2.margin) / (s1.t - s2.t);
      const double c2 = (d01 - d12) / (s0.t - s2.t);  // m(τ) = m0 + d01 (τ − t0) + c2 (τ − t0)(τ − t1)
      for (int iteration = 0; iteration < 8; ++iteration) {
        const double m = s0.margin + d01 * (at - s0.t) + c2 * (at - s0.t) * (at - s1.t);
        const double slope = d01 + c2 * (2 * at - s0.t - s1.t);
        if (!(slope < 0)) break;
        at -= m / slope;
      }
    }
  }
  t = at;
  // u along the line through the last two steps (its error is the step's second order, as the run's x error).
  x = x_offset + s0.u + (have_prev_ >= 2 ? (at - s0.t) * (s0.u - s1.u) / (s0.t - s1.t) : 0.0);
}

PulleyComparison compare_pulley_with_exact(const PulleyCaseSetup& setup) {
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double R = setup.radius, u0 = setup.u0, t0 = setup.chain.t0(), free = ell - kPi * R;
  const double x1 = 0.5 * free + u0, x2 = 0.5 * free - u0;
  // 1. Up the shorter side at x = −R, over the pulley (two fillets of radius R: the half circle about
  //    the origin, nodes on it), down the longer side at x = +R.
  Points<2> vertices(2, 4);
  vertices << -R, -R, R, R, -x2, R, R, -x1;
  const int links = setup.nodes - 1;
  Chain<2> chain = discretize<2>(*rounded_polyline_curve<2>(vertices, R), ell, lambda, links, false);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -g)));
  Obstacle<2> pulley;
  pulley.kind = Obstacle<2>::Kind::kCylinder;
  pulley.radius = R;
  pulley.name = "pulley";
  pulley.arc_links = true;
  StringModelOptions model_options;
  model_options.stabilization_time = 0.02 * std::sqrt(ell / g);  // as a scene's default
  StringModel<2> model(std::move(chain), std::move(forces), {}, model_options,
                       make_contact_module<2>({pulley}));
  const double u_lift = exact::pulley_lift_off_u(u0, R, ell);
  const double t_lift = exact::pulley_time(u_lift, u0, ell, g);
  StringSolver<2> solver(
      model, exact_comparison_run(setup.integrator, std::min(kPastLiftOff * t_lift, setup.t_max_over_t0 * t0)));
  // 2. At every accepted step: u = half the difference of the ends' heights, and the tensions where
  //    the sides meet the pulley, against the exact solution at the same time.
  const double omega2 = 2 * g / ell;
  auto u_of = [&](const Points<2>& x) { return 0.5 * (x(1, 0) - x(1, links)); };
  PulleyComparison c{{},
                     CsvTable({"t", "x", "x_dot", "u", "tension_short", "tension_long", "lift_off_margin"}),
                     {}};
  struct Exact {
    double u, u_dot, tau2, tau1;
  };
  auto exact_at = [&](double t) {
    const double u = exact::pulley_u(t, u0, ell, g), xdd = omega2 * u;
    return Exact{u, exact::pulley_u_dot(t, u0, ell, g), lambda * (0.5 * free - u) * (g + xdd),
                 lambda * (0.5 * free + u) * (g - xdd)};
  };
  double err_x = 0, err_short = 0, err_long = 0, sum_short = 0, sum_long = 0, signed_short = 0, signed_long = 0;
  long tension_steps = 0;
  // The lift-off: the first zero of the string's margin τ2 − λ ẋ² (its tension where the shorter side
  // meets the pulley, its speed), interpolated linearly between the steps where it changes sign. The
  // shorter side runs onto the pulley along its tangent (links along the arc, Obstacle::arc_links): no
  // landing shakes the tension, so the margin needs no average over the landings. Where the pulley lets go of
  // the shorter side before the margin's zero (a pulley of a few links per radius: the contact module reads
  // the node's share of the arc), the run unwraps from there and the steps after it are not compared.
  PulleyLiftOff lift;
  lift.x_offset = 0.5 * free;
  // The pulley's release of the shorter side (PulleyLiftOff::released): a lift-off that is no node leaving
  // the longer side. Each of those lowers the last held index by one (the material moves towards it); a node
  // of the shorter side let go may land again within the same step, so the first held index does not tell.
  long lift_offs_base = -1;
  int last_held_base = -1;
  auto compare_at = [&](double t, const Points<2>& x, const Points<2>& v, const Eigen::VectorXd& tension) {
    if (lift.t) return;  // the exact solution holds up to the lift-off
    int last_held = -1;
    for (const NodeContact<2>& contact : model.contacts()) last_held = std::max(last_held, contact.node);
    long lift_offs = 0;
    for (const LiftOffTotal& total : model.module()->lift_off_totals()) lift_offs += total.total;
    if (lift_offs_base < 0) {
      lift_offs_base = lift_offs;
      last_held_base = last_held;
    }
    if (lift_offs - lift_offs_base > last_held_base - last_held) {
      lift.released();
      return;
    }
    const auto [u, u_dot, tau2, tau1] = exact_at(t);
    const double u_string = u_of(x);
    err_x = std::max(err_x, std::abs(u_string - u));
    const double T2 = tension_at_pulley(x, tension, 0, +1), T1 = tension_at_pulley(x, tension, links, -1);
    if (std::isnan(T1) || std::isnan(T2)) return;
    err_short = std::max(err_short, std::abs(T2 - tau2));
    err_long = std::max(err_long, std::abs(T1 - tau1));
    sum_short += std::abs(T2 - tau2);
    sum_long += std::abs(T1 - tau1);
    signed_short += T2 - tau2;
    signed_long += T1 - tau1;
    ++tension_steps;
    const double speed = 0.5 * (v(1, 0) - v(1, links)), margin = T2 - lambda * speed * speed;
    lift.add(t, margin, u_string);
  };
  solver.on_step = [&](double t, const Eigen::VectorXd& y) {
    const auto snap = model.snapshot(t, y);
    compare_at(t, snap.x, snap.v, snap.tension);
  };
  c.run = run_to_stop(solver);
  for (const StepSample& s : c.run.samples) {  // the exact solution at the rows of string_series.csv
    const Exact e = exact_at(s.t);
    c.exact.add_row({s.t, 0.5 * free + e.u, e.u_dot, e.u, e.tau2, e.tau1, (e.tau2 - lambda * e.u_dot * e.u_dot) / R});
  }
  // 3. The summary: the string's lift-off and the errors up to it.
  std::optional<MeasuredLiftOff> lift_off;
  if (lift.t) lift_off = MeasuredLiftOff{*lift.t, *lift.x};
  c.summary = exact_comparison_summary(c.run, "pulley", setup.nodes, t_lift, 0.5 * free + u_lift, lift_off, err_x);
  c.summary["u0"] = u0;
  c.summary["R"] = R;
  c.summary["u_lift_off_exact"] = u_lift;
  c.summary["max_abs_err_tension_short"] = err_short;
  c.summary["max_abs_err_tension_long"] = err_long;
  const double steps = static_cast<double>(std::max(1L, tension_steps));
  c.summary["mean_abs_err_tension_short"] = sum_short / steps;
  c.summary["mean_abs_err_tension_long"] = sum_long / steps;
  c.summary["mean_err_tension_short"] = signed_short / steps;
  c.summary["mean_err_tension_long"] = signed_long / steps;
  c.summary["max_rel_err_tension"] = std::max(err_short, err_long) / setup.chain.P0();
  c.summary["tension_steps"] = tension_steps;
  // A pulley thinner than the links: the lift-off is not resolved (nodes_resolving_radius), as a scene warns.
  const double h = ell / links;
  if (h * kArcLinksPerRadius > R)
    c.summary["resolution_warning"] = fmt::format(
        "--R = {0:g} m is shorter than {1:g} links ({2:.3g} m): the wrapped part is exact, but the lift-off, read on "
        "links longer than 1/{1:g} of the radius, is not resolved (docs/model.md section 10); set --nodes >= {3} "
        "(links no longer than 1/{1:g} of the radius)",
        R, kArcLinksPerRadius, h * kArcLinksPerRadius, nodes_resolving_radius(R, ell, false, kArcLinksPerRadius));
  return c;
}

}  // namespace chainsim
