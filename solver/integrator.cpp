// The only translation unit that includes ARKODE: see integrator.hpp.
#include "integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <map>
#include <utility>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_butcher_dirk.h>
#include <arkode/arkode_butcher_erk.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "mesh/errors.hpp"
#include "nvector_kernels.hpp"

namespace chainsim {

namespace {

struct Alias {
  const char* table;
  const char* description;
};

const std::map<std::string, Alias>& aliases() {
  static const std::map<std::string, Alias> table = {
      {"erk8", {"ARKODE_FEHLBERG_13_7_8", "explicit, order 8 (Fehlberg 13 stages)"}},
      {"erk6", {"ARKODE_VERNER_8_5_6", "explicit, order 6 (Verner 8 stages)"}},
      {"erk5", {"ARKODE_DORMAND_PRINCE_7_4_5", "explicit, order 5 (Dormand-Prince)"}},
      {"erk4", {"ARKODE_ZONNEVELD_5_3_4", "explicit, order 4 (Zonneveld)"}},
      {"erk3", {"ARKODE_BOGACKI_SHAMPINE_4_2_3", "explicit, order 3 (Bogacki-Shampine)"}},
      {"dirk5", {"ARKODE_KVAERNO_7_4_5", "implicit, order 5 (Kvaerno ESDIRK)"}},
      {"dirk4", {"ARKODE_ARK436L2SA_DIRK_6_3_4", "implicit, order 4 (ARK4(3)6L[2]SA ESDIRK)"}},
      {"dirk3", {"ARKODE_ARK324L2SA_DIRK_4_2_3", "implicit, order 3 (ARK3(2)4L[2]SA ESDIRK)"}},
      {"dirk2", {"ARKODE_SDIRK_2_1_2", "implicit, order 2 (SDIRK)"}},
  };
  return table;
}

std::string table_name(const std::string& method) {
  auto it = aliases().find(method);
  return it == aliases().end() ? method : it->second.table;
}

// The Butcher tables of SUNDIALS 6.4 (arkode_butcher_erk.h, arkode_butcher_dirk.h). Names are
// checked here first: ARKODE's own lookup prints to stderr for an unknown name.
constexpr const char* kErkTables[] = {
    "ARKODE_HEUN_EULER_2_1_2", "ARKODE_BOGACKI_SHAMPINE_4_2_3", "ARKODE_ARK324L2SA_ERK_4_2_3",
    "ARKODE_ZONNEVELD_5_3_4", "ARKODE_ARK436L2SA_ERK_6_3_4", "ARKODE_SAYFY_ABURUB_6_3_4", "ARKODE_CASH_KARP_6_4_5",
    "ARKODE_FEHLBERG_6_4_5", "ARKODE_DORMAND_PRINCE_7_4_5", "ARKODE_ARK548L2SA_ERK_8_4_5", "ARKODE_VERNER_8_5_6",
    "ARKODE_FEHLBERG_13_7_8", "ARKODE_KNOTH_WOLKE_3_3", "ARKODE_ARK437L2SA_ERK_7_3_4",
    "ARKODE_ARK548L2SAb_ERK_8_4_5"};
constexpr const char* kDirkTables[] = {
    "ARKODE_SDIRK_2_1_2", "ARKODE_BILLINGTON_3_3_2", "ARKODE_TRBDF2_3_3_2", "ARKODE_KVAERNO_4_2_3",
    "ARKODE_ARK324L2SA_DIRK_4_2_3", "ARKODE_CASH_5_2_4", "ARKODE_CASH_5_3_4", "ARKODE_SDIRK_5_3_4",
    "ARKODE_KVAERNO_5_3_4", "ARKODE_ARK436L2SA_DIRK_6_3_4", "ARKODE_KVAERNO_7_4_5", "ARKODE_ARK548L2SA_DIRK_8_4_5",
    "ARKODE_ARK437L2SA_DIRK_7_3_4", "ARKODE_ARK548L2SAb_DIRK_8_4_5", "ARKODE_ESDIRK324L2SA_4_2_3",
    "ARKODE_ESDIRK325L2SA_5_2_3", "ARKODE_ESDIRK32I5L2SA_5_2_3", "ARKODE_ESDIRK436L2SA_6_3_4",
    "ARKODE_ESDIRK43I6L2SA_6_3_4", "ARKODE_QESDIRK436L2SA_6_3_4", "ARKODE_ESDIRK437L2SA_7_3_4",
    "ARKODE_ESDIRK547L2SA_7_4_5", "ARKODE_ESDIRK547L2SA2_7_4_5"};

template <std::size_t N>
bool listed(const std::string& name, const char* const (&names)[N]) {
  for (const char* n : names)
    if (name == n) return true;
  return false;
}

/// Loads an ERK or DIRK table by name; both outputs are null for an unknown name.
void load_table(const std::string& name, ARKodeButcherTable& erk, ARKodeButcherTable& dirk) {
  erk = listed(name, kErkTables) ? ARKodeButcherTable_LoadERKByName(name.c_str()) : nullptr;
  dirk = listed(name, kDirkTables) ? ARKodeButcherTable_LoadDIRKByName(name.c_str()) : nullptr;
}

/// ARKODE's name of a return flag. ARKStepGetReturnFlagName allocates the string: the caller frees it.
std::string flag_name(int flag) {
  char* name = ARKStepGetReturnFlagName(flag);
  std::string out = name ? name : "unknown flag";
  std::free(name);
  return out;
}

std::string valid_methods() {
  std::string list;
  for (const auto& [alias, entry] : aliases()) list += (list.empty() ? "" : ", ") + alias;
  return "auto, " + list + ", or an ARKODE_* Butcher table name";
}

/// True if every entry is finite: x·0 is ±0 for a finite x and NaN otherwise, and a sum of zeros is
/// zero. One vectorised pass: Eigen's allFinite() tests entry by entry (7 k instructions per call on a
/// 250-link state, 4 % of an implicit step with its two calls per Newton iteration).
bool all_finite(const Eigen::Ref<const Eigen::VectorXd>& v) { return (v.array() * 0.0).sum() == 0.0; }

InputError unknown_method(const std::string& method) {
  return InputError(fmt::format("method = \"{}\" is not a known integration method: allowed {}", method, valid_methods()));
}

}  // namespace

std::vector<std::pair<std::string, std::string>> method_aliases() {
  std::vector<std::pair<std::string, std::string>> out;
  out.emplace_back("auto", fmt::format("at rtol >= {1:g}: {2} for a system as stiff as a string of {0:g} links or "
                                       "more and without root functions (fronts), else {3}; below: {4} for such a "
                                       "stiff system up to {6:g} links ({2} beyond), else {5}",
                                       Integrator::kAutoImplicitStiffness, kAutoLooseRtol, kAutoImplicit,
                                       kAutoExplicitLoose, kAutoExplicitStiff, kAutoExplicit, kAutoExplicitStiffMax));
  for (const auto& [alias, entry] : aliases())
    out.emplace_back(alias, fmt::format("{} ({})", entry.description, entry.table));
  return out;
}

void IntegratorOptions::validate() const {
  validate_method();
  validate_numbers();
}

void IntegratorOptions::validate_method() const {
  const std::string table = table_name(method);
  if (!(method == "auto" || listed(table, kErkTables) || listed(table, kDirkTables))) throw unknown_method(method);
}

bool IntegratorOptions::implicit_method() const { return listed(table_name(method), kDirkTables); }

void IntegratorOptions::validate_numbers() const {
  require_in_range("rtol", rtol, 1e-14, 1e-2);
  // atol is relative to the state scale: above 1e-2 a component may err by more than 1% of its natural
  // size (a tension of -1e13 N went unnoticed for a while with atol = 1e6).
  require_in_range("atol", atol, 0.0, 1e-2, Bound::kOpen);
  require_in_range("max_step", max_step, 0.0, INFINITY);
  require_in_range("initial_step", initial_step, 0.0, INFINITY);
  if (max_steps < 1)
    throw InputError(fmt::format("max_steps = {} is out of range: allowed max_steps >= 1", max_steps));
  require_in_range("max_wall_s", max_wall_s, 0.0, INFINITY);
}

// ------------------------------------------------------------------------------------------------
struct Integrator::Impl {
  OdeSystem& system;
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  SUNMatrix jac = nullptr;
  SUNLinearSolver ls = nullptr;
  bool implicit = false;
  double rtol = 0, atol = 0;
  std::string table;
  int order = 0;
  int embedding_order = 0;  // of the method's error estimate
  long recoverable_failures = 0;
  // The event functions ARKODE does not see (a constant 1 in their place; empty: none): those whose roots
  // in a step the polish refuted, while advance() takes that step again.
  std::vector<int> muted_events;
  // The system's Newton solver: whether it is set up, and counters.
  bool newton_ready = false;
  long jv_evals = 0;  // right-hand sides of jac_times()
  N_Vector jv_work = nullptr;  // the shifted state of jac_times()
  long newton_setups = 0, newton_solves = 0;
  std::exception_ptr pending;  // exception thrown inside a callback, re-thrown after ARKStepEvolve
  std::string last_error;      // ARKODE's own message for the last failure
  std::string last_recoverable;  // what the model said when it last refused a trial state
  // Watchdog (see integrator.hpp).
  long max_steps = 0;
  double max_wall_s = 0;
  long steps_total = 0;        // accepted steps over the Integrator's life
  // The step the next restart() or resize() starts with (0: ARKODE's estimate); set by an event's polish.
  double h_resume = 0;
  // Predicted steps in a row that ended short of the zero at the previous predicted step's stop time
  // (ARKODE's next step, shortened to that stop time, does not lengthen for a later one), and that stop.
  int stale_stops = 0;
  double last_predicted_stop = NAN;
  // The next zero of a recurring event function (OdeSystem::num_recurring_events), predicted from the
  // rates dg/dt of every event function at the last two polished events (root_rate at root_time, the
  // one before); per function, kPredictionMissed if its prediction ended a step short of its zero
  // since the last event, or if a step past its zero met another root (not predicted again until the
  // next event).
  Eigen::VectorXd root_rate, root_rate_before;
  double root_time = 0, root_time_before = 0;
  static constexpr char kPredictionMissed = 1;
  // The event functions at the last state a prediction was made from since the last event (empty: none).
  Eigen::VectorXd g_last;
  double g_last_time = 0;
  std::vector<char> prediction_off;
  int short_steps = 0;         // accepted steps in a row below the step-size floor
  long refused_before_short = 0;  // recoverable_failures when the first of them began
  // Work vectors kept over the run (a crossing's polish and advance() allocated and freed them at every
  // event: malloc handed a state's bytes back to the system and took them again, page faults for 11 % of
  // the folded compare's time on 3,200 nodes): the start of the step advance() takes; the polish's last
  // integrated state, F there and at its Heun predictor, the predictor and its correction, F at the
  // event, the probe's state and the error weights; ARKODE's error weights and local errors.
  Eigen::VectorXd y_step_start;
  Eigen::VectorXd y_base, f_base, f_euler, y_euler, second, ydot, y_probe, weights;
  N_Vector ewt = nullptr, local_errors = nullptr;
  // provide_start_rhs(): F at (start_time, the state y wrapped at that time), for the next evaluation.
  Eigen::VectorXd start_rhs;
  double start_time = 0;
  bool start_rhs_ready = false;
  // The first step ARKODE takes after the last restart or resize (0: its own estimate), and whether no step
  // has been taken since (advance() may then end a predicted step by that first step instead of a stop time).
  double init_step = 0;
  bool fresh_start = false;
  std::chrono::steady_clock::time_point wall_start = std::chrono::steady_clock::now();

  explicit Impl(OdeSystem& s) : system(s) {}
  ~Impl() {
    if (mem) ARKStepFree(&mem);
    free_linear_solver();
    free_work_vectors();
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }

  /// ARKStepSetInitStep, remembered (init_step).
  void set_init_step(double h) {
    check(ARKStepSetInitStep(mem, h), "ARKStepSetInitStep");
    init_step = h;
  }

  void check(int flag, const char* call) const {
    if (flag < 0)
      throw Error(fmt::format("internal error: {} failed with {} ({})", call, flag, flag_name(flag)));
  }

  /// Scalar tolerances, or atol * state_scale() per component when the system provides a scale.
  /// Must be called again after a resize.
  void apply_tolerances() {
    const Eigen::VectorXd scale = system.state_scale();
    if (scale.size() == 0) {
      check(ARKStepSStolerances(mem, rtol, atol), "ARKStepSStolerances");
      return;
    }
    CHAINSIM_VERIFY(scale.size() == N_VGetLength(y) && (scale.array() > 0).all(),
                    "state_scale() must give one positive entry per state component");
    N_Vector abstol = N_VClone(y);
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(abstol), scale.size()) = atol * scale;
    const int flag = ARKStepSVtolerances(mem, rtol, abstol);
    N_VDestroy(abstol);
    check(flag, "ARKStepSVtolerances");
  }

  /// Krylov dimension of GMRES: with the system's Newton solver as preconditioner one or two
  /// iterations suffice; the rest is room for what it leaves out (drag, a module's loads).
  static constexpr int kKrylovDimension = 10;
  /// Newton iterations per stage before ARKODE calls it a convergence failure (its default is 3). With the
  /// linearisation kept over steps (kLinearizationSteps), a stale one that converges slowly must fail
  /// soon, so that SUNDIALS' Newton re-linearises the stage: at 8 (the limit while the string was
  /// re-linearised at every step) the travelling loop with dirk4 (cases/scenes/travelling_loop.toml)
  /// took 14,094 Newton iterations and 14,631 right-hand sides, at 4, 9,746 and 10,257 (10,170 when
  /// re-linearised at every step). At 3 it took 1,000 steps instead of 508.
  static constexpr int kNewtonIterations = 4;
  /// ARKODE's crdown: the Newton convergence rate it assumes at least, crate = max(crdown · crate,
  /// ‖δ_m‖/‖δ_{m−1}‖), is reset to 1 at every linearisation, so with its default 0.3 the first
  /// stage after it converges only if its second correction is below nlscoef/0.3 = 0.33 in the
  /// error norm. With a fresh exact linearisation the measured rate is ~1e-5, but on a fine string the
  /// second correction is the round-off of the residual (the vertical velocities, weighted by atol
  /// alone, carry the round-off of accelerations of order g·N per node): 0.3–1.3 at 10,000 links,
  /// and Newton "failed" at every fourth step or so (docs/string_solver.md, "The implicit path").
  /// 0.05 lets the measured rate count; the remaining-error estimate crate·‖δ‖ ≤ nlscoef is kept.
  static constexpr double kNewtonRateFloor = 0.05;
  /// Steps between Newton set-ups (ARKODE's msbp) and between linearisations (msbj): ARKODE's defaults.
  /// A set-up at every step (what was done before) cost a linearisation, a factorisation and a second
  /// Newton iteration per step (ARKODE resets its convergence rate to 1 at a set-up, so the first stage
  /// after it can never converge in one iteration): 94 set-ups and 924 Newton iterations over the 94
  /// steps of the hanging chain's first mode at 250 links, against 14 and 441 over 78 steps now.
  static constexpr int kLinearizationSteps = 20;
  static constexpr int kJacobianSteps = 51;
  /// ARKODE's nlscoef: Newton stops when its estimated error is below this fraction of the error test's
  /// tolerance (its default is 0.1). With the stage's right-hand side deduced from the stage equation,
  /// the stage's Newton error enters the step's result itself (y_{n+1} is the last stage of these
  /// stiffly accurate methods) instead of through h J times it: at 0.1 a swinging 10-link chain
  /// (dirk3, rtol 1e-7, test_string_energy.cpp) drifted 1.1e-7 in energy and 2.2e-7 in its
  /// constraints, against 2.4e-8 and 1.6e-7 with the stages' right-hand sides evaluated; at 0.03,
  /// 6.0e-8 and 1.4e-7.
  static constexpr double kNewtonTolerance = 0.03;

  /// The linear solver of an implicit method (after creation and after every resize). With the
  /// system's Newton solver: the solver itself (direct_newton_solver()) when it is exact, else GMRES
  /// (SUNDIALS SPGMR) preconditioned by it, with products J·v from jac_times(). Without one: a
  /// dense difference-quotient Jacobian.
  void attach_linear_solver() {
    free_linear_solver();
    if (system.has_newton_solver()) {
      newton_ready = false;
      if (system.newton_solver_exact()) {
        ls = direct_newton_solver(ctx);
      } else {
        ls = SUNLinSol_SPGMR(y, SUN_PREC_LEFT, kKrylovDimension, ctx);
        if (!ls) throw Error("SUNLinSol_SPGMR failed");
        jv_work = N_VClone(y);
      }
      check(ARKStepSetLinearSolver(mem, ls, nullptr), "ARKStepSetLinearSolver");
      check(ARKStepSetPreconditioner(mem, Impl::newton_linearize, Impl::newton_solve), "ARKStepSetPreconditioner");
      if (jv_work) check(ARKStepSetJacTimes(mem, nullptr, Impl::jac_times), "ARKStepSetJacTimes");
      // Newton's settings (docs/string_solver.md, "Newton's settings"): the linearisation kept over
      // ARKODE's default of up to 20 steps and refactored when γ changes by more than 20 %, a failure
      // to converge with a kept one re-linearising the stage (SUNDIALS' Newton solver does, without
      // cutting the step); the stage's right-hand side deduced from the converged stage equation
      // (F_i = (z_i − the explicit part)/γ, no evaluation of F at the stage: an evaluation multiplies
      // the stage's Newton error by the stiff J, whose fastest modes grow with the links). The stage
      // predictor stays ARKODE's default, the last step's state: the "cutoff" one (3) saved a fifth of
      // the Newton iterations but made the steps depend on the round-off of the linear solve (banded and
      // KLU took 84 and 85 steps at 250 links, where with this one both take 96, the same ω1 to 7 digits).
      check(ARKStepSetLSetupFrequency(mem, kLinearizationSteps), "ARKStepSetLSetupFrequency");
      check(ARKStepSetJacEvalFrequency(mem, kJacobianSteps), "ARKStepSetJacEvalFrequency");
      check(ARKStepSetMaxNonlinIters(mem, kNewtonIterations), "ARKStepSetMaxNonlinIters");
      check(ARKStepSetNonlinCRDown(mem, kNewtonRateFloor), "ARKStepSetNonlinCRDown");
      check(ARKStepSetDeduceImplicitRhs(mem, SUNTRUE), "ARKStepSetDeduceImplicitRhs");
      check(ARKStepSetNonlinConvCoef(mem, kNewtonTolerance), "ARKStepSetNonlinConvCoef");
      return;
    }
    const sunindextype n = N_VGetLength(y);
    jac = SUNDenseMatrix(n, n, ctx);
    ls = SUNLinSol_Dense(y, jac, ctx);
    check(ARKStepSetLinearSolver(mem, ls, jac), "ARKStepSetLinearSolver");
  }

  /// ARKODE's error weights and local errors are copied into these (made at their first use, and
  /// again after a resize).
  void free_work_vectors() {
    if (ewt) N_VDestroy(ewt);
    if (local_errors) N_VDestroy(local_errors);
    ewt = local_errors = nullptr;
  }
  N_Vector work_vector(N_Vector& v) const {
    if (!v) v = N_VClone(y);
    if (!v) throw Error("N_VClone failed");
    return v;
  }

  void free_linear_solver() {
    if (ls) SUNLinSolFree(ls);
    if (jac) SUNMatDestroy(jac);
    if (jv_work) N_VDestroy(jv_work);
    ls = nullptr;
    jac = nullptr;
    jv_work = nullptr;
  }

  /// A SUNDIALS linear solver whose solve is the system's exact Newton solver (ARKODE's
  /// preconditioner set-up and solve, registered by ARKStepSetPreconditioner): GMRES with it as
  /// preconditioner converges in one iteration, which costs a second solve, a product J·v and the
  /// Gram–Schmidt and norm passes of SPGMR per Newton iteration; this takes the first solve as the
  /// correction. It reports itself as iterative (matrix-free) so that ARKODE calls the set-up.
  struct DirectNewton {
    void* data = nullptr;
    SUNPSetupFn setup = nullptr;
    SUNPSolveFn solve = nullptr;
    int last_flag = SUNLS_SUCCESS;
  };
  static SUNLinearSolver direct_newton_solver(SUNContext context) {
    SUNLinearSolver s = SUNLinSolNewEmpty(context);
    if (!s) throw Error("SUNLinSolNewEmpty failed");
    s->content = new DirectNewton;
    s->ops->gettype = [](SUNLinearSolver) { return SUNLINEARSOLVER_ITERATIVE; };
    s->ops->getid = [](SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; };
    s->ops->setatimes = [](SUNLinearSolver, void*, SUNATimesFn) { return int{SUNLS_SUCCESS}; };
    s->ops->setpreconditioner = [](SUNLinearSolver S, void* data, SUNPSetupFn setup, SUNPSolveFn solve) {
      auto* c = static_cast<DirectNewton*>(S->content);
      c->data = data;
      c->setup = setup;
      c->solve = solve;
      return int{SUNLS_SUCCESS};
    };
    // Scaling vectors accepted and unused (the solve is exact): ARKODE then skips the tolerance
    // rescaling it does for iterative solvers without them (a norm per Newton iteration).
    s->ops->setscalingvectors = [](SUNLinearSolver, N_Vector, N_Vector) { return int{SUNLS_SUCCESS}; };
    s->ops->initialize = [](SUNLinearSolver) { return int{SUNLS_SUCCESS}; };
    s->ops->setup = [](SUNLinearSolver S, SUNMatrix) {
      auto* c = static_cast<DirectNewton*>(S->content);
      const int flag = c->setup ? c->setup(c->data) : 0;
      c->last_flag = flag == 0 ? SUNLS_SUCCESS : flag > 0 ? SUNLS_PSET_FAIL_REC : SUNLS_PSET_FAIL_UNREC;
      return c->last_flag;
    };
    s->ops->solve = [](SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, sunrealtype tol) {
      auto* c = static_cast<DirectNewton*>(S->content);
      if (!c->solve) return c->last_flag = SUNLS_ILL_INPUT;
      const int flag = c->solve(c->data, b, x, tol, SUN_PREC_LEFT);
      c->last_flag = flag == 0 ? SUNLS_SUCCESS : flag > 0 ? SUNLS_PSOLVE_FAIL_REC : SUNLS_PSOLVE_FAIL_UNREC;
      return c->last_flag;
    };
    s->ops->numiters = [](SUNLinearSolver) { return 0; };  // no Krylov iterations
    s->ops->resnorm = [](SUNLinearSolver) { return sunrealtype{0}; };
    s->ops->lastflag = [](SUNLinearSolver S) { return static_cast<sunindextype>(static_cast<DirectNewton*>(S->content)->last_flag); };
    s->ops->free = [](SUNLinearSolver S) {
      delete static_cast<DirectNewton*>(S->content);
      S->content = nullptr;
      SUNLinSolFreeEmpty(S);
      return int{SUNLS_SUCCESS};
    };
    return s;
  }

  // J·v from the system's linearisation if it has one (OdeSystem::jacobian_times), else by a
  // difference quotient of the right-hand side, (F(y + σv) − F(y)) / σ with the unweighted
  // increment σ = √ε (1 + ‖y‖∞) / ‖v‖∞. ARKODE's own quotient takes σ = 1/‖v‖_WRMS, a step of the
  // size of the error tolerance: at rtol 1e-4 that moves a node by a few per cent of a short link,
  // and the product is then too inexact for the Newton iteration of a fine string.
  static int jac_times(N_Vector v, N_Vector Jv, sunrealtype t, N_Vector y, N_Vector fy, void* data, N_Vector) {
    auto* self = static_cast<Impl*>(data);
    const long n = N_VGetLength(y);
    Eigen::Map<const Eigen::VectorXd> vm(N_VGetArrayPointer(v), n), ym(N_VGetArrayPointer(y), n),
        fm(N_VGetArrayPointer(fy), n);
    Eigen::Map<Eigen::VectorXd> out(N_VGetArrayPointer(Jv), n);
    if (self->system.jacobian_times(vm, out)) return 0;
    const double vmax = vm.cwiseAbs().maxCoeff();
    if (!(vmax > 0)) {
      out.setZero();
      return 0;
    }
    const double sigma = std::sqrt(std::numeric_limits<double>::epsilon()) * (1 + ym.cwiseAbs().maxCoeff()) / vmax;
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(self->jv_work), n) = ym + sigma * vm;
    ++self->jv_evals;
    const int flag = rhs(t, self->jv_work, Jv, data);
    if (flag != 0) return flag;
    out = (out - fm) / sigma;
    return 0;
  }

  // The linearisation (ARKODE's preconditioner set-up: first step, every few steps, after a
  // convergence failure, or when γ has changed much); jok = the last linearisation may be kept.
  static int newton_linearize(sunrealtype t, N_Vector y, N_Vector, sunbooleantype jok, sunbooleantype* jcur,
                              sunrealtype gamma, void* data) {
    auto* self = static_cast<Impl*>(data);
    Eigen::Map<const Eigen::VectorXd> ym(N_VGetArrayPointer(y), N_VGetLength(y));
    return self->guarded([&] {
      const bool fresh = !jok || !self->newton_ready;
      self->system.newton_setup(t, ym, fresh, gamma);
      *jcur = fresh ? SUNTRUE : SUNFALSE;
      self->newton_ready = true;
      if (fresh) ++self->newton_setups;
      return 0;
    });
  }

  // z = (I − γJ)⁻¹ r from the system's Newton solver (ARKODE's preconditioner solve).
  static int newton_solve(sunrealtype, N_Vector, N_Vector, N_Vector r, N_Vector z, sunrealtype, sunrealtype, int,
                          void* data) {
    auto* self = static_cast<Impl*>(data);
    const long n = N_VGetLength(r);
    Eigen::Map<const Eigen::VectorXd> rm(N_VGetArrayPointer(r), n);
    Eigen::Map<Eigen::VectorXd> zm(N_VGetArrayPointer(z), n);
    return self->guarded([&] {
      self->system.newton_solve(rm, zm);
      ++self->newton_solves;
      return all_finite(zm) ? 0 : 1;
    });
  }

  /// A new state vector: fused vector operations on (ARKODE's stage sums become one call instead
  /// of one per term), and the hot ones computed by Eigen kernels (nvector_kernels.hpp).
  N_Vector new_vector(sunindextype n) const {
    N_Vector v = N_VNew_Serial(n, ctx);
    if (!v) throw Error("N_VNew_Serial failed");
    N_VEnableFusedOps_Serial(v, SUNTRUE);
    use_eigen_kernels(v);
    return v;
  }

  /// The same over `data` (not owned, not freed by N_VDestroy): the Integrator's state y_, so that
  /// ARKODE returns each step's state in place instead of into a vector of its own copied to y_
  /// (a state's bytes less for the whole run). Its clones (ARKODE's vectors) own their data.
  N_Vector wrap_vector(Eigen::VectorXd& data) const {
    N_Vector v = N_VMake_Serial(static_cast<sunindextype>(data.size()), data.data(), ctx);
    if (!v) throw Error("N_VMake_Serial failed");
    N_VEnableFusedOps_Serial(v, SUNTRUE);
    use_eigen_kernels(v);
    return v;
  }

  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* data) {
    auto* self = static_cast<Impl*>(data);
    const long n = N_VGetLength(y);
    Eigen::Map<const Eigen::VectorXd> ym(N_VGetArrayPointer(y), n);
    Eigen::Map<Eigen::VectorXd> dm(N_VGetArrayPointer(ydot), n);
    return self->guarded([&] {
      if (self->start_rhs_ready && self->take_start_rhs(t, ym, dm)) {
        if (!all_finite(dm)) throw RecoverableError("the right-hand side is not finite");
        return 0;
      }
      self->system.rhs(t, ym, dm);
      // a non-finite trial stage: let ARKODE retry with a smaller step
      if (!all_finite(dm)) throw RecoverableError("the right-hand side is not finite");
      return 0;
    });
  }

  /// The right-hand side given by provide_start_rhs() into ydot if (t, y) is its state (bit for bit: ARKODE's
  /// copy of the restart's state); it is used up either way.
  bool take_start_rhs(double t, const Eigen::Map<const Eigen::VectorXd>& ym, Eigen::Map<Eigen::VectorXd>& out) {
    start_rhs_ready = false;
    const Eigen::Map<const Eigen::VectorXd> state(N_VGetArrayPointer(y), N_VGetLength(y));
    if (!(t == start_time && start_rhs.size() == ym.size() && state.size() == ym.size() &&
          std::equal(ym.data(), ym.data() + ym.size(), state.data())))
      return false;
    out = start_rhs;
    return true;
  }

  /// Runs the body of an ARKODE callback: a RecoverableError (a trial state the system cannot use)
  /// returns 1, so that ARKODE retries with a smaller step; any other exception is kept for
  /// re-throwing after ARKStepEvolve and returns −1.
  template <class Body>
  int guarded(Body&& body) {
    try {
      return body();
    } catch (const RecoverableError& e) {
      ++recoverable_failures;
      last_recoverable = e.what();
      return 1;
    } catch (...) {
      pending = std::current_exception();
      return -1;
    }
  }

  static int roots(sunrealtype t, N_Vector y, sunrealtype* g, void* data) {
    auto* self = static_cast<Impl*>(data);
    const long n = N_VGetLength(y);
    Eigen::Map<const Eigen::VectorXd> ym(N_VGetArrayPointer(y), n);
    Eigen::Map<Eigen::VectorXd> gm(g, self->system.num_events());
    try {
      self->system.events(t, ym, gm);
      for (const int e : self->muted_events) gm[e] = 1;
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static void error_handler(int, const char* module, const char* function, char* msg, void* data) {
    static_cast<Impl*>(data)->last_error = fmt::format("{}: {}: {}", module, function, msg);
  }
};

Integrator::Integrator(OdeSystem& system, double t0, const Eigen::VectorXd& y0,
                       const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(system)), t_(t0), y_(y0) {
  options.validate_numbers();  // the method: where its table is loaded, below
  CHAINSIM_VERIFY(y0.size() == system.size(), "initial state has the wrong length");
  Impl& d = *impl_;
  if (SUNContext_Create(nullptr, &d.ctx) != 0) throw Error("SUNContext_Create failed");
  d.y = d.wrap_vector(y_);  // y_ = y0: ARKODE reads the initial state from it and returns states into it

  d.table = table_name(resolve_method(options.method, system, options.rtol));
  ARKodeButcherTable erk = nullptr, dirk = nullptr;
  load_table(d.table, erk, dirk);
  if (!erk && !dirk) throw unknown_method(options.method);
  d.implicit = dirk != nullptr;
  ARKodeButcherTable table = d.implicit ? dirk : erk;
  d.order = table->q;
  d.embedding_order = table->p;
  d.mem = d.implicit ? ARKStepCreate(nullptr, Impl::rhs, t0, d.y, d.ctx)
                     : ARKStepCreate(Impl::rhs, nullptr, t0, d.y, d.ctx);
  if (!d.mem) throw Error("ARKStepCreate failed");
  const int flag = d.implicit ? ARKStepSetTables(d.mem, table->q, table->p, dirk, nullptr)
                              : ARKStepSetTables(d.mem, table->q, table->p, nullptr, erk);
  ARKodeButcherTable_Free(erk);
  ARKodeButcherTable_Free(dirk);
  d.check(flag, "ARKStepSetTables");
  d.check(ARKStepSetUserData(d.mem, &d), "ARKStepSetUserData");
  d.check(ARKStepSetErrHandlerFn(d.mem, Impl::error_handler, &d), "ARKStepSetErrHandlerFn");
  d.rtol = options.rtol;
  d.atol = options.atol;
  d.apply_tolerances();
  d.max_steps = options.max_steps;
  d.max_wall_s = options.max_wall_s;
  d.check(ARKStepSetMaxNumSteps(d.mem, options.max_steps), "ARKStepSetMaxNumSteps");
  if (options.max_step > 0) d.check(ARKStepSetMaxStep(d.mem, options.max_step), "ARKStepSetMaxStep");
  if (options.initial_step > 0)
    d.set_init_step(options.initial_step);
  if (d.implicit) d.attach_linear_solver();

  const int nev = system.num_events();
  if (nev > 0) {
    d.check(ARKStepRootInit(d.mem, nev, Impl::roots), "ARKStepRootInit");
    std::vector<int> dirs = system.event_directions();
    if (!dirs.empty()) {
      CHAINSIM_VERIFY(static_cast<int>(dirs.size()) == nev, "one event direction per event function");
      d.check(ARKStepSetRootDirection(d.mem, dirs.data()), "ARKStepSetRootDirection");
    }
    d.check(ARKStepSetNoInactiveRootWarn(d.mem), "ARKStepSetNoInactiveRootWarn");
    if (d.order > kMaxDenseOrder) d.check(ARKStepSetInterpolantDegree(d.mem, 3), "ARKStepSetInterpolantDegree");
    events_found_.assign(nev, 0);
  }
}

Integrator::~Integrator() = default;

std::string Integrator::resolve_method(const std::string& method, const OdeSystem& system, double rtol) {
  if (method != "auto") return method;
  const bool loose = rtol >= kAutoLooseRtol;
  // A stiff system without root functions: implicit steps follow the motion at a loose tolerance, but at a
  // tight one they follow the tolerance, and an explicit method's cheap stability-bound steps win.
  const double stiffness = system.explicit_stiffness();
  if (stiffness >= kAutoImplicitStiffness && system.num_events() == 0)
    return loose || stiffness > kAutoExplicitStiffMax ? kAutoImplicit : kAutoExplicitStiff;
  return loose ? kAutoExplicitLoose : kAutoExplicit;
}

// The method, tolerance and last step, for the watchdog's messages.
std::string Integrator::diagnosis() const {
  const Impl& d = *impl_;
  sunrealtype h = 0;
  ARKStepGetLastStep(d.mem, &h);
  return fmt::format("last step h = {:.3g} s, {} accepted steps, method {} ({}, order {}), rtol = {:g}", h,
                     d.steps_total, d.table, d.implicit ? "implicit" : "explicit", d.order, d.rtol);
}

// One ARKStepEvolve call towards t_target (never past it); throws on failure. Returns ARKODE's flag.
// Counts the accepted steps against the run's budget and checks the wall-clock budget first.
int Integrator::evolve(double t_target, bool one_step) {
  Impl& d = *impl_;
  if (d.steps_total >= d.max_steps)
    throw NumericalError(fmt::format("time integration stopped at t = {:.12g} s with ARK_TOO_MUCH_WORK: the step "
                                     "budget max_steps = {} of the run is used up ({}). Raise max_steps if the steps "
                                     "are merely many ({}); if they are tiny the solution may be singular near this "
                                     "time",
                                     t_, d.max_steps, diagnosis(),
                                     d.order < 8 ? "a low-order method at a tight rtol needs very many: loosen rtol or "
                                                   "pick a higher-order method such as erk8"
                                                 : "a tight rtol needs very many: loosen rtol"),
                         t_);
  if (d.max_wall_s > 0) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - d.wall_start).count();
    if (wall > d.max_wall_s)
      throw NumericalError(fmt::format("time integration stopped at t = {:.12g} s: the wall-clock budget "
                                       "max_wall_s = {:g} s is used up after {:.3g} s ({}). Raise max_wall_s, "
                                       "loosen rtol, or pick a cheaper method",
                                       t_, d.max_wall_s, wall, diagnosis()),
                           t_);
  }
  d.check(ARKStepSetStopTime(d.mem, t_target), "ARKStepSetStopTime");
  // ARKODE's own per-call limit (it matters in normal mode, e.g. an event polish) is what is left.
  d.check(ARKStepSetMaxNumSteps(d.mem, d.max_steps - d.steps_total), "ARKStepSetMaxNumSteps");
  long steps_before = 0, steps_after = 0;
  ARKStepGetNumSteps(d.mem, &steps_before);
  sunrealtype tret = t_;
  d.pending = nullptr;
  d.last_error.clear();
  const int flag = ARKStepEvolve(d.mem, t_target, d.y, &tret, one_step ? ARK_ONE_STEP : ARK_NORMAL);
  d.fresh_start = false;
  ARKStepGetNumSteps(d.mem, &steps_after);
  d.steps_total += std::max(0L, steps_after - steps_before);
  if (d.pending) std::rethrow_exception(d.pending);
  if (flag == ARK_UNREC_RHSFUNC_ERR) return flag;  // advance() retries from the step's start
  if (flag < 0)
    throw NumericalError(fmt::format("time integration failed at t = {:.12g} s with {}{}{} ({})", tret,
                                     flag_name(flag), d.last_error.empty() ? "" : ": ", d.last_error, diagnosis()),
                         tret);
  t_ = flag == ARK_TSTOP_RETURN ? t_target : tret;
  CHAINSIM_VERIFY(N_VGetArrayPointer(d.y) == y_.data(), "ARKODE returns the state in y_");
  return flag;
}

// After an accepted step that ended neither at the stop time nor at a root: the step size must stay
// above kStepFloor · max(|t|, time_scale()) and t must move, or kStallSteps such steps in a row end the run.
void Integrator::watchdog(double t_before, int flag) {
  Impl& d = *impl_;
  if (flag != ARK_SUCCESS) {
    d.short_steps = 0;
    return;
  }
  sunrealtype h = 0;
  ARKStepGetLastStep(d.mem, &h);
  const double floor = kStepFloor * std::max(std::abs(t_), d.system.time_scale());
  const bool stalled = !(t_ > t_before);
  if (!stalled && std::abs(h) >= floor) {
    d.short_steps = 0;
    return;
  }
  if (d.short_steps == 0) d.refused_before_short = d.recoverable_failures;
  if (++d.short_steps < kStallSteps) return;
  // What the model refused on the way, if it refused trial states (e.g. a link of the string collapsed):
  // the cause of the short steps, named.
  const long refused = d.recoverable_failures - d.refused_before_short;
  throw NumericalError(
      fmt::format("time integration stalled at t = {:.15g} s: {} accepted steps in a row {} ({}){}. The solution is "
                  "probably singular near this time (a speed or a tension that diverges, a cutoff too close to a "
                  "singular end), or the method is unstable at this tolerance: tighten rtol, pick another method "
                  "(e.g. erk8 or dirk5), or stop the run before this time",
                  t_, kStallSteps,
                  stalled ? "did not advance the time in floating point"
                          : fmt::format("were shorter than the step-size floor {:.3g} s = {:.0e} max(|t|, {:.3g} s)",
                                        floor, kStepFloor, d.system.time_scale()),
                  diagnosis(),
                  refused > 0 ? fmt::format("; the model refused {} trial states in those steps, the last: {}",
                                            refused, d.last_recoverable)
                              : ""),
      t_);
}

Integrator::Outcome Integrator::advance(double t_target, bool one_step, const RootStepHook& before_polish) {
  CHAINSIM_VERIFY(t_target >= t_, "the integrator only moves forward in time");
  // Invariant: on entry (t_, y_) is a state the method computed (the end of a step, a restart,
  // or a polished event), never an interpolated one; it is kept as the start of the next step.
  // ARKODE's explicit stages do not recover when the right-hand side refuses a trial state (a
  // RecoverableError, e.g. a stage that overshoots y = 0 near a singular stop): restart from the
  // start of the step with a step four times smaller, up to kMaxRetries times.
  constexpr int kMaxRetries = 30;
  int retries = 0;
  double h_retry = 0;
  // The event functions whose roots in this step the polish refuted: hidden for the step taken again.
  std::vector<int> ignored;
  bool hidden_checked = false;  // a hidden function's zero before another root: looked at once per step
  for (;;) {
    if (t_ >= t_target) return Outcome::kReachedTarget;
    const double t_step_start = t_;
    // Kept over the run with root functions (a crossing's copy no longer allocated at every step); a
    // temporary without, as before: a string without events keeps its peak memory
    // (tests/unit/test_memory.cpp: the temporary is freed while the frames are recorded).
    Eigen::VectorXd local_start;
    Eigen::VectorXd& y_step_start = impl_->system.num_events() > 0 ? impl_->y_step_start : local_start;
    y_step_start = y_;
    int predicted = -1;
    const double t_stop = !ignored.empty() ? t_target : predict_recurring_event(t_target, predicted);
    impl_->muted_events = ignored;
    const long refused_before = impl_->recoverable_failures;
    long fails_before = 0, fails_after = 0;
    ARKStepGetNumErrTestFails(impl_->mem, &fails_before);
    // ARKODE returns a step ended at its stop time through its interpolant (arkEvolve in SUNDIALS 6.4), whose
    // evaluation costs one right-hand side at degree 4 (methods of order 5), two at degree 5. A predicted
    // step that is the first after a restart is instead made that first step, ARKODE's stop time left at
    // the target: no interpolation (on the canonical compares nearly every crossing's step is one).
    double t_evolve = t_stop;
    if (predicted >= 0 && impl_->fresh_start && impl_->init_step > 0 && t_stop > t_ && t_stop - t_ < impl_->init_step) {
      impl_->set_init_step(t_stop - t_);
      t_evolve = t_target;
    }
    const int flag = evolve(t_evolve, /*one_step=*/true);
    impl_->muted_events.clear();
    if (predicted >= 0) set_root_directions();
    ARKStepGetNumErrTestFails(impl_->mem, &fails_after);
    if (flag == ARK_UNREC_RHSFUNC_ERR) {
      if (h_retry == 0) h_retry = last_step();
      h_retry *= 0.25;
      if (++retries > kMaxRetries || !(h_retry > 0))
        throw NumericalError(fmt::format("time integration stalled at t = {:.12g} s: the model refused every trial "
                                         "state down to a step of {:.3g} s ({})",
                                         t_step_start, h_retry, impl_->last_recoverable),
                             t_step_start);
      restart(t_step_start, y_step_start);
      impl_->set_init_step(h_retry);
      continue;
    }
    if (retries > 0) impl_->set_init_step(0.0);  // estimate again
    retries = 0;
    h_retry = 0;
    watchdog(t_step_start, flag);
    const std::vector<int> were_ignored = std::exchange(ignored, {});
    for (const int e : were_ignored) {
      if (!passed_zero(e)) continue;
      if (flag != ARK_ROOT_RETURN) {
        // The step taken again ends past that zero after all: the event, polished back from its end.
        predicted_event(e, t_step_start, y_step_start, before_polish);
        return Outcome::kEvent;
      }
      if (hidden_checked) break;
      // The step taken again stopped at another function's root, and the hidden one has passed its zero
      // before it: that event comes first, polished in [the step's start, that root] from a recomputed
      // state (taking the other root instead lost it: a landing of a loop on a table, the node then fell
      // through). If that polish refutes it too, the step is taken again once more, as before.
      hidden_checked = true;
      const double t_root = t_;
      events_found_.assign(events_found_.size(), 0);
      events_found_[static_cast<std::size_t>(e)] = impl_->system.event_directions()[static_cast<std::size_t>(e)];
      if (before_polish) before_polish(t_step_start, t_root);
      if (polish_event(t_step_start, y_step_start, t_root, /*from_here=*/false) < 0) return Outcome::kEvent;
      break;
    }
    if (hidden_checked && !were_ignored.empty() && t_ == t_step_start) {
      impl_->muted_events.clear();
      ignored = were_ignored;
      continue;
    }
    if (flag == ARK_ROOT_RETURN && predicted >= 0 && passed_zero(predicted)) {
      // Another root after the predicted zero (the step past it went where the front may not go, e.g. a
      // fold's arms apart): that step is taken again without the prediction, and the next crossing is
      // predicted again. A late prediction (the first of a run, from the secant before any event's rate)
      // runs the step far past the zero: the folded compare met its fold's check after its first
      // prediction (its crossing function 3.9e-5 m past its zero on 200 nodes) and, with the prediction
      // off for the run, predicted nothing after it (111,715 right-hand sides on 3,200 nodes, 35 per
      // crossing; 28,803 and 9.1 when predictions resume after the next event).
      const double h = last_step();
      impl_->prediction_off[static_cast<std::size_t>(predicted)] = Impl::kPredictionMissed;
      restart(t_step_start, y_step_start);
      impl_->set_init_step(h);
      continue;
    }
    if (flag == ARK_ROOT_RETURN) {
      impl_->check(ARKStepGetRootInfo(impl_->mem, events_found_.data()), "ARKStepGetRootInfo");
      // The step ARKODE took ends after its root; the polished event lies in that step, not always
      // before ARKODE's root, so the frames up to the step's end are taken before the polish.
      sunrealtype t_step_end = t_;
      impl_->check(ARKStepGetCurrentTime(impl_->mem, &t_step_end), "ARKStepGetCurrentTime");
      t_step_end = std::max<double>(t_step_end, t_);
      if (before_polish) before_polish(t_step_start, t_step_end);
      const int refuted = polish_event(t_step_start, y_step_start, t_step_end, /*from_here=*/false);
      if (refuted < 0) return Outcome::kEvent;
      // No event (the recomputed step refutes ARKODE's root): the step is taken again from its start,
      // as long as ARKODE's, with that function hidden from ARKODE's rootfinding (its interpolant would
      // find the same root again), and its zero checked at the step's end.
      impl_->set_init_step(t_step_end - t_step_start);
      ignored = were_ignored;  // (the step taken again may meet another function's false root)
      ignored.push_back(refuted);
      continue;
    }
    if (predicted >= 0) {
      // The step may end at the stop time with either flag. Past the zero: the event. Short of it, and at
      // the stop time, or after refused trial states or a failed error test on the way: no prediction for
      // that function until the next event (otherwise the steps could shrink towards a stop time they
      // never reach). A step that ARKODE's error control ended short of the stop time is no miss: the next
      // step predicts again. (Counted as one when it was shorter than a quarter of the step the run
      // resumed with, the zero then located on ARKODE's interpolant after a short remainder, it cost
      // hole_release_at_rest.toml 517 steps instead of 300 with the heaps' second crossing predicted.)
      if (passed_zero(predicted)) {
        predicted_event(predicted, t_step_start, y_step_start, before_polish);
        return Outcome::kEvent;
      }
      char& off = impl_->prediction_off[static_cast<std::size_t>(predicted)];
      // (ARKODE ends a step at the stop time up to a few units of round-off short of it, either flag.)
      const bool at_stop = flag == ARK_TSTOP_RETURN || t_stop - t_ <= 1e-6 * (t_stop - t_step_start);
      // A step that ended at the previous prediction's stop time, short of this one's: ARKODE's step was
      // shortened to that stop and cannot lengthen. Twice in a row, and the predictions creep after a zero
      // they do not reach (steps as short as the predictions' differences): a miss.
      const double previous_stop = std::exchange(impl_->last_predicted_stop, t_stop);
      const bool stale = !at_stop && std::abs(t_ - previous_stop) <= 1e-6 * (t_stop - t_step_start);
      impl_->stale_stops = stale ? impl_->stale_stops + 1 : 0;
      if (at_stop || impl_->recoverable_failures > refused_before || fails_after > fails_before ||
          impl_->stale_stops >= 2)
        off = Impl::kPredictionMissed;
      if (t_ < t_target) {
        if (one_step) return Outcome::kStep;
        continue;
      }
    }
    if (flag == ARK_TSTOP_RETURN || t_ >= t_target) {
      t_ = t_target;
      return Outcome::kReachedTarget;
    }
    if (one_step) return Outcome::kStep;
  }
}

// ARKODE locates a root on its interpolant, whose error (degree <= 5, often cubic) is far larger
// than the step's own error for high-order methods. Polish: integrate again from the start of the
// step that holds the root, with rootfinding off, to the root's time, and correct that time with
// Newton steps on g(t) along the flow, dg/dt = ∇g · F, until g vanishes to rounding. The first
// integration is one step of the method from the step's start straight to ARKODE's root (ARKODE
// accepted a longer step from there, so a shorter one meets the tolerance; if it does not, ARKODE
// shortens it and takes more); ARKODE's own estimate of a first step instead began far below the
// step (down to 1e-13 s on the falling chain) and needed several. A Newton correction dt of that
// time is then a step of Heun's method from the integrated state, y + dt (F(y) + F(y + dt F(y))) / 2,
// whose second-order term is checked to be below kHeunShare of the error tolerance (its error,
// O(dt³), is smaller still by dt over the time scale of the motion); a larger correction integrates
// again from the step's start.
int Integrator::polish_event(double t_step_start, const Eigen::VectorXd& y_step_start, double t_step_end,
                             bool from_here) {
  // The largest share of the error tolerance (weighted RMS norm) the second-order term of a Heun
  // correction may have.
  constexpr double kHeunShare = 1e-3;
  // How many times a refused step towards the event is taken again, four times smaller (as advance()).
  constexpr int kMaxPolishRetries = 30;
  // How many corrections in all once one has been a bisection of the root's bracket.
  constexpr int kMaxBracketIterations = 60;
  Impl& d = *impl_;
  int k = 0;
  while (k < static_cast<int>(events_found_.size()) && events_found_[k] == 0) ++k;
  CHAINSIM_VERIFY(k < static_cast<int>(events_found_.size()), "a root return names an event");
  const int nev = d.system.num_events();
  // The step ARKODE would have taken next: the run resumes with it after the event (restart/resize).
  sunrealtype h_next = 0;
  ARKStepGetCurrentStep(d.mem, &h_next);
  d.check(ARKStepRootInit(d.mem, 0, nullptr), "ARKStepRootInit");

  Eigen::VectorXd g(nev), g_ahead(nev), g_start(nev);
  Eigen::VectorXd& ydot = d.ydot;
  ydot.resize(y_.size());
  // The root's bracket: t_lo, the last time at which the function has not reached its zero (the step's
  // start), and t_hi, the first at which a state computed by the method has passed it (NaN: none known;
  // a predicted event's step ends past it).
  const double sense = events_found_[static_cast<std::size_t>(k)];
  const auto passed = [&](double gk) { return gk * sense >= 0; };
  double t_lo = t_step_start, t_hi = from_here ? t_ : std::numeric_limits<double>::quiet_NaN();
  // Every function's rate along the flow at the last state probed, for the next prediction: mostly the last
  // iterate, at the root (a correction that stops short of the Heun share integrates again and probes there);
  // else the step's end for a predicted event, within the correction's dt (10⁻⁴ of the interval) of the root.
  Eigen::VectorXd rates = Eigen::VectorXd::Zero(nev);
  // The last state at which g_k was evaluated on the current flow, for the secant slope.
  double t_previous = t_step_start, g_previous = 0, last_slope = NAN;
  // The last integrated state, F there, and the error weights of the tolerance (ARKStepGetErrWeights).
  // (The Impl's work vectors: see there.)
  double t_base = t_step_start;
  bool have_base = false;
  Eigen::VectorXd &y_base = d.y_base, &f_base = d.f_base, &f_euler = d.f_euler, &weights = d.weights;
  f_euler.resize(y_.size());
  double t_event = t_;
  // g_ahead: the event functions a short time along the flow F = f from (t, y); returns that time.
  const auto probe = [&](double t, const Eigen::VectorXd& y, const Eigen::VectorXd& f) {
    const double dt_probe = 1e-6 * std::max(t_event - t_step_start, 1e-300);
    d.y_probe = y + dt_probe * f;
    d.system.events(t + dt_probe, d.y_probe, g_ahead);
    return dt_probe;
  };
  if (from_here) {
    // (t_, y_) is the end of a step past the root (a predicted one): the corrections start from it.
    t_base = t_;
    y_base = y_;
    have_base = true;
    f_base.resize(y_.size());
    d.system.events(t_, y_, g);
    d.system.rhs(t_, y_, f_base);
    error_weights(weights);
    const double dt_probe = probe(t_, y_, f_base);
    rates = (g_ahead - g) / dt_probe;
    const double slope = rates[k];
    if (slope != 0.0 && std::isfinite(slope)) t_event = std::clamp(t_ - g[k] / slope, t_step_start, t_step_end);
    t_previous = t_;
    g_previous = g[k];
    last_slope = slope;
  }
  int max_iterations = 4;
  bool converged = false, bisecting = false, refuted = false;
  // At the last state computed: the time to the zero by Newton's step, and how far it may be with that
  // state at its zero.
  double remaining = INFINITY, margin_last = 0;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    bool corrected = false;
    if (have_base) {
      const double dt = t_event - t_base;
      Eigen::VectorXd &y_euler = d.y_euler, &second = d.second;
      y_euler = y_base + dt * f_base;
      d.system.rhs(t_event, y_euler, f_euler);
      second = 0.5 * dt * (f_euler - f_base);
      if (std::sqrt((second.array() * weights.array()).square().mean()) <= kHeunShare) {
        t_ = t_event;
        y_ = y_euler + second;
        corrected = true;
      }
    }
    if (!corrected) {
      // As in advance(): when the model refuses a trial state, ARKODE stops without moving (evolve
      // returns ARK_UNREC_RHSFUNC_ERR), so the step is taken again from its start, four times
      // smaller each time; calling evolve() again as it was would spin here for ever.
      double h_try = t_event - t_step_start;
      for (int retries = 0;; ++retries) {
        restart(t_step_start, y_step_start);
        if (h_try > 0) d.set_init_step(h_try);
        int flag = 0;
        while (t_ < t_event && flag != ARK_UNREC_RHSFUNC_ERR) flag = evolve(t_event, /*one_step=*/false);
        if (flag != ARK_UNREC_RHSFUNC_ERR) break;
        h_try *= 0.25;
        if (retries >= kMaxPolishRetries || !(h_try > 0))
          throw NumericalError(fmt::format("locating an event at t = {:.12g} s (root function {}): the model refused "
                                           "every trial state from the step's start at t = {:.12g} s down to a step "
                                           "of {:.3g} s ({})",
                                           t_event, k, t_step_start, h_try, d.last_recoverable),
                               t_step_start);
      }
    }
    d.system.events(t_, y_, g);
    // The slope of g_k along the flow. For a predicted crossing (from_here with a recurring function: a
    // front's crossing function, smooth in t; from_here alone also polishes a contact function found past
    // its zero at the end of a step taken again, advance()) a Heun state lies on the same smooth curve of t
    // as the point before it (the base, or the Heun state of the previous correction), so the secant through
    // the two costs no right-hand side (with a probe at every Heun state a crossing took one more; measured
    // in docs/shocks.md). A correction below the probe's own length (10⁻⁶ of the interval: the last one, as
    // Newton converges) keeps the slope it was made with: the secant over it would be round-off, and the
    // slope changes by less than that over it. Elsewhere, and at an integrated state (a new base, whose F is
    // needed anyway), the probe: ARKODE's roots are also of functions with corners (the smallest of the held
    // nodes' normal forces), across which a secant misleads Newton (two contact tests at rtol 1e-2 stalled).
    const double secant_dt = t_ - t_previous;
    const bool smooth = from_here && k < d.system.num_recurring_events() && corrected;
    const bool secant = smooth && std::abs(secant_dt) >= 1e-6 * std::max(t_event - t_step_start, 1e-300);
    const bool kept = smooth && !secant && last_slope != 0.0 && std::isfinite(last_slope);
    double slope = 0;
    if (secant) {
      slope = (g[k] - g_previous) / secant_dt;
    } else if (kept) {
      slope = last_slope;
    } else {
      d.system.rhs(t_, y_, ydot);
      if (!corrected) {
        t_base = t_;
        y_base = y_;
        have_base = true;
        f_base = ydot;
        error_weights(weights);
      }
      const double dt_probe = probe(t_, y_, ydot);
      rates = (g_ahead - g) / dt_probe;
      slope = rates[k];
    }
    t_previous = t_;
    g_previous = g[k];
    last_slope = slope;
    if (passed(g[k])) {
      if (!(t_ >= t_hi)) t_hi = t_;
    } else if (t_ > t_lo && !(t_ >= t_hi)) {
      t_lo = t_;
    }
    // Converged to a few units of round-off of t (relative: an absolute floor in seconds would
    // stop early on a short time scale, e.g. a 1 mm chain under 1000 m/s²).
    const double t_unit = std::max({std::abs(t_event), std::abs(t_step_start), d.system.time_scale()});
    const double t_tol = 8 * std::numeric_limits<double>::epsilon() * t_unit;
    const bool has_slope = slope != 0.0 && std::isfinite(slope);
    const double margin = std::max(t_tol, 1e-8 * (t_step_end - t_step_start));
    remaining = has_slope ? std::abs(g[k] / slope) : INFINITY;
    margin_last = margin;
    if (!has_slope && !bisecting) {
      // At the step's start the probe has no length (its length is a millionth of the way from the start). If
      // the function has not reached its zero there, a millionth of the step measures its slope; farther from
      // its zero than the margin, with a state past the zero known, the bracket is halved. (Reported there,
      // the state of the event before, the event changed nothing and the same root came back until "events
      // stalled"; a function at its zero there to round-off is that event, as before.)
      if (t_event > t_step_start || passed(g[k]) || std::isnan(t_hi)) break;
      if (secant) d.system.rhs(t_, y_, ydot);
      const double dt_start = 1e-6 * (t_step_end - t_step_start);
      d.y_probe = y_ + dt_start * ydot;
      d.system.events(t_ + dt_start, d.y_probe, g_start);
      const double slope_start = (g_start[k] - g[k]) / dt_start;
      remaining = slope_start != 0.0 && std::isfinite(slope_start) ? std::abs(g[k] / slope_start) : INFINITY;
      if (remaining <= margin) break;
      t_event = 0.5 * (t_lo + t_hi);
      bisecting = true;
      max_iterations = kMaxBracketIterations;
      continue;
    }
    const double t_newton = has_slope ? t_event - g[k] / slope : NAN;
    // Newton's step, inside the step that holds the root (held to it if it leaves it by round-off: a root
    // at the step's start, just after a stop time); once it has left the step, inside the bracket.
    const bool inside = bisecting ? t_newton >= t_lo - t_tol && t_newton <= t_hi + t_tol
                                  : t_newton >= t_step_start - margin && t_newton <= t_step_end + margin;
    double t_next = 0;
    if (inside) {
      t_next = std::clamp(t_newton, t_step_start, t_step_end);
    } else if (!std::isnan(t_hi)) {
      // Newton leaves the step (a function whose rate changes fast, or at a kink: the smallest of
      // several, e.g. the normal forces of the held nodes): the bracket is halved, and the polish
      // goes on until it has converged.
      t_next = 0.5 * (t_lo + t_hi);
      bisecting = true;
      max_iterations = kMaxBracketIterations;
    } else {
      refuted = true;  // no state computed in this step has passed the zero: see below
      break;
    }
    if (std::abs(t_next - t_event) <= t_tol || (bisecting && t_hi - t_lo <= t_tol)) {
      converged = true;
      break;
    }
    t_event = t_next;
    if (iteration + 1 == max_iterations && !bisecting && !(t_ > t_step_start) && !passed(g[k]) &&
        !(remaining <= margin) && !std::isnan(t_hi)) {
      // Newton's iterations are spent at the step's start, short of the zero, with a state past it
      // known: the bracket is halved until it holds the zero to round-off, as when Newton leaves the step.
      t_event = 0.5 * (t_lo + t_hi);
      bisecting = true;
      max_iterations = kMaxBracketIterations;
    }
  }
  // The recomputed state has not reached the zero, and Newton's step from it is longer than the margin
  // (its iterations spent). Without a state past the zero, ARKODE's root was a zero of its interpolant
  // only: refuted, as when Newton leaves the step. With one, at the step's start (the state of the event
  // before: reported there, an event changed nothing, and the same root came back until "events
  // stalled"), the event is the first state known past the zero (below). Inside the step the state is
  // reported as before: the time has moved, and the contact module's windows judge it. A function with
  // no slope there (one held at its cap, e.g. the lift-off function's 1) says nothing of where its zero
  // is: reported as before too (docs/string_solver.md, "Events at loose tolerances").
  const bool short_of_zero = !passed(g[k]) && remaining > margin_last && std::isfinite(remaining);
  if (short_of_zero && std::isnan(t_hi)) refuted = true;
  if (refuted) {
    // No state recomputed in the step has passed the zero, and Newton points out of the step: ARKODE's
    // root was a zero of its interpolant, not of the method's solution (at loose tolerances the
    // interpolant of a function of the tensions may cross where the solution does not). No event here:
    // the integrator is back at the step's start, and advance() takes the step again with this
    // function hidden from ARKODE's rootfinding; if that step ends past the zero, the event is
    // polished back from its end (predicted_event), with the bracket the step's start and end.
    restart(t_step_start, y_step_start);
    d.check(ARKStepRootInit(d.mem, nev, Impl::roots), "ARKStepRootInit");
    d.check(ARKStepSetNoInactiveRootWarn(d.mem), "ARKStepSetNoInactiveRootWarn");
    return k;
  }
  if (!passed(g[k]) && ((!converged && bisecting) || (short_of_zero && !(t_ > t_step_start)))) {
    // (Bisection converges in ~50 halvings of the step: a safeguard.) The event is the first state
    // known to have passed the zero.
    restart(t_step_start, y_step_start);
    d.set_init_step(t_hi - t_step_start);
    int flag = 0;
    while (t_ < t_hi && flag != ARK_UNREC_RHSFUNC_ERR) flag = evolve(t_hi, /*one_step=*/false);
    d.system.events(t_, y_, g);
    d.system.rhs(t_, y_, ydot);
    rates = (g_ahead - g) / probe(t_, y_, ydot);
  }
  d.h_resume = std::abs(h_next);
  d.stale_stops = 0;
  d.last_predicted_stop = NAN;
  // Every function's rate at the event, for the prediction of the next zero of a recurring one.
  std::swap(d.root_rate, d.root_rate_before);
  d.root_time_before = d.root_time;
  d.root_rate = rates;
  d.root_time = t_;
  d.g_last.resize(0);
  d.prediction_off.resize(static_cast<std::size_t>(nev), 0);
  for (char& off : d.prediction_off)
    if (off == Impl::kPredictionMissed) off = 0;

  d.check(ARKStepRootInit(d.mem, nev, Impl::roots), "ARKStepRootInit");
  set_root_directions();
  d.check(ARKStepSetNoInactiveRootWarn(d.mem), "ARKStepSetNoInactiveRootWarn");
  return -1;
}

// The error weights of the tolerance at the current state (ARKStepGetErrWeights), into `weights`.
void Integrator::error_weights(Eigen::VectorXd& weights) const {
  N_Vector w = impl_->work_vector(impl_->ewt);
  impl_->check(ARKStepGetErrWeights(impl_->mem, w), "ARKStepGetErrWeights");
  weights = Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(w), N_VGetLength(w));
}

// ARKODE's root directions: the system's, with function `ignored` (>= 0) turned the other way, so
// that ARKODE does not report its zero.
void Integrator::set_root_directions(int ignored) {
  std::vector<int> dirs = impl_->system.event_directions();
  if (dirs.empty()) return;
  if (ignored >= 0) dirs[static_cast<std::size_t>(ignored)] = -dirs[static_cast<std::size_t>(ignored)];
  impl_->check(ARKStepSetRootDirection(impl_->mem, dirs.data()), "ARKStepSetRootDirection");
}

// A front crosses the nodes one after another, each zero of its crossing function followed by a jump
// back up: without a prediction every crossing is a step past it, its root located on ARKODE's
// interpolant (a right-hand side per evaluation of the degree-4 interpolant of erk5, about ten per
// root), and the step recomputed by the polish: 30 - 50 right-hand sides per crossing on the
// canonical compares. The next zero of each recurring function is predicted here from its value now
// and its rate (the last event's or the secant over the last step, with the change of rate between the
// last two events: a quadratic in t), and the step is ended at kAimPast of the
// way beyond it, the function's own direction turned off in ARKODE's rootfinding for that step, so
// that the step holds the root and the polish corrects from the step's end back to it
// (predicted_event): about one step and a few right-hand sides per crossing. Returns the stop time of
// the next step (t_target: no prediction before it) and the function predicted (`which`, or -1).
double Integrator::predict_recurring_event(double t_target, int& which) {
  // The step ends this fraction of the predicted interval past the predicted zero: more than the
  // prediction's error (the quadratic's, (interval / time scale)^2), little enough for the polish's
  // Heun correction back to the root.
  constexpr double kAimPast = 1e-4;
  // The same for a node out of a heap (a front's second crossing function) whose zero lies beyond
  // ARKODE's next step. ARKODE shortens its next step at the end of each step so as not to pass the
  // stop time, and a later prediction cannot lengthen it again: aimed 1e-4 past, a prediction early by
  // 0.04 - 1 % (the rate of a chain leaving a heap while it swings changes faster than the quadratic
  // follows) left the step before the zero ending short of it and a short remainder after it, and
  // hole_release_at_rest.toml took 513 steps instead of 300, swinging_sliding_chain.toml 501 instead of
  // 311. Aimed 1 % past from farther than a step, such a step ends past the zero and the polish corrects
  // back to it.
  constexpr double kAimPastFar = 1e-2;
  Impl& d = *impl_;
  which = -1;
  const int nev = d.system.num_events();
  const int n = std::min(d.system.num_recurring_events(), nev);
  if (n <= 0 || d.root_rate.size() != nev || d.prediction_off.size() != static_cast<std::size_t>(nev)) return t_target;
  Eigen::VectorXd g(nev);
  try {
    d.system.events(t_, y_, g);
  } catch (const RecoverableError&) {
    return t_target;
  }
  const std::vector<int> dirs = d.system.event_directions();
  const bool two = d.root_rate_before.size() == nev && d.root_time > d.root_time_before;
  const bool secant = d.g_last.size() == nev && t_ > d.g_last_time;
  double best = t_target;
  // Both of each front's crossing functions (FrontKind::crossings): the first (even j: a node into a heap;
  // a fold, kink or touchdown front reaching arc B's first node) and the second (odd j: a node out of a
  // heap, or the heap running empty; such a front reaching arc A's last node). Only the second is aimed
  // far past when far (kAimPastFar): the first aimed so, the folded chain took 274 steps and 2,659
  // right-hand sides instead of 267 and 2,459 (more corrections recomputed the step).
  // ARKODE's current step: the step it attempts next after a step it ended by itself, but the cut step
  // after one cut at a stop time, and the step before a restart or resize after one (ARKODE keeps it):
  // mostly a lower estimate of the next step. Measured against the step ARKODE attempts next (the
  // restart's initial step, or the step the last error allows after a cut), aiming far only beyond that
  // took hole_release_at_rest.toml 316 steps and 4,187 right-hand sides instead of 300 and 3,982.
  sunrealtype h_current = 0;
  ARKStepGetCurrentStep(d.mem, &h_current);
  const double h_next = std::abs(h_current);
  for (int j = 0; j < n; ++j) {
    const int dir = dirs.empty() ? 0 : dirs[static_cast<std::size_t>(j)];
    if (dir == 0 || d.prediction_off[static_cast<std::size_t>(j)] || !(g[j] * dir < 0)) continue;
    const double curvature = two ? (d.root_rate[j] - d.root_rate_before[j]) / (d.root_time - d.root_time_before) : 0.0;
    // The rate now: from the last event's, or, after a step since, from the secant over that step
    // (the function's rate may change at the crossing itself, where the front is re-drawn).
    const double rate = secant ? (g[j] - d.g_last[j]) / (t_ - d.g_last_time) + 0.5 * curvature * (t_ - d.g_last_time)
                               : d.root_rate[j] + curvature * (t_ - d.root_time);
    if (!(rate * dir > 0)) continue;
    double tau = -g[j] / rate;
    for (int iteration = 0; iteration < 3 && std::isfinite(tau); ++iteration) {
      const double slope = rate + curvature * tau;
      tau = slope * dir > 0 ? tau - (g[j] + tau * (rate + 0.5 * curvature * tau)) / slope : NAN;
    }
    const double t_aim = t_ + (1 + (j % 2 == 1 && tau > h_next ? kAimPastFar : kAimPast)) * tau;
    if (tau > 0 && t_aim < best) {
      best = t_aim;
      which = j;
    }
  }
  d.g_last = g;
  d.g_last_time = t_;
  if (which >= 0) set_root_directions(which);
  return best;
}

// Whether event function `which` has reached its zero in its direction at the current state.
bool Integrator::passed_zero(int which) {
  Eigen::VectorXd g(impl_->system.num_events());
  impl_->system.events(t_, y_, g);
  return g[which] * impl_->system.event_directions()[static_cast<std::size_t>(which)] >= 0;
}

// After a predicted step in which the function predicted passed its zero (ARKODE's rootfinding did not
// report it): the event, polished from the step's end back to the zero.
void Integrator::predicted_event(int which, double t_step_start, const Eigen::VectorXd& y_step_start,
                                 const RootStepHook& before_polish) {
  Impl& d = *impl_;
  const int nev = d.system.num_events();
  events_found_.assign(static_cast<std::size_t>(nev), 0);
  events_found_[static_cast<std::size_t>(which)] = d.system.event_directions()[static_cast<std::size_t>(which)];
  const double h_allowed = allowed_step();
  if (before_polish) before_polish(t_step_start, t_);
  polish_event(t_step_start, y_step_start, t_, /*from_here=*/true);
  d.h_resume = std::max(d.h_resume, h_allowed);
}

// The step the run resumes with after a predicted crossing: ARKODE's next step after a step cut at a
// stop time is that cut step (two steps per crossing where one would do). So the step the error of the
// last step allows, 0.7 h err^(-1/(p+1)) with at most 10 times h (the elementary controller of the
// method's error estimate, of order p), if larger. (With 0.9 the falling chain on 41 nodes with eps = 1e-4 erred by
// 1.1e-7 in η near its singular end, against 7.8e-8 before the prediction and 2.4e-8 with 0.7.)
double Integrator::allowed_step() const {
  Impl& d = *impl_;
  N_Vector e = d.work_vector(d.local_errors);
  const int flag = ARKStepGetEstLocalErrors(d.mem, e);
  const Eigen::Map<const Eigen::VectorXd> error(N_VGetArrayPointer(e), N_VGetLength(e));
  double err = 0.0;
  if (flag == ARK_SUCCESS) {
    error_weights(d.weights);
    err = std::sqrt((error.array() * d.weights.array()).square().mean());
  }
  const double h = std::abs(last_step());
  return err > 0 && std::isfinite(err) ? h * std::min(10.0, 0.7 * std::pow(err, -1.0 / (d.embedding_order + 1))) : 0.0;
}

Eigen::VectorXd Integrator::interpolate(double t, int k) const {
  N_Vector out = N_VClone(impl_->y);
  const int flag = ARKStepGetDky(impl_->mem, t, k, out);
  Eigen::VectorXd result = Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(out), N_VGetLength(out));
  N_VDestroy(out);
  impl_->check(flag, "ARKStepGetDky");
  return result;
}

void Integrator::restart(double t, const Eigen::VectorXd& y) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(y.size() == N_VGetLength(d.y), "restart() keeps the state length; use resize()");
  y_ = y;  // the same length: the same storage, which d.y wraps
  d.start_rhs_ready = false;
  d.check(ARKStepReset(d.mem, t, d.y), "ARKStepReset");
  d.set_init_step(d.h_resume);  // 0: ARKODE's estimate
  d.fresh_start = true;
  d.h_resume = 0;
  t_ = t;
}

void Integrator::resize(double t, const Eigen::VectorXd& y) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(y.size() == d.system.size(), "resize() needs the system to report the new size");
  Eigen::VectorXd old = y;  // (y may be state() itself)
  std::swap(old, y_);        // d.y wraps the old state until ARKODE has moved to the new one
  N_Vector ynew = d.wrap_vector(y_);
  const int flag = ARKStepResize(d.mem, ynew, 1.0, t, nullptr, nullptr);
  N_VDestroy(d.y);
  d.y = ynew;
  d.free_work_vectors();  // (of the old length)
  d.start_rhs_ready = false;
  d.check(flag, "ARKStepResize");
  d.set_init_step(d.h_resume);  // 0: ARKODE's estimate
  d.fresh_start = true;
  d.h_resume = 0;
  d.apply_tolerances();
  if (d.implicit) d.attach_linear_solver();
  t_ = t;
}

void Integrator::provide_start_rhs(const Eigen::VectorXd& f) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(f.size() == y_.size(), "provide_start_rhs() takes F at the current state");
  d.start_rhs = f;
  d.start_time = t_;
  d.start_rhs_ready = true;
}

double Integrator::last_step() const {
  sunrealtype h = 0;
  ARKStepGetLastStep(impl_->mem, &h);
  return h;
}

IntegratorStats Integrator::stats() const {
  const Impl& d = *impl_;
  IntegratorStats s;
  long nfe = 0, nfi = 0;
  ARKStepGetNumSteps(d.mem, &s.steps);
  ARKStepGetNumStepAttempts(d.mem, &s.step_attempts);
  ARKStepGetNumErrTestFails(d.mem, &s.error_test_fails);
  ARKStepGetNumRhsEvals(d.mem, &nfe, &nfi);
  s.rhs_evals = nfe + nfi;
  if (d.system.num_events() > 0) ARKStepGetNumGEvals(d.mem, &s.event_evals);
  if (d.implicit) {
    long nfe_ls = 0;
    ARKStepGetNumNonlinSolvIters(d.mem, &s.nonlin_iters);
    ARKStepGetNumNonlinSolvConvFails(d.mem, &s.nonlin_conv_fails);
    ARKStepGetNumJacEvals(d.mem, &s.jac_evals);
    ARKStepGetNumLinSolvSetups(d.mem, &s.lin_setups);
    ARKStepGetNumLinRhsEvals(d.mem, &nfe_ls);
    s.rhs_evals += nfe_ls + d.jv_evals;  // difference-quotient Jacobian columns, products J·v
    if (d.system.has_newton_solver()) {
      ARKStepGetNumLinIters(d.mem, &s.lin_iters);
      s.jac_evals = d.newton_setups;
      s.lin_solves = d.newton_solves;
    }
  }
  s.last_step = last_step();
  s.recoverable_failures = d.recoverable_failures;
  s.method = d.table;
  s.order = d.order;
  s.implicit = d.implicit;
  return s;
}

}  // namespace chainsim
