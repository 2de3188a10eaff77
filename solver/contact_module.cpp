// The module of rigid obstacles along arcs: see contact_module.hpp (docs/model.md §10).
#include "contact_module.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "string_model.hpp"
#include "wrapping_module.hpp"

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
double Obstacle<dim>::gap(const Vec<dim>& x) const {
  if (beyond_edge(*this, x)) return from_edge(*this, x).norm();
  if (kind == Kind::kPlane) return normal.dot(x - point);
  return radial(*this, x).norm() - radius;
}

template <int dim>
Vec<dim> Obstacle<dim>::outward(const Vec<dim>& x) const {
  if (beyond_edge(*this, x)) {
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

namespace {

template <int dim>
class ContactModule final : public WrappingModule<dim> {
  using WrappingModule<dim>::inner_;
  using WrappingModule<dim>::inner_ledgers;
  using WrappingModule<dim>::inner_events;

 public:
  ContactModule(std::vector<Obstacle<dim>> obstacles, std::unique_ptr<StringModule<dim>> inner)
      : WrappingModule<dim>(std::move(inner)), obstacles_(std::move(obstacles)) {}

  // Ledgers: [ the inner module's | W_contact | W_impacts | impulse (dim) ]. Without an inner module
  // the impulse is that of all external forces (the contact forces among them); with one (fronts), the
  // inner module integrates the external forces' impulse (StringModel::external_force has the contact
  // forces) and this one holds only the impacts' momentum jumps, added to it in fill().
  void initialize(StringModel<dim>& model) override {
    if (inner_) inner_->initialize(model);
    const Chain<dim>& chain = model.chain();
    const int n = chain.num_nodes();
    h_ = INFINITY;
    for (int j = 0; j < chain.num_links(); ++j) h_ = std::min(h_, chain.link_length(j));
    held_.assign(static_cast<std::size_t>(n), -1);
    offset_.assign(static_cast<std::size_t>(n), 0.0);
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
    model.refresh();
    settle(model, 0.0, false);
  }
  void node_contacts(const StringModel<dim>& model, std::vector<NodeContact<dim>>& out) const override {
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (!holds(model, static_cast<int>(i))) continue;
      const Obstacle<dim>& o = obstacles_[static_cast<std::size_t>(held_[i])];
      const Vec<dim> x = model.x().col(static_cast<Eigen::Index>(i)), v = model.v().col(static_cast<Eigen::Index>(i));
      out.push_back({static_cast<int>(i), o.outward(x), o.gap(x), o.curvature(x, v)});
    }
  }
  int num_ledgers() const override { return inner_ledgers() + 2 + dim; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override {
    const int k = inner_ledgers();
    if (inner_) inner_->ledger_rates(model, rates.head(k));
    rates[k] = model.contact_power();
    rates[k + 1] = 0;  // the impacts' term jumps at events only
    if (inner_)
      rates.template segment<dim>(k + 2).setZero();
    else
      rates.template segment<dim>(k + 2) = model.external_force();
  }
  Eigen::VectorXd ledger_scale(double mass, double speed, double length) const override {
    const int k = inner_ledgers();
    Eigen::VectorXd scale(num_ledgers());
    if (inner_) scale.head(k) = inner_->ledger_scale(mass, speed, length);
    scale.segment(k, 2).setConstant(mass * speed * speed);
    scale.template segment<dim>(k + 2).setConstant(mass * speed);
    return scale;
  }
  double potential_correction(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const override {
    return inner_ ? inner_->potential_correction(model, ledger.head(inner_ledgers())) : 0.0;
  }
  std::vector<LedgerTerm> ledger_terms() const override {
    using K = LedgerTerm::Kind;
    std::vector<LedgerTerm> terms = inner_ ? inner_->ledger_terms() : std::vector<LedgerTerm>{};
    terms.insert(terms.end(),
                 {{"W_contact", K::kWork}, {"W_impacts", K::kWork}, {"impacts", K::kQuantity}, {"lift_offs", K::kQuantity}});
    return terms;
  }
  void fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override {
    const int k = inner_ledgers();
    if (inner_) {
      inner_->fill(model, ledger.head(k), out);
      out.impulse += ledger.template segment<dim>(k + 2);
    } else {
      out.fronts.clear();
      out.terms.clear();
      out.impulse = ledger.template segment<dim>(k + 2);
      out.support.setZero();
    }
    out.terms.insert(out.terms.end(),
                     {ledger[k], ledger[k + 1], static_cast<double>(impacts_), static_cast<double>(lift_offs_)});
    out.has_momentum_ledger = true;
  }
  int num_events() const override { return inner_events() + 2; }
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
      g[k + 1] = std::min(g[k + 1], model.contact_force(c) / (model.masses()[model.contacts()[c].node] * a));
  }
  std::vector<int> event_directions() const override {
    std::vector<int> directions = inner_ ? inner_->event_directions() : std::vector<int>{};
    directions.insert(directions.end(), {-1, -1});
    return directions;
  }
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>& found) override {
    // The fronts' events first (a crossing moves nodes between arcs, heaps and the sides of an edge),
    // then the held set brought up to the layout they leave, then the landings and lift-offs.
    const int k = inner_events(), kl = inner_ledgers();
    EventAction action = this->handle_inner_events(model, t, ledger, found);
    if (action.kind == EventAction::Kind::kStop) return action;
    bool changed = action.kind == EventAction::Kind::kTransfer;
    Eigen::Ref<Eigen::VectorXd> own = ledger.tail(ledger.size() - kl);
    if (changed) follow_layout(model, t, own);
    const std::size_t land_at = static_cast<std::size_t>(k), lift_at = land_at + 1;
    if (found.size() > land_at && found[land_at] != 0) changed = land(model, t, own) || changed;
    if (found.size() > lift_at && found[lift_at] != 0) changed = settle(model, t, true) || changed;
    if (!changed) return {};
    return {EventAction::Kind::kTransfer, ""};  // the velocities or the held set changed: the integrator restarts
  }
  bool release_contacts(StringModel<dim>& model, double t) override { return settle(model, t, false); }

 private:
  std::vector<Obstacle<dim>> obstacles_;
  std::vector<int> held_;        // per node: the obstacle it is held on, or −1
  std::vector<double> offset_;   // per node: its landing root function's offset (of h)
  double h_ = 1;
  long impacts_ = 0, lift_offs_ = 0;

  static bool free_node(const StringModel<dim>& model, int i) { return model.in_arc(i) && !model.is_prescribed(i); }
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
    int caught = 0, closest = -1;
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
            const std::vector<std::pair<int, int>>& landing) {
    int caught = 0;
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
  /// After the inner module changed the layout (a front crossing): the held nodes a front took (into a
  /// heap, across an edge) are let go, and the free nodes it put on a surface (given out by a heap on
  /// it, brought back over an edge onto the table) are held, with the impact of any normal speed they
  /// have; then the nodes whose force would pull are let go.
  void follow_layout(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger) {
    for (std::size_t i = 0; i < held_.size(); ++i)
      if (held_[i] >= 0 && !holds(model, static_cast<int>(i))) {
        held_[i] = -1;
        offset_[i] = kReleaseGap;
      }
    std::vector<std::pair<int, int>> landing;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      if (held_[i] >= 0 || offset_[i] != 0 || !free_node(model, static_cast<int>(i))) continue;
      const auto [k, gap] = nearest(static_cast<int>(i), model.x().col(static_cast<Eigen::Index>(i)));
      if (k >= 0 && gap <= kLandWindow * h_) landing.emplace_back(static_cast<int>(i), k);
    }
    model.refresh();
    if (!hold(model, t, ledger, landing)) settle(model, t, false);
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
std::unique_ptr<StringModule<dim>> make_contact_module(std::vector<Obstacle<dim>> obstacles,
                                                       std::unique_ptr<StringModule<dim>> inner) {
  CHAINSIM_VERIFY(!obstacles.empty(), "a contact module needs an obstacle");
  return std::make_unique<ContactModule<dim>>(std::move(obstacles), std::move(inner));
}

template struct Obstacle<2>;
template struct Obstacle<3>;
template std::unique_ptr<StringModule<2>> make_contact_module<2>(std::vector<Obstacle<2>>,
                                                                 std::unique_ptr<StringModule<2>>);
template std::unique_ptr<StringModule<3>> make_contact_module<3>(std::vector<Obstacle<3>>,
                                                                 std::unique_ptr<StringModule<3>>);

}  // namespace chainsim
