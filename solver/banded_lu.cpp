// A band LU on SUNDIALS' band matrix and band linear solver: see banded_lu.hpp.
#include "banded_lu.hpp"

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunmatrix/sunmatrix_band.h>

#include "mesh/errors.hpp"

namespace chainsim {

struct BandedLU::Impl {
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

void BandedLU::zero() { SUNMatZero(impl_->matrix); }

bool BandedLU::factor() { return SUNLinSolSetup_Band(impl_->solver, impl_->matrix) == SUNLS_SUCCESS; }

void BandedLU::solve(double* rhs) {
  const std::size_t n = position_.size();
  double* x = impl_->values.data();
  for (std::size_t k = 0; k < n; ++k) x[position_[k]] = rhs[k];
  SUNLinSolSolve_Band(impl_->solver, impl_->matrix, impl_->x, impl_->x, 0.0);  // in place: b = x
  for (std::size_t k = 0; k < n; ++k) rhs[k] = x[position_[k]];
}

}  // namespace chainsim
