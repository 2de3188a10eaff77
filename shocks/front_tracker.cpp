// Front tracking as a module of the one discrete string: see front_tracker.hpp. What a kind of front
// does is in its own file (heap_front.cpp, fold_front.cpp); here is only what all fronts share.
#include "front_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/front_checks.hpp"

namespace chainsim {

template <int dim>
FrontTracker<dim>::FrontTracker(std::vector<std::unique_ptr<FrontKind<dim>>> fronts, const FrontOptions& options)
    : options_(options), fronts_(std::move(fronts)), trace_(std::getenv("CHAINSIM_TRACE_FRONTS") != nullptr),
      record_(trace_) {
  CHAINSIM_VERIFY(!fronts_.empty(), "a front tracker needs a front");
  for (std::size_t k = 1; k < fronts_.size(); ++k)
    if (fronts_[k]->expected_s0 < fronts_[k - 1]->expected_s0)
      throw InputError(fmt::format("the fronts must be given in order of s: the {} at s0 = {:.9g} m comes after the "
                                   "{} at s0 = {:.9g} m",
                                   fronts_[k]->name(), fronts_[k]->expected_s0, fronts_[k - 1]->name(),
                                   fronts_[k - 1]->expected_s0));
}

template <int dim>
int FrontTracker<dim>::num_checks() const {
  int n = 0;
  for (const auto& front : fronts_) n += front->num_checks();
  return n;
}

template <int dim>
std::vector<std::unique_ptr<FrontKind<dim>>> heap_and_fold_fronts(std::vector<HeapSpec<dim>> heaps,
                                                                  const std::optional<FoldSpec>& fold, double ell,
                                                                  double h) {
  const HeapSpec<dim>* before = nullptr;
  const HeapSpec<dim>* after = nullptr;
  for (std::size_t k = 0; k < heaps.size(); ++k) {
    HeapSpec<dim>& heap = heaps[k];
    const bool at_end = heap.side == HeapSpec<dim>::Side::kAfter;
    check_heap_dissipation(heap);
    check_heap_s0(k, at_end, heap.s0, ell);
    if (std::abs(heap.s0 - ell) <= 1e-12 * ell) heap.s0 = ell;  // ℓ is a sum of link lengths
    if (std::abs(heap.s0) <= 1e-12 * ell) heap.s0 = 0;
    auto& slot = at_end ? after : before;
    check_one_heap_per_side(k, at_end, slot ? std::optional<std::size_t>(slot - heaps.data()) : std::nullopt);
    slot = &heap;
  }
  if (fold) {
    check_fold_dissipation(fold->dissipation);
    check_fold_s0(fold->s0, ell, before ? std::optional<double>(before->s0) : std::nullopt,
                  after ? std::optional<double>(after->s0) : std::nullopt);
  }
  if (before && after && after->s0 - before->s0 < 2 * h)
    throw InputError("the heaps are less than two links apart: use more nodes");
  std::vector<std::unique_ptr<FrontKind<dim>>> fronts;
  if (before) fronts.push_back(std::make_unique<HeapFront<dim>>(*before));
  if (fold) fronts.push_back(std::make_unique<FoldFront<dim>>(*fold));
  if (after) fronts.push_back(std::make_unique<HeapFront<dim>>(*after));
  return fronts;
}

template <int dim>
std::vector<ArcRange> FrontTracker<dim>::initial_arcs(const Chain<dim>& chain) {
  check_open_string(chain.closed(), std::any_of(fronts_.begin(), fronts_.end(),
                                                [](const auto& front) { return front->reservoir(); }));
  const int L = chain.num_links();
  const double h = chain.link_length(0);
  for (int j = 1; j < L; ++j)
    if (std::abs(chain.link_length(j) - h) > 1e-12 * h)
      throw InputError("a string with fronts needs links of equal material length");
  if (L < 2) throw InputError(fmt::format("a string with fronts needs at least 2 links, got {}", L));
  material_ = {h, chain.density(), chain.length(), chain.num_nodes()};
  // The arcs: the fronts bound the moving part of the material, then split it, in order of s.
  FrontLayout layout;
  layout.first = 0;
  layout.last = material_.n - 1;
  for (auto& front : fronts_) front->bind(material_);
  for (const auto& front : fronts_) front->trim(layout);
  for (auto& front : fronts_) front->cut(layout);
  std::vector<ArcRange> arcs;
  int first = layout.first;
  for (const int a : layout.splits) {
    arcs.push_back({first, a});
    first = a + 1;
  }
  arcs.push_back({first, layout.last});
  for (const auto& stop : options_.stop_at)
    if (stop.front < 0 || stop.front >= static_cast<int>(fronts_.size()))
      throw InputError(fmt::format("stop condition on front {}: the string has {} fronts", stop.front, fronts_.size()));
  fs_.assign(fronts_.size(), FrontState<dim>{});
  return arcs;
}

template <int dim>
void FrontTracker<dim>::initialize(StringModel<dim>& model) {
  // The fronts book the potential of the material off the nodes (partial links, heaps) in uniform
  // fields only (potential_correction): any other potential would leave the energy ledger open.
  for (const auto& force : model.forces())
    if (force->conservative() && !force->uniform_field())
      throw InputError(fmt::format("the {} effect is conservative but not a uniform field: the fronts book the "
                                   "potential energy of the partial links and of the heaps in uniform fields only",
                                   force->name()));
  for (auto& front : fronts_) front->initialize(model);
  try {
    model.refresh();
  } catch (const RecoverableError& e) {
    throw InputError(fmt::format("the initial shape does not fit the fronts: {}", e.what()));
  }
  // A front is where the links put it: a partial link is straight, so on a curved shape the front
  // lies off s0 by O(κ h²). That is accepted up to a tenth of a link; the masses follow the geometry.
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active &&
        std::abs(fs_[k].s0 - fronts_[k]->expected_s0) > std::max(1e-6 * material_.ell, 0.1 * material_.h))
      throw InputError(fmt::format(
          "the {} front is meant to be at s0 = {:.9g} m but the initial shape puts it at s0 = {:.9g} m: "
          "place the {} at the string's material point s0",
          fronts_[k]->name(), fronts_[k]->expected_s0, fs_[k].s0, fronts_[k]->placed()));
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active) fronts_[k]->check_initial(fs_[k]);
  // ARKODE finds a root only where its function changes sign in the watched direction: a front that starts
  // past one of its crossings (within kLastPartial of a link of a free end, or on a node) would never cross it.
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    if (!fronts_[k]->active) continue;
    double g[2];
    fronts_[k]->crossings(model, fs_[k], g);
    if (!(g[0] > 0) || !(fronts_[k]->second_direction() * g[1] < 0))
      throw InputError(fmt::format(
          "the {} front starts at s0 = {:.9g} m, past one of its crossings (root functions {:.3g} and {:.3g} "
          "of a link): it lies on a node of the mesh or within {} of a link of a free end; move s0 by {:.3g} m "
          "(a thousandth of a link) or more",
          fronts_[k]->name(), fs_[k].s0, g[0] / material_.h, g[1] / material_.h, kLastPartial,
          kLastPartial * material_.h));
  }
  heap_moment0_.setZero();
  for (std::size_t k = 0; k < fronts_.size(); ++k) fronts_[k]->add_held_moment(fs_[k], 0.0, heap_moment0_);
}

template <int dim>
void FrontTracker<dim>::add_mass_and_forces(const StringModel<dim>& model, Eigen::VectorXd& mass, Points<dim>& force) {
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active) fronts_[k]->evaluate(model, fs_[k], mass, force);
  // A node of the arcs whose mass the fronts took (a front overshot it) is refused by the model's refresh(),
  // in its pass over the free nodes (StringModel::lost_mass_floor_).
}

template <int dim>
std::optional<double> FrontTracker<dim>::front_tension_at(const StringModel<dim>& model, int node) const {
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (!fronts_[k]->active) continue;
    else if (const std::optional<double> tension = fronts_[k]->tension_at(model, fs_[k], node))
      return tension;
  return std::nullopt;
}

template <int dim>
void FrontTracker<dim>::node_constraints(const StringModel<dim>& model, std::vector<NodeConstraint<dim>>& out) const {
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active) fronts_[k]->constraints(model, fs_[k], out);
}

template <int dim>
bool FrontTracker<dim>::has_load_derivatives() const {
  return std::all_of(fronts_.begin(), fronts_.end(), [](const auto& front) { return front->has_load_derivatives(); });
}

template <int dim>
void FrontTracker<dim>::load_derivatives(StringModel<dim>& model, std::vector<LoadDerivative<dim>>& out) {
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active) fronts_[k]->add_load_derivatives(model, fs_[k], out);
}

template <int dim>
bool FrontTracker<dim>::events_need_tensions() const {
  return std::any_of(fronts_.begin(), fronts_.end(), [](const auto& front) { return front->checks_need_tensions(); });
}

template <int dim>
void FrontTracker<dim>::ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const {
  // [ W_shocks | W_heaps | impulse | heap moment ]: the external forces on the string are the
  // string's (applied forces, prescribed nodes' reactions) plus the fronts' supports' reactions.
  double w_shocks = 0, w_heaps = 0;
  Vec<dim> external = model.external_force(), heap_moment_rate = Vec<dim>::Zero();
  for (std::size_t k = 0; k < fs_.size(); ++k) {
    if (!fronts_[k]->active) continue;
    const FrontState<dim>& s = fs_[k];
    w_shocks += s.power_shock;
    w_heaps += s.power_heap;
    external += s.reaction;
    if (fronts_[k]->has_constraint_force()) external += fronts_[k]->constraint_force(model);
    fronts_[k]->add_held_moment_rate(s, heap_moment_rate);
  }
  rates[0] = w_shocks;
  rates[1] = w_heaps;
  rates.template segment<dim>(2) = external;
  rates.template segment<dim>(2 + dim) = heap_moment_rate;
}

template <int dim>
Eigen::VectorXd FrontTracker<dim>::ledger_scale(double mass, double speed, double length) const {
  Eigen::VectorXd scale(num_ledgers());
  scale.head(2).setConstant(mass * speed * speed);
  scale.segment(2, dim).setConstant(mass * speed);
  scale.tail(dim).setConstant(mass * length);
  return scale;
}

template <int dim>
double FrontTracker<dim>::potential_correction(const StringModel<dim>& model,
                                               const Eigen::Ref<const Eigen::VectorXd>& ledger) const {
  // The string's V lumps every mass on a node: a partial link of length l on its end node. The
  // potential energy counts it at its midpoint, and the held material at its first moment, in every
  // uniform field the forces declare (initialize() refuses any other conservative force).
  const Vec<dim> g = model.uniform_field();
  double first_moment = g.dot(heap_moment0_ + ledger.template segment<dim>(2 + dim));
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active) first_moment += fronts_[k]->potential_moment(model, fs_[k], g);
  return -first_moment;
}

template <int dim>
std::vector<LedgerTerm> FrontTracker<dim>::ledger_terms() const {
  using K = LedgerTerm::Kind;
  return {{"W_shocks", K::kWork}, {"W_heaps", K::kWork}, {"W_remesh", K::kNumerical}, {"heap_mass", K::kQuantity}};
}

template <int dim>
std::vector<int> FrontTracker<dim>::failed_checks(const Eigen::Ref<const Eigen::VectorXd>& g, bool after_event) const {
  // The checks come last in events(), after the crossings and the stops at s0, each front's in turn.
  auto q = static_cast<Eigen::Index>(2 * fronts_.size() + options_.stop_at.size());
  std::vector<int> found(static_cast<std::size_t>(g.size()), 0);
  bool any = false;
  for (const auto& front : fronts_) {
    for (int c = 0; c < front->num_checks(); ++c, ++q)
      if (front->active && (!after_event || front->check_after_events(c)) && g[q] < 0)
        found[static_cast<std::size_t>(q)] = -1, any = true;
  }
  return any ? found : std::vector<int>{};
}

template <int dim>
ObstacleDrawing FrontTracker<dim>::obstacles() const {
  ObstacleDrawing drawing;
  for (std::size_t k = 0; k < fronts_.size(); ++k) fronts_[k]->draw(static_cast<int>(k), drawing);
  return drawing;
}

template <int dim>
std::vector<FrontField> FrontTracker<dim>::front_fields() const {
  return {{"heap", false}, {"reaction", true}, {"plane_normal", true}};
}

template <int dim>
void FrontTracker<dim>::fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
                             ModuleLedger<dim>& out) const {
  out.fronts.clear();
  for (std::size_t k = 0; k < fs_.size(); ++k) {
    const FrontState<dim>& s = fs_[k];
    FrontRecord<dim> r{s.s0, s.s0_dot, s.position, fronts_[k]->recorded_reaction(model, s), {s.heap ? 1.0 : 0.0}};
    for (int d = 0; d < dim; ++d) r.fields.push_back(r.reaction[d]);
    for (int d = 0; d < dim; ++d) r.fields.push_back(s.plane_normal[d]);
    out.fronts.push_back(std::move(r));
  }
  out.impulse = ledger.template segment<dim>(2);
  out.has_momentum_ledger = true;
  double heap_mass = 0;
  out.support.setZero();
  const Vec<dim> g = model.uniform_field();
  for (std::size_t k = 0; k < fronts_.size(); ++k) fronts_[k]->add_support(fs_[k], g, heap_mass, out.support);
  // In the order of ledger_terms().
  out.terms = {ledger[0], ledger[1], w_remesh_, heap_mass};
}

template <int dim>
void FrontTracker<dim>::events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const {
  // A front that has left the string (FrontKind::active) keeps its root functions, held positive.
  for (std::size_t k = 0; k < fronts_.size(); ++k)
    if (fronts_[k]->active)
      fronts_[k]->crossings(model, fs_[k], g.data() + 2 * k);
    else
      g[2 * static_cast<Eigen::Index>(k)] = g[2 * static_cast<Eigen::Index>(k) + 1] = 1;
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k) {
    const auto& stop = options_.stop_at[k];
    g[2 * static_cast<int>(fronts_.size()) + static_cast<int>(k)] = fs_[static_cast<std::size_t>(stop.front)].s0 - stop.s;
  }
  // Then each front's own checks, positive while the run may go on.
  int q = 2 * static_cast<int>(fronts_.size()) + static_cast<int>(options_.stop_at.size());
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    if (fronts_[k]->active) {
      fronts_[k]->checks(model, fs_[k], g.data() + q);
    } else if (fronts_[k]->num_checks() > 0) {  // its formation takes its first check's slot
      g.segment(q, fronts_[k]->num_checks()).setOnes();
      g[q] = fronts_[k]->formation_margin(model);
    }
    q += fronts_[k]->num_checks();
  }
}

template <int dim>
std::vector<int> FrontTracker<dim>::event_directions() const {
  std::vector<int> dirs;
  for (const auto& front : fronts_) {
    dirs.push_back(-1);
    dirs.push_back(front->second_direction());
  }
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k) dirs.push_back(0);
  for (int k = 0; k < num_checks(); ++k) dirs.push_back(-1);
  return dirs;
}

template <int dim>
std::pair<double, double> FrontTracker<dim>::arm_corner(const StringModel<dim>& model, std::size_t k, int i, double t,
                                                       const char* when) const {
  // The turn of the arm at node i (the node before the front's split link's start, a − 1) against the turn
  // that the front's constraint reaction on i would make in quasi-static balance with the tension τ⁻ on
  // either side: τ⁻ (e2 − e1) + F = 0, F = Σ μ ∂C/∂x_i (docs/model.md §9, "Where the arm's corner comes from").
  if (i < 1 || i + 1 >= model.x().cols()) return {0.0, 0.0};
  const double prev_deg = i >= 2 ? std::acos(std::clamp((model.x().col(i - 1) - model.x().col(i - 2)).normalized().dot(
                                                           (model.x().col(i) - model.x().col(i - 1)).normalized()),
                                                       -1.0, 1.0)) * 180 / kPi
                                 : 0.0;
  const Vec<dim> e1 = (model.x().col(i) - model.x().col(i - 1)).normalized();
  const Vec<dim> e2 = (model.x().col(i + 1) - model.x().col(i)).normalized();
  Vec<dim> F = Vec<dim>::Zero();
  const auto& cs = model.node_constraints();
  const Eigen::VectorXd& mu = model.constraint_multipliers();
  for (std::size_t c = 0; c < cs.size() && static_cast<Eigen::Index>(c) < mu.size(); ++c)
    for (std::size_t q = 0; q < cs[c].nodes.size(); ++q)
      if (cs[c].nodes[q] == i) F += mu[static_cast<Eigen::Index>(c)] * cs[c].gradient.col(static_cast<Eigen::Index>(q));
  const double tau = fs_[k].tension_minus;
  const Vec<dim> turn = e2 - e1, predicted = tau > 0 ? Vec<dim>(-F / tau) : Vec<dim>(Vec<dim>::Zero());
  // Signed along the turn: the share of the corner the reaction accounts for.
  const double tn = turn.norm();
  const double along = tn > 0 ? predicted.dot(turn) / tn : 0.0;
  const double turn_deg = 2 * std::asin(std::min(1.0, 0.5 * tn)) * 180 / kPi;
  const double reaction_deg = 2 * std::asin(std::min(1.0, 0.5 * predicted.norm())) * 180 / kPi;
  // The front's own turn, its speed and l⁻/h, and the tension of the arm's link (i − 1, i) from the last
  // solve: the jump conditions ask τ⁻ = λ ṡ0² to match the arm's tension at the kink (docs/model.md §9).
  const double front_turn_deg = 180 - fs_[k].opening * 180 / kPi;
  const double arm_tension = i >= 1 ? model.link_tension(i - 1) : 0.0;
  if (trace_)
    std::fprintf(stderr, "%s\n",
                 fmt::format("arm_corner when={} t={:.9g} node={} turn_deg={:.6g} reaction_turn_deg={:.6g} "
                             "reaction_along_deg={:.6g} reaction_N={:.6e} tau={:.6e} turn_prev_deg={:.6g} "
                             "front_turn_deg={:.6g} s0_dot={:.6g} l_minus_h={:.6g} arm_tension={:.6e}",
                             when, t, i, turn_deg, reaction_deg, 2 * std::asin(std::clamp(0.5 * along, -1.0, 1.0)) * 180 / kPi,
                             F.norm(), tau, prev_deg, front_turn_deg, fs_[k].s0_dot, fs_[k].l_minus / material_.h,
                             arm_tension)
                     .c_str());
  return {turn_deg, reaction_deg};
}

template <int dim>
EventAction FrontTracker<dim>::handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                                             const std::vector<int>& found) {
  const int nf = static_cast<int>(fronts_.size());
  // A stop at a node's coordinate is reached at that node's crossing, an event a hair's breadth before it (an
  // edge crosses at 1e-8 h, and moves the material 2e-8 h on): its root function changes sign inside the
  // crossing's own handling, where no root is looked for (an edge's stop at s0 = 0.2 m on chain_over_peg.toml,
  // a node every 0.01 m, was passed by, and the run went on to the lift-off). It stops at any event within
  // kStopWindow h of its s0.
  constexpr double kStopWindow = 1e-6;
  for (std::size_t k = 0; k < options_.stop_at.size(); ++k)
    if (found[static_cast<std::size_t>(2 * nf) + k] != 0 ||
        std::abs(fs_[static_cast<std::size_t>(options_.stop_at[k].front)].s0 - options_.stop_at[k].s) <=
            kStopWindow * material_.h)
      return {EventAction::Kind::kStop,
              fmt::format("front {} reached s0 = {:.9g} m", options_.stop_at[k].front, options_.stop_at[k].s)};
  std::optional<std::size_t> forming;     // a front not yet in the string whose formation was found
  std::optional<std::size_t> dissolving;  // a front whose check found that it leaves the string (FrontKind::dissolves)
  for (std::size_t k = 0, q = static_cast<std::size_t>(2 * nf) + options_.stop_at.size(); k < fronts_.size(); ++k)
    for (int c = 0; c < fronts_[k]->num_checks(); ++c)
      if (found[q++] != 0 && fronts_[k]->active && fronts_[k]->dissolves(c) && !dissolving) dissolving = k;
  for (std::size_t k = 0, q = static_cast<std::size_t>(2 * nf) + options_.stop_at.size(); k < fronts_.size(); ++k)
    for (int c = 0; c < fronts_[k]->num_checks(); ++c)
      if (found[q++] != 0) {
        if (!fronts_[k]->active) {
          forming = k;
          continue;
        }
        // A front that dissolves stops nothing: its other checks found at the same root (a kink at rest outside
        // its kinked link: the outside check's sign follows ṡ0's) go with it.
        if (dissolving == k) continue;
        if (std::optional<RunEvent> event = fronts_[k]->check_event(model, fs_[k], t, c)) {
          event->front = static_cast<int>(k);
          events_.push_back(std::move(*event));
        }
        return {EventAction::Kind::kStop, fronts_[k]->check_failed(model, fs_[k], t, c)};
      }
  // Energy, momentum and held masses before, to book what the crossing changes.
  const double K_before = model.kinetic_energy();
  const Drawn before = drawn(model, ledger);
  const double E_before = before.energy;
  bool absorbed = false;
  std::optional<std::size_t> acted = forming ? forming : dissolving;  // the front the event moved
  // |v_a − v_(a−1)| on the front's stencil (a−1, a, b, b+1) before the event, for event_energies_ (only when
  // they are recorded, as the arm's corner and K + V between the re-layout and the projection below).
  double jump_before = 0;
  std::pair<double, double> corner_before{0.0, 0.0};
  if (record_ && !forming && !dissolving)
    for (int f = 0; f < nf; ++f)
      if ((found[static_cast<std::size_t>(2 * f)] != 0 || found[static_cast<std::size_t>(2 * f + 1)] != 0) &&
          fronts_[static_cast<std::size_t>(f)]->active) {
        const std::vector<int> nodes = fronts_[static_cast<std::size_t>(f)]->stencil(model);
        if (nodes.size() == 4) jump_before = (model.v().col(nodes[1]) - model.v().col(nodes[0])).norm();
        if (nodes.size() == 4) corner_before = arm_corner(model, static_cast<std::size_t>(f), nodes[0], t, "before");
        break;
      }
  if (forming && !insert_front(model, *forming, t))
    return {EventAction::Kind::kStop,
            fmt::format("a {} formed at t = {:.9g} s{}, and no link there fits it (its arms need a full link on either "
                        "side, and the arms' meeting point inside the kinked link)",
                        fronts_[*forming]->name(), t, fronts_[*forming]->where_formed(model))};
  bool dissolved = false;
  if (dissolving && !forming) {
    dissolve_front(model, *dissolving, t);
    dissolved = true;
  }
  for (int f = 0; f < nf && !forming && !dissolved; ++f) {
    const int e0 = found[static_cast<std::size_t>(2 * f)], e1 = found[static_cast<std::size_t>(2 * f + 1)];
    if (e0 == 0 && e1 == 0) continue;
    const auto k = static_cast<std::size_t>(f);
    if (!fronts_[k]->active) continue;
    acted = k;
    if (fronts_[k]->absorbed(model, fs_[k], e0)) {
      remove_front(model, k, t);
      absorbed = true;
      break;
    }
    const EventAction action = fronts_[k]->cross(model, fs_[k], e0);
    if (action.kind == EventAction::Kind::kStop) return action;
    ++transfers_;
    // A check that dissolves the front, already negative after the crossing (a kink whose new arm is a slack link):
    // ARKODE would find no sign change from here, so it dissolves now.
    model.refresh();
    std::vector<double> checks(static_cast<std::size_t>(fronts_[k]->num_checks()));
    if (!checks.empty()) fronts_[k]->checks(model, fs_[k], checks.data());
    for (int c = 0; c < fronts_[k]->num_checks(); ++c)
      if (fronts_[k]->dissolves(c) && checks[static_cast<std::size_t>(c)] < 0) {
        dissolve_front(model, k, t);
        dissolved = true;
        break;
      }
    break;  // one crossing per event; a simultaneous one is found again right after
  }
  // The new links are brought back to their lengths (a fold's arms are never exactly antiparallel
  // in the discrete state); the kinetic energy the crossing changes is booked. A front absorbed at a held
  // end leaves velocities that the string's constraints no longer allow (the merged link lengthens, the
  // end is held): they jump by an impact, the snap's law with the scene's restitution where slack is
  // allowed (perfectly inelastic otherwise), and the energy it changes is the front's last dissipation,
  // booked in W_shocks (docs/model.md §2.5, "A kink at a held end").
  model.refresh();
  const bool exact = acted && !forming && !absorbed && !dissolved && fronts_[*acted]->exact_crossing();
  const double K_moved = record_ || exact ? model.kinetic_energy() : 0.0;
  const double E_moved = record_ || exact ? K_moved + model.potential_energy(ledger) : 0.0;
  try {
    if (absorbed)
      model.impact(t, model.options().snap_restitution);
    else
      model.project(t);
  } catch (const NumericalError& e) {
    throw NumericalError(fmt::format("after a front {}: {}", absorbed ? "left the string" : "crossing", e.what()), t);
  }
  model.refresh();
  if (exact) {
    const double projected = model.kinetic_energy() + model.potential_energy(ledger) - E_moved;
    const double scale = model.physical_scales().energy;
    if (!(std::abs(projected) <= kCrossingProjectionTolerance * scale))
      throw NumericalError(
          fmt::format("after the crossing of front {} ({}) at t = {:.9g} s (s0 = {:.9g} m): the projection onto the links' "
                      "lengths changed K + V by {:.3g} J, more than {:g} of the energy scale {:.3g} J (on straight "
                      "sides it is round-off): the crossing left the string far from its constraints, and the run "
                      "past it would not be the string's motion. A side that reaches the point swinging or curved "
                      "does this: an edge takes material that reaches it along a straight side only, and a peg with "
                      "a radius ([[effects.cylinder]]) takes swinging sides (docs/scenes.md, \"Sides that swing\"; "
                      "docs/model.md §8, \"Why a swinging side fails at the point\")",
                      *acted, fronts_[*acted]->name(), t, fs_[*acted].s0, projected, kCrossingProjectionTolerance, scale),
          t);
  }
  // The material a crossing moves between an arc and a heap (the front is re-drawn through the new
  // end node: O(h³) of material) goes with its momentum and is laid at the front; a heap crossing
  // also re-lumps the end's material on the nodes with their own velocities (the lumped momentum
  // changes by O(h²), what the lumped partial link missed, docs/shocks.md), and the projection
  // acts through fixed nodes. All of it is the supports' impulse; the energy it changes is W_remesh.
  const double changed = book_redrawing(model, ledger, before);
  double corner_after = 0;
  if (record_ && acted && !forming && !absorbed && !dissolved) {
    const std::vector<int> nodes = fronts_[*acted]->stencil(model);
    if (nodes.size() == 4) corner_after = arm_corner(model, *acted, nodes[0], t, "after").first;
  }
  if (record_ && acted) {
    const EventEnergy record{t, forming ? "insert" : absorbed ? "absorb" : dissolved ? "dissolve" : "cross", static_cast<int>(*acted),
                             E_moved - E_before, K_moved - K_before, changed - (E_moved - E_before), jump_before,
                             corner_before.first, corner_after, corner_before.second};
    event_energies_.push_back(record);
    if (trace_)
      std::fprintf(stderr, "%s\n",
                   fmt::format("front_event t={:.9g} kind={} front={} relayout={:.6e} relayout_K={:.6e} projection={:.6e} jump_before={:.6e} "
                               "s0={:.9g} s0_dot={:.6g}",
                               t, record.kind, record.front, record.relayout, record.relayout_kinetic, record.projection, record.jump_before,
                               fs_[*acted].s0, fs_[*acted].s0_dot)
                       .c_str());
  }
  if (absorbed)
    ledger[0] += changed;
  else
    w_remesh_ += changed;
  return {EventAction::Kind::kTransfer, {}};
}

template <int dim>
typename FrontTracker<dim>::Drawn FrontTracker<dim>::drawn(const StringModel<dim>& model,
                                                           const Eigen::Ref<const Eigen::VectorXd>& ledger) const {
  Drawn d;
  d.energy = model.kinetic_energy() + model.potential_energy(ledger);
  d.momentum = model.momentum();
  d.held.resize(fronts_.size());
  for (std::size_t k = 0; k < fronts_.size(); ++k) d.held[k] = fronts_[k]->held_mass(fs_[k]);
  return d;
}

template <int dim>
double FrontTracker<dim>::book_redrawing(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> ledger,
                                         const Drawn& before) const {
  ledger.template segment<dim>(2) += model.momentum() - before.momentum;
  for (std::size_t k = 0; k < fronts_.size(); ++k) {
    Vec<dim> moment = ledger.template segment<dim>(2 + dim);
    fronts_[k]->add_held_moment(fs_[k], before.held[k], moment);
    ledger.template segment<dim>(2 + dim) = moment;
  }
  return model.kinetic_energy() + model.potential_energy(ledger) - before.energy;
}

template <int dim>
void FrontTracker<dim>::hold_fronts() {
  for (auto& front : fronts_)
    if (front->active) front->hold_drawing(true);
}

template <int dim>
void FrontTracker<dim>::redraw_fronts(StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> ledger) {
  // A heap's curve to its plane runs through the arc's links up to the first slack one (curve_links in
  // heap_front.cpp). A snap that makes the link next to the end node taut again (or separates it) changes that
  // curve, and the front jumps to where the new one meets the plane: the partial link's length, the end node's
  // mass and the heap's content jump at fixed positions and velocities. Unbooked, each such snap took
  // ½ λ δl |v|² and λ δl v out of the ledgers (the falling chain with shortening links on 161 nodes: 4.3e-4 J and
  // 3.1e-5 of the momentum, the same at every rtol).
  model.refresh();  // the state after the impulse, the fronts as held
  const Drawn before = drawn(model, ledger);
  for (auto& front : fronts_) front->hold_drawing(false);
  model.refresh();
  w_remesh_ += book_redrawing(model, ledger, before);
}

template <int dim>
bool FrontTracker<dim>::insert_front(StringModel<dim>& model, std::size_t k, double t) {
  FrontKind<dim>& front = *fronts_[k];
  if (!front.insert(model)) return false;
  const int split = front.arc_minus;  // arc `split` became arcs split, split + 1
  front.active = true;
  for (auto& other : fronts_) {
    if (other.get() == &front) continue;
    if (other->arc_minus >= split) ++other->arc_minus;
    if (other->arc_plus > split) ++other->arc_plus;
  }
  model.refresh();
  const FrontState<dim>& s = fs_[k];
  RunEvent event{fmt::format("{}_inserted", front.name()), t, static_cast<int>(k), {}, {{"s0", s.s0}, {"s0_dot", s.s0_dot}}};
  for (int d = 0; d < dim; ++d) event.position.push_back(s.position[d]);
  events_.push_back(std::move(event));
  return true;
}

template <int dim>
void FrontTracker<dim>::dissolve_front(StringModel<dim>& model, std::size_t k, double t) {
  const int a = model.arcs()[static_cast<std::size_t>(fronts_[k]->arc_minus)].last;  // the split link (a, a + 1)
  remove_front(model, k, t, "dissolved");
  if (!model.allows_slack()) return;
  const Chain<dim>& chain = model.chain();
  for (int j = std::max(0, a - 1); j <= std::min(chain.num_links() - 1, a + 1); ++j) {
    const double length = (model.x().col(chain.link_end(j)) - model.x().col(chain.link_start(j))).norm();
    if (length < (1 - StringModel<dim>::kSlackGap) * chain.link_length(j)) model.set_slack(j, true);
  }
  model.rebuild();
}

template <int dim>
void FrontTracker<dim>::remove_front(StringModel<dim>& model, std::size_t k, double t, const char* what) {
  FrontKind<dim>& front = *fronts_[k];
  const int gone = front.arc_plus;  // arcs A and B become one: the arcs after B shift down by one
  front.active = false;
  front.remove(model, fs_[k]);
  for (auto& other : fronts_) {
    if (other.get() == &front) continue;
    if (other->arc_minus >= gone) --other->arc_minus;
    if (other->arc_plus >= gone) --other->arc_plus;
  }
  FrontState<dim>& s = fs_[k];
  RunEvent event{fmt::format("{}_{}", front.name(), what), t, static_cast<int>(k), {}, {{"s0", s.s0}, {"s0_dot", s.s0_dot}}};
  for (int d = 0; d < dim; ++d) event.position.push_back(s.position[d]);
  events_.push_back(std::move(event));
  // Its record from now on: where it left, at rest in the material, carrying nothing.
  s.s0_dot = 0;
  s.tension_minus = s.tension_plus = 0;
  s.power_shock = s.power_heap = 0;
  s.reaction.setZero();
}

template <int dim>
StringModel<dim> make_front_model(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                                  std::vector<PrescribedNode<dim>> prescribed,
                                  std::vector<std::unique_ptr<FrontKind<dim>>> fronts, const FrontOptions& options,
                                  const StringModelOptions& model_options) {
  return StringModel<dim>(std::move(chain), std::move(forces), std::move(prescribed), model_options,
                          std::make_unique<FrontTracker<dim>>(std::move(fronts), options));
}

template <int dim>
StringModel<dim> make_front_model(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                                  std::vector<PrescribedNode<dim>> prescribed, std::vector<HeapSpec<dim>> heaps,
                                  std::optional<FoldSpec> fold, const FrontOptions& fronts,
                                  const StringModelOptions& options) {
  // An end on a heap's side is inside the heap: neither prescribed nor loaded.
  auto held = [&](int node) -> std::string {
    for (const auto& p : prescribed)
      if (p.node == node) return "prescribed";
    for (const auto& force : forces)
      if (const auto* load = dynamic_cast<const EndLoad<dim>*>(force.get()); load && load->node() == node) return "loaded";
    return "";
  };
  for (std::size_t k = 0; k < heaps.size(); ++k) {
    const bool at_end = heaps[k].side == HeapSpec<dim>::Side::kAfter;
    check_end_free(k, at_end, heaps[k].s0, held(at_end ? chain.num_nodes() - 1 : 0));
  }
  check_open_string(chain.closed(), !heaps.empty());  // before the fronts' own checks
  const double h = chain.num_links() > 0 ? chain.link_length(0) : 0.0;
  std::vector<std::unique_ptr<FrontKind<dim>>> kinds =
      heap_and_fold_fronts<dim>(std::move(heaps), fold, chain.length(), h);
  return make_front_model<dim>(std::move(chain), std::move(forces), std::move(prescribed), std::move(kinds), fronts,
                               options);
}

template class FrontTracker<2>;
template class FrontTracker<3>;
template StringModel<2> make_front_model<2>(Chain<2>, std::vector<std::unique_ptr<Force<2>>>,
                                            std::vector<PrescribedNode<2>>, std::vector<HeapSpec<2>>,
                                            std::optional<FoldSpec>, const FrontOptions&, const StringModelOptions&);
template StringModel<3> make_front_model<3>(Chain<3>, std::vector<std::unique_ptr<Force<3>>>,
                                            std::vector<PrescribedNode<3>>, std::vector<HeapSpec<3>>,
                                            std::optional<FoldSpec>, const FrontOptions&, const StringModelOptions&);
template StringModel<2> make_front_model<2>(Chain<2>, std::vector<std::unique_ptr<Force<2>>>,
                                            std::vector<PrescribedNode<2>>, std::vector<std::unique_ptr<FrontKind<2>>>,
                                            const FrontOptions&, const StringModelOptions&);
template StringModel<3> make_front_model<3>(Chain<3>, std::vector<std::unique_ptr<Force<3>>>,
                                            std::vector<PrescribedNode<3>>, std::vector<std::unique_ptr<FrontKind<3>>>,
                                            const FrontOptions&, const StringModelOptions&);
template std::vector<std::unique_ptr<FrontKind<2>>> heap_and_fold_fronts<2>(std::vector<HeapSpec<2>>,
                                                                            const std::optional<FoldSpec>&, double,
                                                                            double);
template std::vector<std::unique_ptr<FrontKind<3>>> heap_and_fold_fronts<3>(std::vector<HeapSpec<3>>,
                                                                            const std::optional<FoldSpec>&, double,
                                                                            double);

}  // namespace chainsim
