#pragma once
/// @file tension_system.hpp
/// The discrete tension equation: one sparse linear system per right-hand side (docs/string_solver.md).
///
/// Unknowns. Every arc of the string (string_model.hpp) owns a contiguous block of link tensions
/// T_j (N), in link order. Arcs are not coupled through the matrix: at a front, the jump conditions
/// give the end tensions explicitly (shocks/front_tracker.hpp), and they enter as known loads.
///
/// Rows. Differentiating the link constraint |x_{j+1} − x_j|² = h_j² twice in time and substituting
/// the momentum balance m_i a_i = F_i + T_i e_i − T_{i−1} e_{i−1} gives, per link j (nodes a = j,
/// b = j+1), the symmetric tridiagonal row (cyclic on a closed arc)
///
///   T_{j−1} w_a (e_{j−1}·e_j) − T_j (w_a + w_b) + T_{j+1} w_b (e_j·e_{j+1})
///       = −|Δv_j|²/l_j − e_j·(b_b − b_a) − (2α Δx_j·Δv_j + β² (|Δx_j|² − h_j²)/2)/l_j
///
/// with w_i = 1/m_i and b_i = F_i/m_i for a free node, and w_i = 0, b_i = a_end(t) for a node whose
/// motion is prescribed (fixed or driven: infinite mass). The last term is Baumgarte's stabilisation
/// (α = β = 0 reproduces the exact second derivative of the constraint). The matrix is −G W Gᵀ,
/// G the constraint Jacobian (row j: −e_jᵀ at node a, +e_jᵀ at node b): negative definite whenever
/// the links can move, so no pivoting is needed on an arc.
///
/// Assembly. The pattern (compressed sparse columns) is built once in the constructor; each call
/// writes values into it (zero(), add_diagonal(), set_coupling()) and solve()
/// refactors numerically through a TensionBackend:
///   - "tridiagonal": Thomas' algorithm per arc, Sherman–Morrison for a closed (cyclic) arc,
///   - "klu":         SuiteSparse KLU, klu_analyze once, klu_factor then klu_refactor each call,
///   - "eigen":       Eigen's SparseLU, analyzePattern once, factorize each call (the fallback when
///                    chainsim is built with CHAINSIM_WITH_KLU=OFF),
///   - "auto":        tridiagonal (the fastest for arcs: measured in docs/string_solver.md).
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace chainsim {

/// One arc's block of link unknowns.
struct ArcBlock {
  int first_unknown = 0;  ///< index of its first link's tension
  int num_links = 0;
  bool closed = false;    ///< cyclic block: the last link couples to the first
};

/// A square sparse pattern in compressed sparse column form (0-based, sorted rows per column).
struct SparsePattern {
  int n = 0;
  std::vector<int> col_ptr;    ///< size n+1
  std::vector<int> row_index;  ///< size nnz
  int nnz() const { return static_cast<int>(row_index.size()); }
  /// Position of entry (row, col) in the value array, or -1 if it is not in the pattern.
  int find(int row, int col) const;
  /// Whether `slot` is the position of entry (row, col): find(row, col) == slot without the search (the
  /// rows of a column are unique), for a check of every slot at each rebuild of the system.
  bool holds(int slot, int row, int col) const {
    return col >= 0 && col < n && slot >= col_ptr[static_cast<std::size_t>(col)] &&
           slot < col_ptr[static_cast<std::size_t>(col) + 1] && row_index[static_cast<std::size_t>(slot)] == row;
  }
};

/// Outcome of one factor-and-solve.
struct SolveStatus {
  bool ok = true;
  int unknown = -1;    ///< when !ok: the unknown (column) where the factorization broke down
  double pivot = 0;    ///< when !ok: the offending pivot value
  std::string detail;  ///< backend-specific note
};

/// Where each unknown u's arc entries sit in the value array (−1 where there is none), kept by the
/// TensionSystem that owns the backend (a backend reads them, it does not copy them: 12 bytes a link).
struct ArcSlots {
  const std::vector<int>* diag = nullptr;          ///< A(u, u)
  const std::vector<int>* next = nullptr;          ///< A(u, v), v the next link of u's arc
  const std::vector<int>* prev_of_next = nullptr;  ///< A(v, u)
};

/// A sparse direct solver that keeps its symbolic analysis between calls.
class TensionBackend {
 public:
  virtual ~TensionBackend() = default;
  virtual std::string name() const = 0;
  /// Symbolic phase, called once with the pattern, the arc blocks it contains and their slots (which
  /// outlive the backend).
  virtual void analyze(const SparsePattern& pattern, const std::vector<ArcBlock>& arcs, const ArcSlots& slots) = 0;
  /// Numeric factorization of A (values in pattern order) and solve of A x = b; `rhs` holds b on entry
  /// and x on return. Reports a singular (or numerically singular) matrix instead of throwing.
  virtual SolveStatus factor_solve(const double* values, double* rhs) = 0;
  /// Whether the matrix may be eliminated from both ends of an arc at once (TensionSystem::set_two_ended);
  /// a backend without such an elimination ignores it.
  virtual void set_two_ended(bool) {}
};

/// A sparse LU factorisation of one pattern that keeps its symbolic analysis, and with KLU its pivot
/// sequence, between numeric factorisations: SuiteSparse KLU (klu_analyze once, klu_factor, then
/// klu_refactor; a refactorisation whose reciprocal condition estimate looks bad is redone with a
/// fresh klu_factor before the matrix is declared singular), or Eigen's SparseLU when chainsim is
/// built without KLU. Used by the "klu" backend and by the Newton matrices of implicit methods
/// (string_jacobian.hpp), which factor once and solve many times.
class SparseFactorization {
 public:
  SparseFactorization();
  ~SparseFactorization();
  SparseFactorization(const SparseFactorization&) = delete;
  SparseFactorization& operator=(const SparseFactorization&) = delete;
  /// Symbolic phase for `pattern`; factor() then takes values in its order.
  void analyze(const SparsePattern& pattern);
  bool analyzed() const;
  /// Numeric factorisation. Reports a singular (or numerically singular) matrix instead of throwing.
  SolveStatus factor(const double* values);
  /// x = A⁻¹ b in place, with the last successful factor().
  void solve(double* rhs);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Backends compiled into this build ("tridiagonal", "eigen", and "klu" when CHAINSIM_WITH_KLU).
std::vector<std::string> tension_backend_names();
/// A backend by name; throws InputError (listing the valid names) for an unknown one.
std::unique_ptr<TensionBackend> make_tension_backend(const std::string& name);

/// The sparse tension system of one string model.
class TensionSystem {
 public:
  /// `arc_links[k]`, `arc_closed[k]` describe arc k (its links get consecutive unknowns).
  /// `backend`: see the file comment. Throws InputError for an unknown backend.
  TensionSystem(const std::vector<int>& arc_links, const std::vector<bool>& arc_closed,
                const std::string& backend = "auto");
  ~TensionSystem();
  TensionSystem(const TensionSystem&) = delete;
  TensionSystem& operator=(const TensionSystem&) = delete;

  int size() const { return pattern_.n; }
  const std::vector<ArcBlock>& arcs() const { return arcs_; }
  const SparsePattern& pattern() const { return pattern_; }
  const std::string& backend_name() const { return backend_name_; }

  // --- numeric assembly (every right-hand side) ---------------------------------------------
  /// Sets every matrix value and the right side to zero. An assembly that sets every diagonal
  /// (set_diagonal), coupling and right side, with no unknown excluded, may skip it.
  void zero();
  bool has_exclusions() const { return num_excluded_ > 0; }
  /// A(u, u) += value.
  void add_diagonal(int u, double value) { values_[diag_slot_[u]] += value; }
  /// A(u, u) = value, as zero() then add_diagonal() give it (0.0 + value: +0 for −0), without zero().
  void set_diagonal(int u, double value) { values_[diag_slot_[u]] = 0.0 + value; }
  /// Sets the symmetric coupling A(u, v) = A(v, u) = value between link u and the next link v of its
  /// arc (the first link, for the last link of a closed arc).
  void set_coupling(int u, double value) {
    values_[next_slot_[u]] = value;
    values_[prev_slot_of_next_[u]] = value;
  }
  /// Adds a non-symmetric coupling: A(u, v) += upper, A(v, u) += lower, v the next link of u's arc
  /// (a sliding node's friction, docs/model.md §10). Every backend solves the non-symmetric system:
  /// Thomas' algorithm and Sherman–Morrison read A(u, v) and A(v, u) apart, KLU and SparseLU are LU.
  void add_couplings(int u, double upper, double lower) {
    values_[next_slot_[u]] += upper;
    values_[prev_slot_of_next_[u]] += lower;
  }
  /// Right side b(u).
  double& rhs(int u) { return rhs_[u]; }
  /// Position of entry (row, col) in the value array.
  int slot(int row, int col) const;
  /// Value at a slot found by slot().
  double& value(int slot) { return values_[static_cast<std::size_t>(slot)]; }
  const std::vector<double>& values() const { return values_; }
  const Eigen::VectorXd& rhs_vector() const { return rhs_; }

  /// The tridiagonal backend's elimination of an open arc: from both ends at once (on, the default: twice
  /// the instruction-level parallelism of Thomas' single chain of divisions, the same solution to
  /// round-off), or from the first link down (Thomas' algorithm, off). StringModel turns it off while
  /// a module holds nodes on obstacles or bends links over edges (docs/string_solver.md, "The tension
  /// solve from both ends"): their events decide on quantities at round-off (a reaction on the edge of
  /// the friction cone, a node that lands and is let go at the same instant), tuned with Thomas' rounding.
  void set_two_ended(bool on) { backend_->set_two_ended(on); }

  /// Factors and solves A T = b. Throws NumericalError naming the link (or junction unknown), the
  /// pivot and the time t when the matrix is singular, or when the solution is not finite. Excluded
  /// unknowns (exclude()) come out exactly zero.
  const Eigen::VectorXd& solve(double t);

  // --- unilateral links ([solver] slack = "allow", docs/model.md "Slack and snap-taut") -------
  /// Takes unknown u out of the system until the next zero(): its couplings with its neighbours and
  /// its right side become zero (its diagonal stays), so T_u = 0 and the others do not see it. O(1).
  void exclude(int u);
  bool excluded(int u) const { return !excluded_.empty() && excluded_[static_cast<std::size_t>(u)] != 0; }
  /// The linear complementarity problem of unilateral links on the assembled system (A, b), with the
  /// unknowns excluded so far held at zero:
  ///     T ≥ 0,   w = b − A T ≥ 0,   T_u w_u = 0   for every other unknown u.
  /// A = −G W Gᵀ is negative definite, so −A is symmetric positive definite and the problem has one
  /// solution (a P-matrix LCP). Block principal pivoting (Júdice & Pires): each pass releases
  /// (excludes) the unknowns with T_u < −tolerance and takes back the released ones with
  /// w_u < −tolerance |A_uu|, and solves again, O(N) a pass; after kBlockPasses passes that have not
  /// settled it changes one unknown a pass (Murty's least-index rule, finite for a P-matrix). The
  /// first pass is a plain solve(): a system with no negative unknown costs nothing more.
  /// `tolerance(max |T|)` gives the absolute tolerance (N or N s); it is called only when a T_u < 0.
  /// Throws NumericalError, naming t and the unknowns still in violation, after max_passes(n) passes.
  template <class Tolerance>
  const Eigen::VectorXd& solve_complementarity(double t, Tolerance&& tolerance);
  static constexpr int kBlockPasses = 8;
  /// The passes allowed before the solve gives up: kMaxPasses + 4 n for n unknowns. Murty's rule
  /// changes one unknown a pass, so a problem whose solution differs from the last block pass in n
  /// unknowns needs n passes at least: a string nearly in free fall (every tension slightly negative,
  /// the block pass releasing them all, the solution taking them back one at a time) took n − 1 = 319
  /// passes on 320 links (the pendulum past its whip on 321 nodes, issue 27), past a cap of 200 that
  /// did not grow with n. What the cap still catches is a cycle of round-off.
  static constexpr int kMaxPasses = 200;
  static constexpr int max_passes(int n) { return kMaxPasses + 4 * n; }
  /// What the complementarity solves did: calls that released an unknown, their passes summed and
  /// the most passes one call took.
  struct ComplementarityStats {
    long calls_with_release = 0, passes = 0;
    int max_passes = 0;
  };
  const ComplementarityStats& complementarity_stats() const { return lcp_stats_; }
  /// The last solution.
  const Eigen::VectorXd& solution() const { return solution_; }
  /// Number of factor-and-solve calls so far.
  long num_solves() const { return solves_; }

  /// "link 12 of arc 0".
  std::string describe(int unknown) const;

 private:
  std::vector<ArcBlock> arcs_;
  SparsePattern pattern_;
  std::vector<double> values_;
  std::vector<int> diag_slot_, next_slot_, prev_slot_of_next_;
  Eigen::VectorXd rhs_, solution_;
  std::unique_ptr<TensionBackend> backend_;
  std::string backend_name_;
  long solves_ = 0;
  // unilateral links: per unknown, excluded (1) or not (0), the unknowns before and after it in its arc
  // (−1; built by the first exclude(), so a run that never releases a link does not hold them)
  std::vector<char> excluded_;
  int num_excluded_ = 0;
  std::vector<int> prev_, next_;
  std::vector<double> full_values_;
  Eigen::VectorXd full_rhs_;
  ComplementarityStats lcp_stats_;
  /// Builds prev_ and next_.
  void link_neighbours();
  /// w_u = b_u − (A T)_u with the values `values` and right side `rhs`.
  double complementarity_residual(int u, const std::vector<double>& values, const Eigen::VectorXd& rhs,
                                  const Eigen::VectorXd& T) const;
  [[noreturn]] void complementarity_failure(double t, const std::vector<int>& violating) const;
};

template <class Tolerance>
const Eigen::VectorXd& TensionSystem::solve_complementarity(double t, Tolerance&& tolerance) {
  solve(t);
  const int n = size();
  double max_abs = 0, min_T = 0;
  for (int u = 0; u < n; ++u) {
    min_T = std::min(min_T, solution_[u]);
    max_abs = std::max(max_abs, std::abs(solution_[u]));
  }
  if (!(min_T < 0)) return solution_;
  const double tol = tolerance(max_abs);
  if (!(min_T < -tol)) return solution_;
  // The assembled system with the caller's exclusions, kept to restore and to measure w.
  full_values_ = values_;
  full_rhs_ = rhs_;
  const std::vector<char> fixed = excluded_.empty() ? std::vector<char>(static_cast<std::size_t>(n), 0) : excluded_;
  std::vector<char> released(static_cast<std::size_t>(n), 0);
  std::vector<int> violating;
  ++lcp_stats_.calls_with_release;
  for (int pass = 1;; ++pass) {
    violating.clear();
    for (int u = 0; u < n; ++u) {
      if (fixed[static_cast<std::size_t>(u)]) continue;
      if (!released[static_cast<std::size_t>(u)]) {
        if (solution_[u] < -tol) violating.push_back(u);
      } else if (complementarity_residual(u, full_values_, full_rhs_, solution_) <
                 -tol * std::abs(full_values_[static_cast<std::size_t>(diag_slot_[u])])) {
        violating.push_back(u);
      }
    }
    lcp_stats_.passes += 1;
    lcp_stats_.max_passes = std::max(lcp_stats_.max_passes, pass);
    if (violating.empty()) return solution_;
    if (pass >= max_passes(n)) complementarity_failure(t, violating);
    if (pass < kBlockPasses) {
      for (int u : violating) released[static_cast<std::size_t>(u)] ^= 1;
    } else {
      released[static_cast<std::size_t>(violating.front())] ^= 1;  // least index
    }
    values_ = full_values_;
    rhs_ = full_rhs_;
    excluded_ = fixed;
    num_excluded_ = static_cast<int>(std::count(fixed.begin(), fixed.end(), 1));
    for (int u = 0; u < n; ++u)
      if (released[static_cast<std::size_t>(u)]) exclude(u);
    solve(t);
  }
}

}  // namespace chainsim
