// The reduced models of docs/model.md §4, integrated by ARKODE; see reduced_models.hpp.
#include "reduced_models.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

namespace exact {
namespace {
struct References {
  double (*xi)(double, double, double);
  double (*eta_prime_squared)(double, double, double);
  double (*P)(double, double, double);
  double (*fall_time)(double, double);
};
const References& references(Problem problem) {
  static const References table[] = {
      {falling_xi, falling_eta_prime_squared, falling_P, falling_fall_time},
      {folded_xi, folded_eta_prime_squared, folded_P, folded_fall_time},
      {sliding_xi, sliding_eta_prime_squared, sliding_P, sliding_fall_time}};
  static_assert(static_cast<int>(Problem::kFalling) == 0 && static_cast<int>(Problem::kFolded) == 1 &&
                static_cast<int>(Problem::kSliding) == 2);
  return table[static_cast<int>(problem)];
}
}  // namespace
double xi(Problem p, double f, double eta, double eta0) { return references(p).xi(f, eta, eta0); }
double eta_prime_squared(Problem p, double f, double eta, double eta0) {
  return references(p).eta_prime_squared(f, eta, eta0);
}
double P(Problem p, double f, double eta, double eta0) { return references(p).P(f, eta, eta0); }
double fall_time(Problem p, double f, double eta0) { return references(p).fall_time(f, eta0); }
}  // namespace exact

Problem parse_problem(const std::string& name, const std::string& what) {
  if (name == "falling") return Problem::kFalling;
  if (name == "folded") return Problem::kFolded;
  if (name == "sliding") return Problem::kSliding;
  throw InputError(fmt::format("{} = \"{}\" is not a known problem: allowed falling, folded, sliding", what, name));
}

std::string to_string(Problem problem) {
  switch (problem) {
    case Problem::kFalling: return "falling";
    case Problem::kFolded: return "folded";
    case Problem::kSliding: return "sliding";
  }
  return "?";
}

void ChainParameters::validate() const {
  // Each scale, and the energy scale λ g ℓ² the ledger and the tolerances use, in the range the
  // solvers accept (mesh/errors.hpp): ℓ = 5e-324 made the energy scale 0 (an internal error).
  for (const auto& [name, value] : {std::pair{"--length", length}, {"--density", density}, {"--gravity", gravity}}) {
    require_positive(name, value);
    require_in_range(name, value, kMinScale, kMaxScale);
  }
  require_in_range("--f", dissipation, 0.0, 1.0);
  const double energy = density * gravity * length * length;
  if (!(energy >= kMinScale * kMinScale && energy <= kMaxScale * kMaxScale))
    throw InputError(fmt::format("--length = {}, --density = {}, --gravity = {}: the energy scale lambda g l^2 = {} J "
                                 "is out of the range the solver can represent: allowed {} to {}",
                                 length, density, gravity, energy, kMinScale * kMinScale, kMaxScale * kMaxScale));
}

double ChainParameters::t0() const { return std::sqrt(2.0 * length / gravity); }
double ChainParameters::P0() const { return density * length * gravity; }

IntegratorOptions ReducedSetup::default_integrator() {
  IntegratorOptions o;
  o.method = defaults::kReduced.method;
  o.rtol = defaults::kReduced.rtol;
  o.atol = defaults::kReduced.atol;
  return o;
}

double ReducedSetup::initial_eta() const {
  if (eta0) return *eta0;
  return problem == Problem::kFalling ? 1.0 : 0.0;
}

namespace {

/// Δξ(ε) = C ε^p, the leading term of the exact time (units of t0) between the cutoff ε and the
/// singular end of the fall, from the first integrals of exact_solutions.hpp near the end.
struct TimeToEnd {
  double C = 0, p = 1;
  double at(double eps) const { return C * std::pow(eps, p); }
};

TimeToEnd time_to_end(Problem problem, double f, double eta0) {
  switch (problem) {
    case Problem::kFalling:  // η'² ≈ 4/(3−2f) η0^(3−2f) η^(2f−2) as η → 0
      return {0.5 * std::sqrt(3.0 - 2.0 * f) * std::pow(eta0, -(3.0 - 2.0 * f) / 2.0) / (2.0 - f), 2.0 - f};
    case Problem::kFolded:  // η'² ≈ 2/(2−f) (1−η0)^(2−f) z^(f−1) as z = 1 − η → 0
      return {std::sqrt(1.0 - f / 2.0) * std::pow(1.0 - eta0, -(2.0 - f) / 2.0) / ((3.0 - f) / 2.0), (3.0 - f) / 2.0};
    case Problem::kSliding:
      break;
  }
  return {};
}

/// The smallest hanging fraction η of the sliding chain at its start: far above the smallest normal
/// double even in units of the shortest length a chain may have (kMinScale).
constexpr double kMinHangingFraction = 1e-150;

/// x rounded up to two significant digits, as the double nearest to that decimal (so that the
/// limit printed, and typed back by a user, is exactly the limit checked).
double round_up_2(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1.0);
  return std::stod(fmt::format("{:.1e}", std::ceil(x / unit * (1 - 1e-12)) * unit));
}

}  // namespace

double ReducedSetup::min_cutoff() const {
  if (problem == Problem::kSliding) return 0.0;
  const TimeToEnd law = time_to_end(problem, chain.dissipation, initial_eta());
  return round_up_2(std::pow(kMinTimeToEnd / law.C, 1.0 / law.p));
}

void ReducedSetup::validate() const {
  chain.validate();
  require_in_range("--eps", eps, 0.0, 1.0, Bound::kOpen, Bound::kOpen);
  if (max_rows < 16)
    throw InputError(fmt::format("max_rows = {} is out of range: allowed max_rows >= 16", max_rows));
  const double e0 = initial_eta();
  switch (problem) {
    case Problem::kFalling:
      require_in_range("--eta0", e0, eps, 1.0, Bound::kOpen, Bound::kClosed);
      break;
    case Problem::kFolded:
      require_in_range("--eta0", e0, 0.0, 1.0 - eps, Bound::kClosed, Bound::kOpen);
      break;
    case Problem::kSliding:
      require_in_range("--eta0", e0, 0.0, 1.0, Bound::kClosed, Bound::kOpen);
      break;
  }
  if (problem != Problem::kSliding && eps < min_cutoff()) {
    const double f = chain.dissipation;
    throw InputError(fmt::format(
        "--eps = {} is out of range for the {} chain with f = {}, eta0 = {}: allowed {} <= eps < {}. The "
        "exact time left between that cutoff and the singular end of the fall is {:.2g} t0, less than {:g} t0 "
        "(about 10^3 round-off units of t): the run cannot resolve the cutoff",
        eps, to_string(problem), f, e0, min_cutoff(), problem == Problem::kFalling ? e0 : 1.0 - e0,
        time_to_end(problem, f, e0).at(eps), kMinTimeToEnd));
  }
  if (problem == Problem::kFolded) {
    require_in_range("--force", force, 0.0, INFINITY);
    const double weight = chain.density * chain.gravity * chain.length;
    if (e0 == 0.0 && force > weight)
      throw InputError(fmt::format(
          "--force = {} N exceeds the chain's weight lambda g l = {} N: released at eta0 = 0, the free end would "
          "rise above its start at once, out of the model's domain eta >= 0; allowed 0 <= force <= {} N at "
          "eta0 = 0 (from eta0 > 0 a larger force lifts the fold to the fixed end, where the run stops)",
          force, weight, weight));
  } else if (force != 0.0)
    throw InputError(fmt::format("--force = {} applies to the folded chain only (the {} chain has no loaded end): "
                                 "allowed force = 0",
                                 force, to_string(problem)));
  require_positive("--t-max", t_max_over_t0);
  if (problem == Problem::kSliding && e0 == 0.0) {
    // Up to t_max the chain follows its branch η = τ²/(3 + 2f) (τ = t/t0), whose hanging length
    // must stay a normal number: the model divides by it.
    const double lowest = round_up_2(std::sqrt((3.0 + 2.0 * chain.dissipation) * kMinHangingFraction));
    if (t_max_over_t0 < lowest)
      throw InputError(fmt::format("--t-max = {} is out of range for the sliding chain from eta0 = 0: allowed t_max >= "
                                   "{} (the hanging length at t_max, eta = t_max^2/(3 + 2f) = {} of l, would "
                                   "underflow)",
                                   t_max_over_t0, lowest,
                                   t_max_over_t0 * t_max_over_t0 / (3.0 + 2.0 * chain.dissipation)));
  }
  // The run's length in seconds is a scale like the chain's own: in [kMinScale, kMaxScale] (as a scene's
  // stop.t_end). Below it, ARKODE's stop time rounds onto the start (t_max = 1e-200 failed with
  // ARK_ILL_INPUT); above it, t_max t0 overflows.
  const double t_max_s = t_max_over_t0 * chain.t0();
  if (!(t_max_s >= kMinScale && t_max_s <= kMaxScale))
    throw InputError(fmt::format("--t-max = {} is out of range: t_max t0 = {} s with t0 = {} s; allowed {} <= t_max <= "
                                 "{} (t_max t0 in [{}, {}] s)",
                                 t_max_over_t0, t_max_s, chain.t0(), kMinScale / chain.t0(), kMaxScale / chain.t0(),
                                 kMinScale, kMaxScale));
  integrator.validate();
}

namespace {

/// Mechanical quantities of a reduced model at one state (SI units).
struct Snapshot {
  double y = 0, yd = 0, ydd = 0;
  double P = 0;        ///< dynamic weight (N)
  double K = 0, V = 0; ///< kinetic and potential energy (J)
  double W_shock = 0;  ///< power at the internal shock (W), <= 0
  double W_heap = 0;   ///< power of the external shock at the heap (W)
  double W_force = 0;  ///< power of the end force F (W)
};

/// The ODE for one problem: state (y, ẏ, E_shock, E_heap, E_force), where E_k = ∫ W_k dt.
class ReducedOde : public OdeSystem {
 public:
  /// `t_max`: the run's end (s), which bounds its time scale.
  ReducedOde(const ReducedSetup& s, double t_max)
      : s_(s), l_(s.chain.length), lam_(s.chain.density), g_(s.chain.gravity), f_(s.chain.dissipation),
        t_max_(t_max) {}

  int size() const override { return 5; }

  /// ÿ from the equation of motion; throws RecoverableError outside the model's domain.
  double acceleration(double y, double yd) const {
    const double sq = yd * yd, sgn_sq = yd * std::abs(yd);  // ẏ² and sgn(ẏ) ẏ²
    switch (s_.problem) {
      case Problem::kFalling:
        if (!(y > 0)) throw RecoverableError("falling chain: y <= 0");
        return -g_ - (sq + f_ * sgn_sq) / y;
      case Problem::kFolded:
        if (!(l_ - y > 0)) throw RecoverableError("folded chain: y >= l");
        return (g_ * (l_ - y) + sq - f_ * sgn_sq - s_.force / lam_) / (2.0 * (l_ - y));
      case Problem::kSliding:
        if (!(y > 0)) throw RecoverableError("sliding chain: y <= 0");
        return g_ - (sq + f_ * sgn_sq) / y;
    }
    return 0;
  }

  Snapshot snapshot(double y, double yd) const {
    Snapshot q;
    q.y = y;
    q.yd = yd;
    q.ydd = acceleration(y, yd);
    const double sq = yd * yd, sgn_sq = yd * std::abs(yd), cube_abs = sq * std::abs(yd);
    switch (s_.problem) {
      case Problem::kFalling:
        // Table reaction Φ0 = λẏ² − τ⁻ with τ⁻ = λ(1 + f sgn ẏ)ẏ²; P = Φ0 + weight on the table.
        q.P = -f_ * lam_ * sgn_sq + lam_ * g_ * (l_ - y);
        q.K = 0.5 * lam_ * y * sq;
        q.V = 0.5 * lam_ * g_ * y * y;
        q.W_shock = -f_ * lam_ * cube_abs;  // D = ½ f λ |ṡ0| |[v]|², ṡ0 = ẏ, |[v]|² = 2ẏ²
        q.W_heap = -0.5 * lam_ * yd * sq;   // W*⁺
        break;
      case Problem::kFolded:
        q.P = lam_ * (sq + f_ * sgn_sq) + lam_ * g_ * y;
        q.K = 2.0 * lam_ * (l_ - y) * sq;
        q.V = -0.5 * lam_ * g_ * y * y - 0.5 * lam_ * g_ * (l_ - y) * (3.0 * y - l_);
        q.W_shock = -2.0 * lam_ * f_ * cube_abs;
        q.W_force = -2.0 * s_.force * yd;
        break;
      case Problem::kSliding:
        q.P = f_ * lam_ * sgn_sq + lam_ * g_ * (l_ - y);
        q.K = 0.5 * lam_ * y * sq;
        q.V = -0.5 * lam_ * g_ * y * y;
        q.W_shock = -f_ * lam_ * cube_abs;
        q.W_heap = -0.5 * lam_ * yd * sq;  // W*⁻
        break;
    }
    return q;
  }

  void rhs(double, const Eigen::Ref<const Eigen::VectorXd>& u, Eigen::Ref<Eigen::VectorXd> du) override {
    const Snapshot q = snapshot(u[0], u[1]);
    du << q.yd, q.ydd, q.W_shock, q.W_heap, q.W_force;
  }

  int num_events() const override { return s_.problem == Problem::kFolded ? (s_.force > 0 ? 3 : 2) : 1; }

  void events(double, const Eigen::Ref<const Eigen::VectorXd>& u, Eigen::Ref<Eigen::VectorXd> g) override {
    switch (s_.problem) {
      case Problem::kFalling: g[0] = u[0] - s_.eps * l_; break;
      case Problem::kSliding: g[0] = u[0] - l_; break;
      case Problem::kFolded:
        g[0] = u[0] - (1.0 - s_.eps) * l_;  // the free end reaches the cutoff
        g[1] = u[0];                        // the bight reaches the fixed end
        if (s_.force > 0) g[2] = u[1];      // turning point: sgn ẏ switches the model's branch
        break;
    }
  }

  std::vector<int> event_directions() const override {
    switch (s_.problem) {
      case Problem::kFalling: return {-1};
      case Problem::kSliding: return {+1};
      case Problem::kFolded: return s_.force > 0 ? std::vector<int>{+1, -1, 0} : std::vector<int>{+1, -1};
    }
    return {};
  }

  Eigen::VectorXd state_scale() const override {
    const double speed = std::sqrt(g_ * l_), energy = lam_ * g_ * l_ * l_;
    Eigen::VectorXd scale(5);
    scale << l_, speed, energy, energy, energy;
    return scale;
  }

  /// t0, or the run's length if shorter: the integrator's step-size floor is a fraction of this, so
  /// it stays below the steps a run of any length takes (a run of 1e-7 t0 has steps far below 1e-14 t0).
  double time_scale() const override { return std::min(s_.chain.t0(), t_max_); }

 private:
  const ReducedSetup& s_;
  double l_, lam_, g_, f_, t_max_;
};

/// The recorded series, bounded before the run: rows of accepted steps 0, k, 2k, … (stride k), the
/// stride doubling (every other row dropped) whenever max_rows is reached; the last state offered is
/// always the last row (finish()).
class SeriesRecorder {
 public:
  explicit SeriesRecorder(long max_rows) : max_rows_(static_cast<std::size_t>(max_rows / 2 * 2)) {}

  void offer(std::vector<double> row) {
    kept_last_ = offered_++ % stride_ == 0;
    if (kept_last_)
      push(std::move(row));
    else
      last_ = std::move(row);
  }
  CsvTable finish() {
    if (!kept_last_) push(std::move(last_));
    CsvTable table(series_columns());
    for (const auto& row : rows_) table.add_row(row);
    return table;
  }
  long stride() const { return stride_; }

 private:
  void push(std::vector<double> row) {
    if (rows_.size() >= max_rows_) {  // keep rows 0, 2, 4, …: steps 0, 2k, 4k, …
      for (std::size_t i = 1; 2 * i < rows_.size(); ++i) rows_[i] = std::move(rows_[2 * i]);
      rows_.resize((rows_.size() + 1) / 2);
      stride_ *= 2;
    }
    rows_.push_back(std::move(row));
  }

  std::size_t max_rows_;
  long stride_ = 1, offered_ = 0;
  bool kept_last_ = true;
  std::vector<double> last_;
  std::vector<std::vector<double>> rows_;
};

}  // namespace

std::vector<std::string> series_columns() {
  return {"t", "y", "ydot", "yddot", "P", "K", "V", "W_shock", "W_heap", "W_force", "E_shock", "E_heap",
          "E_force", "ledger", "xi", "eta", "eta_p", "eta_pp", "P_over_P0", "K_over_P0l", "V_over_P0l"};
}

ReducedRun solve_reduced(const ReducedSetup& setup) {
  setup.validate();
  const auto wall_start = std::chrono::steady_clock::now();
  const ChainParameters& c = setup.chain;
  const double l = c.length, g = c.gravity, f = c.dissipation, t0 = c.t0(), P0 = c.P0();
  const double eta0 = setup.initial_eta();

  // 1. Initial state: at rest, except the sliding chain from η0 = 0, which starts on its
  //    non-trivial branch y = a t²/2 at η = kSlidingStartEta (see reduced_models.hpp), or at the
  //    safety stop if that comes first: the branch is the exact solution up to there.
  //    Every time is on the clock of the release (t = 0): the run ends at t_max = t_max/t0 · t0
  //    exactly, whatever its size relative to t0 and to t_start.
  const double t_max = setup.t_max_over_t0 * t0;
  double t_start = 0.0;
  Eigen::VectorXd u0 = Eigen::VectorXd::Zero(5);
  u0[0] = eta0 * l;
  const bool sliding_branch = setup.problem == Problem::kSliding && eta0 == 0.0;
  if (sliding_branch) {
    const double a = g / (3.0 + 2.0 * f);
    t_start = std::min(std::sqrt(2.0 * kSlidingStartEta * l / a), t_max);
    u0[0] = 0.5 * a * t_start * t_start;
    u0[1] = a * t_start;
  }

  // 2. Integrator: record the accepted steps (thinned to max_rows), with steps no longer than t0/500
  //    by default.
  ReducedOde ode(setup, t_max);
  IntegratorOptions opts = setup.integrator;
  if (opts.max_step == 0) opts.max_step = t0 / 500.0;
  Integrator integrator(ode, t_start, u0, opts);

  ReducedRun run{CsvTable(series_columns()), {}};
  SeriesRecorder series(setup.max_rows);
  const Snapshot q0 = ode.snapshot(u0[0], u0[1]);
  const double E0 = q0.K + q0.V;
  double ledger_max = 0, energy_scale = 0;
  auto record = [&](double t, const Eigen::VectorXd& u) {
    const Snapshot q = ode.snapshot(u[0], u[1]);
    const double ledger = q.K + q.V - E0 - (u[2] + u[3] + u[4]);
    ledger_max = std::max(ledger_max, std::abs(ledger));
    energy_scale = std::max(energy_scale, std::abs(q.K) + std::abs(q.V) + std::abs(u[2]) + std::abs(u[3]) +
                                              std::abs(u[4]));
    const double speed_scale = l / t0, energy_unit = P0 * l;
    series.offer({t, q.y, q.yd, q.ydd, q.P, q.K, q.V, q.W_shock, q.W_heap, q.W_force, u[2], u[3], u[4],
                        ledger, t / t0, q.y / l, q.yd / speed_scale, q.ydd * t0 * t0 / l, q.P / P0,
                        q.K / energy_unit, q.V / energy_unit});
  };
  record(t_start, u0);

  // 3. Advance step by step until a stop event (or the safety time).
  std::string stop_reason = "t_max";
  std::string stop_detail = fmt::format("the safety stop t_max = {} t0 was reached before a stop event",
                                        setup.t_max_over_t0);
  int turning_points = 0;
  while (integrator.time() < t_max) {
    const auto outcome = integrator.advance(t_max, /*one_step=*/true);
    record(integrator.time(), integrator.state());
    if (outcome == Integrator::Outcome::kReachedTarget) break;
    if (outcome != Integrator::Outcome::kEvent) continue;
    const auto& ev = integrator.events_found();
    if (ev[0] != 0) {
      stop_reason = setup.problem == Problem::kSliding ? "chain_fully_hanging" : "cutoff";
      stop_detail = setup.problem == Problem::kSliding ? "the whole chain hangs (eta = 1)"
                    : setup.problem == Problem::kFalling
                        ? fmt::format("the falling part reached the cutoff eta = eps = {:g}", setup.eps)
                        : fmt::format("the resting arm reached the cutoff eta = 1 - eps, eps = {:g}", setup.eps);
      break;
    }
    if (setup.problem == Problem::kFolded && ev[1] != 0) {
      stop_reason = "front_reached_fixed_end";
      stop_detail = "the fold reached the fixed end (eta = 0, the boundary of the model's domain): the free end is "
                    "back at the height l above the support it starts from when eta0 = 0";
      break;
    }
    if (setup.problem == Problem::kFolded && ev.size() > 2 && ev[2] != 0) {
      ++turning_points;  // restart so the next step starts on the new branch of sgn ẏ
      Eigen::VectorXd u = integrator.state();
      u[1] = 0.0;
      integrator.restart(integrator.time(), u);
    }
  }

  run.series = series.finish();

  // 4. Summary, with the exact references where the problem has one.
  const double t_stop = integrator.time();
  const Eigen::VectorXd& u = integrator.state();
  const Snapshot q = ode.snapshot(u[0], u[1]);
  if (!std::isfinite(q.P) || !std::isfinite(q.yd))
    throw NumericalError(fmt::format("non-finite state at t = {:.9g} s (y = {:g}, ydot = {:g})", t_stop, q.y, q.yd),
                         t_stop);
  const double eta_stop = q.y / l;
  nlohmann::json ref = nullptr;
  double xi_ref = NAN, P_ref = NAN, fall_ref = NAN;
  if (setup.problem != Problem::kFolded || setup.force == 0.0) {  // no quadrature with an end force
    const double eta_ref = std::min(eta_stop, 1.0);
    xi_ref = exact::xi(setup.problem, f, eta_ref, eta0);
    P_ref = exact::P(setup.problem, f, eta_ref, eta0);
    fall_ref = exact::fall_time(setup.problem, f, eta0);
  }
  auto num_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const bool has_ref = std::isfinite(xi_ref) && stop_reason != "t_max";
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  run.summary = {
      {"problem", to_string(setup.problem)},
      {"model", "reduced"},
      {"parameters",
       {{"length", l}, {"density", c.density}, {"gravity", g}, {"f", f}, {"eps", setup.eps}, {"eta0", eta0},
        {"force", setup.force}}},
      {"t0", t0},
      {"P0", P0},
      {"stop_reason", stop_reason},
      {"stop_detail", stop_detail},
      {"t_start", t_start},
      {"t_stop", t_stop},
      {"t_stop_over_t0", stop_reason == "t_max" ? setup.t_max_over_t0 : t_stop / t0},  // t_max as given
      {"eta_stop", eta_stop},
      {"P_stop", q.P},
      {"P_stop_over_P0", q.P / P0},
      {"t_fall_over_t0", num_or_null(fall_ref)},
      {"t_stop_over_t0_exact", has_ref ? num_or_null(xi_ref) : nullptr},
      {"P_stop_over_P0_exact", has_ref ? num_or_null(P_ref) : nullptr},
      {"rel_err_t_stop", has_ref ? num_or_null(std::abs(t_stop / t0 - xi_ref) / xi_ref) : nullptr},
      {"rel_err_P_stop", has_ref ? num_or_null(std::abs(q.P / P0 - P_ref) / std::abs(P_ref)) : nullptr},
      {"energy_residual", energy_scale > 0 ? ledger_max / energy_scale : 0.0},
      {"turning_points", turning_points},
      {"samples", run.series.rows()},
      {"sample_stride", series.stride()},
      {"integrator", to_json(integrator.stats())},
      {"wall_s", wall_s},
  };
  return run;
}

}  // namespace chainsim
