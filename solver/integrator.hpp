#pragma once
/// @file integrator.hpp
/// A thin, exception-safe front end to SUNDIALS ARKODE (ARKStep) for every ODE chainsim solves.
///
/// The reduced chain models and the string solver both describe themselves as an OdeSystem; the
/// Integrator advances it with an adaptive Runge–Kutta method (explicit ERK by default, or a
/// diagonally implicit DIRK whose Newton systems the system solves itself, as the string does with
/// its sparse linearisation, or else with a dense difference-quotient Jacobian), finds the zeros of the
/// system's event functions with ARKODE's rootfinding, and reports ARKODE's run statistics.
///
/// integrator.cpp is the only file that includes <arkode/...>: moving to SUNDIALS 7 touches one file.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "defaults.hpp"

namespace chainsim {

/// The ODE  y' = F(t, y)  plus optional event functions g_k(t, y) whose zeros ARKODE locates.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  /// Length of the state vector.
  virtual int size() const = 0;
  /// ydot = F(t, y). Throw RecoverableError for a trial state the model cannot evaluate
  /// (ARKODE retries with a smaller step); any other exception aborts the integration.
  virtual void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                   Eigen::Ref<Eigen::VectorXd> ydot) = 0;
  /// Number of event functions (0: no rootfinding is registered at all).
  virtual int num_events() const { return 0; }
  /// g[k] = g_k(t, y) for k < num_events().
  virtual void events(double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& /*y*/,
                      Eigen::Ref<Eigen::VectorXd> /*g*/) {}
  /// Direction of the zero crossings to report per event: +1 increasing, -1 decreasing, 0 both.
  virtual std::vector<int> event_directions() const { return {}; }
  /// The first num_recurring_events() event functions vanish again and again at a steady pace (a
  /// front crossing one node after another, each zero followed by a jump of the function back up).
  /// After a zero of one, the integrator predicts the next from the rates of the last two and ends a
  /// step just before it, so that the root is reached by a short correction instead of being
  /// overstepped, located on the interpolant and the step recomputed (docs/shocks.md, "On fine meshes").
  virtual int num_recurring_events() const { return 0; }
  /// Natural magnitude of each state component (e.g. the length for a position, a reference
  /// speed for a velocity). The absolute tolerance of component i is atol * scale[i], so atol is
  /// dimensionless and results do not depend on the choice of units. Empty = all ones.
  virtual Eigen::VectorXd state_scale() const { return {}; }
  /// Natural time scale of the motion (s), e.g. a free-fall time; 0 = none. The integrator's
  /// step-size floor is kStepFloor · max(|t|, time_scale()), so a system that starts at t = 0 and
  /// gives its scale is also watched over during its first instants.
  virtual double time_scale() const { return 0.0; }

  // --- Newton systems of implicit methods (optional) -----------------------------------------
  /// True if the system solves its own Newton systems (I − γ J) z = r, J = ∂F/∂y: implicit methods
  /// then take the Newton corrections from newton_solve() directly when newton_solver_exact(), else
  /// from GMRES preconditioned by newton_solve(), with products J·v from jacobian_times() or
  /// difference quotients of rhs(); otherwise they use a dense difference-quotient Jacobian.
  virtual bool has_newton_solver() const { return false; }
  /// Prepares newton_solve() for γ at (t, y). `relinearize` false: keep the linearisation of the last
  /// call and only change γ (y is then not used). Throw RecoverableError if (t, y) cannot be
  /// linearised (ARKODE retries with a smaller step).
  virtual void newton_setup(double /*t*/, const Eigen::Ref<const Eigen::VectorXd>& /*y*/, bool /*relinearize*/,
                            double /*gamma*/) {}
  /// z ≈ (I − γ J)⁻¹ r with the γ of the last newton_setup().
  virtual void newton_solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> z) { z = r; }
  /// True if newton_solve() inverts I − γ J for the very J of jacobian_times() (the linearisation
  /// leaves nothing out): the Newton corrections are then newton_solve(r) itself, without GMRES.
  virtual bool newton_solver_exact() const { return false; }
  /// Jv = J v at the last linearisation, if the system has it analytically (true); false: GMRES
  /// takes J v from a difference quotient of rhs().
  virtual bool jacobian_times(const Eigen::Ref<const Eigen::VectorXd>& /*v*/, Eigen::Ref<Eigen::VectorXd> /*Jv*/) {
    return false;
  }
  /// How many explicit steps the stability of an explicit method forces per natural time of the
  /// motion (e.g. links of a string: the fastest wave crosses a link, the motion crosses the
  /// string); 0 = unknown. IntegratorOptions::method = "auto" picks an implicit method when it
  /// reaches Integrator::kAutoImplicitStiffness and the system has no event functions.
  virtual double explicit_stiffness() const { return 0.0; }
};

/// How the integrator advances the ODE. validate() throws InputError naming the bad field.
struct IntegratorOptions {
  /// ARKODE Butcher table by name (ARKODE_ERK_* explicit, ARKODE_*DIRK* implicit), or one of the
  /// short aliases listed by method_aliases(): "erk8" (Fehlberg 13-7-8, default), "erk6" (Verner
  /// 8-5-6), "erk5" (Dormand–Prince 7-4-5), "erk4" (Zonneveld 5-3-4), "erk3" (Bogacki–Shampine),
  /// "dirk5" (Kvaerno 7-4-5), "dirk4" (ARK 4-3-6 DIRK), "dirk3" (ARK 3-2-4 DIRK), "dirk2" (SDIRK 2-1-2),
  /// or "auto": at rtol >= kAutoLooseRtol, kAutoImplicit when OdeSystem::explicit_stiffness() >=
  /// Integrator::kAutoImplicitStiffness and the system has no event functions, else kAutoExplicitLoose;
  /// at tighter tolerances kAutoExplicitStiff for such a stiff system, else kAutoExplicit.
  std::string method = defaults::kLibrary.method;
  double rtol = defaults::kLibrary.rtol;  ///< relative tolerance, in [1e-14, 1e-2]
  double atol = defaults::kLibrary.atol;  ///< absolute tolerance relative to OdeSystem::state_scale(), > 0
  double max_step = 0;   ///< largest step (s); 0 = no limit
  double initial_step = 0;  ///< first step (s); 0 = ARKODE's estimate
  /// Accepted steps allowed in total over the Integrator's life (every advance() call and every
  /// event polish counted), >= 1. Past it the run ends with NumericalError (ARK_TOO_MUCH_WORK).
  long max_steps = defaults::kMaxSteps;
  /// Wall-clock budget (s) of the Integrator from its construction; 0 = none. Past it the run ends
  /// with NumericalError naming the time reached.
  double max_wall_s = 0;
  /// Everything: validate_method() and validate_numbers(). Where the options enter (a command's
  /// options, a scene's keys, a set-up's validate()) they are checked once, located; the Integrator,
  /// the one user of the method, checks the numbers and loads the method's table (an unknown name is
  /// refused there, with the same message).
  void validate() const;
  /// `method` names a known method (an alias, "auto" or an ARKODE_* table): throws InputError.
  void validate_method() const;
  /// The method is an implicit (DIRK) table or alias ("auto" is not: with root functions it is explicit).
  bool implicit_method() const;
  /// The tolerances, step limits and budgets: throws InputError naming the field.
  void validate_numbers() const;
};

/// The methods "auto" chooses between (integrator.hpp, IntegratorOptions::method), the winners of
/// docs/work-precision.md ("What auto picks"): from rtol >= kAutoLooseRtol on, the implicit one for a stiff
/// system without event functions, else kAutoExplicitLoose (erk3 at rtol 1e-3 - 1e-6 on the front problems
/// and the non-stiff strings alike); below it, kAutoExplicitStiff for a stiff system without event functions
/// (implicit steps then follow the tolerance: on the hanging chain of 81 - 641 nodes at rtol 1e-7 - 1e-9 erk3
/// was 1.0 - 4 times faster than dirk4), else kAutoExplicit (erk5 at 1e-8 - 1e-9, where a front's crossings,
/// not stability, set the steps).
inline constexpr const char* kAutoExplicit = "erk5";
inline constexpr const char* kAutoExplicitLoose = "erk3";
inline constexpr const char* kAutoExplicitStiff = "erk3";
/// ... up to this stiffness (the links of a uniform string), the finest measured: erk3's stability-bound steps
/// grow with it, and beyond it dirk4 stays the choice at every rtol (docs/string_solver.md measured dirk4 3 - 5
/// times faster than erk4 at rtol 1e-7 - 1e-8 on 800 - 1,600 links, with another atol than the study's).
inline constexpr double kAutoExplicitStiffMax = 640;
inline constexpr double kAutoLooseRtol = 1e-6;
inline constexpr const char* kAutoImplicit = "dirk4";

/// Short names of the built-in methods, e.g. "erk8", with a one-line description each.
std::vector<std::pair<std::string, std::string>> method_aliases();

/// ARKODE's counters for one integration (cumulative over re-initialisations).
struct IntegratorStats {
  long steps = 0;             ///< accepted steps
  long step_attempts = 0;     ///< accepted + rejected
  long error_test_fails = 0;  ///< steps rejected by the error test
  long rhs_evals = 0;         ///< evaluations of F (explicit + implicit stages)
  long event_evals = 0;       ///< evaluations of the event functions
  long nonlin_iters = 0;      ///< Newton iterations (implicit methods only)
  long nonlin_conv_fails = 0;
  long jac_evals = 0;         ///< Jacobian evaluations or linearisations (implicit methods only)
  long lin_setups = 0;
  long lin_iters = 0;         ///< GMRES iterations (implicit methods with the system's Newton solver)
  long lin_solves = 0;        ///< solves of the system's Newton solver (GMRES preconditioner)
  long recoverable_failures = 0;  ///< RHS calls that asked for a smaller step
  double last_step = 0;       ///< size of the last accepted step (s)
  std::string method;         ///< the Butcher table used
  int order = 0;              ///< its order
  bool implicit = false;
};

/// Advances one OdeSystem from (t0, y0). Not copyable; owns its ARKODE memory.
///
/// Watchdog: no integration can run forever. advance() throws NumericalError, naming the time, the
/// step size, the method and what to change, when
///   - the accepted steps of the whole run exceed IntegratorOptions::max_steps;
///   - the step size collapses: kStallSteps accepted steps in a row shorter than
///     kStepFloor · max(|t|, OdeSystem::time_scale()), or that leave t unchanged in floating point;
///   - the wall-clock time exceeds IntegratorOptions::max_wall_s (if set).
class Integrator {
 public:
  Integrator(OdeSystem& system, double t0, const Eigen::VectorXd& y0, const IntegratorOptions& options);
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  /// Relative step-size floor of the watchdog, and how many accepted steps in a row below it (or
  /// that do not advance t) end the run.
  static constexpr double kStepFloor = 1e-14;
  static constexpr int kStallSteps = 5;
  /// "auto" picks an implicit method from this OdeSystem::explicit_stiffness() on (measured
  /// crossover at equal accuracy, 35 links: docs/string_solver.md, "The implicit path").
  static constexpr double kAutoImplicitStiffness = 50;
  /// Methods up to this order interpolate inside a step with ARKODE's Hermite interpolant of degree
  /// order − 1 (at most 5): frames can be taken from it. Above it the steps are far more accurate than
  /// any interpolant, so frames are stop times, and with event functions the interpolant serves only
  /// ARKODE's rootfinding, whose root the polish recomputes: it is then cubic, whose evaluations need
  /// no right-hand side (degrees 4 and 5 take one and two per evaluation).
  static constexpr int kMaxDenseOrder = 5;
  /// The method "auto" resolves to for `system` at relative tolerance `rtol` (any other name is returned
  /// unchanged).
  static std::string resolve_method(const std::string& method, const OdeSystem& system,
                                    double rtol = defaults::kLibrary.rtol);

  enum class Outcome {
    kReachedTarget,  ///< t == t_target
    kEvent,          ///< stopped at a zero of an event function; see events_found()
    kStep,           ///< one internal step taken (one_step mode), t < t_target
  };

  /// Called by advance() at a root return before the event is polished, with the step that holds
  /// the root: its start and its end (the polished event lies in between, not always before the
  /// root ARKODE located). interpolate() covers [t_start, t_end] during the call (it no longer does
  /// once the polish has recomputed the step). It may be called again within one advance() (a root the
  /// polish refutes: the step is taken again): each call supersedes the last.
  using RootStepHook = std::function<void(double t_start, double t_end)>;

  /// Advance towards t_target (never past it). In one_step mode return after each internal step,
  /// which lets a caller record the adaptive steps. Throws NumericalError when ARKODE fails (the
  /// message carries ARKODE's flag name and the time reached), or when the watchdog (see the class
  /// comment) stops the run.
  Outcome advance(double t_target, bool one_step = false, const RootStepHook& before_polish = {});

  /// Current time and state of the integrator.
  double time() const { return t_; }
  const Eigen::VectorXd& state() const { return y_; }
  /// The current state, moved out: for a caller that is done with the integrator (state() is empty
  /// afterwards), so that keeping the final state costs no second copy beside the integrator's vectors.
  Eigen::VectorXd take_state() { return std::move(y_); }

  /// After Outcome::kEvent: for each event function, +1/-1 if it crossed zero increasing/decreasing, else 0.
  /// The event's time and state are polished to the method's accuracy (not the interpolant's):
  /// the step holding the root is recomputed up to ARKODE's root in one step of the method, and the
  /// root's time corrected by Newton iteration on g (small corrections by a Heun step along the flow,
  /// larger ones by recomputing the step). The next restart() or resize() resumes with the step size
  /// ARKODE had reached before the event rather than a fresh estimate (after a predicted zero of a
  /// recurring function, OdeSystem::num_recurring_events, the step the error of the last step allows,
  /// if larger: the step before it was cut at the stop time).
  const std::vector<int>& events_found() const { return events_found_; }

  /// Interpolated state (k = 0) or its k-th derivative at time t inside the last step (dense output).
  Eigen::VectorXd interpolate(double t, int k = 0) const;

  /// Restart from (t, y) with the same system size: used after a discontinuity (e.g. a
  /// sign change of a velocity that switches the model's branch).
  void restart(double t, const Eigen::VectorXd& y);

  /// Continue with a state of a different length (the OdeSystem's size() must already report it).
  void resize(double t, const Eigen::VectorXd& y);

  /// After restart() or resize(): the right-hand side F(t, y) at the state just given, which the caller has
  /// evaluated since (e.g. for a record of that state). ARKODE's evaluation at the start of the next step,
  /// at that same state, is then taken from it instead of evaluated again (its counters count it as
  /// before); any other first evaluation discards it.
  void provide_start_rhs(const Eigen::VectorXd& f);

  IntegratorStats stats() const;
  /// The size of the last accepted step (s): stats().last_step without the other counters.
  double last_step() const;

 private:
  int evolve(double t_target, bool one_step);
  void watchdog(double t_before, int flag);
  std::string diagnosis() const;
  /// Returns -1 (the event is polished), or the event function whose root the recomputed step refutes
  /// (no event: the integrator is back at the step's start).
  int polish_event(double t_step_start, const Eigen::VectorXd& y_step_start, double t_step_end, bool from_here);
  void error_weights(Eigen::VectorXd& weights) const;
  double allowed_step() const;
  void set_root_directions(int ignored = -1);
  double predict_recurring_event(double t_target, int& which);
  bool passed_zero(int which);
  void predicted_event(int which, double t_step_start, const Eigen::VectorXd& y_step_start,
                       const RootStepHook& before_polish);

  struct Impl;
  std::unique_ptr<Impl> impl_;
  double t_;
  Eigen::VectorXd y_;
  std::vector<int> events_found_;
};

}  // namespace chainsim
