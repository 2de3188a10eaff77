#pragma once
/// @file string_module.hpp
/// What a module adds to the one discrete string (string_model.hpp): the interface through which
/// front tracking (shocks/front_tracker.hpp, one class per kind of front) cuts the material into arcs
/// and imposes the conditions of its fronts, without a second copy of the string. The string knows no
/// kind of front: a module's ledger terms and front fields are named by the module.
///
/// The string owns everything a string has: nodes, links, lumped masses, the tension system of its
/// arcs, the applied forces, the prescribed ends, the constraint projection, the energy ledger of
/// the applied work, snapshots and outputs. A module owns what is particular to its fronts:
///   - the layout: which nodes move, cut into arcs (runs of nodes that move together); the nodes in
///     no arc (held by the module) have no equation of motion;
///   - at every evaluation, the mass and the force it puts on nodes (a partial link's material, the
///     end tensions of the jump conditions) — known loads of the tension system, not new unknowns;
///   - extra ledger components integrated with the ODE (work done at its fronts, impulse of its
///     supports, …), with their rates, and the named terms it reports (ledger_terms);
///   - root functions and what happens at them (a node crossing a front: the layout changes, the
///     string rebuilds its arcs and projects the state back onto the constraints);
///   - its contributions to snapshots (fronts, supports, the named terms).
/// A string without a module runs the same code with one arc and none of these.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mesh/chain.hpp"

namespace chainsim {

template <int dim>
class StringModel;

/// A run of nodes first..last (inclusive) that move together; a closed arc's last link joins last to
/// first.
struct ArcRange {
  int first = 0, last = 0;
  bool closed = false;
  int num_links() const { return closed ? last - first + 1 : last - first; }
  int num_nodes() const { return last - first + 1; }
};

/// A front as the run's outputs show it (snapshots, frames, series.csv, forces.csv, the ParaView
/// fronts): its place in the material and in space and the force of its support. What a kind of front
/// computes beyond this stays in the module (shocks/front_kind.hpp, FrontState).
template <int dim>
struct FrontRecord {
  double s0 = 0;      ///< material coordinate of the front (m)
  double s0_dot = 0;  ///< its speed in the material (m/s)
  Vec<dim> position = Vec<dim>::Zero();  ///< x0 (m)
  Vec<dim> reaction = Vec<dim>::Zero();  ///< the force of the front's support on the string (N); zero if none
  /// The module's further values for the ParaView fronts, in the order of StringModule::front_fields()
  /// (a vector field: dim values).
  std::vector<double> fields;
};

/// A physical event a module located during the run (the summary's `events`): its kind ("lift_off"),
/// time (s), front, position (m, dim components), further named values and named indices. An obstacle's event (a node
/// the contact module let go, solver/contact_module.hpp) names its obstacle instead of a front
/// (`front` −1, `obstacle` e.g. "effects.cylinder[0]"); a front's event has no obstacle ("").
struct RunEvent {
  std::string kind;
  double t = 0;
  int front = -1;
  std::vector<double> position;
  std::vector<std::pair<std::string, double>> values;
  // Default member initializers: the fronts' aggregate initializers stay complete.
  std::string obstacle{};
  std::vector<std::pair<std::string, long>> indices{};  ///< named integers (a node's, a link's index)
};

/// How many lift-offs an obstacle had in the run, all of them, listed in `events` or not (the contact
/// module lists at most a bound per obstacle: ContactModule, kListedLiftOffs).
struct LiftOffTotal {
  std::string obstacle;
  long total = 0;
};

/// What a module draws of the obstacles it models (fixed in space), for the ParaView output
/// (frames/obstacles.vtp, docs/string_solver.md): vertex cells (a 2D edge or peg, seen end-on) and line
/// segments (a 3D edge's line, a table's faces, a surface's outline, a cylinder's circles), each with the
/// obstacle it belongs to (an edge: its front's index; a surface or cylinder: its index in the contact
/// module's list) and what part of it it is. Points in 3D (m; a 2D run's z = 0).
struct ObstacleDrawing {
  /// 0 the edge (its point or its line), 1 the table's face, 2 the wedge's other face (the table's side),
  /// 3 a surface ([[effects.surface]]: a segment in 2D, a rectangle's sides in 3D), 4 a cylinder
  /// ([[effects.cylinder]]: its circle in 2D, its two end circles in 3D), 5 a cylinder's generator (3D).
  enum Part { kEdge = 0, kTable = 1, kSide = 2, kSurface = 3, kCylinder = 4, kGenerator = 5 };
  std::vector<Eigen::Vector3d> points;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  std::vector<int> point_obstacle, segment_obstacle;  ///< per cell: the obstacle's index
  std::vector<int> point_part, segment_part;          ///< per cell: Part
  bool empty() const { return points.empty() && segments.empty(); }
  /// A segment cell of obstacle `obstacle`, part `part`.
  void add_segment(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int obstacle, int part) {
    segments.emplace_back(from, to);
    segment_obstacle.push_back(obstacle);
    segment_part.push_back(part);
  }
  /// A point of the string's space as drawn (z = 0 in 2D).
  template <int dim>
  static Eigen::Vector3d in_3d(const Vec<dim>& v) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p.head(dim) = v;
    return p;
  }
};

/// A field of the ParaView fronts that the module adds (a point-data array of fronts_XXXX.vtp).
struct FrontField {
  std::string name;
  bool vector = false;  ///< dim components (written as 3), else one
};

/// A term the module adds to the ledgers, under the name the outputs give it.
struct LedgerTerm {
  enum class Kind {
    kWork,       ///< energy exchanged (J): booked in the energy ledger and in its physical scale
    kNumerical,  ///< energy a numerical operation changes (J): booked in the ledger, not in its scale
    kQuantity    ///< a recorded quantity (series.csv), in no ledger
  };
  std::string name;  ///< the output column (energy.csv for energies, series.csv for all)
  Kind kind = Kind::kWork;
  bool energy() const { return kind != Kind::kQuantity; }
};

/// The derivative of the mass and force a module puts on node `node` (add_mass_and_forces) with respect
/// to the position (`velocity` false) or the velocity of node `of`: ∂F/∂y (dim × dim) and ∂m/∂y (a
/// row). The string's linearisation (solver/string_jacobian.hpp) takes them into its Newton systems.
template <int dim>
struct LoadDerivative {
  int node = -1, of = -1;
  bool velocity = false;
  Eigen::Matrix<double, dim, dim> force = Eigen::Matrix<double, dim, dim>::Zero();
  Eigen::Matrix<double, 1, dim> mass = Eigen::Matrix<double, 1, dim>::Zero();
};

/// What a module adds to a snapshot: nothing for a string without one.
template <int dim>
struct ModuleLedger {
  std::vector<FrontRecord<dim>> fronts;
  std::vector<double> terms;            ///< the values of StringModule::ledger_terms(), in order
  Vec<dim> impulse = Vec<dim>::Zero();  ///< of all external forces (N s), when the module keeps it
  Vec<dim> support = Vec<dim>::Zero();  ///< force of the module's supports on the system (N)
  bool has_momentum_ledger = false;     ///< impulse is integrated: p − p0 − impulse → 0
};

/// A node held on the surface of a rigid obstacle (a contact module, solver/contact_module.hpp;
/// docs/model.md §10): while it is listed, the node's gap stays zero, its normal acceleration is the
/// one the surface's curvature asks, and the contact force N n (N ≥ 0 while it holds) is the
/// multiplier of that constraint, eliminated node by node from the tension system
/// (StringModel::contact_force).
template <int dim>
struct NodeContact {
  int node = -1;
  Vec<dim> normal = Vec<dim>::Zero();  ///< the obstacle's unit outward normal at the node
  double gap = 0;                      ///< the node's signed distance from the surface (m), ≥ 0 outside
  /// The gap's second derivative at zero acceleration (m/s²): |Q v|² − (n·v)² over the distance
  /// from a cylinder's axis (Q the projection normal to the axis), 0 for a plane.
  double curvature = 0;
  /// Coulomb friction (docs/model.md §10, "Friction"): the obstacle's μ (0: smooth, and the two fields
  /// below are unused). Sliding: the friction force is −μ N t̂, t̂ = `slide` (the unit tangential
  /// direction of the node's motion), and the node's response becomes w (P + μ t̂ nᵀ). Sticking
  /// (`stuck`): the node is held completely (inverse mass 0, acceleration 0), and the tangential
  /// force that takes is StringModel::contact_friction.
  double mu = 0;
  Vec<dim> slide = Vec<dim>::Zero();
  bool stuck = false;
};

/// A kinematic constraint C(x) = 0 on a few nodes that no link expresses (a kink's compatibility,
/// docs/model.md §2.5): its gradient ∂C/∂x_i at each of `nodes`, its value and its second derivative
/// at zero accelerations. Its multiplier μ acts on the nodes as the forces μ ∂C/∂x_i, which do no work
/// while the constraint holds (their power is μ Ċ); StringModel finds it with the link tensions (a
/// bordered solve of the tension system: the matrix stays the arcs' tridiagonal one), and its
/// projections keep C = 0 and Ċ = 0 (StringModel::project).
template <int dim>
struct NodeConstraint {
  std::vector<int> nodes;
  Points<dim> gradient;   ///< ∂C/∂x_i (a column per node of `nodes`)
  double value = 0;       ///< C
  double curvature = 0;   ///< C̈ − Σ ∂C/∂x_i · a_i: C̈ at zero accelerations
};

/// What an event means.
struct EventAction {
  enum class Kind { kNone, kTransfer, kStop } kind = Kind::kNone;
  std::string reason;  ///< for kStop: why the run ends
};

template <int dim>
class StringModule {
 public:
  virtual ~StringModule() = default;

  // --- set-up -----------------------------------------------------------------------------------
  /// The arcs the material starts in (node ranges in increasing order). Throws InputError when the
  /// module's layout does not fit the chain.
  virtual std::vector<ArcRange> initial_arcs(const Chain<dim>& chain) = 0;
  /// Checks that need the built string (its state, masses and arcs); called once, after the string
  /// is built. Throws InputError.
  virtual void initialize(StringModel<dim>& model) = 0;
  /// The start, after the initial state's projection onto the constraints (StringModel::make_consistent)
  /// and before the run: the module acts on the consistent state at t0 (the contact module lets go of the
  /// held nodes whose force would pull there and lands the free nodes that the projection carried into a
  /// surface, docs/model.md §10; the module of unilateral links books the start's snap and snaps the slack
  /// links a landing there carried to their length, §9), booking what it does in its ledgers' initial values
  /// `ledger`. Returns whether it changed the state (model.x(), model.v()).
  virtual bool start(StringModel<dim>& /*model*/, double /*t0*/, Eigen::Ref<Eigen::VectorXd> /*ledger*/) {
    return false;
  }

  // --- every evaluation ---------------------------------------------------------------------------
  /// At the string's current positions and velocities: adds the mass (kg) and the force (N) the
  /// module puts on each node. Throws RecoverableError for a trial state it cannot use.
  virtual void add_mass_and_forces(const StringModel<dim>& model, Eigen::VectorXd& mass, Points<dim>& force) = 0;
  /// Number of ledger components the module integrates (they follow W_applied in the state).
  virtual int num_ledgers() const = 0;
  /// Their rates, after an evaluation (accelerations, reactions known).
  virtual void ledger_rates(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> rates) const = 0;
  /// Their natural magnitudes, for the absolute tolerances (mass, speed and length scales given).
  virtual Eigen::VectorXd ledger_scale(double mass, double speed, double length) const = 0;
  /// The potential energy the lumped masses miss (J): V = Σ forces' V(lumped) + this.
  virtual double potential_correction(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger) const = 0;
  /// The terms it adds to the ledgers (ModuleLedger::terms), named as the outputs write them.
  virtual std::vector<LedgerTerm> ledger_terms() const = 0;
  /// The fields it adds to the ParaView fronts (FrontRecord::fields).
  virtual std::vector<FrontField> front_fields() const = 0;
  /// Fills the module's part of a snapshot.
  virtual void fill(const StringModel<dim>& model, const Eigen::Ref<const Eigen::VectorXd>& ledger,
                    ModuleLedger<dim>& out) const = 0;

  // --- events ------------------------------------------------------------------------------------
  virtual int num_events() const = 0;
  virtual void events(const StringModel<dim>& model, Eigen::Ref<Eigen::VectorXd> g) const = 0;
  virtual std::vector<int> event_directions() const = 0;
  /// Acts on the events found (signs per root function) at the string's current state: moves
  /// nodes across fronts (then calls model.rebuild() and model.project()) and books what the
  /// change does to the ledgers, or reports a stop.
  virtual EventAction handle_events(StringModel<dim>& model, double t, Eigen::Ref<Eigen::VectorXd> ledger,
                                    const std::vector<int>& found) = 0;
  /// Number of node transfers so far.
  virtual long transfers() const = 0;
  /// Number of fronts (entries of ModuleLedger::fronts).
  virtual int num_fronts() const = 0;
  /// The first num_crossing_events() root functions are node crossings of fronts, which recur one
  /// link after another (OdeSystem::num_recurring_events: the integrator ends a step at the next).
  virtual int num_crossing_events() const { return 0; }
  /// The tension (N) the module's partial link carries at `node`, an arc's end node next to a front,
  /// after an evaluation; nothing if no front is next to it. A prescribed node whose arc has no full
  /// link (a front at the fixed end) reports this tension: the one-sided limit at the node.
  virtual std::optional<double> front_tension_at(const StringModel<dim>& model, int node) const = 0;
  /// Whether the root functions read the tensions (then the string evaluates its tension system
  /// before events(), else it only refreshes the module's masses and forces).
  virtual bool events_need_tensions() const { return false; }
  /// Whether load_derivatives() gives every derivative of the masses and forces it adds (then the
  /// string's Newton systems are exact with the module).
  virtual bool has_load_derivatives() const { return false; }
  /// Adds the derivatives of add_mass_and_forces() at the string's current state (after an
  /// evaluation). `model` is not const so that a module may differentiate by moving nodes; it leaves
  /// the string and its own state as it found them.
  virtual void load_derivatives(StringModel<dim>& /*model*/, std::vector<LoadDerivative<dim>>& /*out*/) {}
  /// The nodes held on obstacles at the current positions and velocities (called by refresh(), after
  /// add_mass_and_forces); none without a contact module.
  virtual void node_contacts(const StringModel<dim>&, std::vector<NodeContact<dim>>&) const {}
  /// The constraints that couple nodes beyond the links (NodeConstraint) at the current positions and
  /// velocities (called by refresh(), after node_contacts); none but at a kink front.
  virtual void node_constraints(const StringModel<dim>&, std::vector<NodeConstraint<dim>>&) const {}
  /// After an impulse the module did not make (a snap of the slack module around it): lets go of the
  /// held nodes whose contact force would now pull; returns whether one was let go.
  virtual bool release_contacts(StringModel<dim>&, double) { return false; }
  /// At an event the module did not locate (a snap of the slack module around it): lands the free nodes that have
  /// passed a surface unseen (their landing function below zero at the event's state, where ARKODE, restarting,
  /// would find no root), with the impact booked in `ledger` (the module's ledgers); returns whether one landed.
  virtual bool land_passed(StringModel<dim>&, double, Eigen::Ref<Eigen::VectorXd>) { return false; }
  /// Around an impulse the module did not make (the snaps of the slack module around it), which may change which
  /// links are slack: hold_fronts() keeps the fronts drawn as at the last evaluation (a heap's curve to its plane
  /// stops at a slack link), redraw_fronts() draws them on the links as they are now and books what that moves
  /// between the arcs and the heaps in `ledger` (the module's ledgers), as a crossing's re-drawing is booked.
  virtual void hold_fronts() {}
  virtual void redraw_fronts(StringModel<dim>&, Eigen::Ref<Eigen::VectorXd>) {}
  /// The physical events of the run so far (e.g. a chain lifting off an edge), for the run's summary,
  /// in time order.
  virtual std::vector<RunEvent> run_events() const { return {}; }
  /// Per obstacle, the lift-offs of the run so far, listed in run_events() or not (the summary's
  /// `contact_lift_offs`); empty without a contact module.
  virtual std::vector<LiftOffTotal> lift_off_totals() const { return {}; }
  /// The root functions `g` (events() at the start of the run) that say the run cannot go on from
  /// its very start: ARKODE finds only sign changes, so a check already negative at t0 (an edge that
  /// would have to pull the string it is given) is acted on as an event at t0. Returns `found` for
  /// handle_events (-1 at each such function), or empty when the start is fine.
  virtual std::vector<int> events_failed_at_start(const Eigen::Ref<const Eigen::VectorXd>& /*g*/) const { return {}; }
  /// Whether events_failed_at_start can find anything (else the runner does not evaluate events() at t0).
  virtual bool checks_at_start() const { return false; }
  /// The same after an event's handling, at the state the integrator restarts from (e.g. a front's crossing),
  /// without the checks that a kind of front lets go negative there (FrontKind::check_after_events).
  virtual std::vector<int> events_failed_after_event(const Eigen::Ref<const Eigen::VectorXd>& g) const {
    return events_failed_at_start(g);
  }
  /// The obstacles to draw in the ParaView output (none by default: no obstacles.vtp is written).
  virtual ObstacleDrawing obstacles() const { return {}; }
};

}  // namespace chainsim
