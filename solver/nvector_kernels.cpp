#include "nvector_kernels.hpp"

#include <cmath>

#include <Eigen/Core>

namespace chainsim {

namespace {

using Map = Eigen::Map<Eigen::ArrayXd>;

Map array(N_Vector v) { return Map(N_VGetArrayPointer(v), N_VGetLength(v)); }

// z = a x + b y (z may be x or y)
void linear_sum(sunrealtype a, N_Vector x, sunrealtype b, N_Vector y, N_Vector z) {
  array(z) = a * array(x) + b * array(y);
}

// z = Σ_j c_j X_j (z may be X_0)
int linear_combination(int nvec, sunrealtype* c, N_Vector* X, N_Vector z) {
  Map out = array(z);
  int j = 0;
  if (X[0] == z) {
    if (c[0] != 1.0) out *= c[0];
    j = 1;
  } else if (nvec >= 2) {
    out = c[0] * array(X[0]) + c[1] * array(X[1]);
    j = 2;
  } else {
    out = c[0] * array(X[0]);
    j = 1;
  }
  // two terms per pass: one read-modify-write of z for every two vectors
  for (; j + 1 < nvec; j += 2) out += c[j] * array(X[j]) + c[j + 1] * array(X[j + 1]);
  if (j < nvec) out += c[j] * array(X[j]);
  return 0;
}

// Z_j = a_j x + Y_j
int scale_add_multi(int nvec, sunrealtype* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  const Map xs = array(x);
  for (int j = 0; j < nvec; ++j) array(Z[j]) = a[j] * xs + array(Y[j]);
  return 0;
}

sunrealtype weighted_square_sum(N_Vector x, N_Vector w) { return (array(x) * array(w)).square().sum(); }

sunrealtype wrms_norm(N_Vector x, N_Vector w) {
  return std::sqrt(weighted_square_sum(x, w) / static_cast<double>(N_VGetLength(x)));
}

void scale(sunrealtype c, N_Vector x, N_Vector z) { array(z) = c * array(x); }

// The element-wise operations of ARKODE's error weights and Newton iterations (N_VConst sets the
// zero initial correction of every Newton solve): exact in any order, so the same values as
// SUNDIALS' loops.
void constant(sunrealtype c, N_Vector z) { array(z).setConstant(c); }
void absolute(N_Vector x, N_Vector z) { array(z) = array(x).abs(); }
void inverse(N_Vector x, N_Vector z) { array(z) = array(x).inverse(); }
void add_constant(N_Vector x, sunrealtype b, N_Vector z) { array(z) = array(x) + b; }

}  // namespace

void use_eigen_kernels(N_Vector v) {
  v->ops->nvlinearsum = linear_sum;
  v->ops->nvlinearcombination = linear_combination;
  v->ops->nvscaleaddmulti = scale_add_multi;
  v->ops->nvwsqrsumlocal = weighted_square_sum;
  v->ops->nvwrmsnorm = wrms_norm;
  v->ops->nvscale = scale;
  v->ops->nvconst = constant;
  v->ops->nvabs = absolute;
  v->ops->nvinv = inverse;
  v->ops->nvaddconst = add_constant;
}

}  // namespace chainsim
