// solver/nvector_kernels: every replaced operation against the SUNDIALS serial N_Vector's own.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include "solver/nvector_kernels.hpp"

using namespace chainsim;

namespace {

// Two families of vectors with equal random contents: `plain` uses the SUNDIALS serial operations,
// `fast` the Eigen kernels.
struct Vectors {
  SUNContext ctx = nullptr;
  std::vector<N_Vector> plain, fast;
  Vectors(int count, sunindextype n) {
    SUNContext_Create(nullptr, &ctx);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    N_Vector plain0 = N_VNew_Serial(n, ctx), fast0 = N_VNew_Serial(n, ctx);
    N_VEnableFusedOps_Serial(plain0, SUNTRUE);
    N_VEnableFusedOps_Serial(fast0, SUNTRUE);
    use_eigen_kernels(fast0);
    for (int k = 0; k < count; ++k) {
      plain.push_back(k == 0 ? plain0 : N_VClone(plain0));  // clones carry the operation table
      fast.push_back(k == 0 ? fast0 : N_VClone(fast0));
      for (sunindextype i = 0; i < n; ++i) N_VGetArrayPointer(plain[k])[i] = N_VGetArrayPointer(fast[k])[i] = u(rng);
    }
  }
  ~Vectors() {
    for (N_Vector v : plain) N_VDestroy(v);
    for (N_Vector v : fast) N_VDestroy(v);
    SUNContext_Free(&ctx);
  }
  double max_difference(int k) const {
    double d = 0;
    for (sunindextype i = 0; i < N_VGetLength(plain[k]); ++i)
      d = std::max(d, std::abs(N_VGetArrayPointer(plain[k])[i] - N_VGetArrayPointer(fast[k])[i]));
    return d;
  }
};

}  // namespace

TEST_CASE("Eigen N_Vector kernels agree with the SUNDIALS serial operations", "[unit][integrator]") {
  const sunindextype n = 1001;  // odd: a remainder after the vectorized part
  Vectors v(8, n);
  const double tol = 1e-14;

  SECTION("linear sum, also in place") {
    N_VLinearSum(0.3, v.plain[0], -1.7, v.plain[1], v.plain[2]);
    N_VLinearSum(0.3, v.fast[0], -1.7, v.fast[1], v.fast[2]);
    N_VLinearSum(2.0, v.plain[3], 0.5, v.plain[4], v.plain[3]);
    N_VLinearSum(2.0, v.fast[3], 0.5, v.fast[4], v.fast[3]);
    CHECK(v.max_difference(2) < tol);
    CHECK(v.max_difference(3) < tol);
  }
  SECTION("linear combination of 1 to 6 vectors, into a new vector and into the first") {
    double c[6] = {0.5, -1.25, 2.0, 0.125, -3.0, 1.0};
    for (int nvec = 1; nvec <= 6; ++nvec) {
      N_VLinearCombination(nvec, c, v.plain.data(), v.plain[7]);
      N_VLinearCombination(nvec, c, v.fast.data(), v.fast[7]);
      CHECK(v.max_difference(7) < 1e-13);
    }
    for (double c0 : {1.0, 0.75}) {
      c[0] = c0;
      N_VLinearCombination(5, c, v.plain.data(), v.plain[0]);
      N_VLinearCombination(5, c, v.fast.data(), v.fast[0]);
      CHECK(v.max_difference(0) < 1e-13);
    }
  }
  SECTION("scale-add-multi and scale") {
    double a[2] = {1.5, -0.25};
    N_Vector yp[2] = {v.plain[1], v.plain[2]}, zp[2] = {v.plain[3], v.plain[4]};
    N_Vector yf[2] = {v.fast[1], v.fast[2]}, zf[2] = {v.fast[3], v.fast[4]};
    N_VScaleAddMulti(2, a, v.plain[0], yp, zp);
    N_VScaleAddMulti(2, a, v.fast[0], yf, zf);
    CHECK(v.max_difference(3) < tol);
    CHECK(v.max_difference(4) < tol);
    N_VScale(-3.5, v.plain[5], v.plain[6]);
    N_VScale(-3.5, v.fast[5], v.fast[6]);
    CHECK(v.max_difference(6) == 0.0);
  }
  SECTION("weighted sums of squares and the WRMS norm") {
    const double plain_sum = N_VWSqrSumLocal(v.plain[0], v.plain[1]);
    CHECK(N_VWSqrSumLocal(v.fast[0], v.fast[1]) == Approx(plain_sum).epsilon(1e-13));
    CHECK(N_VWrmsNorm(v.fast[0], v.fast[1]) == Approx(N_VWrmsNorm(v.plain[0], v.plain[1])).epsilon(1e-13));
    CHECK(N_VWrmsNorm(v.fast[0], v.fast[1]) == Approx(std::sqrt(plain_sum / n)).epsilon(1e-13));
  }
  SECTION("constant, absolute value, inverse and added constant: the same values, bit for bit") {
    // ARKODE's error weights (|y|, + atol, 1/·) and Newton's zero initial correction (a constant): each
    // element is one correctly rounded operation, so the kernels must give SUNDIALS' values exactly
    // (the explicit scenes' summaries stay bit-identical).
    N_VConst(0.375, v.plain[0]);
    N_VConst(0.375, v.fast[0]);
    N_VAbs(v.plain[1], v.plain[2]);
    N_VAbs(v.fast[1], v.fast[2]);
    N_VInv(v.plain[3], v.plain[4]);
    N_VInv(v.fast[3], v.fast[4]);
    N_VAddConst(v.plain[5], 1e-7, v.plain[6]);
    N_VAddConst(v.fast[5], 1e-7, v.fast[6]);
    for (int k : {0, 2, 4, 6}) CHECK(v.max_difference(k) == 0.0);
    CHECK(v.fast[0]->ops->nvconst != v.plain[0]->ops->nvconst);  // the kernels are in the table
    CHECK(v.fast[0]->ops->nvinv != v.plain[0]->ops->nvinv);
  }
}
