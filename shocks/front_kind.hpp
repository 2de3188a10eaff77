#pragma once
/// @file front_kind.hpp
/// What one kind of front does (docs/shocks.md; the recipe "a new kind of front" in
/// docs/architecture.md). The tracker (front_tracker.hpp) keeps what all kinds share: the arcs, the
/// booking of the ledgers and of the crossings, the stop events. A kind says
///   - how it cuts the material into arcs (its share of the initial layout: `trim`, `cut`);
///   - the masses and known loads it adds at every evaluation, and its FrontState (`evaluate`), whose
///     tensions, powers and reaction it computes with the jump conditions (jump_conditions.hpp);
///   - its two root functions (`crossings`) and what a crossing does (`cross`), and any root function
///     of its own that stops the run (`num_checks`, `checks`, `check_failed`);
///   - its share of the ledgers: the material it holds outside the arcs (`held_mass`, its first
///     moment), and the potential energy of its partial links (`potential_moment`).
/// Implementations: HeapFront (heap_front.hpp), FoldFront (fold_front.hpp), KinkFront (kink_front.hpp; the
/// fold, the kink and the touchdown share SplitLinkFront, split_link_front.hpp), EdgeFront (edge_front.hpp),
/// TouchdownFront (touchdown_front.hpp).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "solver/string_model.hpp"

namespace chainsim {

/// How far past a node's layout a front's crossing threshold lies, in links: a root function that a
/// crossing, or the initial layout, leaves exactly at zero is not reported by ARKODE (it finds sign
/// changes), and a front at rest on its threshold crosses back and forth on round-off. Heaps widen their
/// band [h/2, 3h/2] by it (heap_front.cpp), folds cross at a partial link of −kCrossingHysteresis·h
/// (fold_front.hpp; docs/shocks.md, "A fold at rest on a node").
inline constexpr double kCrossingHysteresis = 1e-6;

/// A front cannot cross a free end of the string: the end node's mass is the partial link's, λ l, which vanishes as
/// the front reaches it (the trial states past it are refused, "a node has lost its mass", until the steps stall).
/// The run stops when that partial link is this short, in links: a heap whose last node cannot be taken in
/// (heap_front.cpp), a fold or a kink that reaches a free end (split_link_front.hpp).
inline constexpr double kLastPartial = 1e-3;

/// The material the fronts cut: set once the chain is known.
struct FrontMaterial {
  double h = 0;       ///< material length of a link (m)
  double lambda = 0;  ///< linear density (kg/m)
  double ell = 0;     ///< length of the string (m)
  int n = 0;          ///< number of nodes
};

/// The initial layout while the fronts cut it: the moving nodes run from `first` to `last`; each
/// entry of `splits` ends an arc at that node (the next one starts at the node after); `arc` is the
/// arc on the side of larger s of the fronts cut so far.
struct FrontLayout {
  int first = 0, last = 0;
  std::vector<int> splits;
  int arc = 0;
};

/// Geometry and jump quantities of one front at one state (what the kinds compute and the tracker
/// books; the outputs see its FrontRecord, solver/string_module.hpp).
template <int dim>
struct FrontState {
  double s0 = 0;         ///< material coordinate of the front (m)
  double s0_dot = 0;     ///< its speed in the material (m/s)
  double l_minus = 0, l_plus = 0;  ///< partial-link lengths on either side (heap side: 0)
  Vec<dim> direction = Vec<dim>::Zero();  ///< e: heap: from the arc to x0; fold: into the fold along arc A
  Vec<dim> position = Vec<dim>::Zero();   ///< x0 (m)
  double tension_minus = 0, tension_plus = 0;  ///< τ∓ at the front (N); heap side: 0
  double inflow = 0;       ///< heap: w, speed of material entering the arc (m/s)
  double power_shock = 0;  ///< W_s = −D (W)
  double power_heap = 0;   ///< W* (W), heaps only
  Vec<dim> reaction = Vec<dim>::Zero();  ///< heap: the support's reaction on the string at the front (N)
  double opening = 0;  ///< fold: angle between arc A's end link and arc B's first link reversed (rad)
  bool heap = false;   ///< a heap's front (else a fold)
  Vec<dim> plane_normal = Vec<dim>::Zero();  ///< a heap on a plane: the plane's unit normal; else zero
};

template <int dim>
class FrontKind {
 public:
  virtual ~FrontKind() = default;

  double dissipation = 0;  ///< f of the front's internal shock, in [0, 1]
  double expected_s0 = 0;  ///< where the front is meant to start (m)
  int arc_minus = -1, arc_plus = -1;  ///< arcs on either side (−1: the side of a reservoir, e.g. a heap)
  /// False once the front has left the string (a kink absorbed at a held end, docs/model.md §2.5): the
  /// tracker then skips it (no masses, loads, constraints or ledger rates; root functions held positive),
  /// and its record keeps the state it had when it left.
  bool active = true;

  /// "heap", "fold": the kind's name in messages and in the scene description.
  virtual const char* name() const = 0;
  /// What the scene places at the front's material point s0, for messages ("heap point", "fold").
  virtual const char* placed() const = 0;
  /// Whether the front holds material outside the arcs on one side (a heap's reservoir), for messages.
  virtual bool reservoir() const { return false; }

  /// The material, before the layout.
  void bind(const FrontMaterial& material) { m_ = material; }

  // --- layout ------------------------------------------------------------------------------------
  /// First pass over the fronts in order of s: bound the moving part of the material.
  virtual void trim(FrontLayout& /*layout*/) const {}
  /// Second pass, in order of s: split the moving part and take the arcs on either side.
  virtual void cut(FrontLayout& layout) = 0;
  /// Checks of the initial shape before the first evaluation (InputError); a kind may set up the
  /// string there (an edge bends the link it lies in, StringModel::bend_link).
  virtual void initialize(StringModel<dim>& /*model*/) {}
  /// Checks of the initial state after the first evaluation (InputError).
  virtual void check_initial(const FrontState<dim>& /*state*/) const {}

  // --- one evaluation ----------------------------------------------------------------------------
  /// Adds the front's masses and known loads and writes its state (the jump conditions).
  virtual void evaluate(const StringModel<dim>& model, FrontState<dim>& state, Eigen::VectorXd& mass,
                        Points<dim>& force) = 0;
  /// The end tension of the jump conditions at an arc's end node on the front's side, if `node` is one.
  virtual std::optional<double> tension_at(const StringModel<dim>& model, const FrontState<dim>& state,
                                           int node) const = 0;

  // --- the linearisation (the implicit path's Newton systems) ---------------------------------------
  /// The free nodes whose positions and velocities evaluate() reads for its masses and loads; they
  /// include the nodes it loads. Empty: the kind does not say (its loads then stay out of the Newton
  /// systems, and implicit methods take them through GMRES).
  virtual std::vector<int> stencil(const StringModel<dim>& /*model*/) const { return {}; }
  /// Whether the kind gives its stencil (then add_load_derivatives() gives all its derivatives).
  virtual bool has_load_derivatives() const { return false; }
  /// Adds the derivatives of evaluate()'s masses and loads with respect to the positions and
  /// velocities of the stencil's nodes, at the string's current state (after an evaluation, whose
  /// state it restores). By default central differences of evaluate() itself (consistent to about
  /// 1e-10 of the loads: the loads are smooth in the stencil between crossings); a kind with its
  /// derivatives in closed form may override it.
  virtual void add_load_derivatives(StringModel<dim>& model, FrontState<dim>& state,
                                    std::vector<LoadDerivative<dim>>& out);

  // --- ledgers -----------------------------------------------------------------------------------
  /// Mass the front holds outside the arcs (kg): a heap's content.
  virtual double held_mass(const FrontState<dim>& /*state*/) const { return 0; }
  /// Adds the rate of the first moment of that mass (kg m/s).
  virtual void add_held_moment_rate(const FrontState<dim>& /*state*/, Vec<dim>& /*rate*/) const {}
  /// Adds the first moment (kg m) of the held mass at the start, or the change `held_mass − before` a
  /// crossing made (laid at the front).
  virtual void add_held_moment(const FrontState<dim>& /*state*/, double /*before*/, Vec<dim>& /*moment*/) const {}
  /// Adds the held mass and the force the front's support exerts on the system (its reaction, and the
  /// weight of the held mass under the uniform field g).
  virtual void add_support(const FrontState<dim>& /*state*/, const Vec<dim>& /*g*/, double& /*mass*/,
                           Vec<dim>& /*support*/) const {}
  /// The correction to the lumped potential g·Σ m x of the front's partial links: g·(their first
  /// moment about their midpoints − the lumped one) (kg m²/s²).
  virtual double potential_moment(const StringModel<dim>& model, const FrontState<dim>& state,
                                  const Vec<dim>& g) const = 0;

  // --- events ------------------------------------------------------------------------------------
  /// The front's two crossing root functions, g[0] and g[1].
  virtual void crossings(const StringModel<dim>& model, const FrontState<dim>& state, double* g) const = 0;
  /// The direction ARKODE watches g[1] in (g[0]: −1).
  virtual int second_direction() const = 0;
  /// Acts on a crossing (e0: g[0] was found, else g[1]): moves material between the arcs or the front.
  virtual EventAction cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) = 0;
  /// Whether the crossing e0 takes the front out of the string (a kink that reaches a held end, docs/model.md
  /// §2.5): the tracker then calls remove() instead of cross(), and the velocities jump by an impact.
  virtual bool absorbed(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/, int /*e0*/) const {
    return false;
  }
  /// Takes the front out of the string: its two arcs become one (model.arcs(), then model.rebuild()), the
  /// material it split between them lumped as the string lumps a full link, moving with its momentum.
  virtual void remove(StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/) {
    throw Error(fmt::format("a {} front cannot be removed", name()));
  }
  /// A front that is not in the string yet (active false) and may be inserted where its kind forms (a kink
  /// where the string's tangent turns sharply): its formation root function, positive until then (it takes
  /// the slot of the front's first check). 1 for a kind that never forms.
  virtual double formation_margin(const StringModel<dim>& /*model*/) const { return 1; }
  /// Puts the front into the string where it formed: splits an arc (model.arcs(), then model.rebuild()) and
  /// sets arc_minus, arc_plus; returns false if no place fits (the run then stops).
  virtual bool insert(StringModel<dim>& /*model*/) { return false; }
  /// Where the front formed, for the message of an insertion that found no place (" at node j (s = … m, at […])");
  /// empty for a kind that does not say.
  virtual std::string where_formed(const StringModel<dim>& /*model*/) const { return {}; }
  /// Constraints of the front that couple nodes beyond the links (NodeConstraint, a kink's
  /// compatibility), at the string's current state, after `evaluate`.
  virtual void constraints(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/,
                           std::vector<NodeConstraint<dim>>& /*out*/) const {}
  /// The net force of the front's constraints on the string at their current multipliers (after the
  /// tension solve): zero for constraints that only couple nodes (a kink's); the momentum ledger books it.
  virtual Vec<dim> constraint_force(const StringModel<dim>& /*model*/) const { return Vec<dim>::Zero(); }
  virtual bool has_constraint_force() const { return false; }
  /// Whether the projection onto the links' lengths after this front's crossing changes K + V by
  /// round-off only (the crossing re-lays the string exactly, as an edge's does on straight sides): the
  /// tracker then stops the run, located, where a projection changes it by more than
  /// FrontTracker::kCrossingProjectionTolerance of the energy scale (a crossing that left the string far
  /// from its constraints), rather than run on with a motion that is not the string's.
  virtual bool exact_crossing() const { return false; }
  /// Holds (`hold`) the front drawn as at its last evaluation while an impulse changes which links are slack
  /// (the snaps of the slack module: a heap's curve on a plane stops at a slack link), or lets it be drawn on the
  /// links as they are again (FrontTracker::redraw_fronts, which books what the re-drawing moves).
  virtual void hold_drawing(bool /*hold*/) {}
  /// Root functions of the front's own that stop the run (positive while it may go on).
  virtual int num_checks() const { return 0; }
  virtual void checks(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/, double* /*g*/) const {}
  /// What stopped the run where check `check` (0 … num_checks() − 1) reached zero at t (the reason).
  virtual std::string check_failed(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/,
                                   double /*t*/, int /*check*/) const {
    return {};
  }
  /// Whether `checks` read the string's tensions (then the string solves for them before the root
  /// functions are evaluated).
  virtual bool checks_need_tensions() const { return false; }
  /// Whether check `check` (0 … num_checks() − 1), already negative right after an event's handling (a crossing's
  /// re-layout, a snap), stops the run there (StringModule::events_failed_after_event): ARKODE restarts from that
  /// state and finds only sign changes, so such a check would otherwise go unseen.
  virtual bool check_after_events(int /*check*/) const { return true; }
  /// Whether check `check` reaching zero takes the front out of the string instead of stopping the run: the tracker
  /// removes it there (FrontKind::remove, the summary's event named after the front with `_dissolved`, e.g. `kink_dissolved`), the split link's material
  /// re-lumped with its momentum and the energy that changes booked in W_remesh (a kink that no longer carries a
  /// shock, docs/model.md §9, "A kink that comes to rest").
  virtual bool dissolves(int /*check*/) const { return false; }
  /// The physical event that check `check` reaching zero is (the run's summary lists it in `events`), if any.
  virtual std::optional<RunEvent> check_event(const StringModel<dim>& /*model*/, const FrontState<dim>& /*state*/,
                                              double /*t*/, int /*check*/) const {
    return std::nullopt;
  }
  /// The force of the front's obstacle or support on the string that the outputs show (R_front<k>
  /// in forces.csv), after an evaluation: by default the state's reaction.
  virtual Vec<dim> recorded_reaction(const StringModel<dim>& /*model*/, const FrontState<dim>& state) const {
    return state.reaction;
  }
  /// Adds the obstacle this front models, as obstacle number `index`, to the ParaView drawing (none
  /// by default: a heap or a fold is no obstacle).
  virtual void draw(int /*index*/, ObstacleDrawing& /*drawing*/) const {}

 protected:
  FrontMaterial m_;
};

template <int dim>
void FrontKind<dim>::add_load_derivatives(StringModel<dim>& model, FrontState<dim>& state,
                                          std::vector<LoadDerivative<dim>>& out) {
  const std::vector<int> nodes = stencil(model);
  if (nodes.empty()) return;
  const int n = model.chain().num_nodes();
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(n);
  Points<dim> force = Points<dim>::Zero(dim, n);
  // Steps: ε^(1/3) of the link for positions (central differences: error ~ε^(2/3) of the loads); the
  // same fraction of the stencil's speed for velocities (the loads are quadratic in them, so the
  // quotient is exact but for round-off).
  double speed = 0;
  for (int i : nodes) speed = std::max(speed, model.v().col(i).norm());
  const double dx = 6e-6 * this->m_.h, dv = 6e-6 * std::max(speed, 1e-3);
  const std::size_t first = out.size();
  for (int k : nodes)
    for (int i : nodes) {
      out.emplace_back();
      out.back().node = k;
      out.back().of = i;
      out.emplace_back();
      out.back().node = k;
      out.back().of = i;
      out.back().velocity = true;
    }
  const std::size_t per = nodes.size();
  for (std::size_t c = 0; c < per; ++c) {
    const int i = nodes[c];
    for (int velocity = 0; velocity < 2; ++velocity) {
      Points<dim>& y = velocity ? model.v() : model.x();
      const double step = velocity ? dv : dx;
      for (int q = 0; q < dim; ++q) {
        const double keep = y(q, i);
        for (int side = 0; side < 2; ++side) {
          y(q, i) = side ? keep - step : keep + step;
          try {
            this->evaluate(model, state, mass, force);
          } catch (...) {  // a trial state the kind refuses: the string as it was, then the caller decides
            y(q, i) = keep;
            throw;
          }
          const double sign = side ? -1.0 : 1.0;
          for (std::size_t r = 0; r < per; ++r) {
            const int k = nodes[r];
            LoadDerivative<dim>& d = out[first + 2 * (r * per + c) + static_cast<std::size_t>(velocity)];
            d.force.col(q) += sign * force.col(k) / (2 * step);
            d.mass[q] += sign * mass[k] / (2 * step);
            force.col(k).setZero();
            mass[k] = 0;
          }
        }
        y(q, i) = keep;
      }
    }
  }
  this->evaluate(model, state, mass, force);  // the state (and the kind's own) at the unmoved string
}

/// d / |d|, or a RecoverableError naming `what` when d has no length.
template <int dim>
Vec<dim> unit_vector(const Vec<dim>& d, const char* what) {
  const double n = d.norm();
  if (!(n > 0) || !std::isfinite(n)) throw RecoverableError(fmt::format("{} has zero length", what));
  return d / n;
}

}  // namespace chainsim
