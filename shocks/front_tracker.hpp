#pragma once
/// @file front_tracker.hpp
/// Front tracking: the module (solver/string_module.hpp) that makes the one discrete string
/// (solver/string_model.hpp) carry shocks as moving fronts (docs/shocks.md, docs/model.md).
///
/// Material. An open string of N equal links (material length h = ℓ/N), nodes i = 0..N at material
/// coordinate s_i = i h. The material line is cut at *fronts* into *arcs* (runs of moving nodes) and
/// *heaps* (quiescent, shapeless reservoirs). Two kinds of front (each a FrontKind, front_kind.hpp):
///
///   heap   a quiescent heap, either fed through a fixed point x0 (a pile under a hole, an edge:
///          *pinned*) or lying on a plane (the table under a falling chain). The arc ends in a
///          *partial link* of material length l from its end node k to the contact (s0 = s_k ± l):
///          the string there is the quadratic interpolant x(s) (docs/shocks.md, "Second order at a
///          moving front"), e its unit tangent at the contact (from the arc into the heap):
///              pinned     through x_{k∓1}, x_k and the contact x0; l = |x0 − x_k|
///              on a plane through the last three nodes (point p, normal n), s0 its root of
///                         n·(x(s0) − p) = 0; the contact x(s0) slides along the plane
///          w = dl/dt is the rate at which the arc gains material (w < 0: it runs into the heap).
///          Jump conditions (the internal shock of dissipation f at the contact plus the external
///          shock at the heap, docs/shocks.md):
///              end tension  τ = λ w² (1 + f sgn w)
///              W_s = −f λ |w|³ (internal shock)
///              reaction on the string  R = τ e + λ w v_k,  heap power W* = τ e·v_k + ½ λ w |v_k|² − W_s
///          (R and W* are what the discrete string exchanges with the heap; for a string moving along
///          itself they are the paper's (τ − λ w²) e and −½ λ w³). The heap is held at rest by its
///          support: on a tilted string R has a component along the plane (friction, no slip).
///          Falling chain: w = −ẏ < 0, τ = (1 − f) λ ẏ²; sliding chain: w = ẏ > 0, τ = (1 + f) λ ẏ².
///
///   fold   an internal shock at a fold (the bight of a folded chain) between arc A (s < s0) and
///          arc B (s > s0). Momentum balance at a kink with f > 0 is only possible where the arcs
///          are antiparallel (t⁺ = −t⁻): the fold. With e the direction into the fold (along arc A's
///          end tangent), [v] = 2 ṡ0 e, so
///              ṡ0 = ½ (v⁺ − v⁻)·e,   τ⁻ = λ ṡ0² (1 + f sgn ṡ0),   τ⁺ = λ ṡ0² (1 − f sgn ṡ0),
///              W_s = −2 f λ |ṡ0|³,
///          both ends pulled towards the fold along e. The folded link (a, b) holds the fold; its
///          material splits into l_A = ½ (h + (x_b − x_a)·e) on arc A and l_B = h − l_A on arc B.
///
/// Discretization. The string lumps half of each full link of an arc on its nodes; the tracker adds
/// the whole partial link to the arc's end node at a front (so an arc's mass is exactly λ × its
/// material length), and the front forces as known loads of the tension system of each arc. For motions along a straight line (the paper's three problems) the scheme is
/// exact: it reproduces the reduced ODE for every N.
///
/// Front crossings are ARKODE root events (two per front): a heap takes the end node in when the
/// partial link shrinks to h/2 (every other node keeps its state) and gives out a new node when it
/// grows to 3h/2 (at the interpolant's position and velocity there), both thresholds moved out by
/// 1e-6 h so that no crossing, and no initial layout, leaves a front on a threshold (docs/shocks.md,
/// "Model"); a fold moves the node it reaches
/// from one arc to the other, its material moving with its momentum (mass parcels). What a crossing
/// changes in the lumped momentum and energy is booked (heap impulse, W_remesh; zero for straight
/// motions). Then the string rebuilds its arcs, projects positions and velocities onto the link
/// constraints (StringModel::project) and the integration continues with the new state size.
///
/// The tracker's ledgers follow the string's state [ x | v | W_applied ]:
///              [ W_shocks | W_heaps | impulse (dim) | heap moment (dim) ]
///   W_shocks   Σ over internal shocks of W_s = −D (dissipation, ≤ 0)
///   W_heaps    Σ over heaps of W* (external shocks)
///   impulse    ∫ (all external forces on the string and heaps) dt: gravity, drag, loads, the
///              reactions of fixed/driven nodes and of the planes under the heaps, plus what the
///              crossings change in Σ m_i v_i (the re-lumped end's momentum, taken by the heap's support)
///   heap moment  change of Σ over heaps of ∫ x dm (kg m): material laid on a plane stays where the
///              contact was when it arrived, so the heaps' potential energy needs their first moment
/// Ledgers: K + V − (K0 + V0) − W_applied − W_shocks − W_heaps − W_remesh → 0 and
///          p − p0 − impulse → 0 (p = Σ m_i v_i; heaps are at rest), to the discretization error.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "shocks/fold_front.hpp"
#include "shocks/front_kind.hpp"
#include "shocks/heap_front.hpp"
#include "solver/string_model.hpp"
#include "solver/wrapping_module.hpp"

namespace chainsim {

struct FrontOptions {
  /// Stop when a front's material coordinate reaches this value (front index, s (m)); the run also
  /// stops when a front reaches an end of the string or a heap runs empty.
  struct StopAt {
    int front = 0;
    double s = 0;
  };
  std::vector<StopAt> stop_at;
};

/// The module of a string with fronts. It keeps what every kind of front shares (front_kind.hpp): the
/// layout of the arcs, the booking of the ledgers and of the crossings, the stop events; each front's
/// own physics is its FrontKind (HeapFront, FoldFront).
template <int dim>
class FrontTracker final : public StringModule<dim> {
 public:
  /// The largest change of K + V, per the energy scale, that the projection after an exact crossing
  /// (FrontKind::exact_crossing) may make before the run stops: its round-off is 1e-11 of the scale and
  /// less; the crossings that broke on rotated or off-origin edges before their cure changed it by 4.7e-4 to
  /// 1.2e-1 of it (docs/model.md §8, "Round-off at a crossing").
  static constexpr double kCrossingProjectionTolerance = 1e-6;
  /// The fronts, in order of s: fronts()[k] is front k's FrontKind.
  class Fronts {
   public:
    explicit Fronts(const std::vector<std::unique_ptr<FrontKind<dim>>>& fronts) : fronts_(&fronts) {}
    const FrontKind<dim>& operator[](std::size_t k) const { return *(*fronts_)[k]; }
    std::size_t size() const { return fronts_->size(); }

   private:
    const std::vector<std::unique_ptr<FrontKind<dim>>>* fronts_;
  };

  /// The fronts, one FrontKind each, in order of their expected_s0 (InputError otherwise): the
  /// tracker knows no kind, so a new kind is a new class its builder adds to this list.
  FrontTracker(std::vector<std::unique_ptr<FrontKind<dim>>> fronts, const FrontOptions& options);

  Fronts fronts() const { return Fronts(fronts_); }
  /// What one front event (an insertion, a crossing, an absorption) changed in K + V: the re-layout of the
  /// mass parcels (and the insertion's or removal's arcs) and the projection after it (W_remesh), or the
  /// absorption's impact (W_shocks); with the velocity jump |v_a − v_(a−1)| across the last link of the arc
  /// before the front's split link, at the event, before it (docs/model.md §9, "W_remesh event by event").
  struct EventEnergy {
    double t = 0;
    std::string kind;  ///< "insert", "cross" or "absorb"
    int front = -1;
    double relayout = 0;
    double relayout_kinetic = 0;  ///< its part in K (the rest is in V: the parcels' heights, the split link's shape)
    double projection = 0;
    double jump_before = 0;  ///< |v_a − v_(a−1)| (m/s), 0 where the stencil has no such pair
    /// The arm's turn (deg) at a − 1 before the event and at the new a − 1 after it (projection done), and the turn
    /// the front's constraint reaction on a − 1 would make against τ⁻ before it (0 without a constraint).
    double arm_turn_before = 0, arm_turn_after = 0, reaction_turn = 0;
  };
  /// The records of the events since record_event_energies() was called (or since the start with
  /// CHAINSIM_TRACE_FRONTS set); empty otherwise: a run that reads none pays nothing for them.
  const std::vector<EventEnergy>& event_energies() const { return event_energies_; }
  /// Keeps an EventEnergy for each front event from now on (two evaluations of K + V and the arm's corner per
  /// event, docs/shocks.md "What a crossing costs"). Call it before the run.
  void record_event_energies() { record_ = true; }
  /// The state front k wrote at the last evaluation.
  const FrontState<dim>& front_state(std::size_t k) const { return fs_[k]; }

  // --- StringModule ------------------------------------------------------------------------------
  std::vector<ArcRange> initial_arcs(const Chain<dim>& chain) override;
  void initialize(StringModel<dim>& model) override;
  void add_mass_and_forces(const StringModel<dim>& model, Eigen::VectorXd& mass, Points<dim>& force) override;
  int num_ledgers() const override { return 2 + 2 * dim; }
  void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const override;
  Eigen::VectorXd ledger_scale(double mass, double speed, double length) const override;
  double potential_correction(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const override;
  /// W_shocks, W_heaps (work), W_remesh (numerical), heap_mass (kg).
  std::vector<LedgerTerm> ledger_terms() const override;
  /// heap (1 for a heap's front, 0 for a fold), reaction, plane_normal (a heap on a plane: its unit normal).
  std::vector<FrontField> front_fields() const override;
  void fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
            ModuleLedger<dim>& out) const override;
  /// Two per front (crossings), one per stop condition, then the fronts' own checks (a fold: one,
  /// it opens past FoldFront::kMaxOpeningDeg or comes apart).
  int num_events() const override {
    return 2 * static_cast<int>(fronts_.size()) + static_cast<int>(options_.stop_at.size()) + num_checks();
  }
  void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const override;
  std::vector<int> event_directions() const override;
  /// The arm's turn (deg) at node i (a − 1 of front k's stencil) and the turn its constraint reaction would
  /// make against the front's tension τ⁻ (deg); with CHAINSIM_TRACE_FRONTS one `arm_corner` line on stderr.
  std::pair<double, double> arm_corner(const StringModel<dim>& model, std::size_t k, int i, double t, const char* when) const;
  EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                            const std::vector<int>& found) override;
  long transfers() const override { return transfers_; }
  int num_fronts() const override { return static_cast<int>(fronts_.size()); }
  /// Each front's two crossings come first in events(). None are predicted when a front's checks read
  /// the tensions (an edge's lift-off): a chain sliding off a table on 81 links missed its lift-off
  /// with them predicted (tests/convergence/test_edge_front.cpp), not understood yet.
  int num_crossing_events() const override {
    return events_need_tensions() ? 0 : 2 * static_cast<int>(fronts_.size());
  }
  /// The tension at an arc's end node on its front's side, after an evaluation: the end tension of
  /// the jump conditions (τ at a heap, τ∓ at a fold), which its partial link carries to the node.
  std::optional<double> front_tension_at(const StringModel<dim>& model, int node) const override;
  bool events_need_tensions() const override;
  void node_constraints(const StringModel<dim>& model, std::vector<NodeConstraint<dim>>& out) const override;
  bool has_load_derivatives() const override;
  void load_derivatives(StringModel<dim>& model, std::vector<LoadDerivative<dim>>& out) override;
  std::vector<RunEvent> run_events() const override { return events_; }
  ObstacleDrawing obstacles() const override;
  /// The fronts' checks (the lift-off margins) already negative at the start.
  std::vector<int> events_failed_at_start(const Eigen::Ref<const Eigen::VectorXd>& g) const override {
    return failed_checks(g, false);
  }
  std::vector<int> events_failed_after_event(const Eigen::Ref<const Eigen::VectorXd>& g) const override {
    return failed_checks(g, true);
  }
  bool checks_at_start() const override { return num_checks() > 0; }
  void hold_fronts() override;
  /// The fronts drawn on the links as they are after a snap (FrontKind::hold_drawing): the material the
  /// re-drawing moves between an arc and a heap goes with its momentum (the supports' impulse) and is laid at
  /// the front, the energy it changes in W_remesh, as at a crossing (docs/model.md §9, "Slack next to a front").
  void redraw_fronts(StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> ledger) override;

 private:
  /// K + V, the momentum and each front's held mass before an event re-draws the fronts (a crossing, a snap).
  struct Drawn {
    double energy = 0;
    Vec<dim> momentum = Vec<dim>::Zero();
    std::vector<double> held;
  };
  Drawn drawn(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const;
  /// Books the momentum the event changed since `before` as the supports' impulse and the held masses' change at
  /// the fronts' points in their first moment; returns the change of K + V (the caller books it).
  double book_redrawing(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> ledger, const Drawn& before) const;
  /// The active fronts' checks that are negative in g (after an event: of the kinds that watch them there);
  /// an inactive front's check slot holds its formation, which is not a failure.
  std::vector<int> failed_checks(const Eigen::Ref<const Eigen::VectorXd>& g, bool after_event) const;

  int num_checks() const;
  /// Takes front k out of the string at t (FrontKind::absorbed: a kink at a held end; FrontKind::dissolves: a kink
  /// that carries no shock any more): its arcs merge (FrontKind::remove), the other fronts' arc indices follow, it
  /// becomes inactive, and the run's events list the front's name with `_` and `what` ("absorbed", "dissolved"), e.g. `kink_absorbed`.
  void remove_front(StringModel<dim>& model, std::size_t k, double t, const char* what = "absorbed");
  /// remove_front for a front that dissolves: where slack is allowed, the links of its stencil shorter than their
  /// length by more than the slack gap (the merged split link's chord across a corner, a released arm that has
  /// shortened) are slack, not projected back to their lengths.
  void dissolve_front(StringModel<dim>& model, std::size_t k, double t);
  /// Puts front k, not yet in the string, where it formed (FrontKind::insert: a kink where the tangent turns
  /// sharply), the other fronts' arc indices following; the run's events list "<kind>_inserted". False if no
  /// place fits.
  bool insert_front(StringModel<dim>& model, std::size_t k, double t);

  FrontOptions options_;
  FrontMaterial material_;
  std::vector<std::unique_ptr<FrontKind<dim>>> fronts_;
  std::vector<FrontState<dim>> fs_;
  std::vector<RunEvent> events_;
  long transfers_ = 0;
  double w_remesh_ = 0;
  std::vector<EventEnergy> event_energies_;
  bool trace_ = false;  ///< CHAINSIM_TRACE_FRONTS set: event_energies_ also on stderr, one line each
  bool record_ = false;  ///< event_energies_ kept: record_event_energies() called or trace_ set
  Vec<dim> heap_moment0_ = Vec<dim>::Zero();  // Σ held mass × its first moment at t = 0
};

/// Heaps (at most one per side, in any order) and an optional fold as front kinds, checked
/// (front_checks.hpp) against a string of length `ell` and links of length `h`, in order of s (heap
/// before, fold, heap after). A heap's s0 within 1e-12 ℓ of an end is put on it.
template <int dim>
std::vector<std::unique_ptr<FrontKind<dim>>> heap_and_fold_fronts(std::vector<HeapSpec<dim>> heaps,
                                                                  const std::optional<FoldSpec>& fold, double ell,
                                                                  double h);

/// The string with fronts: a StringModel whose module is a FrontTracker of these fronts (in order of
/// s). `prescribed` nodes must lie in an arc. Throws InputError when the layout is inconsistent.
template <int dim>
StringModel<dim> make_front_model(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                                  std::vector<PrescribedNode<dim>> prescribed,
                                  std::vector<std::unique_ptr<FrontKind<dim>>> fronts, const FrontOptions& options,
                                  const StringModelOptions& model_options = {});

/// The same with heaps and a fold (heap_and_fold_fronts); a heap's held end must be free.
template <int dim>
StringModel<dim> make_front_model(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
                                  std::vector<PrescribedNode<dim>> prescribed, std::vector<HeapSpec<dim>> heaps,
                                  std::optional<FoldSpec> fold, const FrontOptions& fronts,
                                  const StringModelOptions& options = {});

/// The tracker of a string with fronts (nullptr for a string without), inside the modules that wrap it
/// (the slack module's, wrapping_module.hpp).
template <int dim>
const FrontTracker<dim>* front_tracker(const StringModel<dim>& model) {
  const StringModule<dim>* module = model.module();
  while (const auto* wrapper = dynamic_cast<const WrappingModule<dim>*>(module)) module = wrapper->inner();
  return dynamic_cast<const FrontTracker<dim>*>(module);
}

/// The same, to change it (FrontTracker::record_event_energies before a run).
template <int dim>
FrontTracker<dim>* front_tracker(StringModel<dim>& model) {
  return const_cast<FrontTracker<dim>*>(front_tracker(static_cast<const StringModel<dim>&>(model)));
}

}  // namespace chainsim
