#pragma once
/// @file wrapping_module.hpp
/// A module that wraps an inner module (string_module.hpp): the slack module around the fronts or the
/// contact module, the contact module around the fronts (docs/architecture.md, "The module chain").
/// The inner module keeps the layout (arcs), the masses and forces it puts on nodes, its ledgers,
/// events, fronts, run events and obstacle drawing; the wrapper passes them through and puts its own
/// ledgers and root functions after the inner module's. Without an inner module (nullptr) the string
/// is one arc and the wrapper adds only its own.
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "string_module.hpp"

namespace chainsim {

template <int dim>
class WrappingModule : public StringModule<dim> {
 public:
  explicit WrappingModule(std::unique_ptr<StringModule<dim>> inner) : inner_(std::move(inner)) {}
  /// The wrapped module (nullptr: none).
  const StringModule<dim>* inner() const { return inner_.get(); }

  std::vector<ArcRange> initial_arcs(const Chain<dim>& chain) override {
    if (inner_) return inner_->initial_arcs(chain);
    return {ArcRange{0, chain.num_nodes() - 1, chain.closed()}};
  }
  bool start(StringModel<dim>& model, double t0, Eigen::Ref<Eigen::VectorXd> ledger) override {
    return inner_ && inner_->start(model, t0, ledger.head(inner_ledgers()));
  }
  void add_mass_and_forces(const StringModel<dim>& model, Eigen::VectorXd& mass, Points<dim>& force) override {
    if (inner_) inner_->add_mass_and_forces(model, mass, force);
  }
  void node_constraints(const StringModel<dim>& model, std::vector<NodeConstraint<dim>>& out) const override {
    if (inner_) inner_->node_constraints(model, out);
  }
  std::vector<FrontField> front_fields() const override {
    return inner_ ? inner_->front_fields() : std::vector<FrontField>{};
  }
  long transfers() const override { return inner_ ? inner_->transfers() : 0; }
  int num_fronts() const override { return inner_ ? inner_->num_fronts() : 0; }
  int num_crossing_events() const override { return inner_ ? inner_->num_crossing_events() : 0; }
  std::optional<double> front_tension_at(const StringModel<dim>& model, int node) const override {
    return inner_ ? inner_->front_tension_at(model, node) : std::nullopt;
  }
  std::vector<RunEvent> run_events() const override {
    return inner_ ? inner_->run_events() : std::vector<RunEvent>{};
  }
  std::vector<LiftOffTotal> lift_off_totals() const override {
    return inner_ ? inner_->lift_off_totals() : std::vector<LiftOffTotal>{};
  }
  ObstacleDrawing obstacles() const override { return inner_ ? inner_->obstacles() : ObstacleDrawing{}; }
  /// The inner module's checks that failed at the start, its root functions first (the wrapper's own
  /// are not checks).
  std::vector<int> events_failed_at_start(const Eigen::Ref<const Eigen::VectorXd>& g) const override {
    if (!inner_) return {};
    std::vector<int> found = inner_->events_failed_at_start(g.head(inner_events()));
    if (!found.empty()) found.resize(static_cast<std::size_t>(this->num_events()), 0);
    return found;
  }
  std::vector<int> events_failed_after_event(const Eigen::Ref<const Eigen::VectorXd>& g) const override {
    if (!inner_) return {};
    std::vector<int> found = inner_->events_failed_after_event(g.head(inner_events()));
    if (!found.empty()) found.resize(static_cast<std::size_t>(this->num_events()), 0);
    return found;
  }
  bool checks_at_start() const override { return inner_ && inner_->checks_at_start(); }
  void hold_fronts() override {
    if (inner_) inner_->hold_fronts();
  }
  void redraw_fronts(StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> ledger) override {
    if (inner_) inner_->redraw_fronts(model, ledger.head(inner_ledgers()));
  }

 protected:
  int inner_ledgers() const { return inner_ ? inner_->num_ledgers() : 0; }
  int inner_events() const { return inner_ ? inner_->num_events() : 0; }
  /// The inner module's share of `found` acted on (nothing when none of its root functions fired).
  EventAction handle_inner_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                                  const std::vector<int>& found) {
    if (!inner_) return {};
    const int k = inner_events();
    const std::vector<int> inner_found(found.begin(), found.begin() + k);
    bool any = false;
    for (int f : inner_found) any = any || f != 0;
    if (!any) return {};
    return inner_->handle_events(model, t, ledger.head(inner_ledgers()), inner_found);
  }
  /// The inner module's part of a snapshot (none without one: no fronts, no terms, no support), with
  /// the impulse this module books (`own_impulse`) added to the inner module's impulse; the wrapper's own
  /// terms go after the inner module's.
  void fill_inner(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
                  const Vec<dim>& own_impulse, ModuleLedger<dim>& out) const {
    if (inner_) {
      inner_->fill(model, ledger.head(inner_ledgers()), out);
      out.impulse += own_impulse;
    } else {
      out.fronts.clear();
      out.terms.clear();
      out.impulse = own_impulse;
      out.support.setZero();
    }
  }

  std::unique_ptr<StringModule<dim>> inner_;
};

}  // namespace chainsim
