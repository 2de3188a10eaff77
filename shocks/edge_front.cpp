// An edge front: see edge_front.hpp (the scheme) and docs/model.md §8 (the physics).
#include "edge_front.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"
#include "shocks/split_link_front.hpp"

namespace chainsim {

namespace {

/// The crossing node's velocity v carried from the side along `from` to the side along `to` (unit
/// vectors): its part along `from` goes along `to` exactly, and the rest turns about the edge's line `axis`
/// (in 2D the out-of-plane axis) by the angle between the sides seen across the line; its length kept where
/// both sides are normal to the line. About the line, not about the sides' own normal: where they are
/// antiparallel (a peg) that normal is made of their round-off, and it would turn the node's velocity
/// across its side about it.
template <int dim>
Vec<dim> rotate_onto(const Vec<dim>& v, const Vec<dim>& from, const Vec<dim>& to, const Vec<dim>& axis) {
  if constexpr (dim == 2) {
    const double c = from.dot(to), s = from[0] * to[1] - from[1] * to[0];
    return Vec<dim>(c * v[0] - s * v[1], s * v[0] + c * v[1]);
  } else {
    const Vec<dim> f = (from - axis.dot(from) * axis).normalized(), g = (to - axis.dot(to) * axis).normalized();
    const double c = f.dot(g), s = f.cross(g).dot(axis);
    const double along = v.dot(from);
    const Vec<dim> rest = v - along * from;
    return along * to + c * rest + s * axis.cross(rest) + (1 - c) * axis.dot(rest) * axis;  // Rodrigues about the line
  }
}

}  // namespace

void check_edge_dissipation(double f, const std::string& name) {
  if (!(f >= 0 && f <= 1))
    throw InputError(fmt::format("{}.f = {} is out of range: allowed 0 <= f <= 1", name, f));
}

template <int dim>
EdgeFront<dim>::EdgeFront(const EdgeSpec<dim>& spec) : point_(spec.point), axis_(spec.axis), table_(spec.table) {
  check_edge_dissipation(spec.dissipation);
  this->dissipation = spec.dissipation;
  this->expected_s0 = spec.s0;
}

template <int dim>
void EdgeFront<dim>::cut(FrontLayout& layout) {
  const double h = this->m_.h;
  const int a = std::clamp(static_cast<int>(std::floor(this->expected_s0 / h)), 0, this->m_.n - 2);
  if (a < layout.first || a + 1 > layout.last)
    throw InputError("the edge must lie inside the moving part of the string");
  link_ = a;
  this->arc_minus = this->arc_plus = layout.arc;  // the string runs on through the edge
}

template <int dim>
void EdgeFront<dim>::initialize(StringModel<dim>& model) {
  const Points<dim>& x = model.x();
  const double h = this->m_.h;
  // The material point s0 on a node c: that node sits on the edge, where the bent link has no
  // direction. The string is taken as it was just before c reached the edge: the side up to c moves
  // back from the edge by 2 kCross h along its tangent there, the side after c towards it, each
  // rigidly (every link keeps its length; the bent link is (c, c + 1)). With a table after the edge
  // (its own, or a surface that ends at it) the string moves on along itself instead, node c onto the
  // table (the bent link is (c − 1, c)): c goes to the table's side either way, so that a layout and its
  // mirror in the material (the table before the edge or after it) start as each other's mirror.
  const double l_minus = this->expected_s0 - model.chain().node_coordinate(link_);
  const int c = l_minus < 2 * kCross * h ? link_ : h - l_minus < 2 * kCross * h ? link_ + 1 : -1;
  if (c >= 0) {
    // Node c may sit off the point by about as much as its material offset (a shape whose length differs
    // from the string's within shape.length_tolerance holds its nodes L/N apart in arc length, so the
    // node at a corner can lie just past it, on the other side). The nudge grows by twice that offset:
    // node c is put exactly at the nudge's place on its side's line below, which changes its links'
    // lengths by up to the offset, and the start's projection may move it back by as much; it must
    // still be more than kCross h from the point, or the crossing's root would start negative.
    const double nudge = 2 * kCross * h + 2 * (x.col(c) - point_).norm();
    if (c == 0 || c + 1 >= this->m_.n)
      throw InputError("the edge point is on an end node of the string: an edge needs string on both sides");
    // A held node (a fixed or driven end) cannot be moved: its support or path starts where it is.
    for (int i = 0; i < this->m_.n; ++i)
      if (model.is_prescribed(i))
        throw InputError(fmt::format(
            "the edge point {} is on node {} (s = {:.9g} m) and node {} of the string is held (a fixed or driven "
            "end): the edge needs its point inside a link there (the string is moved along itself by {:.3g} m to put it "
            "there, which a held node cannot follow); move the point along the string or change string.nodes",
            show_point<dim>(point_), c, model.chain().node_coordinate(c), i, nudge));
    const Vec<dim> tm = unit_vector<dim>(point_ - x.col(c - 1), "the string before the edge");
    const Vec<dim> tp = unit_vector<dim>(x.col(c + 1) - point_, "the string after the edge");
    using Table = typename EdgeSpec<dim>::Table;
    const bool on = table_ == Table::kAfter || surface_side_ == Table::kAfter;
    if (on)
      shift_sides(model, 0, c - 1, c, this->m_.n - 1, nudge, tm, tp);
    else
      shift_sides(model, 0, c, c + 1, this->m_.n - 1, -nudge, tm, tp);
    // Node c goes exactly to the nudge's place on its side's line: left where the shift put it (off by
    // its offset), the bent link's direction, the table's normal and the lift-off cone would tilt by the
    // offset over the nudge (a table 9° off for an offset of 8e-11 m on 2e-10 m).
    Points<dim>& moved = model.x();
    moved.col(c) = on ? Vec<dim>(point_ + nudge * tp) : Vec<dim>(point_ - nudge * tm);
    for (int i = 0; i < this->m_.n; ++i) model.move_initial_node(i, Vec<dim>(x.col(i)));
    link_ = on ? c - 1 : c;
  }
  const int a = link_;
  set_link(model, a);
  start_minus_ = unit_vector<dim>(point_ - x.col(a), "the bent link before the edge");
  start_plus_ = unit_vector<dim>(x.col(a + 1) - point_, "the bent link after the edge");
  if (table_ == EdgeSpec<dim>::Table::kNone) return;
  // The table: the face the string on its side lies on, through x0, normal to that side's tangent, on
  // the side away from the bend (jump::face_normal).
  const Vec<dim> tm = unit_vector<dim>(point_ - x.col(a), "the string before the edge");
  const Vec<dim> tp = unit_vector<dim>(x.col(a + 1) - point_, "the string after the edge");
  const bool before = table_ == EdgeSpec<dim>::Table::kBefore;
  if (!((tp - tm).norm() > 1e-9))
    throw InputError("the string does not turn at the edge: a table needs the string to bend over its edge");
  table_normal_ = jump::face_normal<dim>(before ? tm : tp, tp - tm);
  const Vec<dim> g = model.uniform_field();
  // The table holds its side only by pushing against the field's normal part (its support −m g·n n):
  // a field along the table or none leaves that side free to leave it, and a field away from it pulls it off.
  if (!(g.dot(table_normal_) < 0))
    throw InputError(fmt::format("the table under the string {} the edge has its outward normal {} and the uniform "
                                 "field is {}: {}, so no table holds it; allowed a table the field presses the string "
                                 "onto (g·n < 0), or table = \"none\"",
                                 before ? "before" : "after", show_point<dim>(table_normal_), show_point<dim>(g),
                                 g.dot(table_normal_) > 0 ? "the field pulls the string off it"
                                                          : "the field does not press the string onto it (g·n = 0)"));
  const int first = before ? 0 : a + 1, last = before ? a : this->m_.n - 1;
  for (int i = first; i <= last; ++i) {
    const double off = table_normal_.dot(x.col(i) - point_);
    if (std::abs(off) > 1e-6 * this->m_.ell)
      throw InputError(fmt::format("node {} of the string {} the edge is {:.6g} m off the table (the face through the "
                                   "edge point with outward normal {}): the string there must lie on it",
                                   i, before ? "before" : "after", off, show_point<dim>(table_normal_)));
  }
  // Into the table along its top, normal to the edge's line: back along the side that lies on it.
  Vec<dim> inward = before ? Vec<dim>(-tm) : tp;
  inward -= inward.dot(table_normal_) * table_normal_;
  if constexpr (dim == 3) inward -= inward.dot(axis_) * axis_;
  table_inward_ = inward.normalized();
  const auto [node, gap] = table_body(model);
  if (node >= 0 && gap < 0)
    throw InputError(table_body_start<dim>(node, table_name(), Vec<dim>(x.col(node) - point_), table_normal_, table_inward_));
}

template <int dim>
std::pair<int, double> EdgeFront<dim>::table_body(const StringModel<dim>& model) const {
  std::pair<int, double> deepest{-1, INFINITY};
  if (table_ == EdgeSpec<dim>::Table::kNone) return deepest;
  // The nodes beyond the edge: after the bent link for a table before it, before the bent link otherwise.
  const bool before = table_ == EdgeSpec<dim>::Table::kBefore;
  const int first = before ? link_ + 1 : 0, last = before ? this->m_.n - 1 : link_;
  const double margin = kSideFaceMargin * this->m_.h;
  const Points<dim>& x = model.x();
  for (int i = first; i <= last; ++i) {
    if (!model.in_arc(i)) continue;
    const double gap = table_body_gap<dim>(x.col(i) - point_, table_normal_, table_inward_, margin);
    if (gap < deepest.second) deepest = {i, gap};
  }
  return deepest;
}

template <int dim>
void EdgeFront<dim>::evaluate(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                              Points<dim>& force) {
  const Points<dim>& v = model.v();
  const double h = this->m_.h, lambda = this->m_.lambda;
  const int a = link_, b = link_ + 1;
  // The bent link's two sides, signed (StringModel::bent_sides): a node that a step carries past x0
  // along its side (within kOvershoot h) has l < 0 and the side's direction, so that everything below
  // (the masses, the jump, the reaction, the lift-off margin) runs on continuously through the crossing.
  const typename StringModel<dim>::PointBendSides sides = model.bent_sides(a);
  const double lm = sides.l_minus, lp = sides.l_plus;
  t_minus_ = sides.e_minus;
  t_plus_ = sides.e_plus;
  // A trial stage that carries node a (or b) past x0 by more than kOvershoot h is refused (the
  // integrator retries a shorter step): a step over a crossing must end within that distance, where
  // the crossing's root is located.
  // Measured along the side's last link, a node also lies "past" x0 where the string folds back at it, more
  // than 90° next to the edge (a kink, or a free end whipping round, that reaches the edge): the message
  // says which, by how far the node is from x0.
  const bool past_minus = g_minus(model) < -kOvershoot * h, past_plus = g_plus(model) < -kOvershoot * h;
  if (past_minus || past_plus) {
    const int node = past_minus ? a : b;
    const double away = std::abs(past_minus ? lm : lp);
    throw RecoverableError(
        away > 2 * kOvershoot * h
            ? fmt::format("node {}, {:.3g} links from the edge, turns the string back by more than 90° there (a kink "
                          "or a whipping end has reached the edge, which the edge front does not take)",
                          node, away / h)
            : fmt::format("a node of link {} has passed the edge within a step", a));
  }
  slack_ = model.link_slack(a);
  double s0_dot = 0, l_minus = lm, l_plus = lp;
  if (!slack_) {
    // ṡ0 = dl⁻/dt = −dl⁺/dt (the bent link keeps l⁻ + l⁺ = h): the − side gains material at ṡ0.
    s0_dot = -t_plus_.dot(v.col(b));
    jump_ = jump::pinned_tension_plus<dim>(0.0, t_minus_, t_plus_, this->dissipation, lambda, s0_dot);
  } else {
    // A slack bent link (slack = allow; docs/model.md §9 "Slack over an edge"): the string no longer
    // presses on the edge, and checks() stops the run at once (a lift-off). Until then: no tension on
    // either side, so no kink and no jump; its material h shared in proportion to the two partial
    // lengths (the link's mass stays λ h; the split is the taut one where l⁻ + l⁺ reaches h), ṡ0 the
    // rate at which that share moves from a to b.
    const double L = lm + lp;
    l_minus = h * lm / L;
    l_plus = h - l_minus;
    const double lm_dot = -t_minus_.dot(v.col(a)), lp_dot = t_plus_.dot(v.col(b));
    s0_dot = h * (lm_dot * lp - lm * lp_dot) / (L * L);
    jump_ = 0;
  }
  s.s0 = model.chain().node_coordinate(a) + l_minus;
  s.s0_dot = s0_dot;
  s.l_minus = l_minus;
  s.l_plus = l_plus;
  s.direction = t_minus_;
  s.position = point_;
  s.power_shock =
      slack_ ? 0.0 : -jump::pinned_dissipation_rate<dim>(t_minus_, t_plus_, this->dissipation, lambda, s0_dot);
  s.power_heap = 0;
  // The partial links' masses (the bent link's lumped halves replaced), the jump as a load on b.
  mass[a] += lambda * (l_minus - 0.5 * h);
  mass[b] += lambda * (l_plus - 0.5 * h);
  force.col(b) -= jump_ * t_plus_;
  // What the edge's support gives the string besides the bent link's T (e⁻ − e⁺), which the string
  // books itself: the load, the table's support, and the momentum of the material moved from a to b.
  s.reaction = -jump_ * t_plus_ + lambda * s0_dot * (v.col(a) - v.col(b));
  // The partial links' weight at their midpoints. Each partial link is lumped on its node; where its side turns (a
  // side that swings), the weight at the node works twice what the weight at the midpoint does, ½ λ l g·v⊥ of power
  // booked nowhere (a hanging side started 30° out: energy residual 1.1e-6 of the scale on 101 nodes, first order).
  // As at the kink and the touchdown (SplitLinkFront::add_partial_weight), the partial link continues its side's
  // last full link straight and its weight acts at its midpoint by a couple on that link's two nodes (no net force:
  // the edge's reaction and the momentum are unchanged); potential_moment counts the same midpoints. A side on a
  // table (the edge's own, or a contact surface that ends at the edge) does not turn.
  if (model.uniform_field().squaredNorm() > 0) {
    using Table = typename EdgeSpec<dim>::Table;
    const ArcRange& arc = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
    if (table_ != Table::kBefore && surface_side_ != Table::kBefore && a - 1 >= arc.first)
      SplitLinkFront<dim>::add_partial_weight(model, a, a - 1, l_minus, lambda, force);
    if (table_ != Table::kAfter && surface_side_ != Table::kAfter && b + 1 <= arc.last)
      SplitLinkFront<dim>::add_partial_weight(model, b, b + 1, l_plus, lambda, force);
  }
  if (table_ != EdgeSpec<dim>::Table::kNone) {
    const bool before = table_ == EdgeSpec<dim>::Table::kBefore;
    const Vec<dim> g = model.uniform_field();
    const double gn = g.dot(table_normal_);
    const int first = before ? 0 : b, last = before ? a : this->m_.n - 1;
    for (int i = first; i <= last; ++i) {
      if (!model.in_arc(i) || model.is_prescribed(i)) continue;
      const Vec<dim> support = -mass[i] * gn * table_normal_;
      force.col(i) += support;
      s.reaction += support;
    }
  }
}

template <int dim>
double EdgeFront<dim>::potential_moment(const StringModel<dim>& model, const FrontState<dim>& s,
                                        const Vec<dim>& g) const {
  // The partial links lumped on a and b; their material lies along them, at their midpoints: x_a + ½ l⁻ u with u
  // the direction of the side's last full link towards the point (evaluate's couple), along the partial link itself
  // on a side that lies on a table or has no full link.
  const double lambda = this->m_.lambda;
  using Table = typename EdgeSpec<dim>::Table;
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  const Points<dim>& x = model.x();
  const auto half = [&](int node, int far, double l, bool on_table) -> Vec<dim> {
    if (on_table || far < arc.first || far > arc.last) return 0.5 * l * (point_ - x.col(node));
    return 0.5 * l * l * (x.col(node) - x.col(far)).normalized();
  };
  const int a = link_, b = link_ + 1;
  return lambda * g.dot(half(a, a - 1, s.l_minus, table_ == Table::kBefore || surface_side_ == Table::kBefore) +
                        half(b, b + 1, s.l_plus, table_ == Table::kAfter || surface_side_ == Table::kAfter));
}

template <int dim>
void EdgeFront<dim>::draw(int index, ObstacleDrawing& drawing) const {
  auto in_3d = [](const Vec<dim>& v) { return ObstacleDrawing::in_3d<dim>(v); };
  auto segment = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to, int part) {
    drawing.add_segment(from, to, index, part);
  };
  const double ell = this->m_.ell;
  const Eigen::Vector3d p = in_3d(point_), axis = in_3d(axis_);
  drawing.points.push_back(p);
  drawing.point_obstacle.push_back(index);
  drawing.point_part.push_back(ObstacleDrawing::kEdge);
  const Eigen::Vector3d half = 0.5 * ell * axis;  // a 3D edge's line (zero in 2D)
  if (dim == 3) segment(p - half, p + half, ObstacleDrawing::kEdge);
  if (table_ == EdgeSpec<dim>::Table::kNone) return;
  // A face from the edge into `along` (normal to the edge's line), `depth` deep: a segment in 2D, the
  // three other sides of a rectangle on the edge's line in 3D.
  auto face = [&](const Vec<dim>& along, double depth, int part) {
    Eigen::Vector3d w = in_3d(along);
    w -= w.dot(axis) * axis;
    const Eigen::Vector3d q = p + depth * w.normalized();
    if (dim == 2) {
      segment(p, q, part);
    } else {
      segment(p - half, q - half, part);
      segment(q - half, q + half, part);
      segment(q + half, p + half, part);
    }
  };
  const bool before = table_ == EdgeSpec<dim>::Table::kBefore;
  face(before ? Vec<dim>(-start_minus_) : start_plus_, ell, ObstacleDrawing::kTable);
  face(before ? start_plus_ : Vec<dim>(-start_minus_), 0.25 * ell, ObstacleDrawing::kSide);
}

template <int dim>
void EdgeFront<dim>::set_link(StringModel<dim>& model, int a, int received) {
  link_ = a;
  // A side whose node ends its arc stays unsigned: signed, its mass λ l⁻ (or λ l⁺) would go negative in a stage
  // past the point, and a crossing there stops the run anyway (review of the signed sides).
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  model.bend_link(a, point_, received >= 0 && a > arc.first, received <= 0 && a + 1 < arc.last);
}

template <int dim>
Vec<dim> EdgeFront<dim>::side_direction(const StringModel<dim>& model, int j, bool before) const {
  const Points<dim>& x = model.x();
  const Vec<dim>& p = *model.bend_point(j);
  const int a = j, b = j + 1;
  const double h = this->m_.h;
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  if (before) {
    const bool link_before = a > arc.first && model.bend_point(a - 1) == nullptr;
    return (p - x.col(a)).norm() > 0.5 * h || !link_before
               ? unit_vector<dim>(p - x.col(a), "the string before an edge")
               : unit_vector<dim>(x.col(a) - x.col(a - 1), "the string before an edge");
  }
  const bool link_after = b < arc.last && model.bend_point(b) == nullptr;
  return (x.col(b) - p).norm() > 0.5 * h || !link_after ? unit_vector<dim>(x.col(b) - p, "the string after an edge")
                                                        : unit_vector<dim>(x.col(b + 1) - x.col(b), "the string after an edge");
}

template <int dim>
void EdgeFront<dim>::shift_sides(StringModel<dim>& model, int first, int last_minus, int first_plus, int last,
                                 double step, const Vec<dim>& minus, const Vec<dim>& plus) const {
  Points<dim>& x = model.x();
  Vec<dim> along = minus;
  for (int i = last_minus; i >= first; --i) {
    if (i != link_ && model.bend_point(i))  // passing another edge's bent link i, from node i + 1 to node i
      along = side_direction(model, i, true);
    x.col(i) += step * along;
  }
  along = plus;
  for (int i = first_plus; i <= last; ++i) {
    if (i - 1 != link_ && model.bend_point(i - 1))  // passing another edge's bent link i − 1, from node i − 1 to node i
      along = side_direction(model, i - 1, false);
    x.col(i) += step * along;
  }
}

template <int dim>
double EdgeFront<dim>::g_minus(const StringModel<dim>& model) const {
  // Along the direction the string arrives at a (the link before it, or its part after another edge's
  // point; at the arc's first node the bent link's direction when it was bent): the sign of l⁻.
  return model.bend_side_direction(link_, false).dot(point_ - model.x().col(link_));
}

template <int dim>
double EdgeFront<dim>::g_plus(const StringModel<dim>& model) const {
  return model.bend_side_direction(link_, true).dot(model.x().col(link_ + 1) - point_);
}

template <int dim>
void EdgeFront<dim>::crossings(const StringModel<dim>& model, const FrontState<dim>& /*s*/, double* g) const {
  const double h = this->m_.h;
  g[0] = g_minus(model) / h - kCross;  // node a reaches the edge (material flows to the + side)
  g[1] = g_plus(model) / h - kCross;   // node b reaches it (material flows back)
}

template <int dim>
EventAction EdgeFront<dim>::cross(StringModel<dim>& model, const FrontState<dim>& s, int e0) {
  Points<dim>& x = model.x();
  Points<dim>& v = model.v();
  const int a = link_, b = link_ + 1;
  const int node = e0 != 0 ? a : b;
  const int next = e0 != 0 ? a - 1 : b + 1;
  const ArcRange& arc = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  if (next < arc.first || next > arc.last || model.is_prescribed(node))
    return {EventAction::Kind::kStop,
            fmt::format("the string's {} (node {}) has reached the edge: its last material slides over it at s0 = "
                        "{:.9g} m",
                        next < arc.first ? "first node" : next > arc.last ? "last node" : "held node", node, s.s0)};
  // Neither side may be held by a prescribed node (a fixed or driven end): the crossing moves the
  // material δ + kMirror kCross h over the edge ahead of time, each side on along itself, and a held
  // node cannot follow. On the side the node leaves, the new bent link would end at a node more than
  // h from the edge along a taut side (no position of the crossing node gives it its length); on the
  // other side the crossing node would have to leave the line. Either way the projection after the
  // crossing fails. The run stops instead, before the crossing, with where it happens.
  int held = -1;
  for (int i = arc.first; i <= arc.last && held < 0; ++i)
    if (i != node && model.is_prescribed(i)) held = i;
  if (held >= 0)
    return {EventAction::Kind::kStop,
            fmt::format("the string {} the edge is held at node {} (a fixed or driven end) and node {} has reached the "
                        "edge at s0 = {:.9g} m: an edge carries material over it only while the string on both sides "
                        "is free to move along itself",
                        held < node ? "before" : "after", held, node, s.s0)};
  // The new bent link would be another edge's (two edges within one link of each other): no link is
  // left between them to carry the material from one to the other.
  const int new_link = e0 != 0 ? a - 1 : b;
  if (model.bend_point(new_link) != nullptr)
    return {EventAction::Kind::kStop,
            fmt::format("node {} has reached the edge at {} (s0 = {:.9g} m) and the next link over it, link {}, runs "
                        "over another edge at {}: two edges within one link of each other",
                        node, show_point<dim>(point_), s.s0, new_link, show_point<dim>(*model.bend_point(new_link)))};
  const double h = this->m_.h, past = kMirror * kCross * h;
  const int sign = e0 != 0 ? +1 : -1;
  const double delta = e0 != 0 ? g_minus(model) : g_plus(model);
  // The sides' directions: the crossing node's own partial link is kCross h long, and its direction from
  // the positions carries their error over that length (a node 7.5e-14 m off its side's line tilts it by
  // 1.2e-3 rad on 160 nodes, where the integrator's tolerance allows far more; exactly zero only where the
  // side runs along a coordinate axis), which the velocity's rotation below would turn into a velocity
  // across the new partial link (2.4e-4 m/s: the run failed at the crossing). That side's direction is
  // taken from its whole links (bend_side_direction, as the crossing's root measures it); the other
  // side's partial link is nearly h long (docs/model.md §8, "Round-off at a crossing").
  const Vec<dim> side_minus = e0 != 0 ? model.bend_side_direction(link_, false) : t_minus_;
  const Vec<dim> side_plus = e0 != 0 ? t_plus_ : model.bend_side_direction(link_, true);
  // Each side moves on by δ + kMirror kCross h along itself: from this edge along its line on that side,
  // and beyond another edge's bent link (a second edge or peg on the string) along that edge's line on
  // its far side, so that the material flows through every edge by the same length and every link,
  // straight or bent, keeps its length (to first order in the step; the projection does the rest).
  shift_sides(model, arc.first, node - 1, node + 1, arc.last, sign * (delta + past), side_minus, side_plus);
  if (e0 != 0) {
    x.col(a) = point_ + past * side_plus;
    v.col(a) = rotate_onto<dim>(v.col(a), side_minus, side_plus, axis_);
    link_ = a - 1;
  } else {
    x.col(b) = point_ - past * side_minus;
    v.col(b) = rotate_onto<dim>(v.col(b), side_plus, side_minus, axis_);
    link_ = b;
  }
  model.unbend_link(a);  // this edge's bend only: another edge's stays
  // The side the crossing node now lies on keeps |x − x0| as its partial length (unsigned): that node
  // leaves the point, 2e-8 h past it, with the velocity it crossed with, and where that velocity has a
  // part across its partial link (a side reaching the edge swinging) the node whirls about the point
  // as a short rope round a post, which a signed length would not let it do. The side it left, whose
  // node comes next to the edge, is signed.
  set_link(model, link_, e0 != 0 ? +1 : -1);
  model.rebuild();
  model.refresh();
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
Vec<dim> EdgeFront<dim>::recorded_reaction(const StringModel<dim>& model, const FrontState<dim>& s) const {
  const double tm = tension_minus(model);
  if (!std::isfinite(tm) || slack_) return Vec<dim>::Zero();  // a slack bent link does not press on the edge
  return jump::pinned_reaction<dim>(t_minus_, t_plus_, tm, tm + jump_, this->m_.lambda, s.s0_dot);
}

template <int dim>
void EdgeFront<dim>::checks(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  // A slack bent link (slack = allow) does not press on the edge: the string has left it. The margin,
  // τ (1 − cos θ) − λ ṡ0² |[t]|²/2 for f = 0, reaches zero as the link's tension falls and the lift-off is
  // located there; the link goes slack first only where ṡ0 = 0 exactly (or when a snap leaves it slack, or
  // it was laid slack), and then this check is negative: the run stops at once (docs/model.md §9).
  if (table_ != EdgeSpec<dim>::Table::kNone) g[kTableCheck] = std::min(1.0, table_body(model).second / this->m_.h);
  if (slack_) {
    g[0] = -1;
    if constexpr (dim == 3) g[1] = 1;
    return;
  }
  const Vec<dim> reaction = recorded_reaction(model, s);
  g[0] = jump::pinned_lift_off_margin<dim>(reaction, t_minus_, t_plus_, axis_);
  if constexpr (dim == 3) g[1] = along_line_margin(model, s, reaction);
}

template <int dim>
double EdgeFront<dim>::along_line_scale(const StringModel<dim>& model, const FrontState<dim>& s) const {
  return std::abs(tension_minus(model)) + std::abs(tension_plus(model)) + this->m_.lambda * s.s0_dot * s.s0_dot;
}

template <int dim>
double EdgeFront<dim>::along_line_margin(const StringModel<dim>& model, const FrontState<dim>& s,
                                         const Vec<dim>& reaction) const {
  return kAlongLine * along_line_scale(model, s) - std::abs(reaction.dot(axis_));
}

template <int dim>
std::string EdgeFront<dim>::check_failed(const StringModel<dim>& model, const FrontState<dim>& s, double t, int check) const {
  if (table_ != EdgeSpec<dim>::Table::kNone && check == kTableCheck) {
    const int node = table_body(model).first;
    return table_body_reached<dim>(node, model.chain().node_coordinate(node), point_, table_name(), t,
                                   Vec<dim>(model.x().col(node) - point_), table_normal_, table_inward_,
                                   "docs/model.md §8");
  }
  if (slack_)
    return fmt::format("lifted off the edge at t = {:.9g} s: the link bent over the edge at {} (link {}) has gone slack, "
                       "so the string no longer presses on the edge (s0 = {:.9g} m)",
                       t, show_point<dim>(point_), link_, s.s0);
  const Vec<dim> reaction = recorded_reaction(model, s);
  if (dim == 3 && along_line(model, s))
    return fmt::format(
        "the string crosses the edge at {} obliquely at t = {:.9g} s: held there, it would need a force {:.6g} N along "
        "the edge's line {} (reaction F0 = {} N; allowed at most {:g} of τ⁻ + τ⁺ + λ ṡ0²), which a smooth edge cannot give: the "
        "crossing point would slide along the line, which the edge front does not model (docs/model.md §8, \"An edge "
        "in 3D\"); the string must cross the line at right angles (s0 = {:.9g} m)",
        show_point<dim>(point_), t, reaction.dot(axis_), show_point<dim>(axis_), show_point<dim>(reaction), kAlongLine, s.s0);
  return fmt::format("lifted off the edge at t = {:.9g} s: the edge at {} would have to pull the string (its reaction "
                     "F0 = {} N leaves the edge's normal cone; tensions {:.6g} N before and {:.6g} N after it, "
                     "material speed {:.6g} m/s, s0 = {:.9g} m)",
                     t, show_point<dim>(point_), show_point<dim>(reaction), tension_minus(model), tension_plus(model),
                     std::abs(s.s0_dot), s.s0);
}

template <int dim>
bool EdgeFront<dim>::along_line(const StringModel<dim>& model, const FrontState<dim>& s) const {
  // The check that stopped the run: the along-line one where it is at or past its root (within a
  // thousandth of its scale: both roots can fall in one step) and the lift-off margin is not.
  if (dim != 3 || slack_) return false;
  const Vec<dim> reaction = recorded_reaction(model, s);
  return along_line_margin(model, s, reaction) <= 1e-3 * kAlongLine * along_line_scale(model, s) &&
         jump::pinned_lift_off_margin<dim>(reaction, t_minus_, t_plus_, axis_) > 0;
}

template <int dim>
std::optional<RunEvent> EdgeFront<dim>::check_event(const StringModel<dim>& model, const FrontState<dim>& s,
                                                    double t, int check) const {
  if (along_line(model, s)) return std::nullopt;  // no physical event: the model's limit (check_failed says)
  if (check == kTableCheck) return std::nullopt;  // the same (a table's body)
  RunEvent e;
  e.kind = "lift_off";
  e.t = t;
  e.position.assign(point_.data(), point_.data() + dim);
  e.values = {{"s0", s.s0},
              {"s0_dot", s.s0_dot},
              {"tension_minus", tension_minus(model)},
              {"tension_plus", tension_plus(model)}};
  return e;
}

template <int dim>
Obstacle<dim> edge_table(EdgeFront<dim>& edge, const Vec<dim>& normal, const Vec<dim>& inward, bool before,
                         const Vec<dim>& edge_axis, std::string name) {
  edge.surface_side_ = before ? EdgeSpec<dim>::Table::kBefore : EdgeSpec<dim>::Table::kAfter;
  Obstacle<dim> o;
  o.kind = Obstacle<dim>::Kind::kPlane;
  o.name = std::move(name);
  o.point = edge.point();
  o.normal = normal;
  o.inward = inward;
  o.edge_axis = edge_axis;
  const EdgeFront<dim>* front = &edge;
  o.carries = before ? std::function<bool(int)>([front](int i) { return i <= front->link(); })
                     : std::function<bool(int)>([front](int i) { return i > front->link(); });
  return o;
}

template class EdgeFront<2>;
template class EdgeFront<3>;
template Obstacle<2> edge_table<2>(EdgeFront<2>&, const Vec<2>&, const Vec<2>&, bool, const Vec<2>&, std::string);
template Obstacle<3> edge_table<3>(EdgeFront<3>&, const Vec<3>&, const Vec<3>&, bool, const Vec<3>&, std::string);

}  // namespace chainsim
