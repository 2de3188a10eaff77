// A kink front: see kink_front.hpp and docs/model.md §2.5 (the geometry and the jump conditions).
#include "kink_front.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

template <int dim>
KinkFront<dim>::KinkFront(const KinkSpec& spec) {
  this->dissipation = 0;  // a kink whose arms are not antiparallel dissipates nothing (docs/model.md §2.5)
  this->expected_s0 = spec.s0;
}

template <int dim>
double KinkFront<dim>::turn_margin(const FrontState<dim>& s) const {
  // opening = the angle of the arms from antiparallel, so the arms turn by π − opening.
  return std::cos(s.opening) + std::cos(kMinTurnDeg * kPi / 180);
}

template <int dim>
void KinkFront<dim>::check_initial(const FrontState<dim>& s) const {
  if (turn_margin(s) <= 0)
    throw InputError(fmt::format("the kink at s0 = {:.6g} m turns by {:.3g} degrees: a kink's arms turn by at least {:g} "
                                 "(place it where the shape has a corner)",
                                 s.s0, 180 - s.opening * 180 / kPi, kMinTurnDeg));
}

template <int dim>
void KinkFront<dim>::evaluate(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                              Points<dim>& force) {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const double h = this->m_.h, lambda = this->m_.lambda;
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  const int a = A.last, b = B.first;
  if (A.num_links() == 0 || B.num_links() == 0) throw InputError("a kink needs a full link on either side");
  // The arms' directions t⁻ = t_A (arc A's end link) and t⁺ = t_B (arc B's first link), with their rates.
  Vec<dim> tA_rate, tB_rate;
  const Vec<dim> tA = this->link_tangent(model, a - 1, a, "arc A's end link", tA_rate);
  const Vec<dim> tB = this->link_tangent(model, b, b + 1, "arc B's first link", tB_rate);
  // The kinked link: x_b − x_a = l⁻ t_A + l⁺ t_B with l⁻ + l⁺ = h, i.e. Δ − h t_B = l⁻ d, d = t_A − t_B
  // (= −[t]); l⁻ is its least-squares solution (exact when the arms meet), and ṡ0 follows from the
  // compatibility [v] = −ṡ0 [t] = ṡ0 d the same way. For antiparallel arms (d = 2e) these are the fold's.
  const Vec<dim> d = tA - tB, d_rate = tA_rate - tB_rate;
  const double dd = d.squaredNorm();
  if (!(dd > 0)) throw RecoverableError("the kink's arms are on one line");
  const Vec<dim> chord = x.col(b) - x.col(a), u = v.col(b) - v.col(a);
  const Vec<dim> w = chord - h * tB, w_rate = u - h * tB_rate;
  const double lA = w.dot(d) / dd, lB = h - lA;
  const double lA_rate = (w_rate.dot(d) + w.dot(d_rate)) / dd - 2 * w.dot(d) * d.dot(d_rate) / (dd * dd);
  const double sd = u.dot(d) / dd;
  chord_ = chord.norm() / h;
  s.opening = std::acos(std::clamp(-tA.dot(tB), -1.0, 1.0));
  s.direction = d / std::sqrt(dd);
  s.position = 0.5 * (x.col(a) + lA * tA + x.col(b) - lB * tB);
  s.s0 = model.chain().node_coordinate(a) + lA;
  s.s0_dot = sd;
  s.l_minus = lA;
  s.l_plus = lB;
  // The jump conditions with f = 0: τ⁻ = τ⁺ = λ ṡ0², no dissipation, no support.
  s.tension_minus = jump::end_tension(0.0, lambda, sd, -1);
  s.tension_plus = jump::end_tension(0.0, lambda, sd, +1);
  s.power_shock = 0;
  s.power_heap = 0;
  s.reaction.setZero();
  s.inflow = 0;
  mass[a] += lambda * lA;
  mass[b] += lambda * lB;
  // Forces F_a = ½ λ l̇⁻ u + G, F_b = ½ λ l̇⁻ u − G: their sum λ l̇⁻ u is the momentum flux of the
  // material moving from b to a (momentum exact), and their power on the lumped masses is −G·u
  // (docs/model.md §2.5). G = ½ τ (t_A + t_B) pulls a along t_A and b along −t_B with τ; its
  // correction along d, ½ λ ṡ0 ((t_A + t_B)·u / |d|²) d, zero when u is along d as compatibility asks,
  // makes G·u = 0: the discrete kink dissipates nothing, exactly.
  const Vec<dim> sum = tA + tB;
  const Vec<dim> G = 0.5 * s.tension_minus * sum - 0.5 * lambda * sd * (sum.dot(u) / dd) * d;
  force.col(a) += 0.5 * lambda * lA_rate * u + G;
  force.col(b) += 0.5 * lambda * lA_rate * u - G;
}

template <int dim>
EventAction KinkFront<dim>::cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) {
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  const bool to_A = e0 != 0;
  if ((to_A ? B.num_links() : A.num_links()) < 2 || (!to_A && model.is_prescribed(A.last)))
    return {EventAction::Kind::kStop,
            fmt::format("the kink has reached the {} of the string (its arms need a full link on either side)",
                        to_A ? "end" : "start")};
  return SplitLinkFront<dim>::cross(model, state, e0);
}

template <int dim>
void KinkFront<dim>::checks(const StringModel<dim>& /*model*/, const FrontState<dim>& s, double* g) const {
  g[0] = std::min(turn_margin(s), kMaxChord - chord_);
}

template <int dim>
std::string KinkFront<dim>::check_failed(const StringModel<dim>& model, const FrontState<dim>& s, double t) const {
  const int a = this->node_a(model), b = this->node_b(model);
  if (kMaxChord - chord_ < turn_margin(s))
    return fmt::format(
        "the kink at s0 = {:.6g} m has come apart at t = {:.9g} s: the ends of its kinked link, nodes {} and {}, are "
        "{:.5g} h apart (h = {:.6g} m; arms that meet at the kink need at most h)",
        s.s0, t, a, b, chord_, this->m_.h);
  return fmt::format(
      "the kink at s0 = {:.6g} m has straightened out at t = {:.9g} s: its arms turn by less than {:g} degrees "
      "(nodes {} and {})",
      s.s0, t, kMinTurnDeg, a, b);
}

template class KinkFront<2>;
template class KinkFront<3>;

}  // namespace chainsim
