// The module of rigid obstacles along arcs: see contact_module.hpp (docs/model.md §10).
#include "contact_module.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numeric>
#include <tuple>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "banded_lu.hpp"
#include "mesh/errors.hpp"
#include "string_model.hpp"
#include "wrapping_module.hpp"

namespace chainsim {

namespace {
/// At a landing the free nodes within kLandWindow (of h) of a surface are held; if none is (the state
/// recomputed to the event ends a little short of the located root), the nearest within kCatchWindow.
/// Fractions of h, not of the integration error: the event's polish refutes the interpolant's roots that no
/// recomputed state reaches, and at the step's start reports a root only where the recomputed function has
/// reached its zero or is within its margin of it (docs/string_solver.md, "Events at loose tolerances").
constexpr double kLandWindow = 1e-7;
constexpr double kCatchWindow = 1e-5;
/// A node let go starts its landing root function at +kReleaseGap (ARKODE deactivates a root function
/// that is zero at a restart).
constexpr double kReleaseGap = 2e-7;
/// A node let go, then landing at that same instant and let go again (its contact force after the impact
/// pulls) has not landed: it passes, its velocity projected, and its landing root function restarts at
/// +kPassGap, above the error of the interpolant on which ARKODE looks for roots (at +kReleaseGap that
/// error found its landing again in the next step, the recomputed step put it back at the same instant,
/// and it landed and was let go there over and over).
constexpr double kPassGap = kCatchWindow;
/// A held node's normal force counts as pulling below −kPull of its weight scale m a (a the physical
/// acceleration scale): round-off is not a lift-off.
constexpr double kPull = 1e-9;
/// Links along the arc: a free end lands when its straight part is this share of h (on the tangent line,
/// its gap is then kWrapLand² h²/2R and its normal speed kWrapLand h/R of its speed: an impulse of second
/// order in h). Not closer: a free node near its tangent point is a stiff pendulum (frequency² ~ T/(m s)),
/// whose small swing each landing leaves grows as s shrinks; landing at 10⁻⁵ h or 10⁻² h let it grow from
/// landing to landing into tension spikes (compare pulley on 101 and 801 nodes), at 0.05 h it does not.
constexpr double kWrapLand = 0.05;
/// Links along the arc: a node lands at kWrapLand h from its tangent point, on the circle at that arc behind
/// it, so the link behind it starts with an arc of about −kWrapLand h: its arc runs out at −kWrapEnter h.
constexpr double kWrapEnter = 3 * kWrapLand;
/// Links along the arc: a free end has passed its tangent point (its landing root function read on its side's
/// line, ContactModule::wrap_land_gap) only where the link from the node beyond it runs within 60° of that
/// node's tangent line (cos 60°), as an edge's side is signed (solver/string_model.cpp, kPassedCone).
constexpr double kWrapPassedCone = 0.5;
/// A sliding node whose tangential speed is within kStopWindow of the speed scale √(a ℓ) at a located
/// stop has stopped (the state recomputed to the event is within the integration error of the root).
constexpr double kStopWindow = 1e-5;
/// The summary's `events` lists the first kListedLiftOffs lift-offs of each obstacle; the rest are counted
/// (`contact_lift_offs`, LiftOffTotal). A pulley in node contact lets a node go at every link that leaves it,
/// thousands in a long run (docs/scenes.md, the summary's `events`).
constexpr long kListedLiftOffs = 100;

/// A closed interval (empty when lo > hi) and a half-plane a x + b y ≤ c: the friction cone of a stuck
/// node in 2D in the tensions x, y of its two links.
struct Interval {
  double lo = 0, hi = 0;
  bool empty() const { return lo > hi; }
  double mid() const { return 0.5 * (lo + hi); }
};
struct HalfPlane {
  double a = 0, b = 0, c = 0;
};

/// The range of y over the convex polygon {x ∈ X, y ∈ Y, a_k x + b_k y ≤ c_k} (its projection, from its
/// vertices; tol: the absolute slack of a constraint, N).
Interval project_y(const Interval& X, const Interval& Y, const std::vector<HalfPlane>& cone, double tol) {
  std::vector<HalfPlane> h = {{1, 0, X.hi}, {-1, 0, -X.lo}, {0, 1, Y.hi}, {0, -1, -Y.lo}};
  h.insert(h.end(), cone.begin(), cone.end());
  Interval out{INFINITY, -INFINITY};
  for (std::size_t p = 0; p < h.size(); ++p)
    for (std::size_t q = p + 1; q < h.size(); ++q) {
      const double det = h[p].a * h[q].b - h[q].a * h[p].b;
      if (!(std::abs(det) > 1e-14 * (std::abs(h[p].a * h[q].b) + std::abs(h[q].a * h[p].b)))) continue;
      const double x = (h[p].c * h[q].b - h[q].c * h[p].b) / det, y = (h[p].a * h[q].c - h[q].a * h[p].c) / det;
      bool inside = true;
      for (const HalfPlane& k : h) inside = inside && k.a * x + k.b * y <= k.c + tol;
      if (!inside) continue;
      out.lo = std::min(out.lo, y);
      out.hi = std::max(out.hi, y);
    }
  return out;
}

/// The x ∈ X with a_k x + b_k y ≤ c_k at a given y.
Interval range_x(Interval X, double y, const std::vector<HalfPlane>& cone, double tol) {
  for (const HalfPlane& k : cone) {
    const double r = k.c - k.b * y;
    if (k.a > 0)
      X.hi = std::min(X.hi, (r + tol) / k.a);
    else if (k.a < 0)
      X.lo = std::max(X.lo, (r + tol) / k.a);
    else if (r < -tol)
      return {1, 0};
  }
  return X;
}

template <int dim>
Vec<dim> radial(const Obstacle<dim>& o, const Vec<dim>& x) {
  Vec<dim> r = x - o.point;
  if constexpr (dim == 3) r -= r.dot(o.axis) * o.axis;
  return r;
}

/// A bounded plane (a table ending at an edge): x beyond the edge, where there is no surface.
template <int dim>
bool beyond_edge(const Obstacle<dim>& o, const Vec<dim>& x) {
  return o.kind == Obstacle<dim>::Kind::kPlane && o.inward.squaredNorm() > 0 && !(o.inward.dot(x - o.point) > 0);
}

/// x's offset from a bounded plane's edge line, normal to it.
template <int dim>
Vec<dim> from_edge(const Obstacle<dim>& o, const Vec<dim>& x) {
  Vec<dim> r = x - o.point;
  if constexpr (dim == 3) r -= r.dot(o.edge_axis) * o.edge_axis;
  return r;
}
}  // namespace

template <int dim>
std::string table_body_reached(int node, double s, const Vec<dim>& edge_point, const std::string& table, double t,
                               const Vec<dim>& r, const Vec<dim>& normal, const Vec<dim>& inward, const std::string& see) {
  return fmt::format("node {} (s = {:.6g} m), beyond the edge at {} in the material, has reached the body of the table "
                     "{} at t = {:.9g} s, {:.6g} m beneath its top and {:.6g} m in from its edge: the table's side face "
                     "below the edge is not an obstacle, and the string beyond the edge cannot rest on the table, so the "
                     "string would pass into it (a side that swings back under the table, or over onto it, is not "
                     "modelled: {})",
                     node, s, show_point<dim>(edge_point), table, t, -normal.dot(r), inward.dot(r), see);
}

template <int dim>
std::string table_body_start(int node, const std::string& table, const Vec<dim>& r, const Vec<dim>& normal,
                             const Vec<dim>& inward) {
  return fmt::format("node {} of the string, beyond the table's edge in the material, starts inside the table {}, "
                     "{:.6g} m beneath its top and {:.6g} m in from its edge (allowed: beyond the edge's line, or above "
                     "the table)",
                     node, table, -normal.dot(r), inward.dot(r));
}

template <int dim>
double Obstacle<dim>::gap(const Vec<dim>& x, bool held) const {
  if (!held && beyond_edge(*this, x)) return from_edge(*this, x).norm();
  if (kind == Kind::kPlane) return normal.dot(x - point);
  return radial(*this, x).norm() - radius;
}

template <int dim>
Vec<dim> Obstacle<dim>::outward(const Vec<dim>& x, bool held) const {
  if (!held && beyond_edge(*this, x)) {
    const Vec<dim> r = from_edge(*this, x);
    return r.norm() > 0 ? Vec<dim>(r.normalized()) : normal;
  }
  if (kind == Kind::kPlane) return normal;
  const Vec<dim> r = radial(*this, x);
  const double d = r.norm();
  if (!(d > 0)) throw RecoverableError("a node has reached the axis of a cylinder");
  return r / d;
}

template <int dim>
double Obstacle<dim>::curvature(const Vec<dim>& x, const Vec<dim>& v) const {
  if (kind == Kind::kPlane) return 0;
  // g = |Q r| − R: g'' = n·a + (|Q v|² − (n·v)²)/|Q r|.
  const Vec<dim> r = radial(*this, x);
  Vec<dim> qv = v;
  if constexpr (dim == 3) qv -= v.dot(axis) * axis;
  const double d = r.norm(), nv = r.dot(v) / d;
  return (qv.squaredNorm() - nv * nv) / d;
}

template <int dim>
Eigen::Matrix<double, dim, dim - 1> Obstacle<dim>::tangents(const Vec<dim>& x) const {
  const Vec<dim> n = outward(x, true);
  Eigen::Matrix<double, dim, dim - 1> basis;
  if constexpr (dim == 2) {
    basis.col(0) = Vec<2>(-n[1], n[0]);
  } else {
    const Vec<3> u = kind == Kind::kPlane ? Vec<3>(normal.unitOrthogonal()) : axis;
    basis.col(0) = u;
    basis.col(1) = u.cross(n);
  }
  return basis;
}

template <int dim>
void Obstacle<dim>::draw(int index, const Points<dim>& nodes, double margin, ObstacleDrawing& drawing) const {
  constexpr int kCircleSegments = 64, kGenerators = 8;
  auto in_3d = [](const Vec<dim>& v) { return ObstacleDrawing::in_3d<dim>(v); };
  auto segment = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to, int part) {
    drawing.add_segment(from, to, index, part);
  };
  // The range of the nodes' projections on the unit direction e from the obstacle's point, plus the margin.
  auto span = [&](const Eigen::Vector3d& e) {
    double lo = INFINITY, hi = -INFINITY;
    for (Eigen::Index i = 0; i < nodes.cols(); ++i) {
      const double s = e.dot(in_3d(Vec<dim>(nodes.col(i) - point)));
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    return std::make_pair(lo - margin, hi + margin);
  };
  const Eigen::Vector3d c = in_3d(point);
  // Two unit vectors normal to `a` and to each other (a plane's normal in 2D: e1 in the plane, e2 = z).
  auto normal_pair = [&](const Eigen::Vector3d& a) {
    Eigen::Vector3d e1 = dim == 2 ? Eigen::Vector3d(-a.y(), a.x(), 0.0) : a.unitOrthogonal();
    return std::make_pair(e1, Eigen::Vector3d(a.cross(e1)));
  };
  if (kind == Kind::kPlane) {
    const auto [e1, e2] = normal_pair(in_3d(normal));
    const auto [a0, a1] = span(e1);
    if (dim == 2) {
      segment(c + a0 * e1, c + a1 * e1, ObstacleDrawing::kSurface);
      return;
    }
    const auto [b0, b1] = span(e2);
    const Eigen::Vector3d corners[4] = {c + a0 * e1 + b0 * e2, c + a1 * e1 + b0 * e2, c + a1 * e1 + b1 * e2,
                                        c + a0 * e1 + b1 * e2};
    for (int k = 0; k < 4; ++k) segment(corners[k], corners[(k + 1) % 4], ObstacleDrawing::kSurface);
    return;
  }
  const Eigen::Vector3d a = dim == 2 ? Eigen::Vector3d(0.0, 0.0, 1.0) : in_3d(axis);
  // The circle's plane (a pair, not a structured binding: C++17 lambdas cannot capture those).
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> plane =
      dim == 2 ? std::make_pair(Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.0, 0.0)) : normal_pair(a);
  auto rim = [&](double phi) { return radius * (std::cos(phi) * plane.first + std::sin(phi) * plane.second); };
  const double step = 2 * kPi / kCircleSegments;
  if (dim == 2) {
    for (int k = 0; k < kCircleSegments; ++k)
      segment(c + rim(k * step), c + rim((k + 1) * step), ObstacleDrawing::kCylinder);
    return;
  }
  const auto [z0, z1] = span(a);
  for (const double z : {z0, z1})
    for (int k = 0; k < kCircleSegments; ++k)
      segment(c + z * a + rim(k * step), c + z * a + rim((k + 1) * step), ObstacleDrawing::kCylinder);
  for (int k = 0; k < kGenerators; ++k) {
    const Eigen::Vector3d r = rim(k * 2 * kPi / kGenerators);
    segment(c + z0 * a + r, c + z1 * a + r, ObstacleDrawing::kGenerator);
  }
}

namespace {

template <int dim>
class ContactModule final : public WrappingModule<dim> {
  using WrappingModule<dim>::inner_;
  using WrappingModule<dim>::inner_ledgers;
  using WrappingModule<dim>::inner_events;

 public:
  ContactModule(std::vector<Obstacle<dim>> obstacles, std::unique_ptr<StringModule<dim>> inner)
      : WrappingModule<dim>(std::move(inner)), obstacles_(std::move(obstacles)) {
    for (const Obstacle<dim>& o : obstacles_) {
      friction_ = friction_ || o.mu > 0;
      arc_ = arc_ || on_arc(o);
      side_faces_ = side_faces_ || bounded(o);
    }
  }

  // Ledgers: [ the inner module's | W_contact | W_impacts | impulse (dim) | W_friction (with friction) |
  // W_impacts_supports ]. Without an inner module
  // the impulse is that of all external forces (the contact forces among them); with one (fronts), the
  // inner module integrates the external forces' impulse (StringModel::external_force has the contact
  // forces) and this one holds only the impacts' momentum jumps, added to it in fill().
  void initialize(StringModel<dim>& model) override {
    if (inner_) inner_->initialize(model);
    const Chain<dim>& chain = model.chain();
    const int n = chain.num_nodes();
    h_ = INFINITY;
    for (int j = 0; j < chain.num_links(); ++j) h_ = std::min(h_, chain.link_length(j));
    drawn_nodes_ = model.x();
    held_.assign(static_cast<std::size_t>(n), -1);
    wrap_.assign(static_cast<std::size_t>(chain.num_links()), -1);
    no_wrap_land_.assign(static_cast<std::size_t>(n), 0);
    entering_.assign(static_cast<std::size_t>(chain.num_links()), 0);
    offset_.assign(static_cast<std::size_t>(n), 0.0);
    carried_ = carried(model);
    let_go_at_.assign(static_cast<std::size_t>(n), -INFINITY);
    stuck_.assign(static_cast<std::size_t>(n), 0);
    dir_.setZero(dim - 1, n);
    length_ = chain.length();
    lift_off_totals_.assign(obstacles_.size(), 0);
    for (int i = 0; i < n; ++i) {
      if (!free_node(model, i)) continue;
      const auto [k, gap] = nearest(i, model.x().col(i));
      if (k < 0) continue;
      if (gap < -kInitialContact * h_)
        throw InputError(fmt::format("node {} of the string starts {:.6g} m inside the obstacle {} (allowed: on or "
                                     "outside its surface, within {:g} of a link length)",
                                     i, -gap, obstacles_[static_cast<std::size_t>(k)].name, kInitialContact));
      if (gap <= kInitialContact * h_) held_[static_cast<std::size_t>(i)] = k;
    }
    refuse_locked_loop(model);
    if (side_faces_)
      for (int i = 0; i < n; ++i) {
        const auto [k, gap] = side_face_gap(model, i);  // (−1, +∞) for a held node
        if (k < 0 || gap > 0) continue;
        const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(k)];
        throw InputError(table_body_start<dim>(i, o.name, model.x().col(i) - o.point, o.normal, o.inward));
      }
    if (arc_) {
      // Links along the arc are built for a string that starts wrapped on the circle: a node that reaches
      // it from off the circle lands across a bend, its links chords (an open chain started 3e-5 m off
      // the Atwood pulley at 3 m/s: energy ledger 3.9e-4 by 0.27 s; node contact 8.5e-10).
      for (std::size_t k = 0; k < obstacles_.size(); ++k)
        if (on_arc(obstacles_[k]) && std::find(held_.begin(), held_.end(), static_cast<int>(k)) == held_.end())
          throw InputError(fmt::format(
              "{}.contact = \"arc\": no node of the string starts on the circle (within {:g} of a link length): "
              "links along the arc are built for a string that starts wrapped on it; allowed \"nodes\" for a string "
              "that reaches the cylinder from off it",
              obstacles_[k].name, kInitialContact));
      // The sense each circle is wrapped in: that of the first two consecutive nodes held on it; on a
      // circle that holds no two consecutive nodes (a coarse mesh: one node on the pulley, its two links
      // running round it from free ends), that of the string through its first held node (r × the chord
      // of its neighbours). Without this a lone held node kept the default +1 however the string ran: on 5
      // nodes over the Atwood pulley its links ran round the wrong way, the node was let go at once, and
      // the chain fell through the pulley (energy ledger 1.7e-3).
      sense_.assign(obstacles_.size(), 0.0);
      for (int i = 0; i < n; ++i) {
        const int k = held_[static_cast<std::size_t>(i)];
        if (k < 0 || sense_[static_cast<std::size_t>(k)] != 0) continue;
        const int before = i > 0 ? i - 1 : chain.closed() ? n - 1 : i;
        const int after = i < n - 1 ? i + 1 : chain.closed() ? 0 : i;
        if (before == after) continue;
        const Vec<dim> r = model.x().col(i) - obstacles_[static_cast<std::size_t>(k)].point;
        const Vec<dim> d = model.x().col(after) - model.x().col(before);
        sense_[static_cast<std::size_t>(k)] = r[0] * d[1] - r[1] * d[0] >= 0 ? 1.0 : -1.0;
      }
      for (double& sense : sense_)
        if (sense == 0) sense = 1.0;
      for (int j = 0; j < chain.num_links(); ++j) {
        const int a = chain.link_start(j), b = chain.link_end(j), k = held_[static_cast<std::size_t>(a)];
        if (k < 0 || held_[static_cast<std::size_t>(b)] != k) continue;
        const Vec<dim> ra = model.x().col(a) - obstacles_[static_cast<std::size_t>(k)].point;
        const Vec<dim> rb = model.x().col(b) - obstacles_[static_cast<std::size_t>(k)].point;
        sense_[static_cast<std::size_t>(k)] = ra[0] * rb[1] - ra[1] * rb[0] >= 0 ? 1.0 : -1.0;
      }
      // A node on a straight part within kInitialContact h of the circle (near the tangent point) is not on
      // the arc: the link from it to the next held node would run round the circle backwards (a negative
      // arc). Such end nodes of the held runs are not held, until none is.
      for (bool again = true; again;) {
        again = false;
        refresh(model);
        Points<dim> x = model.x(), v = model.v();
        model.evaluate(0.0, x, v);
        for (int j = 0; j < chain.num_links(); ++j) {
          const auto [k, a_on, b_on] = link_wrap(model, j);
          if (k < 0 || a_on == b_on || !(model.bend_arc(j) < 0)) continue;
          held_[static_cast<std::size_t>(a_on ? chain.link_start(j) : chain.link_end(j))] = -1;
          again = true;
        }
      }
    }
    refresh(model);
    // On a cylinder the nodes start on the circle an arc apart, so the chords between them are short of
    // their links by h³/24R²: the forces are judged on the state projected onto the links and the
    // gaps, or the drift control's pull towards the links' lengths reads as a pull off the cylinder
    // and coarse meshes start by letting go of it (docs/model.md §10). A plane's straight nodes need
    // no projection here (the run's own makes them consistent, and start() judges the forces again there).
    bool curved = false;
    for (std::size_t i = 0; i < held_.size(); ++i)
      curved = curved || (held_[i] >= 0 && obstacle_of(i).kind == Obstacle<dim>::Kind::kCylinder);
    if (curved) {
      // A shape that cannot be fitted to its links is left as it is: the run's own projection
      // (make_consistent) refuses it, naming the cause.
      const Points<dim> x0 = model.x(), v0 = model.v();
      try {
        model.project(0.0);
        model.chain().positions() = model.x();
        model.chain().velocities() = model.v();
      } catch (const NumericalError&) {
        model.x() = x0;
        model.v() = v0;
      } catch (const RecoverableError&) {
        model.x() = x0;
        model.v() = v0;
      }
      refresh(model);
    }
    // The held nodes whose force pulls on the state as given are let go (a node given a velocity off the surface
    // among them: the drift control's pull back onto it is a pull); start() judges the forces again once the
    // start's projection has made the state consistent, and lands a node let go here that the projection, which
    // did not hold it, carried into the surface (docs/model.md §10, "At the start").
    settle(model, 0.0, false);
    if (friction_) {
      // A stuck node cannot be moved by the projection of the initial state (make_consistent): the
      // state is projected first, and the nodes at rest on rough obstacles stick where it puts them.
      model.project(0.0);
      model.chain().positions() = model.x();
      model.chain().velocities() = model.v();
      if (classify(model, 0.0, nullptr)) settle(model, 0.0, false);
    }
  }
  /// The start on the consistent initial state (docs/model.md §10, "At the start"). initialize() let go of the
  /// held nodes whose force pulled on the state as given; the start's projection (StringModel::make_consistent)
  /// then held the others on their surfaces and moved the nodes let go freely, and may have carried one into a
  /// surface (a corner of the shape: the chord across it is short of its link, and lengthening it pushes the
  /// node beside the corner into the table). Here the held nodes whose force pulls on the consistent state are
  /// let go (settle), and the free nodes inside a surface land at t0 with their impacts (hold: the impact's
  /// projection, booked in W_impacts and the impulse), as after an impact's projection: a landing root function
  /// below zero at the start would never find its root, and as the minimum over the free nodes it would hide
  /// every later landing behind it. A lift-off root function below zero would likewise never find its root.
  bool start(StringModel<dim>& model, double t0, Eigen::Ref<Eigen::VectorXd> ledger) override {
    const bool inner_changed = WrappingModule<dim>::start(model, t0, ledger);
    if (inner_changed) refresh(model);
    settle(model, t0, false);
    return land_passed(model, t0, ledger) || inner_changed;
  }
  void node_contacts(const StringModel<dim>& model, std::vector<NodeContact<dim>>& out) const override {
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!holds(model, static_cast<int>(i))) continue;
      const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(held_[i])];
      const Vec<dim> x = model.x().col(static_cast<Eigen::Index>(i)), v = model.v().col(static_cast<Eigen::Index>(i));
      out.push_back({static_cast<int>(i), o.outward(x, true), o.gap(x, true), o.curvature(x, v)});
      if (o.mu > 0) {
        out.back().mu = o.mu;
        out.back().stuck = stuck_[i] != 0;
        if (!stuck_[i]) out.back().slide = slide_direction(model, o, i, x, v);
      }
    }
  }
  int num_ledgers() const override { return inner_ledgers() + supports_index() + 1; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override {
    const int k = inner_ledgers();
    if (inner_) inner_->ledger_rates(model, rates.head(k));
    rates[k] = model.contact_power();
    rates[k + 1] = 0;  // the impacts' term jumps at events only
    if (inner_)
      rates.template segment<dim>(k + 2).setZero();
    else
      rates.template segment<dim>(k + 2) = model.external_force();
    if (friction_) rates[k + kFriction] = model.friction_power();
    rates[k + supports_index()] = 0;  // jumps at impacts only
  }
  Eigen::VectorXd ledger_scale(double mass, double speed, double length) const override {
    const int k = inner_ledgers();
    Eigen::VectorXd scale(num_ledgers());
    if (inner_) scale.head(k) = inner_->ledger_scale(mass, speed, length);
    scale.segment(k, 2).setConstant(mass * speed * speed);
    scale.template segment<dim>(k + 2).setConstant(mass * speed);
    if (friction_) scale[k + kFriction] = mass * speed * speed;
    scale[k + supports_index()] = mass * speed * speed;
    return scale;
  }
  double potential_correction(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const override {
    return inner_ ? inner_->potential_correction(model, ledger.head(inner_ledgers())) : 0.0;
  }
  std::vector<LedgerTerm> ledger_terms() const override {
    using K = LedgerTerm::Kind;
    std::vector<LedgerTerm> terms = inner_ ? inner_->ledger_terms() : std::vector<LedgerTerm>{};
    terms.insert(terms.end(),
                 {{"W_contact", K::kWork},
                  {"W_impacts", K::kWork},
                  {"W_impacts_supports", K::kWork},
                  {"impacts", K::kQuantity},
                  {"lift_offs", K::kQuantity}});
    if (friction_)
      terms.insert(terms.end(), {{"W_friction", K::kWork}, {"sticks", K::kQuantity}, {"slips", K::kQuantity}});
    return terms;
  }
  void fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override {
    const int k = inner_ledgers();
    this->fill_inner(model, ledger, ledger.template segment<dim>(k + 2), out);
    out.terms.insert(out.terms.end(),
                     {ledger[k], ledger[k + 1], ledger[k + supports_index()], static_cast<double>(impacts_),
                      static_cast<double>(lift_offs_)});
    if (friction_)
      out.terms.insert(out.terms.end(),
                       {ledger[k + kFriction], static_cast<double>(sticks_), static_cast<double>(slips_)});
    out.has_momentum_ledger = true;
  }
  int num_events() const override {
    return inner_events() + (friction_ ? 4 : 2) + (arc_ ? 2 : 0) + (side_faces_ ? 1 : 0);
  }
  bool events_need_tensions() const override { return true; }
  void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const override {
    // The inner module's, then: the smallest gap of a free node (landing); the smallest normal force of
    // a held node, per its weight scale (lift-off).
    const int k = inner_events();
    if (inner_) inner_->events(model, g.head(k));
    g[k] = 1;
    for (std::size_t i = 0; i < held_.size(); ++i)
      if (held_[i] < 0 && free_node(model, static_cast<int>(i))) {
        const double gap = nearest(static_cast<int>(i), model.x().col(static_cast<Eigen::Index>(i))).second;
        if (std::isfinite(gap)) g[k] = std::min(g[k], gap / h_ + offset_[i]);
      }
    g[k + 1] = 1;
    const double a = acceleration_scale(model);
    for (std::size_t c = 0; c < model.contacts().size(); ++c)
      g[k + 1] = std::min(g[k + 1], held_force(model, c, a));
    if (friction_) friction_events(model, g.tail(g.size() - k));
    if (arc_) wrap_events(model, g.segment(side_face_event() - 2, 2));
    if (side_faces_) {
      // The smallest distance of a free node from the body of a table that ends at an edge (per link length).
      g[side_face_event()] = 1;
      for (int i = 0; i < static_cast<int>(held_.size()); ++i)
        g[side_face_event()] = std::min(g[side_face_event()], side_face_gap(model, i).second / h_);
    }
  }
  std::vector<int> event_directions() const override {
    std::vector<int> directions = inner_ ? inner_->event_directions() : std::vector<int>{};
    directions.insert(directions.end(), {-1, -1});
    if (friction_) directions.insert(directions.end(), {-1, -1});
    if (arc_) directions.insert(directions.end(), {-1, -1});
    if (side_faces_) directions.push_back(-1);
    return directions;
  }
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>& found) override {
    // The fronts' events first (a crossing moves nodes between arcs, heaps and the sides of an edge),
    // then the held set brought up to the layout they leave, then the landings and lift-offs.
    const int k = inner_events(), kl = inner_ledgers();
    // The side face: at its root, and at any event where a node is already inside (its root function would
    // restart below zero, where ARKODE finds no root: a projection or an impact that carried it in).
    if (side_faces_ && ((found.size() > static_cast<std::size_t>(side_face_event()) && found[side_face_event()] != 0) ||
                        inside_a_table(model)))
      through_side_face(model, t);
    EventAction action = this->handle_inner_events(model, t, ledger, found);
    if (action.kind == EventAction::Kind::kStop) return action;
    bool changed = action.kind == EventAction::Kind::kTransfer;
    Eigen::Ref<Eigen::VectorXd> own = ledger.tail(ledger.size() - kl);
    if (changed) follow_layout(model, t, own);
    const std::size_t land_at = static_cast<std::size_t>(k), lift_at = land_at + 1;
    if (found.size() > land_at && found[land_at] != 0) changed = land(model, t, own) || changed;
    if (found.size() > lift_at && found[lift_at] != 0) changed = settle(model, t, true) || changed;
    const std::size_t stop_at = lift_at + 1, slip_at = lift_at + 2;
    if (friction_ && found.size() > stop_at && found[stop_at] != 0) changed = stop(model, t, own) || changed;
    if (friction_ && found.size() > slip_at && found[slip_at] != 0) changed = slip(model, t) || changed;
    const std::size_t wrap_at = lift_at + (friction_ ? 3 : 1);
    // Links along the arc: at every event, every end that has reached its landing and every arc that has
    // run out (a root of the same function within the step of another one is not located again: its
    // function restarts below zero); the one located caught within kCatchWindow.
    if (arc_) {
      changed = wrap_land(model, t, own, found.size() > wrap_at && found[wrap_at] != 0) || changed;
      changed = wrap_leave(model, t, found.size() > wrap_at + 1 && found[wrap_at + 1] != 0) || changed;
    }
    // A free node whose landing function is below zero has passed a surface unseen (its crossing, inside the
    // step of another event, was not on ARKODE's interpolant, or came after the recomputed event): at the
    // restart its function would start below zero, where ARKODE finds no root, and the node would fall
    // through. It lands here, at this event (docs/string_solver.md, "Events at loose tolerances").
    changed = hold(model, t, own, passed_through(model)) || changed;
    if (side_faces_ && inside_a_table(model)) through_side_face(model, t);
    if (!changed) return {};
    return {EventAction::Kind::kTransfer, ""};  // the velocities or the held set changed: the integrator restarts
  }
  bool release_contacts(StringModel<dim>& model, double t) override { return settle(model, t, false); }
  bool land_passed(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger) override {
    const std::vector<std::pair<int, int>> through = passed_through(model);
    if (through.empty()) return false;
    Eigen::Ref<Eigen::VectorXd> own = ledger.tail(ledger.size() - inner_ledgers());
    return hold(model, t, own, through);
  }
  /// The inner module's events (a front's) and the listed lift-offs, merged in time order (the inner
  /// module's first at equal times).
  std::vector<RunEvent> run_events() const override {
    std::vector<RunEvent> inner = inner_ ? inner_->run_events() : std::vector<RunEvent>{};
    std::vector<RunEvent> all;
    all.reserve(inner.size() + events_.size());
    std::merge(inner.begin(), inner.end(), events_.begin(), events_.end(), std::back_inserter(all),
               [](const RunEvent& a, const RunEvent& b) { return a.t < b.t; });
    return all;
  }
  std::vector<LiftOffTotal> lift_off_totals() const override {
    std::vector<LiftOffTotal> totals;
    for (std::size_t k = 0; k < obstacles_.size(); ++k)
      totals.push_back({obstacles_[k].name, k < lift_off_totals_.size() ? lift_off_totals_[k] : 0});
    return totals;
  }
  /// The inner module's drawing (an edge's), then each obstacle sized to the string's initial nodes
  /// plus a tenth of its length.
  ObstacleDrawing obstacles() const override {
    ObstacleDrawing drawing = inner_ ? inner_->obstacles() : ObstacleDrawing{};
    for (std::size_t k = 0; k < obstacles_.size(); ++k)
      obstacles_[k].draw(static_cast<int>(k), drawn_nodes_, 0.1 * length_, drawing);
    return drawing;
  }

 private:
  std::vector<Obstacle<dim>> obstacles_;
  std::vector<int> held_;        // per node: the obstacle it is held on, or −1
  std::vector<double> offset_;   // per node: its landing root function's offset (of h)
  std::vector<char> carried_;    // per node: some obstacle may hold it, at the last layout (follow_layout)
  std::vector<double> let_go_at_;  // per node: when settle() last let it go (s; −∞: never)
  double h_ = 1;
  long impacts_ = 0, lift_offs_ = 0;
  std::vector<long> lift_off_totals_;  // per obstacle: its lift-offs so far (lift_offs_ is their sum)
  std::vector<RunEvent> events_;       // the lift-offs listed (at most kListedLiftOffs per obstacle), in time order
  // Friction: whether an obstacle has μ > 0; per node, whether it sticks, and the direction it slides
  // in (its coordinates in the obstacle's tangents(); zero: not yet classified, or no friction).
  static constexpr int kFriction = 2 + dim;  // W_friction's place in the module's own ledger (after the inner's)
  /// W_impacts_supports' place in the module's own ledger: the work of the driven supports' impulses in the
  /// impacts (zero at fixed ends), kept out of W_impacts, which is then what the impacts dissipated (≤ 0).
  int supports_index() const { return kFriction + (friction_ ? 1 : 0); }
  bool friction_ = false;
  bool side_faces_ = false;  ///< some obstacle is a table that ends at an edge: the side-face event
  std::vector<char> stuck_;
  Eigen::Matrix<double, dim - 1, Eigen::Dynamic> dir_;
  double length_ = 1;  // the string's length (m)
  long sticks_ = 0, slips_ = 0;

  const Obstacle<dim>& obstacle_of(std::size_t i) const { return obstacles_[static_cast<std::size_t>(held_[i])]; }
  bool sliding(std::size_t i) const {
    return held_[i] >= 0 && obstacle_of(i).mu > 0 && !stuck_[i] && dir_.col(static_cast<Eigen::Index>(i)).squaredNorm() > 0;
  }
  static Vec<dim> tangential(const Obstacle<dim>& o, const Vec<dim>& x, const Vec<dim>& v) {
    const Vec<dim> n = o.outward(x, true);
    return v - n.dot(v) * n;
  }
  /// The direction node i slides in: the stored one carried with the surface (in 2D, always: the
  /// force keeps its sign through the located stop, so the step that finds it is smooth); in 3D the
  /// direction of its tangential velocity while that has a positive part along the stored one and is
  /// above the stop window (below it, the round-off of a velocity starting from rest would turn it).
  Vec<dim> slide_direction(const StringModel<dim>& model, const Obstacle<dim>& o, std::size_t i, const Vec<dim>& x,
                           const Vec<dim>& v) const {
    const Vec<dim> d = o.tangents(x) * dir_.col(static_cast<Eigen::Index>(i));
    if constexpr (dim == 3) {
      const Vec<dim> vt = tangential(o, x, v);
      if (vt.dot(d) > 0 && vt.norm() > kStopWindow * speed_scale(model)) return vt.normalized();
    }
    return d;
  }
  double speed_scale(const StringModel<dim>& model) const { return std::sqrt(acceleration_scale(model) * length_); }
  /// Root functions 2 and 3: the smallest tangential speed of a sliding node along its direction of
  /// sliding, per the speed scale (a stop), and the smallest (μ N − |F_t|)/(m a) of a stuck node (a slip).
  void friction_events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const {
    g[2] = 1;
    const double V = speed_scale(model);
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!sliding(i)) continue;
      const Obstacle<dim>& o = obstacle_of(i);
      const Vec<dim> x = model.x().col(static_cast<Eigen::Index>(i)), v = model.v().col(static_cast<Eigen::Index>(i));
      g[2] = std::min(g[2], tangential(o, x, v).dot(o.tangents(x) * dir_.col(static_cast<Eigen::Index>(i))) / V);
    }
    g[3] = 1;
    const double a = acceleration_scale(model);
    for (std::size_t k = 0; k < model.contacts().size(); ++k) {
      const NodeContact<dim>& c = model.contacts()[k];
      if (c.stuck)
        g[3] = std::min(g[3], (c.mu * model.contact_force(k) - model.contact_friction(k).norm()) / (model.masses()[c.node] * a));
    }
  }
  /// Node i sticks: its tangential velocity (within the stop window, or the integration error of a
  /// located root) is taken, the kinetic energy and momentum that takes booked in W_friction and the impulse.
  void stick_node(StringModel<dim>& model, std::size_t i, Eigen::VectorXd* ledger) {
    const Eigen::Index col = static_cast<Eigen::Index>(i);
    const Vec<dim> vt = tangential(obstacle_of(i), model.x().col(col), model.v().col(col));
    const double m = model.masses()[col];
    if (ledger) {
      (*ledger)[kFriction] -= 0.5 * m * (model.v().col(col).squaredNorm() - (model.v().col(col) - vt).squaredNorm());
      ledger->template segment<dim>(2) -= m * vt;
    }
    model.v().col(col) -= vt;
    stuck_[i] = 1;
    dir_.col(col).setZero();
    ++sticks_;
  }
  /// The held nodes on rough obstacles not yet classified (just landed, or at the start) slide along
  /// their tangential velocity, or stick if it is within the stop window; then the stuck nodes that
  /// the cone cannot hold slip (unstick). Returns whether anything changed.
  bool classify(StringModel<dim>& model, double t, Eigen::VectorXd* ledger) {
    bool changed = false;
    const double V = speed_scale(model);
    for (std::size_t i = 0; i < held_.size(); ++i) {
      const Eigen::Index col = static_cast<Eigen::Index>(i);
      if (held_[i] < 0 || !(obstacle_of(i).mu > 0) || stuck_[i] || dir_.col(col).squaredNorm() > 0) continue;
      const Obstacle<dim>& o = obstacle_of(i);
      const Vec<dim> x = model.x().col(col), vt = tangential(o, x, model.v().col(col));
      if (vt.norm() > kStopWindow * V)
        dir_.col(col) = o.tangents(x).transpose() * vt.normalized();
      else
        stick_node(model, i, ledger);
      changed = true;
    }
    refresh(model);
    return unstick(model, t, false) || changed;
  }
  /// A located stop: the sliding nodes whose speed along their direction has reached zero stick (in 3D
  /// a node whose velocity has turned across its stored direction without stopping takes its new
  /// direction); then classify() lets go of the stuck nodes the cone cannot hold.
  bool stop(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger) {
    const double V = speed_scale(model);
    Eigen::VectorXd book = ledger;
    int caught = 0, closest = -1;
    double closest_g = INFINITY;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!sliding(i)) continue;
      const Eigen::Index col = static_cast<Eigen::Index>(i);
      const Obstacle<dim>& o = obstacle_of(i);
      const Vec<dim> x = model.x().col(col), vt = tangential(o, x, model.v().col(col));
      const Vec<dim> d = o.tangents(x) * dir_.col(col);
      const double g = vt.dot(d) / V;
      if (g <= kStopWindow) {
        if ((vt - vt.dot(d) * d).norm() <= kStopWindow * V)
          stick_node(model, i, &book);
        else
          dir_.col(col) = o.tangents(x).transpose() * vt.normalized();
        ++caught;
      } else if (g < closest_g) {
        closest_g = g;
        closest = static_cast<int>(i);
      }
    }
    if (caught == 0 && closest >= 0 && closest_g < kCatchWindow) {
      stick_node(model, static_cast<std::size_t>(closest), &book);
      ++caught;
    }
    if (caught == 0) return false;
    classify(model, t, &book);
    ledger = book;
    settle(model, t, false);
    return true;
  }
  /// A located slip: in 2D the locked tensions are chosen again inside the cones; if a node still
  /// leaves its cone it slips, and if none does the one whose |F_t| has reached μ N goes, then every
  /// other that the cone cannot hold.
  bool slip(StringModel<dim>& model, double t) {
    // In 2D the locked tensions may first move inside the cones (the cones hold with other tensions).
    Points<dim> x = model.x(), v = model.v();
    model.evaluate(t, x, v);
    const bool rebalanced = balance_locked(model);
    if (!unstick(model, t, false) && !rebalanced && !unstick(model, t, true)) return false;
    settle(model, t, false);
    return true;
  }
  /// The friction cone of stuck node i (contacts()[k]) in the tensions x of the link ending at it
  /// (direction ep) and y of the link starting at it (en): its holding force H = −(F + y en − x ep)
  /// has |t·H| ≤ μ n·H, two half-planes (F the applied force).
  static std::vector<HalfPlane> cone(const StringModel<dim>& model, std::size_t k, const Vec<dim>& ep, const Vec<dim>& en) {
    const NodeContact<dim>& c = model.contacts()[k];
    const Vec<dim> F = model.contact_applied(k), t = Vec<dim>(-c.normal[1], c.normal[0]);
    std::vector<HalfPlane> h;
    for (const double sign : {1.0, -1.0}) {
      const Vec<dim> q = sign * t - c.mu * c.normal;  // q·H ≤ 0
      h.push_back({q.dot(ep), -q.dot(en), q.dot(F)});
    }
    return h;
  }
  /// 2D: the tensions of the locked links (between stuck nodes: statically indeterminate) chosen inside
  /// every stuck node's friction cone where that is possible, segment by segment: a forward pass
  /// carries the interval of tensions each link can have with the cones of the nodes before it held
  /// (the capstan inequality, node by node), a backward pass picks the middle of what the node after
  /// it allows. A segment with no admissible tensions keeps its own (unstick() then lets a node slip).
  /// Returns whether it changed a tension. 3D keeps the tensions the links had when they locked.
  bool balance_locked(StringModel<dim>& model) const {
    if constexpr (dim != 2) {
      return false;
    } else {
      const Chain<dim>& chain = model.chain();
      const int L = chain.num_links();
      if (chain.closed()) return false;
      std::vector<int> contact_of(static_cast<std::size_t>(chain.num_nodes()), -1);
      for (std::size_t k = 0; k < model.contacts().size(); ++k) contact_of[static_cast<std::size_t>(model.contacts()[k].node)] = static_cast<int>(k);
      // Link j's direction at its start node (at_end false) or its end node: a link bent over an edge
      // pulls along e⁻ and e⁺ there, not along its chord.
      auto e = [&](int j, bool at_end) -> Vec<dim> {
        if (j < 0 || j >= L) return Vec<dim>::Zero();
        if (model.link_bent(j)) return model.bent_direction(j, at_end);
        return (model.x().col(chain.link_end(j)) - model.x().col(chain.link_start(j))).normalized();
      };
      auto boundary = [&](int j) { return j < 0 || j >= L ? 0.0 : model.link_tension(j); };
      auto node_cone = [&](int i) {
        const int k = contact_of[static_cast<std::size_t>(i)];
        return k >= 0 && model.contacts()[static_cast<std::size_t>(k)].stuck ? cone(model, static_cast<std::size_t>(k), e(i - 1, true), e(i, false))
                                                                             : std::vector<HalfPlane>{};
      };
      const double scale = std::max(model.physical_scales().tension, 1e-300);
      bool changed = false;
      for (int p = 0; p < L;) {
        if (!model.link_locked(p)) {
          ++p;
          continue;
        }
        int q = p;
        while (q < L && model.link_locked(q)) ++q;  // links p..q−1 locked, nodes p..q
        double top = std::max(std::abs(boundary(p - 1)), std::abs(boundary(q)));
        for (int j = p; j < q; ++j) top = std::max(top, std::abs(model.locked_tension(j)));
        const Interval Y{0.0, 4 * std::max(top, scale)};
        const double tol = 1e-12 * Y.hi;
        std::vector<Interval> S;
        Interval X{boundary(p - 1), boundary(p - 1)};
        bool feasible = true;
        for (int i = p; i < q && feasible; ++i) {
          X = project_y(X, Y, node_cone(i), tol);
          S.push_back(X);
          feasible = !X.empty();
        }
        if (feasible) {
          double y = boundary(q);
          for (int i = q; i > p && feasible; --i) {  // node i: link i−1 from the interval S[i−1−p]
            const Interval J = range_x(S[static_cast<std::size_t>(i - 1 - p)], y, node_cone(i), tol);
            feasible = !J.empty();
            if (!feasible) break;
            y = std::clamp(J.mid(), J.lo, J.hi);
            if (model.locked_tension(i - 1) != y) changed = true;
            model.set_locked_tension(i - 1, y);
          }
        }
        p = q;
      }
      return changed;
    }
  }
  /// The stuck nodes whose holding force leaves the cone (|F_t| > μ N beyond round-off) slip, the
  /// worst first, each with its block: the run of consecutive nodes held on rough obstacles around it
  /// (an inextensible chain held on a surface moves only as a block: a node between two stuck ones
  /// cannot move). At a located slip (`located`) the one at the cone's edge to the root's accuracy
  /// goes first. Returns whether one slipped.
  bool unstick(StringModel<dim>& model, double t, bool located) {
    bool released = false;
    for (std::size_t pass = 0; pass <= held_.size(); ++pass) {
      Points<dim> x = model.x(), v = model.v();
      model.evaluate(t, x, v);
      if (balance_locked(model)) {
        x = model.x();
        v = model.v();
        model.evaluate(t, x, v);
      }
      const double a = acceleration_scale(model);
      int worst = -1;
      double worst_excess = 0;
      Vec<dim> worst_force = Vec<dim>::Zero();
      const double floor = located && !released ? -kCatchWindow : kPull;
      for (std::size_t k = 0; k < model.contacts().size(); ++k) {
        const NodeContact<dim>& c = model.contacts()[k];
        const Vec<dim> ft = model.contact_friction(k);
        if (!c.stuck || !(model.contact_force(k) > 0) || !(ft.norm() > 0)) continue;
        const double excess = (ft.norm() - c.mu * model.contact_force(k)) / (model.masses()[c.node] * a);
        if (excess > floor && (worst < 0 || excess > worst_excess)) {
          worst_excess = excess;
          worst = c.node;
          worst_force = ft;
        }
      }
      if (worst < 0) break;
      slip_block(model, t, worst, worst_force);
      released = true;
    }
    return released;
  }
  /// The direction of the chain at node i, along increasing node index, in the surface's tangent plane;
  /// `fallback` (projected) where the chain is normal to the surface there, the surface's first
  /// tangent if that is normal too.
  Vec<dim> chain_direction(const StringModel<dim>& model, int i, const Vec<dim>& fallback) const {
    const int n = static_cast<int>(held_.size());
    const Obstacle<dim>& o = obstacle_of(static_cast<std::size_t>(i));
    const Vec<dim> normal = o.outward(model.x().col(i), true);
    for (const Vec<dim>& c : {Vec<dim>(model.x().col(std::min(i + 1, n - 1)) - model.x().col(std::max(i - 1, 0))), fallback}) {
      const Vec<dim> t = c - normal.dot(c) * normal;
      if (t.norm() > 1e-12 * c.norm()) return t.normalized();
    }
    return o.tangents(model.x().col(i)).col(0);
  }
  /// 3D: the onset of slip as Coulomb's law has it in the tangent plane (docs/model.md §10, *The onset
  /// of slip in 3D*). Node i of the run `first`..`last` carries G_i = F_i + T_i e_i − T_{i−1} e_{i−1} (F_i
  /// its applied force): a stuck one keeps a_i = 0 while |G_t,i| ≤ μ N_i, else it slips with
  /// a_i = (|G_t,i| − μ N_i)⁺ d_i / m_i, d_i = G_t,i/|G_t,i|; a sliding one (direction t̂_i) has
  /// a_i = (G_t,i + μ (n·G_i) t̂_i)/m_i. The link conditions e_j·(a_{j+1} − a_j) = −|v_{j+1} − v_j|²/ℓ_j are
  /// the gradient of the convex Φ(T) = Σ_i φ_i(G_i) − Σ_j c_j T_j (φ_i = ½ (|G_t| − μ N)⁺²/m_i stuck,
  /// ½ |G_t + μ (n·G) t̂|²/m_i sliding): its minimum over T ≥ 0 (a string cannot push), by a damped,
  /// projected Newton method on the tridiagonal Hessian, gives the nodes that slip and their directions.
  /// The links leaving the run keep their tensions. False (slip_block then tries the chain's two
  /// directions, as in 2D) if a link is bent, the chain closed or Newton's method does not converge;
  /// true: the stuck nodes with (|G_t| − μ N)⁺ > 0 slide along d_i, the others stay stuck with their
  /// links locked at the minimiser's tensions.
  bool slip_onset(StringModel<dim>& model, const std::vector<int>& block, int first, int last) {
    const Chain<dim>& chain = model.chain();
    if (chain.closed() || block.empty()) return false;
    const int L = chain.num_links(), n = last - first;  // unknowns: links first..last−1
    for (int j = std::max(first - 1, 0); j <= std::min(last, L - 1); ++j)
      if (model.link_bent(j)) return false;
    std::vector<int> contact_of(held_.size(), -1);
    for (std::size_t k = 0; k < model.contacts().size(); ++k) contact_of[static_cast<std::size_t>(model.contacts()[k].node)] = static_cast<int>(k);
    const int count = last - first + 1;
    std::vector<Vec<dim>> F(static_cast<std::size_t>(count)), normal(static_cast<std::size_t>(count)), slide(static_cast<std::size_t>(count));
    std::vector<double> mass(static_cast<std::size_t>(count)), mu(static_cast<std::size_t>(count));
    std::vector<char> moving(static_cast<std::size_t>(count), 0);
    for (int i = first; i <= last; ++i) {
      const int k = contact_of[static_cast<std::size_t>(i)];
      if (k < 0) return false;
      const std::size_t b = static_cast<std::size_t>(i - first);
      F[b] = model.contact_applied(static_cast<std::size_t>(k));
      normal[b] = model.contacts()[static_cast<std::size_t>(k)].normal;
      mass[b] = model.masses()[i];
      mu[b] = model.contacts()[static_cast<std::size_t>(k)].mu;
      moving[b] = stuck_[static_cast<std::size_t>(i)] ? 0 : 1;
      slide[b] = model.contacts()[static_cast<std::size_t>(k)].slide;
    }
    auto e = [&](int j) -> Vec<dim> { return (model.x().col(chain.link_end(j)) - model.x().col(chain.link_start(j))).normalized(); };
    std::vector<Vec<dim>> dir(static_cast<std::size_t>(std::max(n, 0)));
    for (int j = 0; j < n; ++j) dir[static_cast<std::size_t>(j)] = e(first + j);
    const double T_before = first > 0 ? model.link_tension(first - 1) : 0.0, T_after = last < L ? model.link_tension(last) : 0.0;
    const Vec<dim> e_before = first > 0 ? e(first - 1) : Vec<dim>::Zero(), e_after = last < L ? e(last) : Vec<dim>::Zero();
    Eigen::VectorXd T(n), c(n);  // c_j = |v_{j+1} − v_j|²/ℓ_j: e_j·(a_{j+1} − a_j) = −c_j
    for (int j = 0; j < n; ++j) {
      T[j] = model.link_tension(first + j);
      const Vec<dim> dx = model.x().col(first + j + 1) - model.x().col(first + j), dv = model.v().col(first + j + 1) - model.v().col(first + j);
      c[j] = dv.squaredNorm() / dx.norm();
    }
    // Node b's load G_b(T), its excess s_b = (|G_t| − μ N)⁺ and its gradient q_b = ∂(|G_t| − μN)/∂G.
    auto load = [&](const Eigen::VectorXd& tension, int b) -> Vec<dim> {
      Vec<dim> G = F[static_cast<std::size_t>(b)];
      if (b < n) G += tension[b] * dir[static_cast<std::size_t>(b)];
      else G += T_after * e_after;
      if (b > 0) G -= tension[b - 1] * dir[static_cast<std::size_t>(b - 1)];
      else G -= T_before * e_before;
      return G;
    };
    auto excess = [&](const Vec<dim>& G, int b, Vec<dim>* q) {
      const Vec<dim>& nb = normal[static_cast<std::size_t>(b)];
      const Vec<dim> Gt = G - nb.dot(G) * nb;
      const double s = Gt.norm() - mu[static_cast<std::size_t>(b)] * (-nb.dot(G));
      if (q) *q = (Gt.norm() > 0 ? Vec<dim>(Gt.normalized()) : Vec<dim>::Zero()) + mu[static_cast<std::size_t>(b)] * nb;
      return std::max(s, 0.0);
    };
    // A node of the run already sliding along d: its acceleration w/m, w = G_t + μ (n·G) d = J G (linear).
    auto sliding_force = [&](const Vec<dim>& G, int b) -> Vec<dim> {
      const Vec<dim>& nb = normal[static_cast<std::size_t>(b)];
      return G - nb.dot(G) * nb + mu[static_cast<std::size_t>(b)] * nb.dot(G) * slide[static_cast<std::size_t>(b)];
    };
    auto phi = [&](const Eigen::VectorXd& tension) {
      double sum = -c.dot(tension);
      for (int b = 0; b < count; ++b) {
        const Vec<dim> G = load(tension, b);
        sum += 0.5 * (moving[static_cast<std::size_t>(b)] ? sliding_force(G, b).squaredNorm() : std::pow(excess(G, b, nullptr), 2)) /
               mass[static_cast<std::size_t>(b)];
      }
      return sum;
    };
    // The link conditions r_j = −e_j·(a_{j+1} − a_j) − c_j = ∂Φ/∂T_j and, with `hessian`, the tridiagonal
    // Hessian (diagonal, off-diagonal).
    Eigen::VectorXd diag(n), off(std::max(n - 1, 0));
    double load_scale = acceleration_scale(model);  // the largest |G_b|/m_b (m/s²): the link conditions' round-off
    auto residuals = [&](const Eigen::VectorXd& tension, bool hessian) {
      std::vector<Vec<dim>> grad(static_cast<std::size_t>(count));
      std::vector<Eigen::Matrix<double, dim, dim>> hess(static_cast<std::size_t>(count));
      for (int b = 0; b < count; ++b) {
        const Vec<dim> G = load(tension, b);
        Vec<dim> q;
        const double s = excess(G, b, &q), m = mass[static_cast<std::size_t>(b)];
        if (hessian) load_scale = std::max(load_scale, G.norm() / m);
        const Vec<dim>& nb = normal[static_cast<std::size_t>(b)];
        const Vec<dim> Gt = G - nb.dot(G) * nb;
        grad[static_cast<std::size_t>(b)] = s * q / m;
        hess[static_cast<std::size_t>(b)].setZero();
        if (moving[static_cast<std::size_t>(b)]) {
          const Eigen::Matrix<double, dim, dim> J = Eigen::Matrix<double, dim, dim>::Identity() - nb * nb.transpose() +
                                                    mu[static_cast<std::size_t>(b)] * slide[static_cast<std::size_t>(b)] * nb.transpose();
          grad[static_cast<std::size_t>(b)] = J.transpose() * sliding_force(G, b) / m;
          hess[static_cast<std::size_t>(b)] = J.transpose() * J / m;
        } else if (s > 0) {
          const Vec<dim> g = Gt.normalized();
          const Eigen::Matrix<double, dim, dim> P = Eigen::Matrix<double, dim, dim>::Identity() - nb * nb.transpose();
          hess[static_cast<std::size_t>(b)] = (q * q.transpose() + s / Gt.norm() * (P - g * g.transpose())) / m;
        }
      }
      Eigen::VectorXd r(n);
      for (int j = 0; j < n; ++j) {
        const Vec<dim>& ej = dir[static_cast<std::size_t>(j)];
        r[j] = ej.dot(grad[static_cast<std::size_t>(j)] - grad[static_cast<std::size_t>(j + 1)]) - c[j];
        if (!hessian) continue;
        diag[j] = ej.dot((hess[static_cast<std::size_t>(j)] + hess[static_cast<std::size_t>(j + 1)]) * ej);
        if (j + 1 < n) off[j] = -ej.dot(hess[static_cast<std::size_t>(j + 1)] * dir[static_cast<std::size_t>(j + 1)]);
      }
      return r;
    };
    const double a = acceleration_scale(model);
    constexpr double kOnsetTolerance = 1e-10, kStallTolerance = 1e-8;  // of the link conditions, per the largest |G|/m
    T = T.cwiseMax(0.0);
    bool converged = n == 0;
    double damping = 1e-12;  // Levenberg–Marquardt's shift of the Hessian, per its largest entry
    BandedLU hessian;
    if (n > 0) {
      std::vector<int> order(static_cast<std::size_t>(n));
      std::iota(order.begin(), order.end(), 0);
      hessian.reset(std::move(order), 1, 1);
    }
    for (int iteration = 0; iteration < 200 && !converged; ++iteration) {
      // A string cannot push: T ≥ 0, and a link at T = 0 whose condition asks for less (r_j > 0, its ends
      // approaching) is held there (it would go slack, which the model's own solve then reports).
      auto worst = [&](const Eigen::VectorXd& tension, const Eigen::VectorXd& rj) {
        double w = 0;
        for (int j = 0; j < n; ++j) w = std::max(w, tension[j] > 0 ? std::abs(rj[j]) : std::max(-rj[j], 0.0));
        return w;
      };
      Eigen::VectorXd r = residuals(T, true);
      const double residual = worst(T, r);
      std::vector<char> held(static_cast<std::size_t>(n), 0);
      for (int j = 0; j < n; ++j) {
        if (!(T[j] <= 0 && r[j] > 0)) continue;
        held[static_cast<std::size_t>(j)] = 1;
        r[j] = 0;
        diag[j] = 1;
        if (j > 0) off[j - 1] = 0;
        if (j + 1 < n) off[j] = 0;
      }
      if (residual <= kOnsetTolerance * load_scale) {
        converged = true;
        break;
      }
      // Newton's step on the tridiagonal Hessian (regularised where a stuck node leaves it singular), by
      // the band LU of the Newton systems (banded_lu.hpp), then halved until Φ decreases (Armijo) or, where
      // Φ's round-off hides its decrease near the minimum, the largest link condition halves.
      const double shift = damping * std::max(diag.cwiseAbs().maxCoeff(), 1e-300);
      hessian.zero();
      for (int j = 0; j < n; ++j) {
        hessian.add(j, j, diag[j] + shift);
        if (j + 1 < n) hessian.add(j, j + 1, off[j]), hessian.add(j + 1, j, off[j]);
      }
      if (!hessian.factor()) break;  // not converged: slip_block's two directions instead
      Eigen::VectorXd dT = -r;
      hessian.solve(dT.data());
      const double phi0 = phi(T), slope = r.dot(dT);
      double step = 1;
      for (; step > 1e-12; step *= 0.5) {
        const Eigen::VectorXd trial = (T + step * dT).cwiseMax(0.0);
        if (phi(trial) <= phi0 + 1e-4 * step * slope || worst(trial, residuals(trial, false)) <= 0.5 * residual) break;
      }
      // Stalled (a node at its cone's edge, where Φ has a kink, and Φ's round-off): accepted if the link
      // conditions hold to kStallTolerance.
      if (!(step > 1e-12) || (!(step > 1e-3) && residual <= kStallTolerance * load_scale)) {
        converged = residual <= kStallTolerance * load_scale;
        break;
      }
      T = (T + step * dT).cwiseMax(0.0);
      damping = step == 1 ? std::max(damping * 0.1, 1e-12) : std::min(damping * 10, 1.0);
    }
    if (!converged) return false;
    for (int b = 0; b < count; ++b) {
      const int i = first + b;
      const Vec<dim> G = load(T, b);
      const Vec<dim>& nb = normal[static_cast<std::size_t>(b)];
      if (!moving[static_cast<std::size_t>(b)] && excess(G, b, nullptr) > kPull * mass[static_cast<std::size_t>(b)] * a) {
        stuck_[static_cast<std::size_t>(i)] = 0;
        dir_.col(i) = obstacle_of(static_cast<std::size_t>(i)).tangents(model.x().col(i)).transpose() * (G - nb.dot(G) * nb).normalized();
      }
    }
    refresh(model);
    for (int j = 0; j < n; ++j)
      if (model.link_locked(first + j)) model.set_locked_tension(first + j, T[j]);
    return true;
  }
  /// Node `node` cannot be held (its cone is left; F_t the force that held it): in 3D its run slips as
  /// slip_onset() finds; in 2D (or where that does not apply) its block, the stuck nodes of its run of
  /// held rough nodes, slides along the chain, in the direction the force pushed the node first, and if
  /// the block's accelerations along it come out negative (inconsistent) the other way. If neither is
  /// consistent (Coulomb's law has no sliding solution there) the run stops.
  void slip_block(StringModel<dim>& model, double t, int node, const Vec<dim>& ft) {
    const int n = static_cast<int>(held_.size());
    auto rough = [&](int i) { return i >= 0 && i < n && held_[static_cast<std::size_t>(i)] >= 0 && obstacle_of(static_cast<std::size_t>(i)).mu > 0; };
    int first = node, last = node;
    while (rough(first - 1)) --first;
    while (rough(last + 1)) ++last;
    std::vector<int> block;
    for (int i = first; i <= last; ++i)
      if (stuck_[static_cast<std::size_t>(i)]) block.push_back(i);
    const double preferred = -ft.dot(chain_direction(model, node, -ft)) >= 0 ? 1.0 : -1.0;
    if constexpr (dim == 3) {
      if (slip_onset(model, block, first, last)) {
        for (int i : block) slips_ += stuck_[static_cast<std::size_t>(i)] ? 0 : 1;
        return;
      }
    }
    const double a = acceleration_scale(model);
    for (const double sign : {preferred, -preferred}) {
      for (int i : block) {
        stuck_[static_cast<std::size_t>(i)] = 0;
        dir_.col(i) = obstacle_of(static_cast<std::size_t>(i)).tangents(model.x().col(i)).transpose() *
                      (sign * chain_direction(model, i, -ft));
      }
      refresh(model);
      Points<dim> x = model.x(), v = model.v();
      bool consistent = true;
      try {
        model.evaluate(t, x, v);
        for (int i : block) {
          const Vec<dim> d = obstacle_of(static_cast<std::size_t>(i)).tangents(model.x().col(i)) * dir_.col(i);
          consistent = consistent && model.accelerations().col(i).dot(d) >= -kPull * a;
        }
      } catch (const NumericalError&) {
        consistent = false;
      }
      if (consistent) {
        slips_ += static_cast<long>(block.size());
        return;
      }
    }
    for (int i : block) {
      stuck_[static_cast<std::size_t>(i)] = 1;
      dir_.col(i).setZero();
    }
    refresh(model);
    throw NumericalError(fmt::format("stuck on {} at t = {:.9g} s, node {}: the friction cone cannot hold it (|F_t| = "
                                     "{:.6g} N beyond mu N), and its block of {} nodes cannot slide either way "
                                     "(Coulomb's law has no consistent motion here)",
                                     obstacle_of(static_cast<std::size_t>(node)).name, t, node, ft.norm(), block.size()),
                         t);
  }
  Points<dim> drawn_nodes_;  // the string's initial nodes, which the obstacles' drawing spans

  // Links along the arc (Obstacle::arc_links): whether an obstacle has them, the sense each circle is
  // wrapped in (+1 counterclockwise along increasing node index), per link the circle a link with both
  // ends free runs round (−1: none; a link with a held end runs round its end's), and per node whether
  // its landing along a link is off (a node let go there, until it is held again).
  bool arc_ = false;
  std::vector<double> sense_;
  std::vector<int> wrap_;
  std::vector<char> no_wrap_land_;
  std::vector<char> entering_;  // per link: made by a landing at its end (its arc starts at about −kWrapLand h)
  static bool on_arc(const Obstacle<dim>& o) {
    return dim == 2 && o.arc_links && o.kind == Obstacle<dim>::Kind::kCylinder && !(o.mu > 0);
  }
  /// The circle node i is held on with links along the arc, or −1.
  int held_on_arc(const StringModel<dim>& model, int i) const {
    const int k = held_[static_cast<std::size_t>(i)];
    return k >= 0 && on_arc(obstacles_[static_cast<std::size_t>(k)]) && holds(model, i) ? k : -1;
  }
  /// The circle link j runs round (−1: none) and whether its ends are held on it.
  std::tuple<int, bool, bool> link_wrap(const StringModel<dim>& model, int j) const {
    const Chain<dim>& chain = model.chain();
    const int ka = held_on_arc(model, chain.link_start(j)), kb = held_on_arc(model, chain.link_end(j));
    const int k = ka >= 0 ? ka : kb >= 0 ? kb : wrap_[static_cast<std::size_t>(j)];
    return {k, k >= 0 && ka == k, k >= 0 && kb == k};
  }
  /// The links along the arcs set on the model from the held set, then its refresh.
  void refresh(StringModel<dim>& model) {
    if (arc_) {
      model.clear_circle_bends();
      for (int j = 0; j < model.chain().num_links(); ++j) {
        const auto [k, a_on, b_on] = link_wrap(model, j);
        if (k < 0) continue;
        const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(k)];
        model.bend_link_on_circle(j, o.point, o.radius, sense_[static_cast<std::size_t>(k)], a_on, b_on);
      }
    }
    model.refresh();
  }
  /// Held contact k's force per its mass and the acceleration scale a (the lift-off root function). On a
  /// circle with links along the arc the links press on it too (T (e⁻ − e⁺) on each, the string's
  /// pressure T/R): its force per length is the node's N over its mass's length plus its share of its
  /// links' reactions over their arcs' length (half of a link between two held nodes, the whole arc of
  /// a link from a free end): (T − λ v²)/R − λ g·n in the limit.
  double held_force(const StringModel<dim>& model, std::size_t c, double a) const {
    const int i = model.contacts()[c].node;
    if (!arc_ || held_on_arc(model, i) < 0) return model.contact_force(c) / (model.masses()[i] * a);
    const Vec<dim> n = model.contacts()[c].normal;
    const Chain<dim>& chain = model.chain();
    const int L = chain.num_links();
    double force = 0, length = 0;
    for (const int j : {i - 1, i}) {
      const int jj = chain.closed() ? (j + L) % L : j;
      if (jj < 0 || jj >= L || !model.link_bent(jj)) continue;
      const double T = model.link_tension(jj), arc = model.bend_arc(jj);
      if (!std::isfinite(T) || !(arc > 0)) continue;
      const int other = jj == i - 1 || (chain.closed() && jj == (i - 1 + L) % L) ? chain.link_start(jj) : chain.link_end(jj);
      const double share = held_on_arc(model, other) >= 0 ? 0.5 : 1.0;
      force += share * T * n.dot(model.bent_direction(jj, false) - model.bent_direction(jj, true));
      length += share * arc;
    }
    const double per_mass = model.contact_force(c) / model.masses()[i];
    return (per_mass + (length > 0 ? force / (model.chain().density() * length) : 0.0)) / a;
  }
  /// Links along the arc: the landing root function of the free end of link j (its end node if `at_end`, else its
  /// start node), which runs round circle k (wrapped in the sense sense_[k]): its straight part s per h, less
  /// kWrapLand, zero where the node is at kWrapLand h from its tangent point. Past its tangent point along its side
  /// it is negative where the node went through that distance. Unsigned, a step that carried a free end through its
  /// tangent point ended with s as long again on the other side (the link then runs round the circle from a tangent
  /// point ahead of the node, its length smooth through there to third order): no sign change, the landing lost,
  /// the node gone on off the circle, the tension several times, up to 10⁵ times, off (issue #23: compare pulley
  /// --R 0.005 --u0 0.1 on 801 nodes with erk8, 3·10⁶ N). The side is the straight link beyond the end i, to node
  /// `far`, with far's tangent line t_far (its line were it straight). Once i lies beyond far's tangent point along
  /// it, q = (c − x_i)·t_far < 0 (c the centre; that link within 60° of t_far, kWrapPassedCone), the value is that
  /// at q = 0 on the line through x_i along t_far: s* = √(D² − R²) (D the centre's distance from that line; −√(R² −
  /// D²) where the line cuts the circle), so the value is continuous at q = 0 (there s = s*; both negative where
  /// D < R, where s is 0): negative exactly where that line passes within kWrapLand h of its tangent point, where a
  /// node moving along it went through its landing distance. (Signing −s there instead, as before, jumped from
  /// +s* to −s* at q = 0: a root of a node off the line, s* = √(2Rp + p²) for a node p off it, one that never came
  /// within kWrapLand h: R = 4h, p = 0.01 h, +0.23 → −0.33.) An end with no straight link beyond it (the string's
  /// end, a neighbour held or on the circle) keeps s unsigned.
  double wrap_land_gap(const StringModel<dim>& model, int j, bool at_end, int k) const {
    const Chain<dim>& chain = model.chain();
    const double h = chain.link_length(j), s = model.bend_straight(j, at_end);
    if constexpr (dim == 2) {
      const int beyond = at_end ? j + 1 : j - 1;  // the link from the end away from the circle
      const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(k)];
      if (!chain.closed() && beyond >= 0 && beyond < chain.num_links() && !model.link_bent(beyond)) {
        const int i = at_end ? chain.link_end(j) : chain.link_start(j);
        const int far = at_end ? chain.link_end(beyond) : chain.link_start(beyond);
        const Vec<2> r = Vec<2>(model.x().col(far)) - o.point;
        const double d2 = r.squaredNorm(), R = o.radius;
        if (free_node(model, far) && d2 > R * R) {
          // From node `far` towards its tangent point (the one the string runs onto, as bend_link_on_circle's):
          // (−s_far r + σ R r⊥)/|r|², σ the sense, reversed at a link's end node (the string leaves the circle).
          const double s_far = std::sqrt(d2 - R * R), turn = at_end ? -sense_[static_cast<std::size_t>(k)]
                                                                    : sense_[static_cast<std::size_t>(k)];
          const Vec<2> t = (-s_far * r + turn * R * Vec<2>(-r[1], r[0])) / d2;
          const double along = (Vec<2>(model.x().col(i)) - Vec<2>(model.x().col(far))).dot(t);
          if (s_far - along < 0 && along > kWrapPassedCone * h) {
            const Vec<2> ri = Vec<2>(model.x().col(i)) - o.point;
            const double u = ri.dot(t), m2 = ri.squaredNorm() - u * u - R * R;  // u = −q; m2 = D² − R²
            return std::copysign(std::sqrt(std::abs(m2)), m2) / h - kWrapLand;
          }
        }
      }
    }
    return s / h - kWrapLand;
  }
  /// Links along the arc, two root functions: the smallest straight part of a free end of a link that
  /// runs round a circle, per h, less kWrapLand (the end lands: wrap_land_gap), and the smallest arc of a link with a
  /// free end, per h (it runs out: its held end leaves the circle, or a link with two free ends is
  /// straight again; a link entering from a free start at −kWrapEnter).
  void wrap_events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const {
    g.setOnes();
    const Chain<dim>& chain = model.chain();
    for (int j = 0; j < chain.num_links(); ++j) {
      if (!model.link_bent(j)) continue;
      const double arc = model.bend_arc(j);
      if (!std::isfinite(arc)) continue;
      const auto [k, a_on, b_on] = link_wrap(model, j);
      if (k < 0) continue;
      const int a = chain.link_start(j), b = chain.link_end(j);
      const double h = chain.link_length(j);
      if (!a_on && !no_wrap_land_[static_cast<std::size_t>(a)] && free_node(model, a))
        g[0] = std::min(g[0], wrap_land_gap(model, j, false, k));
      if (!b_on && !no_wrap_land_[static_cast<std::size_t>(b)] && free_node(model, b))
        g[0] = std::min(g[0], wrap_land_gap(model, j, true, k));
      if (a_on && b_on) continue;
      g[1] = std::min(g[1], arc / h + (entering_[static_cast<std::size_t>(j)] ? kWrapEnter : 0.0));
    }
  }
  /// Node i, held on a circle with links along the arc, is let go: its links with a free far end run
  /// round the circle from both free ends, except `straight` (a link whose arc has run out).
  void release_on_arc(const StringModel<dim>& model, int i, int straight) {
    const int k = held_on_arc(model, i);
    if (k < 0) return;
    const Chain<dim>& chain = model.chain();
    const int L = chain.num_links();
    for (const int j0 : {i - 1, i}) {
      const int j = chain.closed() ? (j0 + L) % L : j0;
      if (j < 0 || j >= L) continue;
      const int other = chain.link_start(j) == i ? chain.link_end(j) : chain.link_start(j);
      wrap_[static_cast<std::size_t>(j)] = j != straight && held_on_arc(model, other) < 0 ? k : -1;
      entering_[static_cast<std::size_t>(j)] = 0;
    }
    no_wrap_land_[static_cast<std::size_t>(i)] = 1;
  }
  /// A free end lands along its link: held, with the impact of what normal speed it has (of order
  /// kWrapLand h v/R).
  bool wrap_land(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger, bool located) {
    const Chain<dim>& chain = model.chain();
    std::vector<std::pair<int, int>> landing;
    int closest = -1, closest_k = -1;
    double closest_g = INFINITY;
    for (int j = 0; j < chain.num_links(); ++j) {
      const auto [k, a_on, b_on] = link_wrap(model, j);
      if (k < 0 || !model.link_bent(j)) continue;
      for (const bool at_end : {false, true}) {
        const int i = at_end ? chain.link_end(j) : chain.link_start(j);
        if ((at_end ? b_on : a_on) || no_wrap_land_[static_cast<std::size_t>(i)] || !free_node(model, i)) continue;
        const double g = wrap_land_gap(model, j, at_end, k);
        if (g <= kLandWindow) {
          if (std::none_of(landing.begin(), landing.end(), [&](const auto& p) { return p.first == i; }))
            landing.emplace_back(i, k);
        } else if (g < closest_g) {
          closest_g = g;
          closest = i;
          closest_k = k;
        }
      }
    }
    if (located && landing.empty() && closest >= 0 && closest_g < kCatchWindow) landing.emplace_back(closest, closest_k);
    for (const auto& [i, k] : landing)  // the links from it with a free far end now run from a held end
      for (const int j : {i - 1, i})
        if (j >= 0 && j < chain.num_links()) {
          wrap_[static_cast<std::size_t>(j)] = -1;
          const int other = j == i ? chain.link_end(j) : chain.link_start(j);
          entering_[static_cast<std::size_t>(j)] = held_on_arc(model, other) < 0 ? 1 : 0;
        }
    // The impact places the landing node on the circle (from its gap, kWrapLand² h²/2R) and the links on
    // their lengths along it: hold() books the potential energy that moves with the impact's kinetic energy.
    return hold(model, t, ledger, landing);
  }
  /// A link's arc has run out: its held end leaves the circle (no impulse: it moves along the circle's
  /// tangent, which its link continues), or a link with two free ends is straight again.
  bool wrap_leave(StringModel<dim>& model, double t, bool located) {
    const Chain<dim>& chain = model.chain();
    bool changed = false;
    int closest = -1;
    double closest_g = INFINITY;
    std::vector<int> out;
    for (int j = 0; j < chain.num_links(); ++j) {
      if (!model.link_bent(j)) continue;
      const auto [k, a_on, b_on] = link_wrap(model, j);
      if (k < 0 || (a_on && b_on)) continue;
      const double g = model.bend_arc(j) / chain.link_length(j) + (entering_[static_cast<std::size_t>(j)] ? kWrapEnter : 0.0);
      if (g <= kLandWindow)
        out.push_back(j);
      else if (g < closest_g) {
        closest_g = g;
        closest = j;
      }
    }
    if (located && out.empty() && closest >= 0 && closest_g < kCatchWindow) out.push_back(closest);
    for (const int j : out) {
      const auto [k, a_on, b_on] = link_wrap(model, j);
      if (k < 0) continue;
      const int held = a_on ? chain.link_start(j) : b_on ? chain.link_end(j) : -1;
      if (held >= 0) {
        lift_off(model, t, held, {}, j);
        release_on_arc(model, held, j);
        held_[static_cast<std::size_t>(held)] = -1;
        offset_[static_cast<std::size_t>(held)] = kReleaseGap;
        let_go_at_[static_cast<std::size_t>(held)] = t;
      } else {
        wrap_[static_cast<std::size_t>(j)] = -1;
      }
      changed = true;
    }
    if (!changed) return false;
    refresh(model);
    settle(model, t, false);
    return true;
  }

  static bool free_node(const StringModel<dim>& model, int i) { return model.in_arc(i) && !model.is_prescribed(i); }
  /// A closed string that starts with every node held on one cylinder, wrapping it in a circle (in 3D at right
  /// angles to the axis: every node at one axial coordinate), is locked there: no motion but a rigid turn keeps it
  /// on the cylinder and its links at their lengths, and its tension has a uniform part that nothing determines
  /// (any uniform tension is balanced by the cylinder's push; the tension system is singular). Refused before the
  /// run (InputError) with that cause, rather than the singular solve's pivot. A loop round a 3D cylinder at an
  /// angle to its axis is not locked (a uniform tension would push it along the cylinder: it may deform) and runs.
  void refuse_locked_loop(const StringModel<dim>& model) const {
    const Chain<dim>& chain = model.chain();
    if (!chain.closed()) return;
    int k = -1;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!free_node(model, static_cast<int>(i))) continue;
      if (k < 0) k = held_[i];
      if (held_[i] < 0 || held_[i] != k) return;
    }
    if (k < 0 || obstacles_[static_cast<std::size_t>(k)].kind != Obstacle<dim>::Kind::kCylinder) return;
    // The winding about the axis: the angles between consecutive nodes seen from it, summed round the loop.
    const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(k)];
    const Eigen::Matrix<double, dim, 2> basis = [&] {
      Eigen::Matrix<double, dim, 2> b = Eigen::Matrix<double, dim, 2>::Zero();
      if constexpr (dim == 2) {
        b(0, 0) = b(1, 1) = 1;
      } else {
        b.col(0) = o.axis.unitOrthogonal();
        b.col(1) = o.axis.cross(Vec<3>(b.col(0)));
      }
      return b;
    }();
    const int n = chain.num_nodes();
    double winding = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = basis.transpose() * (model.x().col(i) - o.point);
      const Eigen::Vector2d q = basis.transpose() * (model.x().col((i + 1) % n) - o.point);
      winding += std::atan2(p[0] * q[1] - p[1] * q[0], p.dot(q));
    }
    if (!(std::abs(winding) > kPi)) return;
    if constexpr (dim == 3) {
      const auto axial = [&](int i) { return o.axis.dot(model.x().col(i) - o.point); };
      for (int i = 1; i < n; ++i)
        if (std::abs(axial(i) - axial(0)) > kInitialContact * h_) return;
    }
    throw InputError(fmt::format(
        "the closed string starts with all its {} nodes held on {} (within {:g} of a link length of its surface), "
        "wrapped round it: it is locked there, and its tension is indeterminate (any uniform tension is balanced by "
        "the cylinder's push), which an inextensible string does not resolve; allowed: a closed string that does not "
        "lie all round the cylinder (longer than its circumference, in 3D at an angle to its axis, or round a smaller "
        "cylinder)",
        n, o.name, kInitialContact));
  }
  /// A table that ends at an edge: a plane bounded by its edge.
  static bool bounded(const Obstacle<dim>& o) {
    return o.kind == Obstacle<dim>::Kind::kPlane && o.inward.squaredNorm() > 0;
  }
  /// The index of the side-face event: the last of this module's.
  int side_face_event() const { return num_events() - (side_faces_ ? 1 : 0); }
  /// A table's body is the quarter-plane (a quarter-space in 3D) beneath its top and in from its edge. The nodes
  /// beyond the edge in the material (the edge front's other side) cannot rest on the table, and its side face
  /// below the edge is not an obstacle (docs/scenes.md, "[[effects.surface]]"): such a node that reaches the body
  /// stops the run. The bounded table that may not hold free node i and the node's distance from its body,
  /// max(n·r + δ, δ − d·r) with r from the edge, n the top's normal and d the direction into the table:
  /// < 0 inside it. The margins δ = kSideFaceMargin h leave a side hanging flush with the face (the chain off a
  /// table, d·r at the integration error) and the node crossing the edge at the top's level outside.
  /// (−1, +∞) for a held node, a node every bounded table may hold, or without bounded tables.
  std::pair<int, double> side_face_gap(const StringModel<dim>& model, int i) const {
    std::pair<int, double> nearest{-1, INFINITY};
    if (held_[static_cast<std::size_t>(i)] >= 0 || !free_node(model, i)) return nearest;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
      const Obstacle<dim>& o = obstacles_[k];
      if (!bounded(o) || o.may_hold(i)) continue;
      const double gap = table_body_gap<dim>(model.x().col(i) - o.point, o.normal, o.inward, kSideFaceMargin * h_);
      if (gap < nearest.second) nearest = {static_cast<int>(k), gap};
    }
    return nearest;
  }
  /// Some free node that a table may not hold is inside that table's body.
  bool inside_a_table(const StringModel<dim>& model) const {
    for (int i = 0; i < static_cast<int>(held_.size()); ++i)
      if (side_face_gap(model, i).second < 0) return true;
    return false;
  }
  /// A free node has reached a table's body through its side face: the run stops, located (a NumericalError:
  /// the motion past it would pass through the table, which the model does not hold there).
  [[noreturn]] void through_side_face(const StringModel<dim>& model, double t) const {
    int node = -1, table = -1;
    double deepest = INFINITY;
    for (int i = 0; i < static_cast<int>(held_.size()); ++i) {
      const auto [k, gap] = side_face_gap(model, i);
      if (k >= 0 && gap < deepest) std::tie(node, table, deepest) = std::tie(i, k, gap);
    }
    const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(table)];
    throw NumericalError(table_body_reached<dim>(node, model.chain().node_coordinate(node), o.point, o.name, t,
                                                 model.x().col(node) - o.point, o.normal, o.inward,
                                                 "docs/scenes.md, \"[[effects.surface]]\""),
                         t);
  }
  /// Node i is held now: on an obstacle, free (a front may have taken it into a heap), and on the
  /// obstacle's side of its edge (a node that has crossed the edge is the edge front's).
  bool holds(const StringModel<dim>& model, int i) const {
    const int k = held_[static_cast<std::size_t>(i)];
    return k >= 0 && free_node(model, i) && obstacles_[static_cast<std::size_t>(k)].may_hold(i);
  }
  /// The nearest obstacle that may hold node i at x and its gap there (−1 and +∞ if none may).
  std::pair<int, double> nearest(int i, const Vec<dim>& x) const {
    int best = -1;
    double gap = INFINITY;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
      if (!obstacles_[k].may_hold(i)) continue;
      const double g = obstacles_[k].gap(x);
      if (g < gap) {
        gap = g;
        best = static_cast<int>(k);
      }
    }
    return {best, gap};
  }
  static double acceleration_scale(const StringModel<dim>& model) {
    const double a = model.physical_scales().tension / (model.chain().density() * model.chain().length());
    return a > 0 ? a : 1.0;
  }
  /// A landing: the free nodes at a surface are held, and the velocities projected onto the
  /// constraints (a perfectly inelastic impact: Carnot's loss, booked in W_impacts).
  bool land(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger) {
    int closest = -1;
    double closest_gap = INFINITY;
    std::vector<std::pair<int, int>> landing;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (held_[i] >= 0 || !free_node(model, static_cast<int>(i))) continue;
      const auto [k, gap] = nearest(static_cast<int>(i), model.x().col(static_cast<Eigen::Index>(i)));
      if (k < 0) continue;
      const double g = gap / h_ + offset_[i];
      if (g <= kLandWindow) landing.emplace_back(static_cast<int>(i), k);
      if (g < closest_gap) {
        closest_gap = g;
        closest = static_cast<int>(i);
      }
    }
    if (landing.empty() && closest >= 0 && closest_gap < kCatchWindow)
      landing.emplace_back(closest, nearest(closest, model.x().col(closest)).first);
    return hold(model, t, ledger, landing);
  }
  /// Holds the nodes `landing` (node, obstacle) with an impact (booked in the ledgers); false if none.
  bool hold(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
            const std::vector<std::pair<int, int>>& landing, int round = 0) {
    int caught = 0;
    for (const auto& [i, k] : landing) {
      held_[static_cast<std::size_t>(i)] = k;
      offset_[static_cast<std::size_t>(i)] = 0;
      if (arc_) no_wrap_land_[static_cast<std::size_t>(i)] = 0;
      ++caught;
    }
    if (caught == 0) return false;
    // The normal impulses the rough obstacles take (−m n·v of each landing node: its links are tangent
    // to the surface to first order, so the obstacle takes the node's normal momentum).
    std::vector<double> normal_impulse;
    if (friction_)
      for (const auto& [i, k] : landing) {
        const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(k)];
        const Vec<dim> x = model.x().col(i);
        normal_impulse.push_back(o.mu > 0 ? std::max(0.0, -o.outward(x, true).dot(model.v().col(i))) * model.masses()[i] : 0.0);
      }
    // The impact projects the positions onto the taut links' lengths and the surfaces: it moves the landing nodes
    // by their gaps, and with links along the arc a link that the landing routes round the circle (its chord cut
    // into it) onto its length along it, which can move the whole side it holds (docs/model.md §10, "Landings
    // that move the string"). The potential energy that moves is booked with the impact's kinetic energy in
    // W_impacts (before, with node contact, only the kinetic energy: a chain jerked over a 3D pulley, 161 nodes,
    // lost 1.69e-6 J of its ledger at one landing at t = 0.2237 s).
    const Eigen::VectorXd no_ledger = Eigen::VectorXd::Zero(this->num_ledgers());
    const double V_before = model.potential_energy(no_ledger);
    const double K_before = model.kinetic_energy();
    const Vec<dim> p_before = model.momentum();
    refresh(model);
    const double work = model.impact(t);
    refresh(model);
    ledger[1] += model.kinetic_energy() - K_before - work + model.potential_energy(no_ledger) - V_before;
    ledger[supports_index()] += work;
    ledger.template segment<dim>(2) += model.momentum() - p_before;
    ++impacts_;
    std::vector<double> let_go_before;
    for (const auto& [i, k] : landing) let_go_before.push_back(let_go_at_[static_cast<std::size_t>(i)]);
    settle(model, t, false);
    if (friction_) {
      Eigen::VectorXd book = ledger;
      landing_friction(model, t, landing, normal_impulse, book);
      classify(model, t, &book);
      ledger = book;
      settle(model, t, false);
    }
    for (std::size_t q = 0; q < landing.size(); ++q) {  // let go, caught and let go again at t: it passes
      const auto i = static_cast<std::size_t>(landing[q].first);
      if (held_[i] < 0 && let_go_before[q] == t) offset_[i] = kPassGap;
    }
    // The impact's projection onto the links' lengths may carry a free node through a surface (at loose
    // tolerances the links are off their lengths by up to a few % of h): its landing function would start
    // below zero, where ARKODE never finds its root, and the node would fall through the obstacle. Such
    // nodes land too, at this same instant (at most one round per node).
    const std::vector<std::pair<int, int>> through = passed_through(model);
    if (!through.empty() && round < static_cast<int>(held_.size())) hold(model, t, ledger, through, round + 1);
    return true;
  }
  /// The free nodes whose landing function is below zero (node, obstacle): inside a surface, where ARKODE
  /// would never find their landing root.
  std::vector<std::pair<int, int>> passed_through(const StringModel<dim>& model) const {
    std::vector<std::pair<int, int>> through;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (held_[i] >= 0 || !free_node(model, static_cast<int>(i))) continue;
      const auto [k, gap] = nearest(static_cast<int>(i), model.x().col(static_cast<Eigen::Index>(i)));
      if (k >= 0 && gap / h_ + offset_[i] < 0) through.emplace_back(static_cast<int>(i), k);
    }
    return through;
  }
  /// Coulomb's impulse at a landing: each landing node still held on a rough obstacle takes the
  /// tangential impulse −μ P_n t̂ (at most what stops its tangential motion), and the velocities are
  /// projected again onto the constraints (the links pass it on along the chain). Its work is booked
  /// in W_friction, its impulse in the momentum ledger. Without it the landings' normal impulses, O(h)
  /// in all along a touchdown, would carry no friction: an O(h) error.
  void landing_friction(StringModel<dim>& model, double t, const std::vector<std::pair<int, int>>& landing,
                        const std::vector<double>& normal_impulse, Eigen::VectorXd& ledger) {
    const double K_before = model.kinetic_energy();
    const Vec<dim> p_before = model.momentum();
    bool applied = false;
    for (std::size_t q = 0; q < landing.size(); ++q) {
      const int i = landing[q].first;
      if (held_[static_cast<std::size_t>(i)] < 0 || !(normal_impulse[q] > 0)) continue;
      const Obstacle<dim>& o = obstacle_of(static_cast<std::size_t>(i));
      const Vec<dim> vt = tangential(o, model.x().col(i), model.v().col(i));
      const double speed = vt.norm();
      if (!(speed > 0)) continue;
      const double dv = std::min(o.mu * normal_impulse[q] / model.masses()[i], speed);
      model.v().col(i) -= dv * vt / speed;
      applied = true;
    }
    if (!applied) return;
    refresh(model);
    const double work = model.project(t);
    refresh(model);
    ledger[kFriction] += model.kinetic_energy() - K_before - work;
    ledger[supports_index()] += work;
    ledger.template segment<dim>(2) += model.momentum() - p_before;
  }
  /// After the inner module changed the layout (a front crossing): the held nodes a front took (into a
  /// heap, across an edge) are let go, and the free nodes it put on a surface (given out by a heap on
  /// it, brought back over an edge onto the table) are held, with the impact of any normal speed they
  /// have; then the nodes whose force would pull are let go.
  /// A node let go earlier (its landing root function offset by kReleaseGap or kPassGap) is held here only if
  /// the layout has just given it back to a surface that did not carry it before (a touchdown front landing a
  /// node it had lifted off: put on the plane with no normal speed, it would otherwise fall kReleaseGap h into
  /// it before its landing is seen, and the front's constraint would have to pull it back, docs/model.md §10).
  void follow_layout(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger) {
    std::vector<char> released(held_.size(), 0);
    for (std::size_t i = 0; i < held_.size(); ++i)
      if (held_[i] >= 0 && !holds(model, static_cast<int>(i))) {
        held_[i] = -1;
        offset_[i] = kReleaseGap;
        released[i] = 1;
      }
    const std::vector<char> now = carried(model);
    std::vector<std::pair<int, int>> landing;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      const bool given_back = now[i] && !carried_[i] && !released[i];
      if (held_[i] >= 0 || (offset_[i] != 0 && !given_back) || !free_node(model, static_cast<int>(i))) continue;
      const auto [k, gap] = nearest(static_cast<int>(i), model.x().col(static_cast<Eigen::Index>(i)));
      if (k >= 0 && gap <= kLandWindow * h_) landing.emplace_back(static_cast<int>(i), k);
    }
    carried_ = now;
    refresh(model);
    if (!hold(model, t, ledger, landing)) settle(model, t, false);
  }
  /// Per node, whether some obstacle may hold it (Obstacle::carries: a touchdown front's lying arc, a table's
  /// side of its edge; every node for the other obstacles).
  std::vector<char> carried(const StringModel<dim>& model) const {
    std::vector<char> c(static_cast<std::size_t>(model.chain().num_nodes()), 0);
    for (std::size_t i = 0; i < c.size(); ++i)
      for (const Obstacle<dim>& o : obstacles_)
        if (o.may_hold(static_cast<int>(i))) c[i] = 1;
    return c;
  }
  /// Node i, held, is let go at t: counted (lift_offs_, per obstacle), and listed in the summary's `events`
  /// while its obstacle has had fewer than kListedLiftOffs: at its position, with its index, its material
  /// coordinate s and the release's cause: `values` (the force N that no longer pushes) or `link` (≥ 0: the
  /// link whose arc ran out).
  void lift_off(const StringModel<dim>& model, double t, int i, std::vector<std::pair<std::string, double>> values,
                int link) {
    const std::size_t k = static_cast<std::size_t>(held_[static_cast<std::size_t>(i)]);
    ++lift_offs_;
    if (++lift_off_totals_[k] > kListedLiftOffs) return;
    RunEvent e;
    e.kind = "lift_off";
    e.t = t;
    const Vec<dim> x = model.x().col(i);
    e.position.assign(x.data(), x.data() + dim);
    e.indices = {{"node", i}};
    if (link >= 0) e.indices.emplace_back("link", link);
    e.values = {{"s", model.chain().node_coordinate(i)}};
    e.values.insert(e.values.end(), values.begin(), values.end());
    e.obstacle = obstacles_[k].name;
    events_.push_back(std::move(e));
  }
  /// Lets go of the held nodes whose normal force pulls, one at a time, most negative first (each
  /// release changes the others' forces), until none pulls; at a located lift-off (`located`) the one
  /// whose force has reached zero to the root's accuracy goes first. Returns whether one was let go.
  bool settle(StringModel<dim>& model, double t, bool located) {
    bool released = false;
    for (std::size_t pass = 0; pass <= held_.size(); ++pass) {
      Points<dim> x = model.x(), v = model.v();
      model.evaluate(t, x, v);
      const double a = acceleration_scale(model);
      int worst = -1;
      double worst_force = 0;
      for (std::size_t k = 0; k < model.contacts().size(); ++k) {
        const int i = model.contacts()[k].node;
        const double f = held_force(model, k, a);
        if (f < -kPull && f < worst_force) {
          worst_force = f;
          worst = i;
        }
      }
      if (worst < 0 && located && !released) {
        for (std::size_t k = 0; k < model.contacts().size(); ++k) {
          const int i = model.contacts()[k].node;
          const double f = held_force(model, k, a);
          if (f <= kCatchWindow && (worst < 0 || f < worst_force)) {
            worst_force = f;
            worst = i;
          }
        }
      }
      if (worst < 0) break;
      lift_off(model, t, worst, {{"N", worst_force * model.masses()[worst] * a}}, -1);
      if (arc_) release_on_arc(model, worst, -1);
      held_[static_cast<std::size_t>(worst)] = -1;
      offset_[static_cast<std::size_t>(worst)] = kReleaseGap;
      let_go_at_[static_cast<std::size_t>(worst)] = t;
      if (friction_) {
        stuck_[static_cast<std::size_t>(worst)] = 0;
        dir_.col(worst).setZero();
      }
      released = true;
      refresh(model);
    }
    return released;
  }
};

}  // namespace

template <int dim>
std::unique_ptr<StringModule<dim>> make_contact_module(std::vector<Obstacle<dim>> obstacles,
                                                       std::unique_ptr<StringModule<dim>> inner) {
  CHAINSIM_VERIFY(!obstacles.empty(), "a contact module needs an obstacle");
  return std::make_unique<ContactModule<dim>>(std::move(obstacles), std::move(inner));
}

template struct Obstacle<2>;
template struct Obstacle<3>;
template std::string table_body_reached<2>(int, double, const Vec<2>&, const std::string&, double, const Vec<2>&,
                                           const Vec<2>&, const Vec<2>&, const std::string&);
template std::string table_body_reached<3>(int, double, const Vec<3>&, const std::string&, double, const Vec<3>&,
                                           const Vec<3>&, const Vec<3>&, const std::string&);
template std::string table_body_start<2>(int, const std::string&, const Vec<2>&, const Vec<2>&, const Vec<2>&);
template std::string table_body_start<3>(int, const std::string&, const Vec<3>&, const Vec<3>&, const Vec<3>&);
template std::unique_ptr<StringModule<2>> make_contact_module<2>(std::vector<Obstacle<2>>,
                                                                 std::unique_ptr<StringModule<2>>);
template std::unique_ptr<StringModule<3>> make_contact_module<3>(std::vector<Obstacle<3>>,
                                                                 std::unique_ptr<StringModule<3>>);

}  // namespace chainsim
