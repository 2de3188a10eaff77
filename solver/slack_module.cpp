// The module of unilateral links: see slack_module.hpp.
#include "slack_module.hpp"

#include <cmath>

#include <fmt/format.h>

#include "string_model.hpp"
#include "wrapping_module.hpp"

namespace chainsim {

namespace {

/// −Σ T_j dl_j/dt over the links of the arcs, after an evaluation (W): the power the link tensions
/// give the nodes. Zero while every taut link keeps its length; a link the complementarity problem
/// released (T_j = 0) that returns to its length before it has gone slack (before it is shorter than
/// (1 − kSlackGap) h_j) is pulled back by the drift control with T_j > 0 while dl_j/dt > 0: this is
/// the energy it loses, the snap that was not located. O(N), no square root: a link with a tension is
/// taut-flagged, its length within kSlackGap of h_j, so dl_j/dt = Δx_j·Δv_j / h_j to that share of itself.
template <int dim>
double link_power(const StringModel<dim>& model) {
  const Chain<dim>& chain = model.chain();
  double power = 0;
  for (int j = 0; j < chain.num_links(); ++j) {
    const double T = model.link_tension(j);
    if (!(T != 0) || std::isnan(T)) continue;  // slack, released, or in no arc
    if (model.link_bent(j)) {  // over an edge: its length runs over the point
      power -= T * model.link_rate(j);
      continue;
    }
    const int a = chain.link_start(j), b = chain.link_end(j);
    const Vec<dim> dx = model.x().col(b) - model.x().col(a);
    power -= T * dx.dot(model.v().col(b) - model.v().col(a)) / chain.link_length(j);
  }
  return power;
}

template <int dim>
class SlackModule final : public WrappingModule<dim> {
  using WrappingModule<dim>::inner_;
  using WrappingModule<dim>::inner_ledgers;
  using WrappingModule<dim>::inner_events;

 public:
  explicit SlackModule(std::unique_ptr<StringModule<dim>> inner) : WrappingModule<dim>(std::move(inner)) {}

  // Ledgers: [ the inner module's | W_snap | W_snap_supports | W_links | impulse (dim) ]. Without an inner module
  // the impulse is that of all external forces (its rate the string's external force, its jumps the
  // supports' impulses at snaps); with one (fronts), the inner module integrates the external forces'
  // impulse and this one holds only the snaps' support impulses, added to it in fill().
  void initialize(StringModel<dim>& model) override {
    if (inner_) inner_->initialize(model);
  }
  /// The start (docs/model.md §9, "The start" and "A landing at the start"). The start's own snap
  /// (StringModel::make_consistent, the velocities by the snap's law) is booked here: what it dissipated is W_snap
  /// at t0 (the runner holds it in W_applied with the rest of the jump, at an impulsive start), and it counts as
  /// one snap. Then the inner module's start (the contact module's lift-offs and landings at t0), whose landings
  /// project the positions onto the taut links and the surfaces and may carry a slack link to or past its length:
  /// its root function would start at or below zero, where ARKODE never finds the snap, and the link would go on
  /// stretching unseen. Such links are taut again and the start's law acts once more (StringModel::impact with the
  /// scene's restitution: the positions onto the taut links' lengths and the surfaces, the velocities by the snap's
  /// problem, the links it leaves shortening slack again), its change of K less the driven supports' work booked in
  /// W_snap, that work in W_snap_supports and the change of momentum in the supports' impulse, counted as a snap; the held nodes it would pull off are let go and the free nodes its
  /// projection carried into a surface land, which may stretch another slack link (at most one round per link).
  bool start(StringModel<dim>& model, double t0, Eigen::Ref<Eigen::VectorXd> ledger) override {
    const int kl = inner_ledgers();
    const auto& impulsive = model.impulsive_start();
    if (impulsive.detected() && impulsive.dissipated > 0) {
      ledger[kl] -= impulsive.dissipated;
      ++snaps_;
    }
    bool changed = WrappingModule<dim>::start(model, t0, ledger);
    const Chain<dim>& chain = model.chain();
    for (int round = 0; changed && round <= chain.num_links(); ++round) {
      model.refresh();
      if (!(model.slack_gap() <= 0)) break;
      bool caught = false;
      for (int j = 0; j < chain.num_links(); ++j) {
        if (!model.link_slack(j) || model.link_bent(j)) continue;
        const double h = chain.link_length(j);
        if ((model.x().col(chain.link_end(j)) - model.x().col(chain.link_start(j))).norm() >=
            (1 - StringModel<dim>::kSnapWindow) * h) {
          model.set_slack(j, false);
          caught = true;
        }
      }
      if (!caught) break;
      const double K_before = model.kinetic_energy();
      const Vec<dim> p_before = model.momentum();
      model.refresh();
      const double work = model.impact(t0, model.options().snap_restitution);
      model.refresh();
      typename StringModel<dim>::SnapResult snap;
      snap.dissipated = K_before + work - model.kinetic_energy();  // the driven supports' work booked apart
      snap.support_work = work;
      snap.support_impulse = model.momentum() - p_before;
      book(snap, ledger);
      if (!inner_) break;
      inner_->release_contacts(model, t0);
      if (!inner_->land_passed(model, t0, ledger.head(kl))) break;
    }
    return changed;
  }
  int num_ledgers() const override { return inner_ledgers() + 3 + dim; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override {
    const int k = inner_ledgers();
    if (inner_) inner_->ledger_rates(model, rates.head(k));
    rates[k] = rates[k + 1] = 0;  // the snaps' terms jump at events only
    // W_links counts from the first release on (or from the start with links laid slack): until the
    // complementarity problem has released a link every link is taut and its rate is the drift's, which
    // a taut run does not book either; the O(N) pass then costs nothing on a run that never goes slack.
    if (!counting_)
      counting_ = model.num_slack_links() > 0 ||
                  (model.has_tension_system() && model.tension_system().complementarity_stats().calls_with_release > 0);
    rates[k + 2] = counting_ ? link_power(model) : 0.0;
    if (inner_)
      rates.template segment<dim>(k + 3).setZero();
    else
      rates.template segment<dim>(k + 3) = model.external_force();
  }
  Eigen::VectorXd ledger_scale(double mass, double speed, double length) const override {
    const int k = inner_ledgers();
    Eigen::VectorXd scale(num_ledgers());
    if (inner_) scale.head(k) = inner_->ledger_scale(mass, speed, length);
    scale.segment(k, 3).setConstant(mass * speed * speed);
    scale.template segment<dim>(k + 3).setConstant(mass * speed);
    return scale;
  }
  double potential_correction(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const override {
    return inner_ ? inner_->potential_correction(model, ledger.head(inner_ledgers())) : 0.0;
  }
  std::vector<LedgerTerm> ledger_terms() const override {
    using K = LedgerTerm::Kind;
    std::vector<LedgerTerm> terms = inner_ ? inner_->ledger_terms() : std::vector<LedgerTerm>{};
    terms.insert(terms.end(), {{"W_snap", K::kWork},
                               {"W_snap_supports", K::kWork},
                               {"W_links", K::kNumerical},
                               {"snaps", K::kQuantity}});
    return terms;
  }
  void fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override {
    const int k = inner_ledgers();
    this->fill_inner(model, ledger, ledger.template segment<dim>(k + 3), out);
    out.terms.insert(out.terms.end(), {ledger[k], ledger[k + 1], ledger[k + 2], static_cast<double>(snaps_)});
    out.has_momentum_ledger = true;
  }
  int num_events() const override { return inner_events() + 2; }
  void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const override {
    const int k = inner_events();
    if (inner_) inner_->events(model, g.head(k));
    g[k] = model.slack_gap();
    g[k + 1] = model.release_root();
  }
  std::vector<int> event_directions() const override {
    std::vector<int> directions = inner_ ? inner_->event_directions() : std::vector<int>{};
    directions.push_back(-1);
    directions.push_back(-1);
    return directions;
  }
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>& found) override {
    const int k = inner_events(), kl = inner_ledgers();
    // The fronts' events first (a crossing rebuilds the arcs; a slack link that leaves them is taut
    // again, StringModel::rebuild), then the snap on the layout they leave.
    EventAction action = this->handle_inner_events(model, t, ledger, found);
    if (action.kind == EventAction::Kind::kStop) return action;
    // A node that has passed a surface inside the step of a snap lands now, before the snap (its landing
    // function would restart below zero, where ARKODE finds no root: a loop dropped onto a pulley, a node
    // 10⁻⁵ h inside at a snap then fell through it). The inner module acts so at its own events.
    if (inner_ && found[static_cast<std::size_t>(k)] != 0 && inner_->land_passed(model, t, ledger.head(kl)))
      action = {EventAction::Kind::kTransfer, ""};
    if (action.kind == EventAction::Kind::kTransfer) model.refresh();
    // A transfer of the inner module (a landing's impact projects the positions) may carry a slack link
    // past its length: its snap is now, with the root function below zero at the restart, where ARKODE
    // would never find it (a loop round a pulley: the link then went on stretching unseen).
    const bool stretched = action.kind == EventAction::Kind::kTransfer && model.slack_gap() <= 0;
    // A located release: the links whose tension has reached the release threshold are slack from this instant;
    // so are those the tension problem releases at the state another event left (their release term would restart
    // at or below zero, where ARKODE finds no root). Inside the fronts' held drawing, as a snap is: a heap's curve
    // to its plane stops at the first slack link.
    if (found[static_cast<std::size_t>(k) + 1] != 0 || action.kind == EventAction::Kind::kTransfer)
      release(model, t, ledger.head(kl), action);
    if (found[static_cast<std::size_t>(k)] == 0 && !stretched) return action;
    const long snaps_before = snaps_;
    // The fronts keep their drawing through the impulses, and are drawn on the links they leave afterwards, what
    // that moves booked (a heap's curve to its plane stops at a slack link: FrontTracker::redraw_fronts).
    if (inner_) inner_->hold_fronts();
    const typename StringModel<dim>::SnapResult snap = model.snap(t);
    if (snap.caught == 0) {
      if (inner_) inner_->redraw_fronts(model, ledger.head(kl));
      return action;
    }
    book(snap, ledger);
    // The snap's impulses can leave another slack link at or past its length with its root function at or below
    // zero at the restart, where ARKODE would never find its snap: one already past its length whose offset the
    // impulse ended (it turned to lengthening, slack_root), or one whose rate is a rounding zero. Every later snap
    // would then go unseen, and accept_step stops the run ("its snap taut was not located": contact = "arc" on a
    // shaken pulley, 51 to 401 nodes). Such links are caught now, by the same law, round after round (each catches a
    // link at least; a link can be caught again if a later round's impulses set it slack, so the rounds are capped
    // at the number of links). The held nodes the snaps would pull off a surface are let go between rounds: a
    // lift-off re-routes a link along an arc, which changes its length at once.
    const int max_rounds = model.chain().num_links();
    for (int round = 0;; ++round) {
      while (round < max_rounds && model.slack_gap() <= 0) {
        // Judged against the first snap's speed: the links these rounds catch were left at their length by its
        // impulses, at round-off rates, and would separate and be caught again for ever when judged against those
        // rates (a folded chain jerked down: two links at rest in free fall, 100 rounds, the root left below zero).
        const typename StringModel<dim>::SnapResult again = model.snap(t, snap.speed);
        if (again.caught == 0) break;
        book(again, ledger);
        ++round;
      }
      if (!inner_ || !inner_->release_contacts(model, t) || round >= max_rounds) break;
      model.refresh();
    }
    if (inner_) inner_->redraw_fronts(model, ledger.head(kl));
    // No release at the state the snaps leave: it would undo what the snap decided, a separation held taut because
    // its flight would stay within kSlackGap of its length (hold_unresolved_flights). A link the tension problem
    // releases there is taken up at the next accepted step, as a release the root function does not see (the
    // shaken pulley of docs/data/pulley_shaken_slack.toml, released so after a snap, failed ARKODE's error test
    // 0.2 ns after a landing at 0.469346 s; not released, it completes with the energy closed to 9.3e-7).
    if (inner_) {
      // ARKODE restarts from the state after the snap and finds only sign changes from there: a check of
      // the fronts that the snap has made fail (an edge that would now have to pull the string) is acted
      // on here, as at the start of a run.
      if (inner_->checks_at_start()) {
        model.evaluate(t, model.x(), model.v());
        Eigen::VectorXd g(k);
        inner_->events(model, g);
        const std::vector<int> failed = inner_->events_failed_after_event(g);
        if (!failed.empty()) {
          EventAction stop = inner_->handle_events(model, t, ledger.head(kl), failed);
          if (stop.kind == EventAction::Kind::kStop) {
            snaps_ = snaps_before;  // the run stops on the state before them (the runner records that state)
            stop.reason = fmt::format("at the snap taut at t = {:.9g} s: {}", t, stop.reason);
            return stop;
          }
        }
      }
    }
    return {EventAction::Kind::kTransfer, ""};  // the velocities changed: the integrator restarts
  }
  bool events_need_tensions() const override { return true; }
  void node_contacts(const StringModel<dim>& model, std::vector<NodeContact<dim>>& out) const override {
    if (inner_) inner_->node_contacts(model, out);
  }
  bool release_contacts(StringModel<dim>& model, double t) override {
    return inner_ && inner_->release_contacts(model, t);
  }
 private:
  long snaps_ = 0;
  mutable bool counting_ = false;  // W_links: a link has been released (found by the const ledger_rates)

  /// The links the tension problem releases at the current state (their terms of release_root() ≤ 0) are slack
  /// from here: at a located release, and at the state another event leaves, where their release term would
  /// restart at or below zero and ARKODE would find no root. Inside the fronts' held drawing, as a snap is (a
  /// heap's curve to its plane stops at the first slack link); with no link released nothing is drawn again.
  void release(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> inner_ledger, EventAction& action) {
    model.evaluate(t, model.x(), model.v());
    if (model.release_root() > 0) return;
    if (inner_) inner_->hold_fronts();
    model.release_links();
    if (inner_) inner_->redraw_fronts(model, inner_ledger);
    if (action.kind != EventAction::Kind::kStop) action = {EventAction::Kind::kTransfer, ""};
  }

  /// A snap's terms in the ledgers (the whole module's `ledger`), counted.
  void book(const typename StringModel<dim>::SnapResult& snap, Eigen::Ref<Eigen::VectorXd> ledger) {
    const int kl = inner_ledgers();
    ledger[kl] -= snap.dissipated;
    ledger[kl + 1] += snap.support_work;
    ledger.template segment<dim>(kl + 3) += snap.support_impulse;
    ++snaps_;
  }
};

}  // namespace

template <int dim>
std::unique_ptr<StringModule<dim>> make_slack_module(std::unique_ptr<StringModule<dim>> inner) {
  return std::make_unique<SlackModule<dim>>(std::move(inner));
}

template std::unique_ptr<StringModule<2>> make_slack_module<2>(std::unique_ptr<StringModule<2>>);
template std::unique_ptr<StringModule<3>> make_slack_module<3>(std::unique_ptr<StringModule<3>>);

}  // namespace chainsim
