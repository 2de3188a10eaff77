// What a fold and a kink share: see split_link_front.hpp.
#include "split_link_front.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim {

template <int dim>
void SplitLinkFront<dim>::cut(FrontLayout& layout) {
  const double h = this->m_.h;
  const int a = std::clamp(static_cast<int>(std::floor(this->expected_s0 / h + 1e-9)), 0, this->m_.n - 1);
  if (a < layout.first || a + 1 > layout.last)
    throw InputError(fmt::format("the {} must lie inside the moving part of the string", this->name()));
  layout.splits.push_back(a);
  this->arc_minus = layout.arc;
  this->arc_plus = ++layout.arc;
}

template <int dim>
Vec<dim> SplitLinkFront<dim>::link_tangent(const StringModel<dim>& model, int i, int j, const char* what,
                                           Vec<dim>& rate) {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  const Vec<dim> link = x.col(j) - x.col(i), link_rate = v.col(j) - v.col(i);
  const Vec<dim> t = unit_vector<dim>(link, what);
  rate = (link_rate - t * t.dot(link_rate)) / link.norm();
  return t;
}

template <int dim>
std::vector<int> SplitLinkFront<dim>::stencil(const StringModel<dim>& model) const {
  // evaluate() reads arc A's end link and arc B's first link.
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  std::vector<int> nodes;
  for (int i : {A.last - 1, A.last, B.first, B.first + 1})
    if ((i >= A.first && i <= A.last) || (i >= B.first && i <= B.last))
      if (!model.is_prescribed(i)) nodes.push_back(i);
  return nodes;
}

template <int dim>
std::optional<double> SplitLinkFront<dim>::tension_at(const StringModel<dim>& model, const FrontState<dim>& s,
                                                      int node) const {
  if (node_a(model) == node) return s.tension_minus;
  if (node_b(model) == node) return s.tension_plus;
  return std::nullopt;
}

template <int dim>
double SplitLinkFront<dim>::potential_moment(const StringModel<dim>& model, const FrontState<dim>& f,
                                             const Vec<dim>& g) const {
  const double lambda = this->m_.lambda;
  const int a = node_a(model), b = node_b(model);
  return lambda * f.l_minus * g.dot(0.5 * (f.position - model.x().col(a))) +
         lambda * f.l_plus * g.dot(0.5 * (f.position - model.x().col(b)));
}

template <int dim>
void SplitLinkFront<dim>::crossings(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  g[0] = s.l_plus - end_margin(model, true);    // the front reaches arc B's first node
  g[1] = s.l_minus - end_margin(model, false);  // the front reaches arc A's last node
}

template <int dim>
double SplitLinkFront<dim>::end_margin(const StringModel<dim>& model, bool plus) const {
  // The split link is the string's last (first) and its end node moves: that node's mass is λ l⁺ (λ l⁻) alone.
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(plus ? this->arc_plus : this->arc_minus)];
  const int end = plus ? arc.first : arc.last;
  return is_free_end(model, end) ? kLastPartial * this->m_.h : 0.0;
}

template <int dim>
bool SplitLinkFront<dim>::is_free_end(const StringModel<dim>& model, int node) {
  // An arc of no links is not always at an end: it can lie between two fronts.
  const Chain<dim>& chain = model.chain();
  return !chain.closed() && (node == 0 || node == chain.num_nodes() - 1) && !model.is_prescribed(node);
}

template <int dim>
double SplitLinkFront<dim>::outside_margin(const FrontState<dim>& s) const {
  if (!relaid_) return 1.0;
  const double out_minus = s.l_minus / this->m_.h + kMaxOutside, out_plus = s.l_plus / this->m_.h + kMaxOutside;
  if (out_minus >= 0 && out_plus >= 0) relaid_ = false;
  return std::min({1.0, out_minus < 0 && s.s0_dot < 0 ? out_minus : 1.0, out_plus < 0 && s.s0_dot > 0 ? out_plus : 1.0});
}

template <int dim>
EventAction SplitLinkFront<dim>::cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) {
  Points<dim>& v = model.v();
  const double h = this->m_.h, lambda = this->m_.lambda;
  ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  // e0: the front reached B's first node (it joins A); e1: it reached A's last node (it joins B).
  const bool to_A = e0 != 0;
  // An arc of no links ends the string or meets the next front (two fronts in one link are not modelled).
  const int last_node = model.chain().num_nodes() - 1;
  if (to_A && B.num_links() == 0)
    return {EventAction::Kind::kStop,
            B.first == last_node && !model.chain().closed()
                ? fmt::format("the {} has reached the end of the string", this->name())
                : fmt::format("the {} has reached the link of the next front at node {} (two fronts in one link "
                              "are not modelled)", this->name(), B.first)};
  if (!to_A && A.num_links() == 0 && !(A.last == 0 && !model.chain().closed()))
    return {EventAction::Kind::kStop,
            fmt::format("the {} has reached the link of the previous front at node {} (two fronts in one link are "
                        "not modelled)", this->name(), A.last)};
  if (!to_A && (A.num_links() == 0 || model.is_prescribed(A.last)))
    return {EventAction::Kind::kStop, fmt::format("the {} has reached the start of the string", this->name())};
  // Mass parcels: each link's mass is split between its two nodes (½–½ for a full link, l⁻–l⁺ for
  // the split one). Moving the front changes the split of two links; the mass that changes node
  // carries its velocity, so momentum is conserved exactly. `state` is the tracker's, so that after
  // the refresh below it holds the new split.
  const int a = A.last, b = B.first;
  const int lo = to_A ? a : a - 1;  // the two links whose split changes: (lo, lo+1), (lo+1, lo+2)
  auto shares = [&](int j) -> std::pair<double, double> {
    // split of link (j, j+1) between its start and end node under the current arcs
    if (model.arc_of(j) == model.arc_of(j + 1)) return {0.5 * lambda * h, 0.5 * lambda * h};
    return {lambda * state.l_minus, lambda * state.l_plus};
  };
  const auto old0 = shares(lo), old1 = shares(lo + 1);
  Eigen::VectorXd mass(3);
  Points<dim> mom(dim, 3);
  for (int q = 0; q < 3; ++q) {
    mass[q] = model.masses()[lo + q];
    mom.col(q) = model.masses()[lo + q] * v.col(lo + q);
  }
  if (to_A) {
    A.last = b;
    B.first = b + 1;
  } else {
    A.last = a - 1;
    B.first = a;
  }
  model.rebuild();
  model.refresh();
  const auto new0 = shares(lo), new1 = shares(lo + 1);
  move_parcel(model, lo, lo, new0.first - old0.first, mass, mom);
  move_parcel(model, lo, lo + 1, new1.first - old1.first, mass, mom);
  set_velocities(model, lo, mass, mom);
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
void SplitLinkFront<dim>::move_parcel(const StringModel<dim>& model, int lo, int j, double delta, Eigen::Ref<Eigen::VectorXd> mass,
                                      Points<dim>& mom) {
  // delta: the change of link j's share on its start node j; the material that changes node carries the
  // velocity of the node it leaves.
  const int q = j - lo;
  const int giver = delta < 0 ? j : j + 1;
  mass[q] += delta;
  mom.col(q) += delta * model.v().col(giver);
  mass[q + 1] -= delta;
  mom.col(q + 1) -= delta * model.v().col(giver);
}

template <int dim>
void SplitLinkFront<dim>::add_partial_weight(const StringModel<dim>& model, int p, int q, double l, double lambda,
                                             Points<dim>& force) {
  const Vec<dim> field = model.uniform_field();
  if (!(field.squaredNorm() > 0)) return;
  // The weight at x_p + ½ l u: the power of W on p plus that of the couple, (l / 2L) W⊥·(v_p − v_q) = ½ l W·u̇,
  // is W·d/dt(x_p + ½ l u) at fixed l, exactly (u̇ = (v_p − v_q)⊥ / L, whether or not L = h).
  const Vec<dim> link = model.x().col(p) - model.x().col(q);
  const double L = link.norm();
  const Vec<dim> u = link / L, W = lambda * l * field;
  const Vec<dim> couple = (0.5 * l / L) * (W - u.dot(W) * u);
  force.col(p) += couple;
  force.col(q) -= couple;
}

template <int dim>
void SplitLinkFront<dim>::set_velocities(StringModel<dim>& model, int lo, const Eigen::Ref<const Eigen::VectorXd>& mass,
                                         const Points<dim>& mom) {
  Points<dim> v_new = model.v();
  for (int q = 0; q < mass.size(); ++q)
    if (!model.is_prescribed(lo + q) && model.in_arc(lo + q)) v_new.col(lo + q) = mom.col(q) / mass[q];
  model.v() = v_new;
}

template <int dim>
void SplitLinkFront<dim>::remove(StringModel<dim>& model, const FrontState<dim>& state) {
  // The split link (a, b) becomes a full link of one arc: its shares go from λ l⁻ on a and λ l⁺ on b to
  // ½ λ h on each, the material that changes node moving with its velocity (momentum exact; the kinetic
  // energy of the lumped masses changes by −½ (λ l⁻ − ½ λ h)(...)², a perfectly inelastic merge of the
  // parcel, of order λ h |[v]|²: docs/model.md §2.5).
  const double h = this->m_.h, lambda = this->m_.lambda;
  std::vector<ArcRange>& arcs = model.arcs();
  const auto A = static_cast<std::size_t>(this->arc_minus), B = static_cast<std::size_t>(this->arc_plus);
  const int a = arcs[A].last;
  Eigen::Vector2d mass(model.masses()[a], model.masses()[a + 1]);
  Points<dim> mom(dim, 2);
  for (int q = 0; q < 2; ++q) mom.col(q) = mass[q] * model.v().col(a + q);
  move_parcel(model, a, a, 0.5 * lambda * h - lambda * state.l_minus, mass, mom);
  arcs[A].last = arcs[B].last;
  arcs.erase(arcs.begin() + static_cast<std::ptrdiff_t>(B));
  model.rebuild();
  set_velocities(model, a, mass, mom);
}

template class SplitLinkFront<2>;
template class SplitLinkFront<3>;

}  // namespace chainsim
