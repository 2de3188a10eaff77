// A kink front: see kink_front.hpp and docs/model.md §2.5 (the geometry and the jump conditions).
#include "kink_front.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

template <int dim>
KinkFront<dim>::KinkFront(const KinkSpec& spec) : spec_(spec) {
  this->dissipation = 0;  // a kink whose arms are not antiparallel dissipates nothing (docs/model.md §2.5)
  this->expected_s0 = spec.s0;
  this->active = !spec.inserted;
}

template <int dim>
void KinkFront<dim>::cut(FrontLayout& layout) {
  if (this->active) SplitLinkFront<dim>::cut(layout);
}

namespace {
/// A link of first … last (links by their first node) is slack.
template <int dim>
bool any_slack(const StringModel<dim>& model, int first, int last) {
  if (!model.allows_slack()) return false;
  for (int j = first; j <= last; ++j)
    if (model.link_slack(j)) return true;
  return false;
}
}  // namespace

template <int dim>
double KinkFront<dim>::formation_margin(const StringModel<dim>& model) const {
  // The turn between the links at either end of a window of 2m links (m ≥ 1), centred on link j, inside one arc.
  // Only a taut window: a slack link's direction is not the string's tangent (a pendulum released above the
  // horizontal falls freely with its first link slack, at any angle to the next), and a kink forms in a taut
  // string (docs/model.md §9).
  const Points<dim>& x = model.x();
  const int m = window_half_links(spec_.window, this->m_.h);
  double lowest = 2;
  sharpest_ = -1;
  for (const ArcRange& arc : model.arcs())
    for (int j = arc.first + m; j + m + 1 <= arc.last; ++j) {
      if (any_slack(model, j - m, j + m)) continue;
      const Vec<dim> t1 = x.col(j - m + 1) - x.col(j - m), t2 = x.col(j + m + 1) - x.col(j + m);
      const double n = t1.norm() * t2.norm();
      if (!(n > 0)) continue;
      const double c = t1.dot(t2) / n;
      if (c < lowest) lowest = c, sharpest_ = j;
    }
  return lowest - std::cos(spec_.turn_deg * kPi / 180);
}

template <int dim>
bool KinkFront<dim>::insert(StringModel<dim>& model) {
  formation_margin(model);
  if (sharpest_ < 0) return false;
  const Points<dim>& x = model.x();
  const double h = this->m_.h;
  const int m = window_half_links(spec_.window, h);
  std::vector<ArcRange>& arcs = model.arcs();
  const int k = model.arc_of(sharpest_);
  const ArcRange arc = arcs[static_cast<std::size_t>(k)];
  // The link (j, j+1) of the window whose neighbours turn most, with the arms' meeting point inside it
  // (l⁻ in (0.05 h, 0.95 h)) and a full link on either side.
  int best = -1;
  double best_cos = 2, best_l = 0;
  for (int j = std::max(arc.first + 1, sharpest_ - m); j <= std::min(arc.last - 2, sharpest_ + m); ++j) {
    if (any_slack(model, j - 1, j + 1)) continue;  // the arms and the kinked link are taut
    const Vec<dim> tA = (x.col(j) - x.col(j - 1)).normalized(), tB = (x.col(j + 2) - x.col(j + 1)).normalized();
    const Vec<dim> d = tA - tB;
    if (!(d.squaredNorm() > 0)) continue;
    const double lA = (x.col(j + 1) - x.col(j) - h * tB).dot(d) / d.squaredNorm();
    const double c = tA.dot(tB);
    if (c < best_cos && lA > 0.05 * h && lA < 0.95 * h) best = j, best_cos = c, best_l = lA;
  }
  if (best < 0) return false;
  // The arms are full taut links; the kinked link leaves the arcs (StringModel::rebuild).
  if (model.allows_slack()) {
    model.set_slack(best - 1, false);
    model.set_slack(best + 1, false);
  }
  arcs[static_cast<std::size_t>(k)].last = best;
  arcs.insert(arcs.begin() + k + 1, ArcRange{best + 1, arc.last, false});
  this->arc_minus = k;
  this->arc_plus = k + 1;
  this->expected_s0 = model.chain().node_coordinate(best) + best_l;
  sense_ = 0;
  model.rebuild();
  return true;
}

template <int dim>
std::string KinkFront<dim>::where_formed(const StringModel<dim>& model) const {
  if (sharpest_ < 0) return {};
  return fmt::format(" at node {} (s = {:.6g} m, at {}, where the tangent turns most)", sharpest_,
                     model.chain().node_coordinate(sharpest_), show_point<dim>(Vec<dim>(model.x().col(sharpest_))));
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
  const double lA = meeting_point(d, dd, w), lB = h - lA;
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
  // Each partial link continues its arm's link straight beyond a (b): its weight at its midpoint, so that it
  // does the work its potential (potential_moment) says as the arm turns (docs/model.md §10, "The partial
  // links' weight"; without it the U's energy ledger closed only to first order, §9).
  this->add_partial_weight(model, a, a - 1, lA, lambda, force);
  this->add_partial_weight(model, b, b + 1, lB, lambda, force);
}

template <int dim>
void KinkFront<dim>::constraints(const StringModel<dim>& model, const FrontState<dim>& /*state*/,
                                 std::vector<NodeConstraint<dim>>& out) const {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const double h = this->m_.h;
  const int a = this->node_a(model), b = this->node_b(model);
  // With the arms' links as chords (t_A = (x_a − x_{a−1})/h, t_B = (x_{b+1} − x_b)/h, unit while the
  // links hold their length): w = x_b − x_a − h t_B = 2x_b − x_a − x_{b+1} =: p and h d = x_a + x_b −
  // x_{a−1} − x_{b+1} =: q, so C = (p × q)/h is bilinear in the positions. ∂C/∂x_i = (c_i q − k_i p)
  // × e / h (2D: its normal), with c the coefficients of p and k those of q at node i, and its second
  // derivative at zero accelerations 2 (ṗ × q̇)/h.
  const int nodes[4] = {a - 1, a, b, b + 1};
  const double cp[4] = {0, -1, 2, -1}, cq[4] = {-1, 1, 1, -1};
  Vec<dim> p = Vec<dim>::Zero(), q = Vec<dim>::Zero(), pd = Vec<dim>::Zero(), qd = Vec<dim>::Zero();
  for (int k = 0; k < 4; ++k) {
    p += cp[k] * x.col(nodes[k]);
    q += cq[k] * x.col(nodes[k]);
    pd += cp[k] * v.col(nodes[k]);
    qd += cq[k] * v.col(nodes[k]);
  }
  auto constraint = [&]() {
    NodeConstraint<dim> c;
    c.nodes.assign(nodes, nodes + 4);
    c.gradient = Points<dim>::Zero(dim, 4);
    return c;
  };
  if constexpr (dim == 2) {
    auto cross = [](const Vec<2>& l, const Vec<2>& r) { return l[0] * r[1] - l[1] * r[0]; };
    NodeConstraint<dim> c = constraint();
    for (int k = 0; k < 4; ++k) {
      const Vec<2> g = cp[k] * q - cq[k] * p;
      c.gradient.col(k) = Vec<2>(g[1], -g[0]) / h;
    }
    c.value = cross(p, q) / h;
    c.curvature = 2 * cross(pd, qd) / h;
    out.push_back(std::move(c));
  } else {
    // The two components of p × q normal to d (its component along d is zero: p × q ⊥ q).
    const Vec<3> dn = q.normalized(), e1 = dn.unitOrthogonal(), e2 = dn.cross(e1);
    for (const Vec<3>& e : {e1, e2}) {
      NodeConstraint<dim> c = constraint();
      for (int k = 0; k < 4; ++k) c.gradient.col(k) = (cp[k] * q - cq[k] * p).cross(e) / h;
      c.value = e.dot(p.cross(q)) / h;
      c.curvature = 2 * e.dot(pd.cross(qd)) / h;
      out.push_back(std::move(c));
    }
  }
}

template <int dim>
bool KinkFront<dim>::absorbed(const StringModel<dim>& model, const FrontState<dim>& /*state*/, int e0) const {
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  // e0: the kink reached arc B's first node (towards the end of the string), else arc A's last node.
  if (e0 != 0) return B.num_links() < 2 && model.is_prescribed(B.last);
  return A.num_links() < 2 && model.is_prescribed(A.first);
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
  // Across node n (b, or a) the kinked link becomes an arm and the arc's next link the other arm. The new arms
  // meet at l⁻ from the new kinked link's start, usually inside it (a partial link of −10⁻² h is routine and
  // harmless: the front moves on into the link); where the string turns sharply one link beyond n (a free
  // end's tip curling), they meet outside it, and the re-lumped node there, λ (h/2 + l⁻) or λ (h/2 + l⁺), keeps
  // less than half its material beyond kMaxRelaidOutside h (none at h/2): the discrete kink cannot pass that
  // corner (docs/model.md §9).
  const Points<dim>& x = model.x();
  const double h = this->m_.h;
  const int n = to_A ? B.first : A.last;
  const int p = to_A ? n : n - 1;  // the new kinked link (p, p + 1), its arms (p − 1, p) and (p + 1, p + 2)
  const Vec<dim> tA = (x.col(p) - x.col(p - 1)).normalized(), tB = (x.col(p + 2) - x.col(p + 1)).normalized();
  const Vec<dim> d = tA - tB;
  const double dd = d.squaredNorm();
  const double lA = dd > 0 ? meeting_point(d, dd, Vec<dim>(x.col(p + 1) - x.col(p) - h * tB)) : 0.5 * h;
  if (!(lA > -kMaxRelaidOutside * h && lA < (1 + kMaxRelaidOutside) * h)) {
    const int corner = to_A ? n + 1 : n - 1;
    const Vec<dim> t_in = (x.col(to_A ? n + 1 : n) - x.col(to_A ? n : n - 1)).normalized(), t_out = to_A ? tB : tA;
    const double corner_deg = std::acos(std::clamp(t_in.dot(t_out), -1.0, 1.0)) * 180 / kPi;
    const double outside = lA < 0 ? -lA / h : lA / h - 1;
    return {EventAction::Kind::kStop,
            fmt::format("the kink at s0 = {:.6g} m (its arms turning by {:.3g} degrees) has reached node {} with a second "
                        "corner one link beyond it: the string turns by {:.3g} degrees at node {}, so that across node "
                        "{} the kink's arms would meet {:.3g} h outside the next link and node {} would keep {} "
                        "(the discrete kink's arms need a straight link on either side; docs/model.md §9)",
                        state.s0, 180 - state.opening * 180 / kPi, n, corner_deg, corner, n, outside, lA < 0 ? p : p + 1,
                        outside < 0.5 ? fmt::format("{:.0f} % of its mass", 100 * (1 - 2 * outside)) : "no mass")};
  }
  EventAction action = SplitLinkFront<dim>::cross(model, state, e0);
  if (action.kind != EventAction::Kind::kStop) {
    this->watch_outside();  // the arms may meet outside the new link
    sense_ = 0;             // ṡ0 from the new stencil
  }
  return action;
}

template <int dim>
double KinkFront<dim>::shock_margin(const StringModel<dim>& model, const FrontState<dim>& s) const {
  if (sense_ == 0 && s.s0_dot != 0) sense_ = s.s0_dot > 0 ? 1 : -1;
  // ṡ0 in units of the speed of a wave along a link under its own weight over h: the margin is O(1) where the
  // arms' is.
  const double g_field = model.uniform_field().norm();
  const double speed = std::sqrt(std::max(g_field, 1.0) * this->m_.h);
  double margin = sense_ == 0 ? 1.0 : sense_ * s.s0_dot / speed;
  if (model.allows_slack()) {
    const Points<dim>& x = model.x();
    const int a = this->node_a(model), b = this->node_b(model);
    for (const int j : {a - 1, b}) {  // the arms' links (a − 1, a) and (b, b + 1)
      if (!model.link_slack(j) && model.link_tension(j) > 0) continue;
      const double length = (x.col(j + 1) - x.col(j)).norm() / model.chain().link_length(j);
      margin = std::min(margin, length - (1 - StringModel<dim>::kSlackGap));
    }
  }
  return margin;
}

template <int dim>
void KinkFront<dim>::checks(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  g[0] = kMaxChord - chord_;
  g[1] = std::min(shock_margin(model, s), turn_margin(s));
  g[2] = this->outside_margin(s);
}

template <int dim>
std::string KinkFront<dim>::check_failed(const StringModel<dim>& model, const FrontState<dim>& s, double t, int check) const {
  const int a = this->node_a(model), b = this->node_b(model);
  if (check == 2) {
    // Moving out on A's side (towards the start) or on B's (towards the end), with the links left on that side.
    const bool start = s.l_minus < s.l_plus;
    const int links = model.arcs()[static_cast<std::size_t>(start ? this->arc_minus : this->arc_plus)].num_links();
    return fmt::format(
        "the kink at s0 = {:.6g} m lies {:.4g} h outside its kinked link, beyond node {}, and moves on away from it at "
        "t = {:.9g} s (ds0/dt = {:.4g} m/s): its last crossing re-laid it where its arms meet, outside the new kinked "
        "link because the string turns sharply next to it, and it moves away from the link past a crossing's root "
        "that the integrator no longer sees{} (docs/model.md §9)",
        s.s0, -std::min(s.l_minus, s.l_plus) / this->m_.h, start ? a : b, t, s.s0_dot,
        links < 2 ? fmt::format(": it has in effect reached the {} of the string (its arms need a full link on either "
                                "side, and {} has {} left)",
                                start ? "start" : "end", start ? "the arm before it" : "the arm after it", links == 1 ? "one" : "none")
                  : std::string());
  }
  return fmt::format(
      "the kink at s0 = {:.6g} m has come apart at t = {:.9g} s: the ends of its kinked link, nodes {} and {}, are "
      "{:.5g} h apart (h = {:.6g} m; arms that meet at the kink need at most h)",
      s.s0, t, a, b, chord_, this->m_.h);
}

template class KinkFront<2>;
template class KinkFront<3>;

}  // namespace chainsim
