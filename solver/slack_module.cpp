// The module of unilateral links: see slack_module.hpp.
#include "slack_module.hpp"

#include "string_model.hpp"

namespace chainsim {

namespace {

template <int dim>
class SlackModule final : public StringModule<dim> {
 public:
  // [ W_snap | W_snap_supports | impulse (dim) ]
  std::vector<ArcRange> initial_arcs(const Chain<dim>& chain) override {
    return {ArcRange{0, chain.num_nodes() - 1, chain.closed()}};
  }
  void initialize(StringModel<dim>&) override {}
  void add_mass_and_forces(const StringModel<dim>&, Eigen::VectorXd&, Points<dim>&) override {}
  int num_ledgers() const override { return 2 + dim; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override {
    rates[0] = rates[1] = 0;  // the snaps' terms jump at events only
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
    return {{"W_snap", K::kWork}, {"W_snap_supports", K::kWork}, {"snaps", K::kQuantity}};
  }
  std::vector<FrontField> front_fields() const override { return {}; }
  void fill(const StringModel<dim>&, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override {
    out.fronts.clear();
    out.terms = {ledger[0], ledger[1], static_cast<double>(snaps_)};
    out.impulse = ledger.template segment<dim>(2);
    out.has_momentum_ledger = true;
    out.support.setZero();
  }
  int num_events() const override { return 1; }
  void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const override {
    g[0] = model.slack_gap();
  }
  std::vector<int> event_directions() const override { return {-1}; }
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>&) override {
    const typename StringModel<dim>::SnapResult snap = model.snap(t);
    if (snap.caught == 0) return {};
    ledger[0] -= snap.dissipated;
    ledger[1] += snap.support_work;
    ledger.template segment<dim>(2) += snap.support_impulse;
    ++snaps_;
    return {EventAction::Kind::kTransfer, ""};  // the velocities changed: the integrator restarts
  }
  long transfers() const override { return 0; }
  int num_fronts() const override { return 0; }
  std::optional<double> front_tension_at(const StringModel<dim>&, int) const override { return std::nullopt; }

 private:
  long snaps_ = 0;
};

}  // namespace

template <int dim>
std::unique_ptr<StringModule<dim>> make_slack_module() {
  return std::make_unique<SlackModule<dim>>();
}

template std::unique_ptr<StringModule<2>> make_slack_module<2>();
template std::unique_ptr<StringModule<3>> make_slack_module<3>();

}  // namespace chainsim
