// The sparse tension system and its backends: see tension_system.hpp.
#include "tension_system.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <fmt/format.h>

#ifdef CHAINSIM_WITH_KLU
#include <klu.h>
#endif

#include "mesh/errors.hpp"

namespace chainsim {

namespace {

/// A pivot smaller than this times its row's |diagonal entry| (tridiagonal), or a reciprocal pivot
/// growth below it (KLU), counts as zero: the system is singular to working precision.
constexpr double kSingularPivot = 1e-13;

// ----------------------------------------------------------------------------------------------
// Tridiagonal backend: Thomas' algorithm per arc, cyclic arcs by Sherman–Morrison.
// The matrix is (negative) definite on an arc, so elimination without pivoting is stable.
class TridiagonalBackend final : public TensionBackend {
 public:
  std::string name() const override { return "tridiagonal"; }

  void analyze(const SparsePattern& pattern, const std::vector<ArcBlock>& arcs, const ArcSlots& slots) override {
    arcs_ = arcs;
    const int n = pattern.n;
    int expected = 0;
    // The system's slots: A(u, u) = diag, A(u, u+1) = next[u], A(u+1, u) = prev_of_next[u] (the
    // backend keeps no copy of them).
    CHAINSIM_VERIFY(slots.diag && slots.next && slots.prev_of_next && static_cast<int>(slots.diag->size()) == n &&
                        static_cast<int>(slots.next->size()) == n && static_cast<int>(slots.prev_of_next->size()) == n,
                    "one diagonal, next and previous slot per unknown");
    diag_ = slots.diag->data();
    upper_ = slots.next->data();
    lower_of_prev_ = slots.prev_of_next->data();
    corner_lo_.assign(arcs.size(), -1);
    corner_up_.assign(arcs.size(), -1);
    int covered = 0;
    for (std::size_t k = 0; k < arcs.size(); ++k) {
      const ArcBlock& arc = arcs[k];
      const int f = arc.first_unknown, m = arc.num_links;
      covered += m;
      for (int i = 0; i < m; ++i) {
        CHAINSIM_VERIFY(pattern.holds(diag_[f + i], f + i, f + i) &&
                            (i + 1 == m || (pattern.holds(upper_[f + i], f + i, f + i + 1) &&
                                            pattern.holds(lower_of_prev_[f + i], f + i + 1, f + i))),
                        "the tension system's slots are its pattern's");
      }
      expected += m + 2 * (m - 1);
      if (arc.closed && m >= 3) {
        corner_lo_[k] = pattern.find(f + m - 1, f);  // A(last, first)
        corner_up_[k] = pattern.find(f, f + m - 1);  // A(first, last)
        expected += 2;
      }
    }
    if (covered != n || pattern.nnz() != expected)
      throw InputError(
          "the tridiagonal tension backend solves arcs only; this system has entries coupling arcs: "
          "use backend = \"klu\" or \"eigen\"");
    // Workspace for the longest arc; the cyclic solve's two vectors only for the closed arcs.
    std::size_t max_links = 0, max_closed = 0;
    for (const ArcBlock& arc : arcs) {
      max_links = std::max(max_links, static_cast<std::size_t>(arc.num_links));
      if (arc.closed && arc.num_links >= 3) max_closed = std::max(max_closed, static_cast<std::size_t>(arc.num_links));
    }
    cp_.resize(max_links);
    z_.resize(max_closed);
    bb_.resize(max_closed);
  }

  SolveStatus factor_solve(const double* values, double* rhs) override {
    for (std::size_t k = 0; k < arcs_.size(); ++k) {
      const ArcBlock& arc = arcs_[k];
      SolveStatus status = arc.closed && arc.num_links >= 3
                               ? cyclic(values, rhs, arc, corner_lo_[k], corner_up_[k])
                               : two_ended_ ? twisted(values, rhs, arc.first_unknown, arc.num_links)
                                            : thomas(values, rhs, arc.first_unknown, arc.num_links, nullptr, nullptr);
      if (!status.ok) return status;
    }
    return {};
  }

  void set_two_ended(bool on) override { two_ended_ = on; }

 private:
  bool two_ended_ = true;
  /// Solves the tridiagonal block [f, f+m) with diagonal `bmod` (if given, else from values) for the
  /// right side r (in place); if `second` is given, applies the same elimination to it.
  SolveStatus thomas(const double* A, double* r, int f, int m, const double* bmod, double* second) {
    // A pivot that cancels its row's diagonal to round-off means a singular matrix.
    double piv = bmod ? bmod[0] : A[diag_[f]];
    if (!(std::abs(piv) > kSingularPivot * std::abs(A[diag_[f]]))) return {false, f, piv, "Thomas elimination"};
    double inv = 1.0 / piv;
    cp_[0] = m > 1 ? A[upper_[f]] * inv : 0.0;
    r[f] *= inv;
    if (second) second[0] *= inv;
    for (int i = 1; i < m; ++i) {
      const double a = A[lower_of_prev_[f + i - 1]];  // A(f+i, f+i-1)
      const double b = bmod ? bmod[i] : A[diag_[f + i]];
      piv = b - a * cp_[static_cast<std::size_t>(i - 1)];
      if (!(std::abs(piv) > kSingularPivot * std::abs(b))) return {false, f + i, piv, "Thomas elimination"};
      inv = 1.0 / piv;
      cp_[static_cast<std::size_t>(i)] = i + 1 < m ? A[upper_[f + i]] * inv : 0.0;
      r[f + i] = (r[f + i] - a * r[f + i - 1]) * inv;
      if (second) second[i] = (second[i] - a * second[i - 1]) * inv;
    }
    for (int i = m - 2; i >= 0; --i) {
      r[f + i] -= cp_[static_cast<std::size_t>(i)] * r[f + i + 1];
      if (second) second[i] -= cp_[static_cast<std::size_t>(i)] * second[i + 1];
    }
    return {};
  }

  /// The same system as thomas() (without a second right side) eliminated from both ends at once: rows
  /// 0 … k−1 downwards as Thomas' algorithm does, rows m−1 … k+1 upwards (the mirror image: each row's
  /// coupling with the row below eliminated), the middle row k = m/2 solved from both, and the two
  /// halves substituted back outwards from it (a twisted factorisation, "burn at both ends"). The two
  /// chains are independent: each row's division waits for the previous row's of its own chain only, so
  /// the processor runs both at once, where Thomas' single chain waits a division's latency per row.
  /// The same pivots for the top half; the bottom half's and the middle's differ at round-off. The
  /// matrix is definite on an arc, so every pivot of either direction is safe without pivoting.
  SolveStatus twisted(const double* A, double* r, int f, int m) {
    const int k = m / 2;  // rows 0 … k−1 from the top, m−1 … k+1 from the bottom
    double* const cp = cp_.data();  // top: A(i, i+1) / pivot_i; bottom: A(j, j−1) / pivot_j
    double* const x = r + f;
    const auto lower = [&](int i) { return A[lower_of_prev_[f + i - 1]]; };  // A(i, i−1), i >= 1
    const auto upper = [&](int i) { return A[upper_[f + i]]; };               // A(i, i+1), i <= m−2
    const auto diag = [&](int i) { return A[diag_[f + i]]; };
    double cp_top = 0, x_top = 0, cp_bottom = 0, x_bottom = 0;  // the last row's of each chain
    const int bottom_rows = m - 1 - k;                           // k or k − 1
    for (int s = 0; s < k; ++s) {
      {  // top row i = s
        const int i = s;
        const double a = i > 0 ? lower(i) : 0.0, b = diag(i);
        const double piv = b - a * cp_top;
        if (!(std::abs(piv) > kSingularPivot * std::abs(b))) return {false, f + i, piv, "Thomas elimination"};
        const double inv = 1.0 / piv;
        cp[i] = cp_top = upper(i) * inv;
        x[i] = x_top = (x[i] - a * x_top) * inv;
      }
      if (s < bottom_rows) {  // bottom row j = m − 1 − s
        const int j = m - 1 - s;
        const double c = j + 1 < m ? upper(j) : 0.0, b = diag(j);
        const double piv = b - c * cp_bottom;
        if (!(std::abs(piv) > kSingularPivot * std::abs(b))) return {false, f + j, piv, "Thomas elimination"};
        const double inv = 1.0 / piv;
        cp[j] = cp_bottom = lower(j) * inv;
        x[j] = x_bottom = (x[j] - c * x_bottom) * inv;
      }
    }
    // The middle row k with T(k−1) = x_top − cp_top T(k) and T(k+1) = x_bottom − cp_bottom T(k).
    const double a = k > 0 ? lower(k) : 0.0, c = k + 1 < m ? upper(k) : 0.0, b = diag(k);
    const double piv = b - a * cp_top - c * cp_bottom;
    if (!(std::abs(piv) > kSingularPivot * std::abs(b))) return {false, f + k, piv, "Thomas elimination"};
    x[k] = (x[k] - a * x_top - c * x_bottom) / piv;
    for (int s = 1; s <= k; ++s) {
      x[k - s] -= cp[k - s] * x[k - s + 1];
      if (s <= bottom_rows) x[k + s] -= cp[k + s] * x[k + s - 1];
    }
    return {};
  }

  /// Cyclic tridiagonal block by Sherman–Morrison: A = B + u vᵀ with u = (γ, 0, …, 0, α),
  /// v = (1, 0, …, 0, β/γ), α = A(last, first), β = A(first, last), γ = −A(0, 0).
  SolveStatus cyclic(const double* A, double* r, const ArcBlock& arc, int slot_lo, int slot_up) {
    const int f = arc.first_unknown, m = arc.num_links;
    const double alpha = A[slot_lo], beta = A[slot_up];
    const double gamma = -A[diag_[f]];
    if (!(std::abs(gamma) > 0)) return {false, f, A[diag_[f]], "cyclic elimination"};
    for (int i = 0; i < m; ++i) bb_[static_cast<std::size_t>(i)] = A[diag_[f + i]];
    bb_[0] -= gamma;
    bb_[static_cast<std::size_t>(m - 1)] -= alpha * beta / gamma;
    std::fill(z_.begin(), z_.begin() + m, 0.0);
    z_[0] = gamma;
    z_[static_cast<std::size_t>(m - 1)] = alpha;
    SolveStatus status = thomas(A, r, f, m, bb_.data(), z_.data());
    if (!status.ok) return status;
    const double denom = 1.0 + z_[0] + beta * z_[static_cast<std::size_t>(m - 1)] / gamma;
    const double factor_scale = 1.0 + std::abs(z_[0]) + std::abs(beta * z_[static_cast<std::size_t>(m - 1)] / gamma);
    if (!(std::abs(denom) > kSingularPivot * factor_scale))
      return {false, f + m - 1, denom, "Sherman-Morrison correction of the closed arc"};
    const double fact = (r[f] + beta * r[f + m - 1] / gamma) / denom;
    for (int i = 0; i < m; ++i) r[f + i] -= fact * z_[static_cast<std::size_t>(i)];
    return {};
  }

  std::vector<ArcBlock> arcs_;
  // the system's slots (ArcSlots): A(u, u), A(u, u+1) and A(u+1, u)
  const int* diag_ = nullptr;
  const int* upper_ = nullptr;
  const int* lower_of_prev_ = nullptr;
  std::vector<int> corner_lo_, corner_up_;
  std::vector<double> cp_, z_, bb_;
};

// ----------------------------------------------------------------------------------------------
// Eigen SparseLU: analyzePattern once, factorize every call.
class EigenBackend final : public TensionBackend {
 public:
  std::string name() const override { return "eigen"; }

  void analyze(const SparsePattern& pattern, const std::vector<ArcBlock>&, const ArcSlots&) override {
    std::vector<Eigen::Triplet<double>> triplets;
    for (int c = 0; c < pattern.n; ++c)
      for (int k = pattern.col_ptr[c]; k < pattern.col_ptr[c + 1]; ++k)
        triplets.emplace_back(pattern.row_index[k], c, 1.0);
    matrix_.resize(pattern.n, pattern.n);
    matrix_.setFromTriplets(triplets.begin(), triplets.end());
    matrix_.makeCompressed();
    CHAINSIM_VERIFY(matrix_.nonZeros() == pattern.nnz() &&
                        std::equal(pattern.row_index.begin(), pattern.row_index.end(), matrix_.innerIndexPtr()),
                    "Eigen's compressed storage differs from the tension pattern");
    lu_.analyzePattern(matrix_);
    x_.resize(pattern.n);
  }

  SolveStatus factor_solve(const double* values, double* rhs) override {
    std::copy(values, values + matrix_.nonZeros(), matrix_.valuePtr());
    lu_.factorize(matrix_);
    if (lu_.info() != Eigen::Success) {
      SolveStatus s{false, -1, 0.0, "Eigen SparseLU: " + lu_.lastErrorMessage()};
      return s;
    }
    Eigen::Map<Eigen::VectorXd> b(rhs, matrix_.rows());
    x_ = lu_.solve(b);
    b = x_;
    return {};
  }

 private:
  Eigen::SparseMatrix<double> matrix_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_;
  Eigen::VectorXd x_;
};

#ifdef CHAINSIM_WITH_KLU
// ----------------------------------------------------------------------------------------------
// SuiteSparse KLU through SparseFactorization (klu_refactor between calls).
class KluBackend final : public TensionBackend {
 public:
  std::string name() const override { return "klu"; }
  void analyze(const SparsePattern& pattern, const std::vector<ArcBlock>&, const ArcSlots&) override {
    lu_.analyze(pattern);
  }
  SolveStatus factor_solve(const double* values, double* rhs) override {
    SolveStatus s = lu_.factor(values);
    if (s.ok) lu_.solve(rhs);
    return s;
  }

 private:
  SparseFactorization lu_;
};
#endif

}  // namespace

// ------------------------------------------------------------------------------------------------
#ifdef CHAINSIM_WITH_KLU
struct SparseFactorization::Impl {
  Impl() { klu_defaults(&common); }
  ~Impl() { release(); }
  klu_common common{};
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  int n = 0;
  std::vector<int> ap, ai;

  bool well_conditioned() {
    if (common.status != KLU_OK) return false;
    if (!klu_rcond(symbolic, numeric, &common)) return false;
    return common.rcond > kSingularPivot;
  }
  SolveStatus singular_status() {
    SolveStatus s{false, -1, 0.0, fmt::format("KLU (status {}, rcond {:.3g})", common.status, common.rcond)};
    if (numeric && numeric->Udiag) {
      // Smallest |U(k,k)|; column k of the permuted matrix is column Q[k] of A.
      const auto* udiag = static_cast<const double*>(numeric->Udiag);
      int worst = 0;
      for (int k = 1; k < n; ++k)
        if (std::abs(udiag[k]) < std::abs(udiag[worst])) worst = k;
      s.unknown = symbolic->Q ? symbolic->Q[worst] : worst;
      s.pivot = udiag[worst];
    } else if (common.singular_col >= 0 && common.singular_col < n) {
      s.unknown = static_cast<int>(common.singular_col);
    }
    if (numeric) klu_free_numeric(&numeric, &common);
    return s;
  }
  void release() {
    if (numeric) klu_free_numeric(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
};

void SparseFactorization::analyze(const SparsePattern& pattern) {
  Impl& d = *impl_;
  d.release();
  d.n = pattern.n;
  d.ap = pattern.col_ptr;
  d.ai = pattern.row_index;
  d.symbolic = klu_analyze(d.n, d.ap.data(), d.ai.data(), &d.common);
  if (!d.symbolic) throw Error(fmt::format("internal error: klu_analyze failed (status {})", d.common.status));
}

bool SparseFactorization::analyzed() const { return impl_->symbolic != nullptr; }

SolveStatus SparseFactorization::factor(const double* values) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(d.symbolic, "analyze() comes before factor()");
  auto* ax = const_cast<double*>(values);  // KLU's C interface is not const-correct; it does not write Ax
  bool ok = false;
  if (d.numeric) {
    ok = klu_refactor(d.ap.data(), d.ai.data(), ax, d.symbolic, d.numeric, &d.common) && d.well_conditioned();
    if (!ok) klu_free_numeric(&d.numeric, &d.common);
  }
  if (!d.numeric) {
    d.numeric = klu_factor(d.ap.data(), d.ai.data(), ax, d.symbolic, &d.common);
    ok = d.numeric != nullptr && d.well_conditioned();
  }
  return ok ? SolveStatus{} : d.singular_status();
}

void SparseFactorization::solve(double* rhs) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(d.numeric, "factor() comes before solve()");
  if (!klu_solve(d.symbolic, d.numeric, d.n, 1, rhs, &d.common))
    throw Error(fmt::format("internal error: klu_solve failed (status {})", d.common.status));
}
#else
struct SparseFactorization::Impl {
  Eigen::SparseMatrix<double> matrix;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  Eigen::VectorXd x;
  bool analyzed = false, factored = false;
};

void SparseFactorization::analyze(const SparsePattern& pattern) {
  Impl& d = *impl_;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int c = 0; c < pattern.n; ++c)
    for (int k = pattern.col_ptr[c]; k < pattern.col_ptr[c + 1]; ++k) triplets.emplace_back(pattern.row_index[k], c, 1.0);
  d.matrix.resize(pattern.n, pattern.n);
  d.matrix.setFromTriplets(triplets.begin(), triplets.end());
  d.matrix.makeCompressed();
  d.lu.analyzePattern(d.matrix);
  d.analyzed = true;
  d.factored = false;
}

bool SparseFactorization::analyzed() const { return impl_->analyzed; }

SolveStatus SparseFactorization::factor(const double* values) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(d.analyzed, "analyze() comes before factor()");
  std::copy(values, values + d.matrix.nonZeros(), d.matrix.valuePtr());
  d.lu.factorize(d.matrix);
  d.factored = d.lu.info() == Eigen::Success;
  return d.factored ? SolveStatus{} : SolveStatus{false, -1, 0.0, "Eigen SparseLU: " + d.lu.lastErrorMessage()};
}

void SparseFactorization::solve(double* rhs) {
  Impl& d = *impl_;
  CHAINSIM_VERIFY(d.factored, "factor() comes before solve()");
  Eigen::Map<Eigen::VectorXd> b(rhs, d.matrix.rows());
  d.x = d.lu.solve(b);
  b = d.x;
}
#endif

SparseFactorization::SparseFactorization() : impl_(std::make_unique<Impl>()) {}
SparseFactorization::~SparseFactorization() = default;

int SparsePattern::find(int row, int col) const {
  if (col < 0 || col >= n) return -1;
  auto begin = row_index.begin() + col_ptr[col], end = row_index.begin() + col_ptr[col + 1];
  auto it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int>(it - row_index.begin()) : -1;
}

std::vector<std::string> tension_backend_names() {
#ifdef CHAINSIM_WITH_KLU
  return {"tridiagonal", "klu", "eigen"};
#else
  return {"tridiagonal", "eigen"};
#endif
}

std::unique_ptr<TensionBackend> make_tension_backend(const std::string& name) {
  if (name == "tridiagonal") return std::make_unique<TridiagonalBackend>();
  if (name == "eigen") return std::make_unique<EigenBackend>();
#ifdef CHAINSIM_WITH_KLU
  if (name == "klu") return std::make_unique<KluBackend>();
#else
  if (name == "klu")
    throw InputError("backend = \"klu\" is not available: chainsim was built with CHAINSIM_WITH_KLU=OFF; "
                     "use \"tridiagonal\" or \"eigen\"");
#endif
  std::string list;
  for (const auto& b : tension_backend_names()) list += (list.empty() ? "" : ", ") + b;
  throw InputError(fmt::format("backend = \"{}\" is not a tension solver: allowed auto, {}", name, list));
}

TensionSystem::TensionSystem(const std::vector<int>& arc_links, const std::vector<bool>& arc_closed,
                             const std::string& backend) {
  CHAINSIM_VERIFY(arc_links.size() == arc_closed.size() && !arc_links.empty(), "one closed flag per arc");
  // 1. Unknowns: one contiguous block of link tensions per arc.
  int n = 0;
  for (std::size_t k = 0; k < arc_links.size(); ++k) {
    CHAINSIM_VERIFY(arc_links[k] >= 1 && (!arc_closed[k] || arc_links[k] >= 3), "arc too short");
    arcs_.push_back(ArcBlock{n, arc_links[k], arc_closed[k]});
    n += arc_links[k];
  }
  // 2. Pattern: tridiagonal (cyclic) blocks, column by column in the order of the unknowns, each
  //    column's rows sorted and unique (compressed columns). Built directly, in O(n): the system is
  //    built again at every front crossing, and sorting the (row, column) pairs took a tenth of the
  //    folded compare's instructions on 800 nodes.
  pattern_.n = n;
  pattern_.col_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
  pattern_.row_index.clear();
  std::size_t nnz = 0;
  for (const ArcBlock& arc : arcs_) nnz += static_cast<std::size_t>(3 * arc.num_links - 2 + (arc.closed ? 2 : 0));
  pattern_.row_index.reserve(nnz);  // exactly: not grown by doubling (up to 4 bytes per entry spare)
  // 3. Slots of the arc entries, so the model writes values without searching: each entry's position
  //    as it is written, A(u, u) = diag, A(u, next) = next_slot, A(next, u) = prev_slot_of_next.
  diag_slot_.assign(n, -1);
  next_slot_.assign(n, -1);
  prev_slot_of_next_.assign(n, -1);
  for (const ArcBlock& arc : arcs_) {
    const int f = arc.first_unknown, m = arc.num_links;
    // The link after link u of the arc (−1: none), as the slots are defined.
    const auto next_of = [&](int u) { return u + 1 < f + m ? u + 1 : (arc.closed ? f : -1); };
    for (int i = 0; i < m; ++i) {
      const int c = f + i;
      int rows[5];
      int k = 0;
      if (i > 0) rows[k++] = c - 1;          // (c - 1, c): the coupling with the link before
      rows[k++] = c;                         // the diagonal
      if (i + 1 < m) rows[k++] = c + 1;      // (c + 1, c): the coupling with the link after
      if (arc.closed && i == 0) rows[k++] = f + m - 1;  // a closed arc's last link before its first
      if (arc.closed && i + 1 == m) rows[k++] = f;      // and its first after its last
      // (An open arc's rows c − 1, c, c + 1 are sorted and unique as written: the sort only for a closed one.)
      if (arc.closed) std::sort(rows, rows + k);
      const int unique = arc.closed ? static_cast<int>(std::unique(rows, rows + k) - rows) : k;
      for (int q = 0; q < unique; ++q) {
        const int r = rows[q], slot = static_cast<int>(pattern_.row_index.size());
        if (r == c) diag_slot_[c] = slot;
        if (next_of(r) == c && r != c) next_slot_[r] = slot;           // A(r, next of r)
        if (next_of(c) == r && r != c) prev_slot_of_next_[c] = slot;   // A(next of c, c)
        pattern_.row_index.push_back(r);  // (reserved: a store, where insert() called memmove per column)
      }
      pattern_.col_ptr[static_cast<std::size_t>(c) + 1] = static_cast<int>(pattern_.row_index.size());
    }
  }
  CHAINSIM_VERIFY(pattern_.row_index.size() == nnz, "the tension system's pattern has its entries");
  values_.assign(pattern_.row_index.size(), 0.0);
  rhs_ = Eigen::VectorXd::Zero(n);
  solution_ = Eigen::VectorXd::Zero(n);

  // 4. Backend: symbolic analysis once.
  backend_name_ = backend == "auto" ? "tridiagonal" : backend;
  backend_ = make_tension_backend(backend_name_);
  backend_->analyze(pattern_, arcs_, ArcSlots{&diag_slot_, &next_slot_, &prev_slot_of_next_});
}

void TensionSystem::link_neighbours() {
  const int n = size();
  next_.assign(static_cast<std::size_t>(n), -1);
  prev_.assign(static_cast<std::size_t>(n), -1);
  for (const ArcBlock& arc : arcs_) {
    const int f = arc.first_unknown, m = arc.num_links;
    for (int i = 0; i < m; ++i) {
      if (i + 1 == m && !arc.closed) break;
      const int next = i + 1 < m ? f + i + 1 : f;
      next_[static_cast<std::size_t>(f + i)] = next;
      prev_[static_cast<std::size_t>(next)] = f + i;
    }
  }
}

TensionSystem::~TensionSystem() = default;

void TensionSystem::zero() {
  std::fill(values_.begin(), values_.end(), 0.0);
  rhs_.setZero();
  if (num_excluded_ > 0) {
    std::fill(excluded_.begin(), excluded_.end(), 0);
    num_excluded_ = 0;
  }
}

void TensionSystem::exclude(int u) {
  if (excluded_.empty()) excluded_.assign(static_cast<std::size_t>(size()), 0);
  if (prev_.empty()) link_neighbours();
  if (!excluded_[static_cast<std::size_t>(u)]) {
    excluded_[static_cast<std::size_t>(u)] = 1;
    ++num_excluded_;
  }
  rhs_[u] = 0;
  if (next_slot_[u] >= 0) set_coupling(u, 0.0);
  const int p = prev_[static_cast<std::size_t>(u)];
  if (p >= 0 && next_slot_[p] >= 0) set_coupling(p, 0.0);
}

double TensionSystem::complementarity_residual(int u, const std::vector<double>& values, const Eigen::VectorXd& rhs,
                                               const Eigen::VectorXd& T) const {
  // Row u of A: its diagonal, its coupling with the next unknown, and the previous unknown's with it.
  double AT = values[static_cast<std::size_t>(diag_slot_[u])] * T[u];
  const int next = next_[static_cast<std::size_t>(u)];
  if (next >= 0) AT += values[static_cast<std::size_t>(next_slot_[u])] * T[next];
  const int p = prev_[static_cast<std::size_t>(u)];
  if (p >= 0 && prev_slot_of_next_[p] >= 0) AT += values[static_cast<std::size_t>(prev_slot_of_next_[p])] * T[p];
  return rhs[u] - AT;
}

void TensionSystem::complementarity_failure(double t, const std::vector<int>& violating) const {
  std::string which;
  for (std::size_t k = 0; k < violating.size() && k < 5; ++k) which += (k ? ", " : "") + describe(violating[k]);
  if (violating.size() > 5) which += fmt::format(" and {} more", violating.size() - 5);
  throw NumericalError(fmt::format("at t = {:.9g} s the complementarity problem of the slack links (T >= 0, "
                                   "acceleration of the length <= 0, one of them zero) did not settle after {} "
                                   "pivoting passes: {} still {} it",
                                   t, max_passes(size()), which, violating.size() == 1 ? "violates" : "violate"),
                       t);
}

int TensionSystem::slot(int row, int col) const {
  const int s = pattern_.find(row, col);
  CHAINSIM_VERIFY(s >= 0, fmt::format("entry ({}, {}) was not declared in the tension pattern", row, col));
  return s;
}

const Eigen::VectorXd& TensionSystem::solve(double t) {
  ++solves_;
  solution_ = rhs_;
  const SolveStatus status = backend_->factor_solve(values_.data(), solution_.data());
  if (num_excluded_ > 0 && status.ok)
    for (int u = 0; u < size(); ++u)
      if (excluded_[static_cast<std::size_t>(u)]) solution_[u] = 0;  // exact, also on a closed arc
  if (!status.ok)
    throw NumericalError(fmt::format("the tension system is singular at t = {:.9g} s: {} has pivot {:.3g} ({}); "
                                     "the string cannot move as its constraints require (taut between "
                                     "prescribed points, or folded onto itself)",
                                     t, status.unknown >= 0 ? describe(status.unknown) : "an unknown", status.pivot,
                                     status.detail),
                         t);
  if (!solution_.allFinite()) {
    int bad = 0;
    while (bad < solution_.size() && std::isfinite(solution_[bad])) ++bad;
    throw NumericalError(fmt::format("the tension solve returned a non-finite value at t = {:.9g} s for {}", t,
                                     describe(bad)),
                         t);
  }
  return solution_;
}

std::string TensionSystem::describe(int unknown) const {
  for (std::size_t k = 0; k < arcs_.size(); ++k) {
    const ArcBlock& a = arcs_[k];
    if (unknown >= a.first_unknown && unknown < a.first_unknown + a.num_links)
      return fmt::format("link {} of arc {}", unknown - a.first_unknown, k);
  }
  return fmt::format("unknown {}", unknown);
}

}  // namespace chainsim
