// The module of rigid obstacles along arcs: see contact_module.hpp (docs/model.md §10).
#include "contact_module.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "string_model.hpp"

namespace chainsim {

namespace {
/// At a landing the free nodes within kLandWindow (of h) of a surface are held; if none is (the state
/// recomputed to the event ends a little short of the located root), the nearest within kCatchWindow.
constexpr double kLandWindow = 1e-7;
constexpr double kCatchWindow = 1e-5;
/// A node let go starts its landing root function at +kReleaseGap (ARKODE deactivates a root function
/// that is zero at a restart).
constexpr double kReleaseGap = 2e-7;
/// A held node's normal force counts as pulling below −kPull of its weight scale m a (a the physical
/// acceleration scale): round-off is not a lift-off.
constexpr double kPull = 1e-9;

template <int dim>
Vec<dim> radial(const Obstacle<dim>& o, const Vec<dim>& x) {
  Vec<dim> r = x - o.point;
  if constexpr (dim == 3) r -= r.dot(o.axis) * o.axis;
  return r;
}
}  // namespace

template <int dim>
double Obstacle<dim>::gap(const Vec<dim>& x) const {
  if (kind == Kind::kPlane) return normal.dot(x - point);
  return radial(*this, x).norm() - radius;
}

template <int dim>
Vec<dim> Obstacle<dim>::outward(const Vec<dim>& x) const {
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
  const auto [e1, e2] = dim == 2 ? std::make_pair(Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.0, 0.0))
                                 : normal_pair(a);
  auto rim = [&](double phi) { return radius * (std::cos(phi) * e1 + std::sin(phi) * e2); };
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
class ContactModule final : public StringModule<dim> {
 public:
  explicit ContactModule(std::vector<Obstacle<dim>> obstacles) : obstacles_(std::move(obstacles)) {}

  // [ W_contact | W_impacts | impulse (dim) ]
  std::vector<ArcRange> initial_arcs(const Chain<dim>& chain) override {
    return {ArcRange{0, chain.num_nodes() - 1, chain.closed()}};
  }
  void initialize(StringModel<dim>& model) override {
    const Chain<dim>& chain = model.chain();
    const int n = chain.num_nodes();
    h_ = INFINITY;
    for (int j = 0; j < chain.num_links(); ++j) h_ = std::min(h_, chain.link_length(j));
    drawn_nodes_ = model.x();
    length_ = chain.length();
    held_.assign(static_cast<std::size_t>(n), -1);
    offset_.assign(static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) {
      if (!free_node(model, i)) continue;
      const auto [k, gap] = nearest(model.x().col(i));
      if (gap < -kInitialContact * h_)
        throw InputError(fmt::format("node {} of the string starts {:.6g} m inside the obstacle {} (allowed: on or "
                                     "outside its surface, within {:g} of a link length)",
                                     i, -gap, obstacles_[static_cast<std::size_t>(k)].name, kInitialContact));
      if (gap <= kInitialContact * h_) held_[static_cast<std::size_t>(i)] = k;
    }
    model.refresh();
    settle(model, 0.0, false);
  }
  void add_mass_and_forces(const StringModel<dim>&, Eigen::VectorXd&, Points<dim>&) override {}
  void node_contacts(const StringModel<dim>& model, std::vector<NodeContact<dim>>& out) const override {
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (held_[i] < 0) continue;
      const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(held_[i])];
      const Vec<dim> x = model.x().col(static_cast<Eigen::Index>(i)), v = model.v().col(static_cast<Eigen::Index>(i));
      out.push_back({static_cast<int>(i), o.outward(x), o.gap(x), o.curvature(x, v)});
    }
  }
  int num_ledgers() const override { return 2 + dim; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override {
    rates[0] = model.contact_power();
    rates[1] = 0;  // the impacts' term jumps at events only
    rates.template segment<dim>(2) = model.external_force();
  }
  Eigen::VectorXd ledger_scale(double mass, double speed, double) const override {
    Eigen::VectorXd scale(num_ledgers());
    scale.head(2).setConstant(mass * speed * speed);
    scale.template segment<dim>(2).setConstant(mass * speed);
    return scale;
  }
  double potential_correction(const StringModel<dim>&, const Eigen::Ref<const Eigen::VectorXd>&) const override {
    return 0;
  }
  std::vector<LedgerTerm> ledger_terms() const override {
    using K = LedgerTerm::Kind;
    return {{"W_contact", K::kWork}, {"W_impacts", K::kWork}, {"impacts", K::kQuantity}, {"lift_offs", K::kQuantity}};
  }
  std::vector<FrontField> front_fields() const override { return {}; }
  void fill(const StringModel<dim>&, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override {
    out.fronts.clear();
    out.terms = {ledger[0], ledger[1], static_cast<double>(impacts_), static_cast<double>(lift_offs_)};
    out.impulse = ledger.template segment<dim>(2);
    out.has_momentum_ledger = true;
    out.support.setZero();
  }
  int num_events() const override { return 2; }
  bool events_need_tensions() const override { return true; }
  void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const override {
    // 0: the smallest gap of a free node (landing); 1: the smallest normal force of a held node, per
    // its weight scale (lift-off).
    g[0] = 1;
    for (std::size_t i = 0; i < held_.size(); ++i)
      if (held_[i] < 0 && free_node(model, static_cast<int>(i)))
        g[0] = std::min(g[0], nearest(model.x().col(static_cast<Eigen::Index>(i))).second / h_ + offset_[i]);
    g[1] = 1;
    const double a = acceleration_scale(model);
    for (std::size_t k = 0; k < model.contacts().size(); ++k)
      g[1] = std::min(g[1], model.contact_force(k) / (model.masses()[model.contacts()[k].node] * a));
  }
  std::vector<int> event_directions() const override { return {-1, -1}; }
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>& found) override {
    bool changed = false;
    if (found.size() > 0 && found[0] != 0) changed = land(model, t, ledger) || changed;
    if (found.size() > 1 && found[1] != 0) changed = settle(model, t, true) || changed;
    if (!changed) return {};
    return {EventAction::Kind::kTransfer, ""};  // the velocities or the held set changed: the integrator restarts
  }
  bool release_contacts(StringModel<dim>& model, double t) override { return settle(model, t, false); }
  long transfers() const override { return 0; }
  /// Each obstacle sized to the string's initial nodes plus a tenth of its length.
  ObstacleDrawing obstacles() const override {
    ObstacleDrawing drawing;
    for (std::size_t k = 0; k < obstacles_.size(); ++k)
      obstacles_[k].draw(static_cast<int>(k), drawn_nodes_, 0.1 * length_, drawing);
    return drawing;
  }
  int num_fronts() const override { return 0; }
  std::optional<double> front_tension_at(const StringModel<dim>&, int) const override { return std::nullopt; }

 private:
  std::vector<Obstacle<dim>> obstacles_;
  std::vector<int> held_;        // per node: the obstacle it is held on, or −1
  std::vector<double> offset_;   // per node: its landing root function's offset (of h)
  double h_ = 1;
  long impacts_ = 0, lift_offs_ = 0;
  Points<dim> drawn_nodes_;       // the string's initial nodes, which the obstacles' drawing spans
  double length_ = 0;             // the string's length (m)

  static bool free_node(const StringModel<dim>& model, int i) { return model.in_arc(i) && !model.is_prescribed(i); }
  std::pair<int, double> nearest(const Vec<dim>& x) const {
    int best = 0;
    double gap = INFINITY;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
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
    int caught = 0, closest = -1;
    double closest_gap = INFINITY;
    std::vector<std::pair<int, int>> landing;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (held_[i] >= 0 || !free_node(model, static_cast<int>(i))) continue;
      const auto [k, gap] = nearest(model.x().col(static_cast<Eigen::Index>(i)));
      const double g = gap / h_ + offset_[i];
      if (g <= kLandWindow) landing.emplace_back(static_cast<int>(i), k);
      if (g < closest_gap) {
        closest_gap = g;
        closest = static_cast<int>(i);
      }
    }
    if (landing.empty() && closest >= 0 && closest_gap < kCatchWindow)
      landing.emplace_back(closest, nearest(model.x().col(closest)).first);
    for (const auto& [i, k] : landing) {
      held_[static_cast<std::size_t>(i)] = k;
      offset_[static_cast<std::size_t>(i)] = 0;
      ++caught;
    }
    if (caught == 0) return false;
    const double K_before = model.kinetic_energy();
    const Vec<dim> p_before = model.momentum();
    model.refresh();
    model.impact(t);
    model.refresh();
    ledger[1] += model.kinetic_energy() - K_before;
    ledger.template segment<dim>(2) += model.momentum() - p_before;
    ++impacts_;
    settle(model, t, false);
    return true;
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
        const double f = model.contact_force(k) / (model.masses()[i] * a);
        if (f < -kPull && f < worst_force) {
          worst_force = f;
          worst = i;
        }
      }
      if (worst < 0 && located && !released) {
        for (std::size_t k = 0; k < model.contacts().size(); ++k) {
          const int i = model.contacts()[k].node;
          const double f = model.contact_force(k) / (model.masses()[i] * a);
          if (f <= kCatchWindow && (worst < 0 || f < worst_force)) {
            worst_force = f;
            worst = i;
          }
        }
      }
      if (worst < 0) break;
      held_[static_cast<std::size_t>(worst)] = -1;
      offset_[static_cast<std::size_t>(worst)] = kReleaseGap;
      ++lift_offs_;
      released = true;
      model.refresh();
    }
    return released;
  }
};

}  // namespace

template <int dim>
std::unique_ptr<StringModule<dim>> make_contact_module(std::vector<Obstacle<dim>> obstacles) {
  CHAINSIM_VERIFY(!obstacles.empty(), "a contact module needs an obstacle");
  return std::make_unique<ContactModule<dim>>(std::move(obstacles));
}

template struct Obstacle<2>;
template struct Obstacle<3>;
template std::unique_ptr<StringModule<2>> make_contact_module<2>(std::vector<Obstacle<2>>);
template std::unique_ptr<StringModule<3>> make_contact_module<3>(std::vector<Obstacle<3>>);

}  // namespace chainsim
