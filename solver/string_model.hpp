#pragma once
/// @file string_model.hpp
/// The one discrete inextensible string of chainsim, as an ODE system (docs/string_solver.md).
/// Every model runs on it: a plain string, and a string with a module (string_module.hpp; front
/// tracking is one, shocks/front_tracker.hpp) that cuts the material into arcs and adds the masses,
/// loads and ledgers of its fronts.
///
/// Momentum per free node i (the tension T_j acts along the link unit vector e_j, from node j towards
/// node j+1):
///
///     m_i a_i = F_i + T_i e_i − T_{i−1} e_{i−1}
///
/// with the applied forces F_i of the scene's effects (forces.hpp). The tensions come from the
/// tension system (tension_system.hpp), solved at every right-hand side. Nodes with a prescribed
/// motion (fixed or driven ends) are not in the ODE state; their position, velocity and acceleration
/// come from their EndPath.
///
/// Arcs. The moving nodes form arcs (ArcRange: runs of nodes with no front inside; one arc, open or
/// closed, without a module). Each arc owns a block of the tension system; nodes in no arc (held by
/// the module) have no equation of motion. Masses are lumped per arc, m_i = Σ ½ λ h_j over the arc's
/// links at node i, plus what the module adds (a partial link's material).
///
/// ODE state y = [ x of the free nodes (dim each, node order) | v of the free nodes | W_applied |
///                 the module's ledgers ].
/// The last component integrates the power of the non-conservative effects and of the drivers,
///     dW/dt = Σ_free F_nc,i · v_i + Σ_prescribed (m_i a_i − m_i g − (tension force)_i) · v_i,
/// as an extra ODE component (so it is error-controlled like the rest), and the ledger
///     drift = K + V − (K0 + V0) − W_applied,   K = ½ Σ m_i |v_i|², V = −Σ m_i g·x_i (all nodes),
/// vanishes for the exact solution.
///
/// Drift control: Baumgarte stabilisation of the link constraints C_j = (|Δx_j|² − h_j²)/2,
///     C'' + 2α C' + β² C = 0,   α = β = 1/τ_b,
/// a critically damped return of each constraint error with the user's time scale τ_b
/// (StringModelOptions::stabilization_time). τ_b should be long compared with the step size (the
/// term adds eigenvalues −1/τ_b, harmless to an explicit method when τ_b ≫ h) and short compared
/// with the run; it does not change the exact solution, for which C = C' = 0. τ_b = 0 turns it off.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mesh/chain.hpp"
#include "forces.hpp"
#include "integrator.hpp"
#include "string_module.hpp"
#include "tension_system.hpp"

namespace chainsim {

template <int dim>
class StringJacobian;
template <int dim>
class QuadraticString;

/// SlackPolicy (defaults.hpp): what a run does at a slack link.
/// "stop", "warn", "ignore", "allow".
const char* to_string(SlackPolicy policy);

/// Where and when a string first went slack.
struct SlackReport {
  double t = 0;        ///< s
  int link = 0;        ///< the most negative link
  double s_mid = 0;    ///< its midpoint's material coordinate (m)
  double tension = 0;  ///< its tension (N), < 0
  double scale = 0;    ///< the tension scale it is compared with (N)
  std::string message() const;
};

struct StringModelOptions {
  /// Baumgarte time scale τ_b (s) of the link-constraint stabilisation (α = β = 1/τ_b); 0 = off.
  double stabilization_time = defaults::kLibraryStabilizationTime;
  /// Tension solver: "auto", "tridiagonal", "klu" or "eigen" (tension_system.hpp).
  std::string backend = defaults::kBackend;
  /// The factorisation of the implicit methods' Newton systems (string_jacobian.hpp): "banded" (a band
  /// LU in the order along the string, O(N)), "klu" (sparse LU), or "auto": banded for a string
  /// without a module (fronts), KLU with one.
  std::string linear_solver = defaults::kLinearSolver;
  /// Slack (negative tension) at accepted steps: stop, warn or ignore (StringSolver).
  SlackPolicy slack = defaults::kLibrarySlack;
  /// Slack means T_j < −slack_tolerance · max_k |T_k| (relative, so round-off is not slack).
  double slack_tolerance = defaults::kSlackTolerance;
  /// The discretization: "links" (lumped masses, one tension per link, order 2) or "quadratic"
  /// (quadratic elements, consistent mass, tension at the Gauss points, order 4 for smooth arcs:
  /// quadratic_string.hpp; open strings without fronts only).
  std::string elements = defaults::kElements;
  /// slack = allow: Newton's coefficient of restitution e of a link that snaps taut (0: perfectly
  /// inelastic, 1: elastic); the approach speed of its ends becomes −e times itself.
  double snap_restitution = 0;
  /// slack = allow with `[velocity] kind = "tangential"`: the speed (m/s, towards larger s) of the string
  /// sliding along itself, whose initial velocities the model sets once its module has bent its links
  /// (StringModel::set_sliding_velocities; docs/scenes.md, the velocity kinds). Unset: the chain's own.
  std::optional<double> sliding_speed;
  /// `[velocity] kind = "rotation"`: a rigid rotation v = ω × (x − c). The model gives it to the free nodes in its
  /// arcs at the start, after the positions' projection onto the links' lengths (make_consistent), so that it is
  /// the rigid rotation of the projected shape: compatible with every link, no snap at t = 0 (docs/scenes.md, the
  /// velocity kinds). Unset: the chain's own velocities.
  struct RigidRotation {
    Eigen::Vector3d omega = Eigen::Vector3d::Zero();   ///< rad/s; in 2D omega.z() only (out of the plane)
    Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< m; in 2D its first two components
    /// ω × (x − c) at x.
    template <int dim>
    Vec<dim> velocity(const Vec<dim>& x) const {
      if constexpr (dim == 2) {
        const Vec<dim> r = x - center.head<2>();
        return omega.z() * Vec<dim>(-r[1], r[0]);
      } else {
        return omega.cross(Eigen::Vector3d(x - center));
      }
    }
  };
  std::optional<RigidRotation> rotation;
  void validate() const;
};

template <int dim>
class StringModel final : public OdeSystem {
 public:
  /// The model of `chain` (its current positions and velocities are the initial state) under the
  /// given forces, with the listed nodes prescribed, and an optional module (front tracking).
  /// Throws InputError on bad input.
  StringModel(Chain<dim> chain, std::vector<std::unique_ptr<Force<dim>>> forces,
              std::vector<PrescribedNode<dim>> prescribed, const StringModelOptions& options,
              std::unique_ptr<StringModule<dim>> module = nullptr);

  // --- OdeSystem ----------------------------------------------------------------------------
  int size() const override { return 2 * dim * num_free_ + 1 + num_ledgers_; }
  void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) override;
  int num_events() const override { return module_ ? module_->num_events() : 0; }
  void events(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) override;
  std::vector<int> event_directions() const override {
    return module_ ? module_->event_directions() : std::vector<int>{};
  }
  int num_recurring_events() const override { return module_ ? module_->num_crossing_events() : 0; }
  /// With a module: positions scale with ℓ, velocities with a reference speed, ledgers with the
  /// matching energies; without one, plain absolute tolerances (empty).
  Eigen::VectorXd state_scale() const override;
  /// Implicit methods: the exact Newton systems of the string (string_jacobian.hpp), O(N) each.
  bool has_newton_solver() const override { return system_ != nullptr; }
  void newton_setup(double t, const Eigen::Ref<const Eigen::VectorXd>& y, bool relinearize, double gamma) override;
  void newton_solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> z) override;
  /// No module and only state-independent applied forces (gravity, end loads): the linearisation
  /// is exact (string_jacobian.hpp).
  bool newton_solver_exact() const override;
  /// J v of the last linearisation; only without a module (whose loads it leaves out).
  bool jacobian_times(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> Jv) override;
  /// ℓ / h_min: the fastest transverse wave crosses a link in ~h/c, the motion the string in ~ℓ/c.
  double explicit_stiffness() const override;

  // --- set-up -------------------------------------------------------------------------------
  /// Puts the prescribed nodes on their paths at t0, then projects the positions and velocities of
  /// the moving nodes onto the link constraints (project()). The chain's positions and velocities
  /// become the projected ones. Returns the largest position correction (m). Throws InputError if
  /// the projection fails (e.g. fixed ends further apart than the string is long).
  double make_consistent(double t0);
  /// What the projection of the initial velocities did (make_consistent, summed over its calls): the
  /// kinetic energy it gave the string (J; K after − K before, the scene's velocities with the
  /// prescribed nodes at their paths' velocities) and the largest change of a node's velocity (m/s).
  /// An inextensible string cannot start at rest while a driven end moves: its velocities jump to
  /// the compatible ones at t = 0 (an impulsive start), and the runner books the energy given.
  struct ImpulsiveStart {
    double kinetic_energy = 0;    ///< J
    double max_speed_change = 0;  ///< m/s
    double speed_scale = 0;       ///< m/s: the largest speed before or after
    /// With slack = allow the start is a snap taut (start_impulses): the energy its impulses
    /// dissipated (J, ≥ 0; zero for slack = stop, whose jump is the drivers' work alone).
    double dissipated = 0;
    /// The velocities changed beyond round-off (kImpulsiveSpeed of the speed scale).
    bool detected() const { return max_speed_change > kImpulsiveSpeed * speed_scale; }
    static constexpr double kImpulsiveSpeed = 1e-9;
  };
  const ImpulsiveStart& impulsive_start() const { return impulsive_start_; }
  /// After make_consistent: the module's start on the consistent state at t0 (StringModule::start: the
  /// contact module's lift-offs and landings there), booked in `ledger`, the module's ledgers' initial
  /// values. The chain's positions and velocities follow the state. Returns whether the state changed.
  bool start_module(double t0, Eigen::Ref<Eigen::VectorXd> ledger);
  /// The ODE state of the chain's current positions and velocities, with every ledger zero.
  Eigen::VectorXd state_from_chain() const;

  // --- evaluation ---------------------------------------------------------------------------
  /// All node positions and velocities at (t, y) (prescribed nodes from their paths; nodes in no
  /// arc keep their last known values).
  void unpack(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x, Points<dim>& v) const;

  /// Everything at one state (one tension solve).
  struct Snapshot : ModuleLedger<dim> {
    double t = 0;
    Points<dim> x, v;               ///< positions and velocities of all nodes (the accelerations:
                                    ///< accelerations(), set by the snapshot's evaluation)
    Eigen::VectorXd tension;        ///< T_j (N) of every link; NaN for a link in no arc
    double kinetic = 0;             ///< K (J)
    double potential = 0;           ///< V (J)
    double work = 0;                ///< W_applied (J)
    double power = 0;               ///< dW_applied/dt (W)
    double max_violation = 0;       ///< max_j | |Δx_j| − h_j | / h_j over the links of the arcs
    double max_rate_violation = 0;  ///< max_j |e_j·Δv_j| (m/s)
    Vec<dim> momentum = Vec<dim>::Zero();  ///< Σ m_i v_i (N s)
    double moving_mass = 0;                ///< Σ m_i over the moving nodes (kg)
    /// Per prescribed node (in the order of prescribed()): the force its support or driver exerts on
    /// the string (N), and the tension of the link at it (N; the pivot tension of a hanging chain).
    std::vector<Vec<dim>> end_reactions;
    std::vector<double> end_tensions;
    /// The physical scales of this state (physical_scales()): a tension (N) and an energy (J).
    double tension_scale = 0, energy_scale = 0;
  };
  /// With `rates`: also the right-hand side at (t, y), rhs()'s numbers from the same evaluation.
  Snapshot snapshot(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::VectorXd* rates = nullptr);

  /// max_j | |Δx_j| − h_j | / h_j at (t, y) over the links of the arcs, without a tension solve.
  double max_constraint_violation(double t, const Eigen::Ref<const Eigen::VectorXd>& y) const;
  /// The same, with the taut link where it is reached and that link's length (link −1 with quadratic
  /// elements, whose violation is not a link's).
  struct ConstraintViolation {
    double relative = 0;
    int link = -1;
    double length = 0;
  };
  ConstraintViolation worst_constraint_violation(double t, const Eigen::Ref<const Eigen::VectorXd>& y) const;
  /// The physical scales of the current state (never the round-off of a solve), from its velocities,
  /// forces and the drivers' accelerations (valid once evaluate_current has set the forces):
  ///   tension  λ (|g| ℓ + max |v|² + ℓ max |a_driven|) + Σ |F_i − m_i g|: the weight, the centripetal
  ///            tension, what the drivers' accelerations ask of the whole string, and every other
  ///            applied force (end loads, drag) on the moving nodes;
  ///   energy   ℓ (λ |g| ℓ + Σ |F_i − m_i g|): the work of the weight and of the loads along the string
  ///            (the kinetic energy and the work done are added by the runner, which sees the run).
  /// Both are zero only for a string with no weight, load, speed or driver: its exact tension is zero.
  struct PhysicalScales {
    double tension = 0, energy = 0;
  };
  PhysicalScales physical_scales() const;
  /// The most negative link if some T_j < −slack_tolerance·scale at (t, y), where scale is the larger
  /// of max |T| and the physical tension scale (physical_scales()), so that a string whose exact
  /// tension is zero (free fall, or rest without weight or load) is not slack by round-off; nothing
  /// otherwise, and never when the physical scale is zero. One tension solve.
  std::optional<SlackReport> find_slack(double t, const Eigen::Ref<const Eigen::VectorXd>& y);
  /// Acts on the root functions found at (t, y) (the module's events): `y` is replaced by the new,
  /// possibly longer or shorter, state after a transfer.
  EventAction handle_events(double t, Eigen::VectorXd& y, const std::vector<int>& found);

  // --- unilateral links (slack = allow; docs/model.md "Slack and snap-taut") ------------------
  bool allows_slack() const { return options_.slack == SlackPolicy::kAllow; }
  /// Link j is slack: T_j = 0 and its length is free (< h_j) until it snaps taut.
  bool link_slack(int j) const { return !slack_.empty() && slack_[static_cast<std::size_t>(j)] != 0; }
  int num_slack_links() const { return num_slack_; }
  /// Declares link j slack before the run (a string laid shorter than its length); slack = allow
  /// only. make_consistent() then leaves its length alone and refuses it if it is not shorter than h_j.
  void set_slack(int j, bool slack);
  /// The snap root function at the current positions: min over the slack links of slack_root(j), 1 with
  /// none. One root function for all links (ARKODE evaluates every root function at every step: N
  /// per-link functions cost N times more evaluations of the same numbers).
  double slack_gap() const;
  /// The release root function at the last evaluation: min over the taut links in an arc, not bent and not the
  /// arm of a front's split link (the front's own checks judge those: a kink whose arm is released dissolves), of
  /// T_j / scale + slack_tolerance (scale as solve_tensions judges a release), −slack_tolerance for a link the
  /// complementarity problem released; 1 with none. It crosses zero where the first tension reaches the
  /// release threshold, so the release is located and the link declared slack at that instant.
  double release_root() const;
  /// Declares slack the links whose term of release_root() is ≤ 0 at the last evaluation, each with its root
  /// offset (a release flight, slack_root); returns how many.
  int release_links();
  /// What a snap did: the energy it dissipated (J, ≥ 0), the work and impulse of the supports'
  /// impulses (J, N s), and how many links it caught.
  struct SnapResult {
    double dissipated = 0, support_work = 0;
    Vec<dim> support_impulse = Vec<dim>::Zero();
    int caught = 0;
    /// The speed a separation is judged against (m/s): the largest rate of a taut link before the impulses, or
    /// the floor passed in; a link that opens slower than kSeparation of it is round-off and stays taut.
    double speed = 0;
  };
  /// The impact at the current state (a slack link reached its length): the links within
  /// kSnapWindow of their length become taut, and the impulsive tensions P ≥ 0 of the taut links
  /// solve the complementarity problem u⁺ = u⁻ + A P ≤ −e u⁻, P (u⁺ + e u⁻) = 0 (u: rate of
  /// lengthening); the velocities jump, and links that separate afterwards go slack. A caught link whose
  /// rebounds would accumulate (rebounds_accumulate) takes e = 0. `speed_floor`: the least speed a
  /// separation is judged against (m/s); the catch rounds after a snap pass its speed (SnapResult::speed), where
  /// the links caught approach at round-off rates.
  SnapResult snap(double t, double speed_floor = 0);
  /// The impact of nodes landing on obstacles (a contact module has just held them): the state onto
  /// the constraints of the links and the held nodes, the velocities by a perfectly inelastic impact.
  /// Bilateral links: the mass-weighted projection (project()). With slack = allow: the held nodes'
  /// normal velocity is taken, and the links' impulses solve the snap's complementarity problem at
  /// e = 0 on the contact-reduced matrix (a link the landing would push goes slack).
  /// `e`: Newton's restitution of the links' impulses (slack = allow; a front absorbed at a held end takes the
  /// scene's snap_restitution, shocks/front_tracker.cpp).
  /// Returns the work (J) of the impulses the driven supports take in the impact (zero at fixed ends): the
  /// kinetic energy's change less it is what the impact dissipated.
  double impact(double t, double e = 0);
  /// At an accepted step (t, y): the taut links shorter than (1 − kSlackGap) h_j (released by the
  /// complementarity problem during the step) become slack; a slack link past its length (a snap not
  /// located) throws NumericalError. O(N), no tension solve.
  void accept_step(double t, const Eigen::Ref<const Eigen::VectorXd>& y);
  /// A released link goes slack once shorter than (1 − kSlackGap) h; a link that goes slack at a snap
  /// starts with its root function at +kSlackGap.
  static constexpr double kSlackGap = 2e-7;
  /// At a snap the slack links within kSnapWindow of their length are caught; if none is (the state
  /// recomputed to the event is a little short of the located root), the nearest one within
  /// kCatchWindow.
  static constexpr double kSnapWindow = 1e-7;
  static constexpr double kCatchWindow = 1e-5;
  /// A release flight is located on its return to its length at the release once it has flown shorter than
  /// that length by this share of h at an accepted step (slack_root): deeper than the round-off of the positions
  /// (ε |x| / h, 4e-14 on a 1 m chain of 400 links), which a link that stays at rest at its length in free fall
  /// reaches at once; shallower, it keeps the offset kSlackGap.
  static constexpr double kFlightDepth = 1e-10;
  /// After a snap, a taut link goes slack when it separates faster than this share of the largest
  /// approach speed of the snap (slower, it stays taut and the tension solve releases it if it must).
  static constexpr double kSeparation = 1e-6;
  /// The accumulation rule's time, in units of the time h_j / U the motion takes to cross link j.
  static constexpr double kAccumulation = 1.0;

  // --- access -------------------------------------------------------------------------------
  const Chain<dim>& chain() const { return chain_; }
  Chain<dim>& chain() { return chain_; }
  const std::vector<std::unique_ptr<Force<dim>>>& forces() const { return forces_; }
  const std::vector<PrescribedNode<dim>>& prescribed() const { return prescribed_; }
  const StringModelOptions& options() const { return options_; }
  const StringModule<dim>* module() const { return module_.get(); }
  bool is_prescribed(int node) const { return path_of_[static_cast<std::size_t>(node)] >= 0; }
  /// Nodes with an equation of motion: in an arc and not prescribed.
  int num_free_nodes() const { return num_free_; }
  /// An alias of num_free_nodes() (series.csv's moving_nodes).
  int num_moving_nodes() const { return num_free_nodes(); }
  int work_index() const { return 2 * dim * num_free_; }
  /// Baumgarte coefficients α, β (1/s).
  double alpha() const { return alpha_; }
  double beta() const { return beta_; }
  TensionSystem& tension_system() { return *system_; }
  const TensionSystem& tension_system() const { return *system_; }
  bool has_tension_system() const { return system_ != nullptr; }
  long tension_solves() const;
  /// The quadratic elements (StringModelOptions::elements = "quadratic"), or null.
  const QuadraticString<dim>* quadratic() const { return quadratic_.get(); }
  /// Tensions (per tension unknown) and accelerations of the last evaluation (rhs or snapshot).
  const Eigen::VectorXd& tensions() const { return system_->solution(); }
  /// Bends link `link` over a point fixed in space (an edge or a peg, docs/model.md §8): its
  /// constraint becomes |point − x_a| + |x_b − point| = h (a = its start node, b = its end node), its
  /// tension pulls node a along e⁻ = (point − x_a)/l⁻ and node b along −e⁺ = −(x_b − point)/l⁺, and
  /// the point takes the difference: the string runs over it, its tension a multiplier of the same
  /// tension system. Link elements only; implicit methods refuse a bent link (its linearisation is not
  /// written). Replaces any earlier bend of the same link. `signed_minus` and `signed_plus`: whether a
  /// side's partial length turns negative where its node has passed the point (bent_sides); an edge
  /// front leaves it unsigned on the side its crossing has just put a node on.
  void bend_link(int link, const Vec<dim>& point, bool signed_minus = true, bool signed_plus = true);
  /// Moves node `node` of the initial shape (and of the current state) to `x`: a module placing its
  /// fronts before the start (an edge moves a node off its point).
  void move_initial_node(int node, const Vec<dim>& x) {
    chain_.positions().col(node) = x;
    x_.col(node) = x;
  }
  /// Bends link `link` over a circle (2D; docs/model.md §10, "Links along the arc"): the link runs
  /// round the circle of `center` and `radius` in the sense `sigma` (+1 counterclockwise from its
  /// start node to its end node), its constraint l = s_a + R σ (θ_out − θ_in) + s_b = h. An end on the
  /// circle (`a_on`, `b_on`: held there by the contact module) enters at its own angle with s = 0; a
  /// free end enters along the line tangent to the circle through it, s its distance from the tangent
  /// point. Its tension pulls node a along e⁻ = σ t(θ_in) and node b along −e⁺ = −σ t(θ_out) (t the
  /// circle's counterclockwise tangent), and the circle takes T (e⁻ − e⁺): the string's pressure on
  /// the arc of the link. Replaces any earlier bend of the same link.
  void bend_link_on_circle(int link, const Vec<dim>& center, double radius, double sigma, bool a_on, bool b_on);
  /// Straightens the links bent over circles (bend_link_on_circle); the links bent over points stay.
  void clear_circle_bends();
  /// A link bent over a circle after an evaluation: the length of its arc on the circle, R σ (θ_out −
  /// θ_in) (m, negative where the tangent points have passed each other), and the straight part at its
  /// start (`at_end` false) or its end node (m, 0 for an end on the circle). NaN for another link.
  double bend_arc(int link) const;
  double bend_straight(int link, bool at_end) const;
  /// Straightens every bent link.
  void clear_bends() { bends_.clear(); }
  /// Straightens link `link` if it is bent, the other bends kept (an edge front whose material crosses
  /// its point moves its bend to the next link; another edge's bend stays).
  void unbend_link(int link) {
    for (auto it = bends_.begin(); it != bends_.end(); ++it)
      if (it->link == link) {
        bends_.erase(it);
        return;
      }
  }
  /// The point link `link` is bent over (bend_link), or null if it is straight.
  const Vec<dim>* bend_point(int link) const {
    const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
    return bend ? &bend->point : nullptr;
  }
  /// Whether a link is bent over a point (an edge front's).
  bool has_bends() const { return !bends_.empty(); }
  /// Link `link` is bent over a point (bend_link).
  bool link_bent(int link) const { return !bends_.empty() && bend_of(link) != nullptr; }
  /// A bent link's unit vectors after an evaluation: e⁻ at its start node (`at_end` false), e⁺ at its end
  /// node: the directions its tension pulls along there (T e⁻ on the start node, −T e⁺ on the end node).
  Vec<dim> bent_direction(int link, bool at_end) const { return at_end ? bend_of(link)->e_plus : Vec<dim>(e_.col(link)); }
  /// The two sides of a link bent over a point (bend_link) at the current positions: its partial lengths
  /// and unit vectors, the one place they are computed (the constraint, the edge front's masses, tension
  /// jump, reaction and lift-off margin all read them). The lengths are signed: with d⁻ the direction the
  /// string arrives at the start node a (bend_side_direction), l⁻ = σ |x0 − x_a| and e⁻ = σ (x0 − x_a)/|x0 − x_a|,
  /// σ = sign(d⁻·(x0 − x_a)): past the point along d⁻ (a step that ends just past an edge front's crossing,
  /// inside its overshoot band) l⁻ < 0 and e⁻ still points along the side, so that for a node moving along
  /// a straight line through the point l⁻ runs on through zero and e⁻ stays; the same at the end node b
  /// (docs/model.md §8, "Past the point"). σ = −1 only within 60° of that line beyond the point, and
  /// only on a signed side (bend_link). A signed side within kNearPoint h (1e-4 links) of the point is
  /// measured along its side's line, l = d·(x0 − x_a), e = d (docs/model.md §8, "Round-off at a crossing":
  /// d / |d| would carry the node's position error over |d|). An unsigned side within kBentLinkFloor h of
  /// the point keeps its direction of the last evaluation. RecoverableError if a side has no direction.
  struct PointBendSides {
    double l_minus = 0, l_plus = 0;  ///< signed partial lengths (m), l⁻ + l⁺ = h on the constraint
    Vec<dim> e_minus = Vec<dim>::Zero(), e_plus = Vec<dim>::Zero();
    bool near_minus = false, near_plus = false;  ///< measured along the side's line (within kNearPoint h)
  };
  PointBendSides bent_sides(int link) const;
  /// The direction the string arrives at the start node a of bent link `link` (`at_end` false: along the
  /// link before a, or from the point that link is bent over) or leaves its end node b (`at_end` true:
  /// along the link after b, or to its point), at the current positions; at an end of its arc (no link
  /// beyond), the bent link's own direction when it was bent. It signs the partial lengths (bent_sides)
  /// and measures an edge front's crossings.
  Vec<dim> bend_side_direction(int link, bool at_end) const;
  /// Link j's rate of lengthening after an evaluation (m/s): e_j·Δv_j, a bent link's d(l⁻ + l⁺)/dt.
  double link_rate(int j) const;
  /// The force the points of the bent links exert on the string after an evaluation (N): Σ T (e⁻ − e⁺).
  Vec<dim> bend_reaction() const;
  /// The tension of link `link` after an evaluation (N): its multiplier; NaN for a link in no arc.
  double link_tension(int link) const;
  const Points<dim>& accelerations() const { return a_; }
  /// The constraints beyond the links (StringModule::node_constraints, a kink's compatibility) at the
  /// last refresh(), and after an evaluation their multipliers μ_k (forces μ_k ∂C_k/∂x_i).
  const std::vector<NodeConstraint<dim>>& node_constraints() const { return constraints_; }
  const Eigen::VectorXd& constraint_multipliers() const { return constraint_multipliers_; }
  // --- nodes held on obstacles (a contact module; docs/model.md §10) ---------------------------
  /// The nodes the module holds on obstacles (StringModule::node_contacts), at the last refresh().
  const std::vector<NodeContact<dim>>& contacts() const { return contacts_; }
  /// After an evaluation: the normal force N_k (N) of contacts()[k] on its node (≥ 0 while it holds).
  double contact_force(std::size_t k) const { return contact_force_[k]; }
  /// After an evaluation: Σ_k N_k n_k · v_k, the power of the contact forces (W; zero on the surface,
  /// up to the drift control).
  double contact_power() const;
  /// After an evaluation: the friction force (N) of contacts()[k] on its node: −μ N t̂ while it
  /// slides, the tangential force that holds it while it sticks, zero on a smooth obstacle.
  Vec<dim> contact_friction(std::size_t k) const { return contact_friction_.col(static_cast<Eigen::Index>(k)); }
  /// After an evaluation: Σ_k (friction force)·v_k, the power of friction (W, ≤ 0).
  double friction_power() const;
  /// After an evaluation, for a contact with friction: the applied force on its node, m_i b_i (N).
  Vec<dim> contact_applied(std::size_t k) const {
    return m_[contacts_[k].node] * Vec<dim>(contact_b_.col(static_cast<Eigen::Index>(k)));
  }
  /// A link between two nodes that cannot move (NodeContact::stuck, or prescribed) is locked: its
  /// tension is statically indeterminate and kept at the value set here (by default the one it had
  /// when it locked); the contact module chooses one inside the friction cones of its nodes.
  bool link_locked(int j) const { return !locked_.empty() && locked_[static_cast<std::size_t>(j)] != 0; }
  void set_locked_tension(int j, double T) { locked_tension_[static_cast<std::size_t>(j)] = T; }
  double locked_tension(int j) const { return locked_tension_[static_cast<std::size_t>(j)]; }
  /// The sum of the uniform fields the forces declare (Force::uniform_field; gravity's g, zero
  /// without one): the weight per unit mass in the physical scales, and what the module books for
  /// material not lumped on nodes.
  Vec<dim> uniform_field() const;

  /// Evaluates accelerations a_ (and tensions) from all-node x, v at time t; returns dW/dt.
  /// Public for tests: the core of rhs().
  double evaluate(double t, const Points<dim>& x, const Points<dim>& v);

  // --- what a module works with (shocks/front_tracker.hpp) --------------------------------------
  const std::vector<ArcRange>& arcs() const { return arcs_; }
  /// The arcs, to change at a front crossing; call rebuild() after.
  std::vector<ArcRange>& arcs() { return arcs_; }
  /// After the arcs change: free-node slots, lumped masses and the tension system anew.
  void rebuild();
  /// Index of the arc holding `node`, or −1 (in no arc: held by the module).
  int arc_of(int node) const { return arc_of_[static_cast<std::size_t>(node)]; }
  bool in_arc(int node) const { return arc_of(node) >= 0; }
  /// The current positions and velocities of all nodes (the state being evaluated).
  const Points<dim>& x() const { return x_; }
  const Points<dim>& v() const { return v_; }
  Points<dim>& x() { return x_; }
  Points<dim>& v() { return v_; }
  /// Current masses (lumped plus the module's), after refresh() or an evaluation.
  const Eigen::VectorXd& masses() const { return m_; }
  /// Recomputes the masses (and the module's fronts) at the current x(), v(); no tension solve.
  void refresh();
  /// Sum over the moving nodes of the applied forces and the prescribed nodes' support reactions,
  /// and the force of the points the links are bent over (bend_reaction), after an evaluation (N).
  const Vec<dim>& external_force() const { return external_; }
  /// Sum of the prescribed nodes' support reactions on the string, after an evaluation (N).
  Vec<dim> support_reaction() const;
  /// K = ½ Σ m_i |v_i|² and p = Σ m_i v_i over the moving nodes at the current state.
  double kinetic_energy() const;
  Vec<dim> momentum() const;
  /// V at the current state (needs refresh() or an evaluation): the forces' potentials with the
  /// lumped masses, plus the module's correction.
  double potential_energy(const Eigen::Ref<const Eigen::VectorXd>& ledger) const;
  /// Projects x(), v() of the moving nodes onto the link constraints (prescribed nodes on their paths
  /// at t): the smallest mass-weighted correction onto |Δx_j| = h_j (Newton's method, until every link
  /// is right to the round-off of its coordinates), then onto e_j·Δv_j = 0. Throws NumericalError
  /// naming t and the residual if it does not converge. Returns the work (J) of the driven supports'
  /// impulses in the velocities' projection (project_velocities).
  double project(double t);
  /// The state y at t with its positions and velocities projected onto the link constraints by
  /// project() (the ledgers unchanged): an interpolated output frame made consistent.
  Eigen::VectorXd projected_state(double t, const Eigen::Ref<const Eigen::VectorXd>& y);

 private:
  /// Link geometry (dx_, dv_, l_, e_) of the arcs and the largest coordinate x_max_ of their nodes.
  void links();
  /// The relative accuracy to which link lengths are known after links(): the larger of the
  /// projection's tolerance and the round-off of the coordinates, kRoundoffUlps · ε · x_max / h_min.
  /// The projection converges to it, and the drift control's response to it stays below the
  /// physical accelerations (evaluate_current caps β²).
  double constraint_tolerance() const;
  void assemble_matrix();
  Eigen::VectorXd pack(const Eigen::Ref<const Eigen::VectorXd>& ledgers) const;
  void unpack_state(double t, const Eigen::Ref<const Eigen::VectorXd>& y);
  /// The free nodes as runs of consecutive nodes with consecutive slots (one run for a string with a
  /// fixed end), and the prescribed nodes in an arc: what fill_moving() and rhs() copy, found by
  /// rebuild() from slot_ and arc_of_.
  struct FreeRun {
    int node = 0, slot = 0, count = 0;
  };
  std::vector<FreeRun> free_runs_;
  std::vector<int> prescribed_in_arcs_;
  void find_free_runs();
  /// Positions and velocities of the nodes in an arc at (t, y) into x, v (the others untouched).
  void fill_moving(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Points<dim>& x, Points<dim>& v) const;
  double evaluate_current(double t);
  /// rhs()'s output from the evaluation just made (evaluate_current, which returned `power`).
  void write_rates(double power, Eigen::Ref<Eigen::VectorXd> ydot);
  /// evaluate_current without bent links, for arcs in order: the tension forces T_j e_j − T_{j−1} e_{j−1}
  /// of the nodes from the tensions T (per unknown), arc by arc in one pass (zero at the nodes in no arc).
  void tension_forces_of_string(const Eigen::VectorXd& T);
  /// The tension solve of an evaluation: the linear system, or with slack = allow the
  /// complementarity problem on the taut links (slack ones excluded).
  const Eigen::VectorXd& solve_tensions(double t);
  /// target_a −= w_a ν_j e_j, target_b += w_b ν_j e_j for every link j (and a bent link's end along
  /// e⁺): the mass-weighted response to link multipliers ν (projection: corrections; snap: −P).
  void add_link_responses(Points<dim>& target, const Eigen::VectorXd& nu) const;
  /// project(t) in two steps: the positions onto the links' lengths and the held nodes' surfaces;
  /// the velocities onto e_j·Δv_j = 0 and n_i·v_i = 0 (mass-weighted, linear), returning the work (J) of
  /// the driven supports' impulses in it (supports_work).
  void project_positions(double t);
  double project_velocities(double t);
  /// The initial velocities of the string sliding along itself at `speed` (m/s, towards larger s):
  /// every node of an arc moves along the string, so that every link's rate of lengthening is ≥ 0 and
  /// exactly 0 where the string is straight, on a circle, and over a point a link is bent over (each
  /// of its ends along its own side). docs/scenes.md ("The velocity kinds") derives the rule.
  void set_sliding_velocities(double speed);
  /// make_consistent with slack = allow: the positions projected, the velocities by the snap's law at
  /// t0 (link_impulses with the scene's restitution; links shortening at the start go slack).
  void start_impulses(double t0);
  /// make_consistent with options_.rotation, after the positions' projection: v = ω × (x − c) at the free nodes
  /// in the arcs (the prescribed ones keep their paths' velocities, nodes in no arc the chain's).
  void set_rotation_velocities();
  /// project_positions' Newton iteration onto the links' lengths and the held nodes' surfaces.
  void project_link_lengths(double t);
  /// The module's constraints beyond the links (NodeConstraint): evaluate_current, after the tension
  /// solve, finds their multipliers by a bordered solve (the tension system once more per constraint
  /// and once for the sum: its matrix is unchanged, so every backend keeps its band) and puts their
  /// forces on the nodes; the projections correct along their mass-weighted gradients.
  std::vector<NodeConstraint<dim>> constraints_;
  Eigen::VectorXd constraint_multipliers_;
  void impose_constraints(double t);
  /// z + W Gᵀ ν with G (z + W Gᵀ ν) = 0: a field's mass-weighted projection onto the links' rates
  /// (the system assembled at the current positions).
  /// Returns ν, the links' multipliers (add_link_responses' sign).
  Eigen::VectorXd project_onto_links(double t, Points<dim>& z);
  /// Adds to `field` the combination Σ μ_k P(W ∂C_k) (P: project_onto_links) with ∂C_l · (the
  /// correction) = −target_l for every constraint l: the projections' share of the constraints.
  /// Returns the work (J) that the driven supports' impulses would do if `field` were the velocities.
  double correct_constraints(double t, const Eigen::VectorXd& target, Points<dim>& field);
  /// The work (J) of the impulses that the prescribed nodes' supports take, at their velocities, when the
  /// links act with the multipliers ν of add_link_responses (a link's impulse −ν e_j on its start node, ν e⁺_j
  /// on its end node): a support takes the opposite of what the links give its node. Zero at fixed ends.
  double supports_work(const Eigen::VectorXd& nu) const;
  /// The largest |C_k| (m) at the last refresh().
  double constraint_violation() const;
  /// The impulsive tensions P ≥ 0 of the taut links for restitution e (the snap's complementarity
  /// problem on the tension matrix, contact-reduced at held nodes): the velocities jump, links that
  /// separate go slack (faster than kSeparation of the larger of their approach speed and u_floor);
  /// the dissipated energy, the supports' and obstacles' impulses and work.
  /// `inelastic`: per link, 1 where the snap takes e = 0 for that link (the accumulation rule, snap()).
  SnapResult link_impulses(double t, double e, double u_floor = 0, const std::vector<char>* inelastic = nullptr,
                           bool rebounds = false);
  /// At a snap (link_impulses with `rebounds`): of the links about to separate, holds taut those whose flight
  /// would not take them more than kSlackGap h_j below their length before their closing acceleration brought
  /// them back (u²/(2a) ≤ kSlackGap h_j, a from the state after the jump, one evaluation): `separating` keeps
  /// the others. True if one was held (the velocities are then projected onto the taut links).
  bool hold_unresolved_flights(double t, std::vector<int>& separating);
  /// The accumulation rule of snap() (docs/model.md §9, "Accumulating rebounds"): link j's snap is perfectly
  /// inelastic if it rebounded at its previous snap and the rebounds that would follow end within
  /// kAccumulation · h_j / U (U: speed_scale(), the motion's scale at the start). Only snap() records
  /// rebounds (link_impulses' `rebounds`): a link that separates at the start or at a landing begins a flight.
  bool rebounds_accumulate(int j, double t, double e) const;
  /// The speed scale of the motion: max(√(|g| ℓ), the fastest node of the initial state) (ℓ if both are zero).
  double speed_scale() const;
  /// Excludes the slack links from the assembled tension system (their T = 0).
  void exclude_slack_links();
  template <class Visit>
  void for_each_link(Visit&& visit) const;
  friend class StringJacobian<dim>;
  std::shared_ptr<StringJacobian<dim>> jacobian_;  // built by the first newton_setup()
  std::shared_ptr<QuadraticString<dim>> quadratic_;  // elements = "quadratic"
  /// β² = 1/τ_b², capped where its response to the round-off of the coordinates would exceed the
  /// physical accelerations (needs x_max_).
  double capped_beta2() const;

  Chain<dim> chain_;
  std::vector<std::unique_ptr<Force<dim>>> forces_;
  std::vector<PrescribedNode<dim>> prescribed_;
  StringModelOptions options_;
  std::unique_ptr<StringModule<dim>> module_;
  int num_ledgers_ = 0;
  std::vector<ArcRange> arcs_;
  std::vector<int> first_unknown_;  // per arc: its first tension unknown (−1: no link)
  std::unique_ptr<TensionSystem> system_;
  long solves_ = 0;              // tension solves of systems replaced by rebuild()
  std::vector<int> arc_of_;      // node -> arc, or -1
  std::vector<int> slot_;        // node -> index among free nodes, or -1 (prescribed or in no arc)
  std::vector<int> path_of_;     // node -> index into prescribed_, or -1
  std::vector<int> link_unknown_;  // link -> tension unknown, or -1 (in no arc)
  /// A link bent over a fixed point (bend_link): the point, and after links() the partial lengths
  /// and the unit vector e⁺ at the end node (e_ holds e⁻, the one at the start node).
  struct Bend {
    int link = -1;
    Vec<dim> point = Vec<dim>::Zero();
    Vec<dim> e_plus = Vec<dim>::Zero();
    Vec<dim> e_minus_last = Vec<dim>::Zero(), e_plus_last = Vec<dim>::Zero();  // of the last evaluation
    // The directions from x_a to the point and from it to x_b when it was bent (bend_side_direction at an arc's end).
    Vec<dim> bent_minus = Vec<dim>::Zero(), bent_plus = Vec<dim>::Zero();
    bool signed_minus = true, signed_plus = true;  // (bend_link)
    double l_minus = 0, l_plus = 0;  // a point's: signed (point_bend_sides)
    bool near_minus = false, near_plus = false;  // a point's side measured along its line (point_bend_sides)
    // Bent over a circle (bend_link_on_circle): its centre, radius and sense, which ends are on it; after
    // links() the arc's length, the quadratic term of d²l/dt² at zero accelerations (q), and its angles.
    bool circle = false, a_on = false, b_on = false;
    Vec<dim> center = Vec<dim>::Zero();
    double radius = 0, sigma = 1, arc = 0, q = 0;
  };
  std::vector<Bend> bends_;
  // Node contacts (refresh(): from the module): held nodes, their normal forces after an evaluation,
  // and n·b of their unconstrained accelerations (evaluate_current).
  std::vector<NodeContact<dim>> contacts_;
  std::vector<double> contact_force_, contact_bn_;
  // Friction (contacts with μ > 0): the held nodes' unconstrained accelerations b_i and their friction
  // forces after an evaluation; whether any contact has friction or sticks (refresh()).
  Points<dim> contact_b_, contact_friction_;
  bool contact_friction_on_ = false, contact_stuck_ = false;
  /// evaluate_current, after assemble_matrix: the sliding nodes' responses w (P + μ t̂ nᵀ): the
  /// non-symmetric part μ w (e·t̂)(n·e') of their links' rows (the projections keep w P).
  void friction_couplings();
  /// A link whose two nodes cannot move (stuck, or stuck and prescribed) is locked: its tension is
  /// statically indeterminate, and it keeps the one it had when it locked (continuity in time). Its
  /// row becomes −s T_j = −s T_lock (s = 1/m_a + 1/m_b): lock_stuck_links (assemble_matrix) writes
  /// the diagonal, locked_rhs (evaluate_current) the right side; refresh() locks and unlocks.
  std::vector<char> locked_;
  std::vector<double> locked_tension_, last_tension_;
  void lock_stuck_links();
  void locked_rhs();
  void update_locked_links();
  /// The links ending at node i and starting at it (−1 where there is none).
  std::pair<int, int> node_links(int i) const;
  /// evaluate_current, after the contact forces: each friction node's force (contact_friction_) and
  /// a sliding node's acceleration from its links' share of it.
  void contact_friction_forces();
  /// evaluate_current: each held node's b_i becomes P b_i + c_i n (P = I − n nᵀ, c_i the normal
  /// acceleration the surface asks, with the drift control of its gap).
  void constrain_contact_nodes();
  /// assemble_matrix: the held nodes' inverse masses become w_i P in the rows of their two links.
  void contact_couplings();
  /// project(): puts the held nodes back on their surfaces (x −= gap n); returns the largest gap / h.
  double place_contact_nodes();
  void bend_links();               // links(): the bent links' lengths and directions
  /// A link bent over a circle at x_, v_: its length, arc, straight parts, directions e⁻, e⁺ and the
  /// quadratic term q of d²l/dt² = e⁺·a_b − e⁻·a_a + q.
  struct CircleBend {
    double l = 0, arc = 0, s_a = 0, s_b = 0, q = 0;
    Vec<dim> e_minus = Vec<dim>::Zero(), e_plus = Vec<dim>::Zero();
  };
  CircleBend circle_bend(const Bend& bend) const { return circle_bend(bend, [this](int i) { return x_.col(i); }); }
  /// The same at the positions x(i) (a callable: x_, or a state's y) and the velocities v_ (for q only).
  template <class Position>
  CircleBend circle_bend(const Bend& bend, const Position& x) const;
  /// Link j's direction at its end node, in the rows of a node held there: e⁺ for a bent link (over a circle
  /// or a point), e_j otherwise. (A link bent over a point once kept e_j here: a table after its edge in the
  /// material, whose first node b is held at the end of the bent link, then saw that link run along its
  /// hanging side, uncoupled from the table's links, and its tension there fell to zero: issue #23.)
  Vec<dim> end_direction_at_contact(int j) const;
  void bend_couplings();           // assemble_matrix(): their couplings at the end node
  double bend_rate(const Bend& bend) const;  // d(l⁻ + l⁺)/dt
  /// bend_side_direction and bent_sides at the positions x(i) (a callable: x_, or a state's y); without
  /// `directions` the lengths only (no error where a side has no direction).
  template <class Position>
  Vec<dim> side_reference(const Bend& bend, bool at_end, const Position& x) const;
  template <class Position>
  PointBendSides point_bend_sides(const Bend& bend, const Position& x, bool directions) const;
  const Bend* bend_of(int link) const;       // the bend of a link, or null
  /// Whether a link is bent over a point (an edge or a peg; not over a cylinder).
  bool point_bent(int link) const {
    const Bend* bend = bends_.empty() ? nullptr : bend_of(link);
    return bend && !bend->circle;
  }
  /// Link j's length at x_ (a bent link's runs over its point: l⁻ + l⁺), without links().
  double current_length(int j) const;
  /// Slack link j's root: (h_j − l_j)/h_j at the current positions, plus its offset (≥ 0, when it went slack
  /// at a snap at full length) while it is still shortening.
  double slack_root(int j) const;
  Eigen::VectorXd base_mass_;    // lumped masses of the arcs' links
  Eigen::VectorXd m_;            // current masses (base + module)
  Eigen::VectorXd w_;            // 1/m_i for free nodes, 0 otherwise
  Eigen::VectorXd base_w_;       // w_ of the base masses (rebuild(), with a module): refresh() takes it where m_i is the base mass
  /// refresh() (with a module): a free node whose mass m_i (the module's partial links included) is not above
  /// this has lost its mass, a RecoverableError (a front overshot it; 1e-12 λ h, rebuild()).
  double lost_mass_floor_ = 0;
  int num_free_ = 0;
  double alpha_ = 0, beta_ = 0;
  /// β² of the last evaluation: 1/τ_b², capped where its response to round-off would exceed the
  /// physical accelerations (evaluate_current); the Jacobian uses the same value.
  double beta2_ = 0;
  Vec<dim> external_ = Vec<dim>::Zero();
  // workspace
  Points<dim> x_, v_, a_, force_, force_nc_, module_force_, tension_force_, b_, reaction_;
  /// Node i's non-conservative force: +0 (exactly what the zeroed array held) when force_nc_ is not
  /// kept, for a run with no such force.
  Vec<dim> force_nc(int i) const { return force_nc_.cols() ? Vec<dim>(force_nc_.col(i)) : Vec<dim>::Zero(); }
  Points<dim> dx_, dv_, e_;
  Eigen::VectorXd l_;
  double x_max_ = 0, h_min_ = INFINITY;
  ImpulsiveStart impulsive_start_;
  std::vector<char> slack_;            // per link: slack (slack = allow)
  std::vector<double> slack_offset_;   // per link: its root function's offset
  // per link: 0, no release flight; 1, slack since a located release at length l_r; 2, and since then shorter
  // than l_r by kFlightDepth h at an accepted step (its root function is (l_r − l)/h from then on: slack_root)
  std::vector<char> release_flight_;
  /// Link j borders a link that no arc holds (a front's split link): a front's arm, whose release the front judges.
  bool borders_front(int j) const;
  std::vector<double> rebound_time_, rebound_speed_;  // per link: when and how fast it separated at its last snap (NaN: it did not)
  // per link: released by the complementarity problem at some evaluation since the last accepted step (accept_step)
  std::vector<char> released_;
  bool any_released_ = false;
  int num_slack_ = 0;
};

template <int dim>
template <class Visit>
void StringModel<dim>::for_each_link(Visit&& visit) const {
  // visit(j, u, next): link j, its tension unknown u, and the next link of its arc (−1 at an open end).
  for (std::size_t k = 0; k < arcs_.size(); ++k) {
    const ArcRange& arc = arcs_[k];
    const int nl = arc.num_links(), u0 = first_unknown_[k];
    for (int q = 0; q + 1 < nl; ++q) visit(arc.first + q, u0 + q, arc.first + q + 1);
    if (nl > 0) visit(arc.first + nl - 1, u0 + nl - 1, arc.closed ? arc.first : -1);
  }
}

}  // namespace chainsim
