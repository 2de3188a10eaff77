#pragma once
/// @file front_model.hpp
/// A string whose motion carries shocks, tracked as moving fronts (DESIGN.md §1, §3; docs/shocks.md).
///
/// Material. An open string of N equal links (material length h = ℓ/N), nodes i = 0..N at material
/// coordinate s_i = i h. The material line is cut at *fronts* into *arcs* (runs of moving nodes) and
/// *heaps* (quiescent, shapeless reservoirs). Two kinds of front:
///
///   heap   a quiescent heap, either fed through a fixed point x0 (a pile under a hole, an edge:
///          *pinned*) or lying on a plane (the table under a falling chain). The arc ends in a
///          straight *partial link* of material length l from its end node k to the contact
///          (s0 = s_k ± l), in direction e (from the arc into the heap):
///              pinned     the contact is x0, l = |x0 − x_k|, e = (x0 − x_k)/l
///              on a plane the arc's last full link continued to the plane (point p, normal n):
///                         l = n·(p − x_k)/(n·e); the contact x_k + l e slides along the plane
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
/// Discretization. Every node carries half of each adjacent full link and, if it is an arc's end
/// at a front, the whole partial link (so an arc's mass is exactly λ × its material length).
/// Momentum per moving node m_i a_i = F_i + (tension forces) + (front force), tensions from the
/// tridiagonal tension system of each arc (solver/tension_system.hpp) with the front forces as
/// known loads. For motions along a straight line (the paper's three problems) the scheme is
/// exact: it reproduces the reduced ODE for every N.
///
/// Front crossings are ARKODE root events (two per front): a heap takes the end node in when the
/// partial link shrinks to h/2 and gives out a new node when it grows to 3h/2; a fold moves the node
/// it reaches from one arc to the other. Material moves with its momentum (mass parcels carry their
/// velocity), so mass and momentum are conserved at every crossing; the kinetic energy a crossing
/// removes is booked as W_remesh (zero for straight motions). Then positions and velocities are
/// projected onto the link constraints and the integration continues with the new state size.
///
/// ODE state: [ x of moving free nodes | v of them | W_applied | W_shocks | W_heaps | impulse (dim) |
///              heap moment (dim) ]
///   W_applied  work of drag, end loads and drivers (as StringModel)
///   W_shocks   Σ over internal shocks of W_s = −D (dissipation, ≤ 0)
///   W_heaps    Σ over heaps of W* (external shocks)
///   impulse    ∫ (all external forces on the string and heaps) dt: gravity, drag, loads, the
///              reactions of fixed/driven nodes and of the planes under the heaps
///   heap moment  change of Σ over heaps of ∫ x dm (kg m): material laid on a plane stays where the
///              contact was when it arrived, so the heaps' potential energy needs their first moment
/// Ledgers: K + V − (K0 + V0) − W_applied − W_shocks − W_heaps − W_remesh → 0 and
///          p − p0 − impulse → 0 (p = Σ m_i v_i; heaps are at rest), to the discretization error.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/chain.hpp"
#include "solver/forces.hpp"
#include "solver/integrator.hpp"
#include "solver/tension_system.hpp"

namespace chainsim {

/// A quiescent heap at a fixed point x0 holding the material on one side of a front.
template <int dim>
struct HeapSpec {
  enum class Side { kBefore, kAfter };
  Side side = Side::kAfter;  ///< kAfter: the heap holds s > s0 (string runs into it at its end, e.g.
                             ///< falling chain); kBefore: it holds s < s0 (feeds the string, sliding chain)
  Vec<dim> point = Vec<dim>::Zero();  ///< x0 (m)
  double dissipation = 0;             ///< f of the internal shock at x0, in [0, 1]
  double s0 = 0;                      ///< initial material coordinate of the front (m), in (0, ℓ)
  /// Unset: the front is pinned at `point` (a hole or an edge the string runs through). Set: the
  /// heap lies on the smooth plane through `point` with this normal (pointing to the string's side),
  /// and the contact slides along the plane where the string meets it (a table under a falling chain).
  std::optional<Vec<dim>> plane_normal;
};

/// A fold (internal shock) between the arc before and the arc after s0.
struct FoldSpec {
  double dissipation = 0;  ///< f, in [0, 1]
  double s0 = 0;           ///< initial material coordinate of the fold (m), in [0, ℓ)
};

struct FrontModelOptions {
  double stabilization_time = 0;  ///< Baumgarte time τ_b (s) of the link constraints; 0 = off
  /// Stop when a front's material coordinate reaches this value (front index, s (m)); the run also
  /// stops when a front reaches an end of the string or a heap runs empty.
  struct StopAt {
    int front = 0;
    double s = 0;
  };
  std::vector<StopAt> stop_at;
};

template <int dim>
class FrontModel final : public OdeSystem {
 public:
  enum class FrontKind { kHeap, kFold };
  struct Front {
    FrontKind kind = FrontKind::kHeap;
    double dissipation = 0;
    Vec<dim> point = Vec<dim>::Zero();  ///< heap point x0 (on a plane: a point of the plane)
    bool on_plane = false;               ///< the contact slides along the plane (point, normal)
    Vec<dim> normal = Vec<dim>::Zero();  ///< unit normal of the plane, towards the string's side
    Vec<dim> last_direction = Vec<dim>::Zero();  ///< on a plane, once the arc has no full link left:
                                                 ///< the direction its partial link keeps
    int arc_minus = -1, arc_plus = -1;  ///< arcs on either side (−1: the heap's side)
  };
  struct ArcRange {
    int first = 0, last = 0;  ///< nodes first..last (inclusive), moving together
    int num_links() const { return last - first; }
  };
  /// Geometry and jump quantities of one front at the current state.
  struct FrontState {
    double s0 = 0;         ///< material coordinate of the front (m)
    double s0_dot = 0;     ///< its speed in the material (m/s)
    double l_minus = 0, l_plus = 0;  ///< partial-link lengths on either side (heap side: 0)
    Vec<dim> direction = Vec<dim>::Zero();  ///< e: heap: from the arc to x0; fold: into the fold along arc A
    Vec<dim> position = Vec<dim>::Zero();   ///< x0 (m)
    double tension_minus = 0, tension_plus = 0;  ///< τ∓ at the front (N); heap side: 0
    double inflow = 0;     ///< heap: w, speed of material entering the arc (m/s)
    double power_shock = 0;  ///< W_s = −D (W)
    double power_heap = 0;   ///< W* (W), heaps only
    Vec<dim> reaction = Vec<dim>::Zero();  ///< heap: (τ − λ w²) e, the plane's reaction on the string (N)
    double opening = 0;  ///< fold: angle between arc A's end link and arc B's first link reversed (rad); 0 = antiparallel
  };

  /// `chain`: uniform open chain with the initial positions and velocities (nodes inside heaps are
  /// ignored). Heaps (at most one per side) and an optional fold; `prescribed` nodes must lie in an
  /// arc. Throws InputError when the layout is inconsistent.
  FrontModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
             std::vector<PrescribedNode<dim>> prescribed, std::vector<HeapSpec<dim>> heaps,
             std::optional<FoldSpec> fold, const FrontModelOptions& options);

  // --- OdeSystem ----------------------------------------------------------------------------
  int size() const override { return 2 * dim * num_moving_ + kLedger + 2 * dim; }
  void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) override;
  /// Two per front (crossings), one per stop condition, one per fold (it opens past kMaxFoldOpeningDeg).
  int num_events() const override {
    return 2 * static_cast<int>(fronts_.size()) + static_cast<int>(options_.stop_at.size()) + num_folds();
  }
  void events(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) override;
  std::vector<int> event_directions() const override;
  Eigen::VectorXd state_scale() const override;

  // --- set-up and front crossings -------------------------------------------------------------
  /// Projects the chain's positions and velocities onto the link constraints (prescribed nodes on
  /// their paths at t0). Returns the largest position correction (m).
  double make_consistent(double t0);
  /// The ODE state of the chain's current positions and velocities (ledgers zero).
  Eigen::VectorXd state_from_chain() const;

  /// What an event means.
  struct EventAction {
    enum class Kind { kNone, kTransfer, kStop } kind = Kind::kNone;
    std::string reason;  ///< for kStop: why the run ends
  };
  /// Handles the events found at (t, y) (signs from Integrator::events_found()): moves nodes across
  /// fronts (then `y` is replaced by the new, possibly longer or shorter, state) or reports a stop.
  EventAction handle_events(double t, Eigen::VectorXd& y, const std::vector<int>& found);

  // --- evaluation ---------------------------------------------------------------------------
  struct Snapshot {
    double t = 0;
    Points<dim> x, v;                 ///< all nodes (nodes in heaps: last known)
    std::vector<FrontState> fronts;
    double kinetic = 0, potential = 0;  ///< K, V (V: gravity, moving string + heaps, links at their midpoints)
    double w_applied = 0, w_shocks = 0, w_heaps = 0, w_remesh = 0;
    Vec<dim> momentum = Vec<dim>::Zero(), impulse = Vec<dim>::Zero();
    Vec<dim> heap_moment = Vec<dim>::Zero();  ///< Σ over heaps of ∫ x dm (kg m): heap mass × centre

    Vec<dim> support = Vec<dim>::Zero();  ///< force of all supports (planes under heaps incl. their weight, fixed/driven nodes) on the system (N)
    double moving_mass = 0, heap_mass = 0;
    double max_violation = 0;         ///< max | |Δx_j| − h | / h over full links
  };
  Snapshot snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y);

  // --- access -------------------------------------------------------------------------------
  const Chain<dim>& chain() const { return chain_; }
  const std::vector<Front>& fronts() const { return fronts_; }
  const std::vector<ArcRange>& arcs() const { return arcs_; }
  int num_moving_nodes() const { return num_moving_; }
  long transfers() const { return transfers_; }
  double remesh_work() const { return w_remesh_; }
  double link_length() const { return h_; }
  long tension_solves() const { return solves_; }
  Vec<dim> gravity() const;
  static constexpr int kLedger = 3;  ///< W_applied, W_shocks, W_heaps
  /// A fold is a tight bight: its arms leave it along one line. The jump conditions allow a
  /// dissipative kink nowhere else (docs/shocks.md), so a run stops when the arms open wider than
  /// this angle from antiparallel (and a fold that starts wider is refused).
  static constexpr double kMaxFoldOpeningDeg = 20;
  int num_folds() const {
    int n = 0;
    for (const Front& front : fronts_) n += front.kind == FrontKind::kFold ? 1 : 0;
    return n;
  }

 private:
  void rebuild();  // slots, tension system, after a topology change
  void unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y);
  void front_states();  // fills fs_ and masses m_ from x_, v_
  double evaluate(double t);  // accelerations a_, returns dW_applied/dt; needs unpack + front_states
  double potential(const Eigen::Ref<const Eigen::VectorXd>& ledger) const;  // V; needs front_states
  double heap_mass(std::size_t front) const;                                 // needs front_states
  void project(double t);     // constraint projection of x_, v_ (moving nodes)
  Eigen::VectorXd pack(const Eigen::VectorXd& ledger) const;
  bool in_arc(int node) const { return arc_of_[static_cast<std::size_t>(node)] >= 0; }
  /// The arc end at a heap front: its end node, the node inside the arc next to it, the node that
  /// comes out of the heap next, and whether the end node can be taken in / a node given out.
  struct HeapEnd {
    bool after = true;  ///< the heap holds s > s0
    int arc = 0, node = 0, inner = 0, outer = 0;
    bool removable = false, insertable = false;
  };
  HeapEnd heap_end(const Front& front) const;
  std::string fold_opened_message(std::size_t front) const;  // needs front_states

  Chain<dim> chain_;
  std::vector<std::unique_ptr<Force<dim>>> forces_;
  std::vector<PrescribedNode<dim>> prescribed_;
  FrontModelOptions options_;
  double h_ = 0, lambda_ = 0;
  int n_ = 0;  // nodes
  std::vector<Front> fronts_;
  std::vector<ArcRange> arcs_;
  std::vector<int> arc_of_, slot_, path_of_;
  int num_moving_ = 0;
  std::unique_ptr<TensionSystem> system_;
  std::vector<int> first_unknown_;  // per arc
  double alpha_ = 0, beta_ = 0;
  long transfers_ = 0, solves_ = 0;
  double w_remesh_ = 0;
  Vec<dim> heap_moment0_ = Vec<dim>::Zero();  // Σ heap mass × point at t = 0
  // workspace (all nodes)
  Points<dim> x_, v_, a_, force_, force_nc_, front_force_, tension_force_, b_;
  Points<dim> e_;         // unit vector of link (j, j+1) in column j, for the links inside arcs
  Points<dim> reaction_;  // support reaction on prescribed nodes (zero elsewhere), from evaluate()
  Eigen::VectorXd m_;
  std::vector<FrontState> fs_;
};

}  // namespace chainsim
