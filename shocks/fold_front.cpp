// A fold front: see fold_front.hpp and front_tracker.hpp (the physics), docs/shocks.md (the numerics).
#include "fold_front.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

template <int dim>
FoldFront<dim>::FoldFront(const FoldSpec& spec) {
  this->dissipation = spec.dissipation;
  this->expected_s0 = spec.s0;
}

template <int dim>
void FoldFront<dim>::check_initial(const FrontState<dim>& s) const {
  if (s.opening > kMaxOpeningDeg * kPi / 180) throw InputError(opened_message(s));
}

template <int dim>
void FoldFront<dim>::evaluate(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                              Points<dim>& force) {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const double h = this->m_.h, lambda = this->m_.lambda;
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  const int a = A.last, b = B.first;
  // The fold direction e: the bisector of arc A's end link t_A and arc B's first link reversed (−t_B),
  // or the one of them that exists; with its rate ė, for the mass flux below.
  Vec<dim> tA_rate = Vec<dim>::Zero(), tB_rate = Vec<dim>::Zero();
  const bool has_A = A.num_links() > 0, has_B = B.num_links() > 0;
  if (!has_A && !has_B) throw InputError("a fold needs at least one full link next to it");
  const Vec<dim> tA = has_A ? this->link_tangent(model, a - 1, a, "arc A's end link", tA_rate) : Vec<dim>::Zero();
  const Vec<dim> tB = has_B ? this->link_tangent(model, b, b + 1, "arc B's first link", tB_rate) : Vec<dim>::Zero();
  const Vec<dim> d = tA - tB, d_rate = tA_rate - tB_rate;
  const Vec<dim> e = unit_vector<dim>(d, "the fold direction");
  const Vec<dim> e_rate = (d_rate - e * e.dot(d_rate)) / d.norm();
  s.opening = has_A && has_B ? std::acos(std::clamp(-tA.dot(tB), -1.0, 1.0)) : 0.0;
  const double c = (x.col(b) - x.col(a)).dot(e);
  chord_ = (x.col(b) - x.col(a)).norm() / h;
  const double lA = 0.5 * (h + c), lB = 0.5 * (h - c);
  const double sd = 0.5 * (v.col(b) - v.col(a)).dot(e);
  s.direction = e;
  s.position = 0.5 * (x.col(a) + x.col(b)) + 0.5 * h * e;
  s.s0 = model.chain().node_coordinate(a) + lA;
  s.s0_dot = sd;
  s.l_minus = lA;
  s.l_plus = lB;
  // The jump conditions at a fold ([v] = 2 ṡ0 e): the end tensions on either side and the power of
  // the internal shock (two shocks' worth, |[v]|² = 4 ṡ0²); a fold exchanges nothing with a support.
  s.tension_minus = jump::end_tension(this->dissipation, lambda, sd, -1);
  s.tension_plus = jump::end_tension(this->dissipation, lambda, sd, +1);
  s.power_shock = jump::shock_power(this->dissipation, lambda, sd, 2);
  s.power_heap = 0;
  s.reaction.setZero();
  s.inflow = 0;
  mass[a] += lambda * lA;
  mass[b] += lambda * lB;
  // Material crosses from b to a at the rate l̇_A = ½ (u·e + (x_b − x_a)·ė), u = v_b − v_a, carrying
  // the momentum flux λ l̇_A u. For arms on one line (u = 2 ṡ0 e, ė = 0) that is 2 λ ṡ0² e = τ⁻ + τ⁺,
  // the paper's fold. Otherwise the remainder δ, shared equally by the two nodes, keeps momentum
  // exact, and the energy then balances with W_s = −2 f λ |ṡ0|³ exactly (docs/shocks.md).
  const Vec<dim> u = v.col(b) - v.col(a);
  const double lA_rate = 0.5 * (u.dot(e) + (x.col(b) - x.col(a)).dot(e_rate));
  const Vec<dim> delta = lambda * lA_rate * u - 2 * lambda * sd * sd * e;
  force.col(a) += s.tension_minus * e + 0.5 * delta;
  force.col(b) += s.tension_plus * e + 0.5 * delta;
}

template <int dim>
void FoldFront<dim>::crossings(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  g[0] = s.l_plus + kCrossingHysteresis * this->m_.h - this->end_margin(model, true);
  g[1] = s.l_minus + kCrossingHysteresis * this->m_.h - this->end_margin(model, false);
}

template <int dim>
void FoldFront<dim>::checks(const StringModel<dim>& /*model*/, const FrontState<dim>& s, double* g) const {
  g[0] = std::min(std::cos(s.opening) - std::cos(kMaxOpeningDeg * kPi / 180), max_chord() - chord_);
}

template <int dim>
std::string FoldFront<dim>::check_failed(const StringModel<dim>& model, const FrontState<dim>& s, double t, int /*check*/) const {
  const bool apart = max_chord() - chord_ <= std::cos(s.opening) - std::cos(kMaxOpeningDeg * kPi / 180);
  return apart ? apart_message(model, s, t) : opened_message(s, t);
}

template <int dim>
std::string FoldFront<dim>::opened_message(const FrontState<dim>& s, std::optional<double> t) const {
  return fmt::format(
      "the fold at s0 = {:.6g} m has opened{}: its arms leave it {:.3g} degrees from antiparallel (a tight bight allows "
      "at most {:g}; a dissipative fold needs both arms along one line, and a bight that opens, as in a folded chain "
      "whose ends are apart, is resolved by the string solver without [effects.fold]: docs/shocks.md)",
      s.s0, t ? fmt::format(" at t = {:.9g} s", *t) : std::string(), s.opening * 180 / kPi, kMaxOpeningDeg);
}

template <int dim>
std::string FoldFront<dim>::apart_message(const StringModel<dim>& model, const FrontState<dim>& s, double t) const {
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  const int a = A.last, b = B.first;
  // The arms at the fold: arc A's end link and arc B's first link (an arc without a full link: its
  // partial link to the fold point x0), on one line for a tight fold; and the transverse force the
  // momentum balance needs there for dissipation f: F0 = f λ ṡ0 |ṡ0| (t⁺ + t⁻) (docs/shocks.md).
  const Points<dim>& x = model.x();
  const Vec<dim> t_minus =
      (A.num_links() > 0 ? Vec<dim>(x.col(a) - x.col(a - 1)) : Vec<dim>(s.position - x.col(a))).normalized();
  const Vec<dim> t_plus =
      (B.num_links() > 0 ? Vec<dim>(x.col(b + 1) - x.col(b)) : Vec<dim>(x.col(b) - s.position)).normalized();
  const double angle = std::acos(std::clamp(-t_minus.dot(t_plus), -1.0, 1.0));
  const double missing = this->dissipation * this->m_.lambda * s.s0_dot * s.s0_dot * (t_plus + t_minus).norm();
  return fmt::format(
      "the fold at s0 = {:.6g} m has come apart at t = {:.9g} s: the ends of its folded link, nodes {} and {} (s = {:.6g} "
      "and {:.6g} m), are {:.5g} h apart (h = {:.6g} m): the link's material no longer reaches across, and a tight fold "
      "(arms within {:g} degrees of antiparallel) needs at most {:.5g} h to cross a node; its arms leave it {:.3g} degrees from antiparallel, ds0/dt = {:.4g} m/s, tension {:.4g} N before the fold and {:.4g} N after it. "
      "Across a kink whose arms are not antiparallel the momentum balance needs a transverse force f lambda "
      "ds0/dt |ds0/dt| |t+ + t-| = {:.3g} N at the fold, zero only for f = 0, and the fold has none: a tight fold "
      "cannot form here. For f = 0 run the scene without [effects.fold] (the string resolves the kink); for f > 0 a "
      "tight fold needs its arms on one line (docs/shocks.md, \"A fold whose arms turn apart\")",
      s.s0, t, a, b, model.chain().node_coordinate(a), model.chain().node_coordinate(b), chord_, this->m_.h,
      kMaxOpeningDeg, max_chord(), angle * 180 / kPi, s.s0_dot, s.tension_minus, s.tension_plus, missing);
}

template class FoldFront<2>;
template class FoldFront<3>;

}  // namespace chainsim
