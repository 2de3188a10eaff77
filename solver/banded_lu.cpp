// A band LU on SUNDIALS' band matrix and band linear solver: see banded_lu.hpp.
#include "banded_lu.hpp"

#include <algorithm>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunmatrix/sunmatrix_band.h>

#include "mesh/errors.hpp"
#include "quadratic_string.hpp"

namespace chainsim {

namespace {
/// The block-tridiagonal factorisation of one block size.
class BlockEngine {
 public:
  virtual ~BlockEngine() = default;
  /// Allocates `blocks` block rows and points `out` at their (lower, diagonal, upper) blocks.
  virtual void resize(int blocks, std::vector<double*>& out) = 0;
  /// Zeroes, with identity rows for the places from n on.
  virtual void zero(int n) = 0;
  virtual bool factor() = 0;
  /// x = A⁻¹ b in place, x[k] the unknown at place position[k].
  virtual void solve(double* x, const std::vector<int>& position) = 0;
};

/// A solve whose residual exceeds this fraction of the right-hand side (max norms) is refined once.
constexpr double kRefine = 1e-14;

template <int K>
class FixedBlockEngine final : public BlockEngine {
  // The columns are contiguous and unpadded: the solve scatters to and gathers from them as one array.
  static_assert(sizeof(typename BlockTridiagonal<K>::Column) == K * sizeof(double), "a column is K packed doubles");

 public:
  void resize(int blocks, std::vector<double*>& out) override {
    system_.resize(blocks);
    rhs_.resize(static_cast<std::size_t>(blocks));
    out.resize(static_cast<std::size_t>(3 * blocks));
    for (std::size_t b = 0; b < static_cast<std::size_t>(blocks); ++b) {
      out[3 * b] = system_.lower[b].data();
      out[3 * b + 1] = system_.diag[b].data();
      out[3 * b + 2] = system_.upper[b].data();
    }
  }
  void zero(int n) override {
    system_.set_zero();
    const int places = K * system_.blocks();
    for (int p = n; p < places; ++p) system_.diag[static_cast<std::size_t>(p / K)](p % K, p % K) = 1.0;
  }
  bool factor() override {
    diag0_ = system_.diag;  // the matrix itself, for the residual of the refinement
    system_.factor();
    return !system_.singular();
  }
  void solve(double* x, const std::vector<int>& position) override {
    rhs_.back().setZero();  // the identity rows past n
    const std::size_t n = position.size();
    double* flat = rhs_.front().data();  // place p of the order is entry p (Column: K packed doubles)
    for (std::size_t k = 0; k < n; ++k) flat[position[k]] = x[k];
    b_ = rhs_;
    system_.solve(rhs_);
    // One step of iterative refinement when the residual is above round-off: the block elimination
    // pivots inside the pivot blocks only, and on stiff Newton matrices (γ²‖P‖ ≫ 1) its residual
    // can reach 1e-8 of ‖b‖ (test_string_jacobian.cpp asks 1e-9); a second solve with the residual,
    // computed with the blocks themselves, restores it. On the hanging chain (docs/string_solver.md,
    // "What remains of a step") this refines nearly every solve, although their normwise backward
    // error is within a few ε already; the refined solutions are what keeps the step count at 10,000
    // links near that at 100 (68 steps against 58; skipping the refinement where the componentwise
    // backward error is below 1e-14 gave 74–84, never refining 83).
    const std::size_t nb = rhs_.size();
    double b_max = 0, r_max = 0;
    for (std::size_t i = 0; i < nb; ++i) {
      b_max = std::max(b_max, b_[i].cwiseAbs().maxCoeff());
      b_[i].noalias() -= diag0_[i] * rhs_[i];
      if (i > 0) b_[i].noalias() -= system_.lower[i] * rhs_[i - 1];
      if (i + 1 < nb) b_[i].noalias() -= system_.upper[i] * rhs_[i + 1];
      r_max = std::max(r_max, b_[i].cwiseAbs().maxCoeff());
    }
    if (r_max > kRefine * b_max) {
      system_.solve(b_);
      for (std::size_t i = 0; i < nb; ++i) rhs_[i] += b_[i];
    }
    for (std::size_t k = 0; k < n; ++k) x[k] = flat[position[k]];
  }

 private:
  BlockTridiagonal<K> system_;
  std::vector<typename BlockTridiagonal<K>::Column> rhs_, b_;
  std::vector<typename BlockTridiagonal<K>::Block> diag0_;
};

/// The smallest block size that holds the band, or 0 (SUNDIALS' band LU).
int block_size_for(int lower, int upper) {
  const int width = std::max(lower, upper);
  for (int k : {6, 8, 12, 16})
    if (width <= k) return k;
  return 0;
}

std::unique_ptr<BlockEngine> make_block_engine(int k) {
  switch (k) {
    case 6: return std::make_unique<FixedBlockEngine<6>>();
    case 8: return std::make_unique<FixedBlockEngine<8>>();
    case 12: return std::make_unique<FixedBlockEngine<12>>();
    case 16: return std::make_unique<FixedBlockEngine<16>>();
    default: return nullptr;
  }
}
}  // namespace

struct BandedLU::Impl {
  std::unique_ptr<BlockEngine> blocks;  // when the band fits in blocks
  SUNContext ctx = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  N_Vector x = nullptr;  // wraps `values`: the permuted right-hand side and solution
  std::vector<double> values;
  Impl() {
    if (SUNContext_Create(nullptr, &ctx) != 0) throw Error("SUNContext_Create failed");
  }
  ~Impl() {
    release();
    SUNContext_Free(&ctx);
  }
  void release() {
    if (solver) SUNLinSolFree(solver);
    if (matrix) SUNMatDestroy(matrix);
    if (x) N_VDestroy(x);
    solver = nullptr;
    matrix = nullptr;
    x = nullptr;
  }
};

BandedLU::BandedLU() : impl_(std::make_unique<Impl>()) {}
BandedLU::~BandedLU() = default;

void BandedLU::reset(std::vector<int> position, int lower, int upper) {
  const int n = static_cast<int>(position.size());
  CHAINSIM_VERIFY(n > 0 && lower >= 0 && upper >= 0, "a band matrix has unknowns and bandwidths >= 0");
  position_ = std::move(position);
  const int k = block_size_for(lower, upper);
  if (k > 0) {
    if (k != block_ || !impl_->blocks || static_cast<int>(blocks_.size()) != 3 * ((n + k - 1) / k)) {
      impl_->release();
      impl_->blocks = make_block_engine(k);
      impl_->blocks->resize((n + k - 1) / k, blocks_);
    }
    block_ = k;
    lower_ = lower;
    upper_ = upper;
    zero();
    return;
  }
  impl_->blocks.reset();
  block_ = 0;
  if (!impl_->matrix || SUNBandMatrix_Columns(impl_->matrix) != n || lower != lower_ || upper != upper_) {
    impl_->release();
    lower_ = lower;
    upper_ = upper;
    impl_->matrix = SUNBandMatrix(n, upper, lower, impl_->ctx);  // stores upper + lower super-diagonals (pivoting)
    impl_->values.assign(static_cast<std::size_t>(n), 0.0);
    impl_->x = N_VMake_Serial(n, impl_->values.data(), impl_->ctx);
    if (!impl_->matrix || !impl_->x) throw Error("SUNBandMatrix failed");
    impl_->solver = SUNLinSol_Band(impl_->x, impl_->matrix, impl_->ctx);
    if (!impl_->solver) throw Error("SUNLinSol_Band failed");
    columns_.resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) columns_[static_cast<std::size_t>(j)] = SUNBandMatrix_Column(impl_->matrix, j);
  }
  zero();
}

void BandedLU::zero() {
  if (impl_->blocks)
    impl_->blocks->zero(size());
  else
    SUNMatZero(impl_->matrix);
}

bool BandedLU::factor() {
  if (impl_->blocks) return impl_->blocks->factor();
  return SUNLinSolSetup_Band(impl_->solver, impl_->matrix) == SUNLS_SUCCESS;
}

void BandedLU::solve(double* rhs) {
  const std::size_t n = position_.size();
  if (impl_->blocks) {
    impl_->blocks->solve(rhs, position_);
    return;
  }
  double* x = impl_->values.data();
  for (std::size_t k = 0; k < n; ++k) x[position_[k]] = rhs[k];
  SUNLinSolSolve_Band(impl_->solver, impl_->matrix, impl_->x, impl_->x, 0.0);  // in place: b = x
  for (std::size_t k = 0; k < n; ++k) rhs[k] = x[position_[k]];
}

}  // namespace chainsim
