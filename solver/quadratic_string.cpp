#include "quadratic_string.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim {

namespace {
/// The two Gauss points on [−1, 1].
const double kGauss[2] = {-1.0 / std::sqrt(3.0), 1.0 / std::sqrt(3.0)};
/// dN_a/dξ at ξ for a = L, M, R.
inline double shape_derivative(int a, double xi) { return a == 0 ? xi - 0.5 : (a == 1 ? -2.0 * xi : xi + 0.5); }
/// Consistent mass of an element of unit λh: ∫ N_a N_b ds / h.
const double kMass[3][3] = {{4.0 / 30, 2.0 / 30, -1.0 / 30}, {2.0 / 30, 16.0 / 30, 2.0 / 30}, {-1.0 / 30, 2.0 / 30, 4.0 / 30}};
const char* const kSingularMessage =
    "the quadratic elements' tension system is singular: the string cannot move as its constraints require (taut "
    "between prescribed points, folded onto itself, or a Gauss point with x' = 0)";
/// Newton iterations of the projection.
constexpr int kMaxProjection = 60;
/// Round-off of the coordinates, in ulps of max |x| / h_min (as StringModel's projection).
constexpr double kRoundoffUlps = 64;
}  // namespace

// --- BlockTridiagonal ---------------------------------------------------------------------------

template <int K, int O, int W>
void BlockTridiagonal<K, O, W>::resize(int blocks) {
  const auto n = static_cast<std::size_t>(blocks);
  lower.resize(n);
  diag.resize(n);
  upper.resize(n);
  y_.resize(n);
}

template <int K, int O, int W>
void BlockTridiagonal<K, O, W>::set_zero() {
  for (std::size_t i = 0; i < diag.size(); ++i) {
    lower[i].setZero();
    diag[i].setZero();
    upper[i].setZero();
  }
}

namespace {
/// Inverts a small fixed-size matrix in place by Gauss–Jordan elimination with partial pivoting, after
/// scaling its rows and then its columns to a largest entry of 1 (the blocks mix masses, kg, with
/// constraint gradients, 1). Eigen's LU of a 6×6 or 8×8 block goes through its general (blocked,
/// dynamic-size) triangular kernels, which cost several times the arithmetic at this size; these
/// loops unroll. Returns false for a singular block: a zero or non-finite pivot, or an inverse of the
/// scaled block beyond 1/kSingularBlock (its condition number, to a factor of K).
constexpr double kSingularBlock = 1e-13;
template <int K>
bool invert_in_place(Eigen::Matrix<double, K, K>& A) {
  Eigen::Matrix<double, K, 1> row_scale, col_scale;
  for (int i = 0; i < K; ++i) {
    const double m = A.row(i).cwiseAbs().maxCoeff();
    if (!(m > 0) || !std::isfinite(m)) return false;
    row_scale[i] = 1.0 / m;
  }
  A = row_scale.asDiagonal() * A;
  for (int j = 0; j < K; ++j) col_scale[j] = 1.0 / A.col(j).cwiseAbs().maxCoeff();
  A = A * col_scale.asDiagonal();
  int perm[K];
  for (int i = 0; i < K; ++i) perm[i] = i;
  for (int c = 0; c < K; ++c) {
    int p = c;
    for (int r = c + 1; r < K; ++r)
      if (std::abs(A(r, c)) > std::abs(A(p, c))) p = r;
    if (!(std::abs(A(p, c)) > 0) || !std::isfinite(A(p, c))) return false;
    if (p != c) {
      A.row(p).swap(A.row(c));
      std::swap(perm[p], perm[c]);
    }
    const double inv = 1.0 / A(c, c);
    A(c, c) = 1.0;
    A.row(c) *= inv;
    for (int r = 0; r < K; ++r) {
      if (r == c) continue;
      const double f = A(r, c);
      if (f == 0) continue;
      A(r, c) = 0.0;
      A.row(r) -= f * A.row(c);
    }
  }
  if (!(A.cwiseAbs().maxCoeff() < 1.0 / kSingularBlock)) return false;
  // The rows were exchanged: the inverse has its columns exchanged back; then the scalings undone,
  // A⁻¹ = C (R A C)⁻¹ R.
  Eigen::Matrix<double, K, K> out;
  for (int i = 0; i < K; ++i) out.col(perm[i]) = A.col(i);
  A = col_scale.asDiagonal() * out * row_scale.asDiagonal();
  return true;
}
}  // namespace

template <int K, int O, int W>
void BlockTridiagonal<K, O, W>::factor() {
  const std::size_t n = diag.size();
  singular_ = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) diag[i].noalias() -= lower[i].template middleCols<W>(O) * y_[i - 1].template middleRows<W>(O);
    if (!invert_in_place<K>(diag[i])) singular_ = true;  // diag[i] holds the pivot block's inverse
    if (i + 1 < n) y_[i].noalias() = diag[i].template middleCols<W>(O) * upper[i].template middleRows<W>(O);
  }
}

template <int K, int O, int W>
void BlockTridiagonal<K, O, W>::solve(std::vector<Column>& rhs) const {
  const std::size_t n = diag.size();
  Column z;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) rhs[i].noalias() -= lower[i].template middleCols<W>(O) * rhs[i - 1].template segment<W>(O);
    z.noalias() = diag[i] * rhs[i];
    rhs[i] = z;
  }
  for (std::size_t i = n - 1; i-- > 0;) rhs[i].noalias() -= y_[i] * rhs[i + 1];
}

template class BlockTridiagonal<6>;
template class BlockTridiagonal<8>;  // 8, 12, 16: the links' Newton systems (banded_lu.hpp)
template class BlockTridiagonal<12>;
template class BlockTridiagonal<16>;
template class BlockTridiagonal<6, 2, 2>;
template class BlockTridiagonal<8, 3, 3>;

// --- QuadraticString ----------------------------------------------------------------------------

template <int dim>
QuadraticString<dim>::QuadraticString(const Chain<dim>& chain, const std::vector<PrescribedNode<dim>>& prescribed)
    : density_(chain.density()), num_nodes_(chain.num_nodes()) {
  const int n = num_nodes_;
  if (chain.closed())
    throw InputError("string.elements = \"quadratic\" holds open strings only: this string is closed "
                     "(use elements = \"links\")");
  if (n < 3 || n % 2 == 0)
    throw InputError(fmt::format("string.nodes = {} does not make quadratic elements: allowed an odd number >= 3 "
                                 "(two nodes per element, plus one)", n));
  num_elements_ = (n - 1) / 2;
  for (int a = 0; a < n; ++a) s_.push_back(chain.node_coordinate(a));
  h_.resize(static_cast<std::size_t>(num_elements_));
  h_min_ = std::numeric_limits<double>::infinity();
  for (int e = 0; e < num_elements_; ++e) {
    const double s0 = s_[2 * e], s1 = s_[2 * e + 1], s2 = s_[2 * e + 2];
    if (std::abs(s1 - 0.5 * (s0 + s2)) > 1e-12 * chain.length())
      throw InputError(fmt::format("quadratic element {} has its middle node {} at s = {:g} m, not at its midpoint "
                                   "{:g} m: its two links must be equally long",
                                   e, 2 * e + 1, s1, 0.5 * (s0 + s2)));
    h_[static_cast<std::size_t>(e)] = s2 - s0;
    h_min_ = std::min(h_min_, s2 - s0);
  }
  prescribed_.assign(static_cast<std::size_t>(n), false);
  for (const auto& p : prescribed) prescribed_[static_cast<std::size_t>(p.node)] = true;
  mass_row_ = Eigen::VectorXd::Zero(n);
  for (int e = 0; e < num_elements_; ++e)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) mass_row_[2 * e + a] += density_ * h_[static_cast<std::size_t>(e)] * kMass[a][b];
  blocks_.resize(num_elements_ + 1);
  newton_.resize(num_elements_ + 1);
  work_.resize(static_cast<std::size_t>(num_elements_ + 1));
  for (Points<dim>* p : {&a_, &rhs_, &tension_force_, &inertia_}) *p = Points<dim>::Zero(dim, n);
  tension_ = Eigen::VectorXd::Zero(2 * num_elements_);
  r_ = Eigen::VectorXd::Zero(2 * num_elements_);
}

template <int dim>
Vec<dim> QuadraticString<dim>::derivative(const Points<dim>& x, int e, int k) const {
  Vec<dim> d = Vec<dim>::Zero();
  for (int a = 0; a < 3; ++a) d += shape_derivative(a, kGauss[k]) * x.col(2 * e + a);
  return d * (2.0 / h_[static_cast<std::size_t>(e)]);
}

template <int dim>
double QuadraticString<dim>::gauss_coordinate(int e, int k) const {
  return s_[2 * e] + 0.5 * (1.0 + kGauss[k]) * h_[static_cast<std::size_t>(e)];
}

template <int dim>
void QuadraticString<dim>::assemble_and_factor(const Points<dim>& x, double gamma) {
  Blocks& sys = gamma > 0 ? newton_ : blocks_;  // a Newton system is kept across right-hand sides
  sys.set_zero();
  // Entry (row block I) × (column block J), J − I ∈ {−1, 0, 1}.
  auto block = [&](int I, int J) -> typename Blocks::Block& {
    const auto i = static_cast<std::size_t>(I);
    return J == I ? sys.diag[i] : (J < I ? sys.lower[i] : sys.upper[i]);
  };
  for (int r = 0; r < kBlock; ++r)  // block 0 holds node 0 only, at offset dim
    if (r < dim || r >= 2 * dim) sys.diag[0](r, r) = 1.0;
  for (int e = 0; e < num_elements_; ++e) {
    const double h = h_[static_cast<std::size_t>(e)];
    const int tb = e + 1;  // the block of the element's tensions
    for (int k = 0; k < 2; ++k) {
      const int g = 2 * e + k;
      const Vec<dim> d = derivative(x, e, k);
      // The constraint row's vector: x' (B), plus γ² (2α v' + β² x' + a') + γ (2 v' + 2α x') in a
      // Newton system (−γ² C_x − γ C_v).
      const Vec<dim> row = gamma > 0 ? Vec<dim>(d + gamma * gamma * cx_lin_.col(g) + gamma * cv_lin_.col(g)) : d;
      for (int a = 0; a < 3; ++a) {
        const int node = 2 * e + a, nb = block_of_node(node), no = offset_of_node(node);
        const double dn = shape_derivative(a, kGauss[k]);
        // Constraint row (e, k): B_ek,a a_a;  momentum rows of a free node: + B_ek,aᵀ T_ek.
        block(tb, nb).block(2 * dim + k, no, 1, dim) += dn * row.transpose();
        if (!prescribed_[static_cast<std::size_t>(node)]) block(nb, tb).block(no, 2 * dim + k, dim, 1) += dn * d;
      }
    }
    for (int a = 0; a < 3; ++a) {
      const int na = 2 * e + a;
      if (prescribed_[static_cast<std::size_t>(na)]) continue;
      for (int b = 0; b < 3; ++b) {
        const int nb = 2 * e + b;
        double m = density_ * h * kMass[a][b];
        if (gamma > 0)  // + γ² K_T
          for (int k = 0; k < 2; ++k)
            m += gamma * gamma * t_lin_[2 * e + k] * shape_derivative(a, kGauss[k]) * shape_derivative(b, kGauss[k]) *
                 (2.0 / h);
        block(block_of_node(na), block_of_node(nb))
            .block(offset_of_node(na), offset_of_node(nb), dim, dim)
            .diagonal()
            .array() += m;
      }
    }
  }
  for (int a = 0; a < num_nodes_; ++a)
    if (prescribed_[static_cast<std::size_t>(a)])
      sys.diag[static_cast<std::size_t>(block_of_node(a))]
          .block(offset_of_node(a), offset_of_node(a), dim, dim)
          .diagonal()
          .array() += 1.0;
  sys.factor();
}

template <int dim>
void QuadraticString<dim>::solve(const Points<dim>& f, const Eigen::VectorXd& r, Points<dim>& d, Eigen::VectorXd* mu,
                                 bool newton) {
  const Blocks& sys = newton ? newton_ : blocks_;
  for (auto& w : work_) w.setZero();
  for (int a = 0; a < num_nodes_; ++a)
    work_[static_cast<std::size_t>(block_of_node(a))].template segment<dim>(offset_of_node(a)) = f.col(a);
  for (int e = 0; e < num_elements_; ++e)
    for (int k = 0; k < 2; ++k) work_[static_cast<std::size_t>(e + 1)][2 * dim + k] = r[2 * e + k];
  if (sys.singular()) throw RecoverableError(kSingularMessage);
  sys.solve(work_);
  ++solves_;
  for (int a = 0; a < num_nodes_; ++a)
    d.col(a) = work_[static_cast<std::size_t>(block_of_node(a))].template segment<dim>(offset_of_node(a));
  if (mu)
    for (int e = 0; e < num_elements_; ++e)
      for (int k = 0; k < 2; ++k) (*mu)[2 * e + k] = work_[static_cast<std::size_t>(e + 1)][2 * dim + k];
  if (!d.allFinite() || (mu && !mu->allFinite()))
    throw RecoverableError(kSingularMessage);
}

template <int dim>
void QuadraticString<dim>::evaluate(const Points<dim>& x, const Points<dim>& v, const Points<dim>& load,
                                    const Points<dim>& load2, const Points<dim>& prescribed_a, double alpha,
                                    double beta2) {
  assemble_and_factor(x);
  for (int a = 0; a < num_nodes_; ++a)
    rhs_.col(a) = prescribed_[static_cast<std::size_t>(a)] ? Vec<dim>(prescribed_a.col(a)) : Vec<dim>(load.col(a) + load2.col(a));
  for (int e = 0; e < num_elements_; ++e) {
    const double h = h_[static_cast<std::size_t>(e)];
    for (int k = 0; k < 2; ++k) {
      const Vec<dim> dx = derivative(x, e, k), dv = derivative(v, e, k);
      r_[2 * e + k] = -0.5 * h * (dv.squaredNorm() + 2 * alpha * dx.dot(dv) + 0.5 * beta2 * (dx.squaredNorm() - 1.0));
    }
  }
  solve(rhs_, r_, a_, &tension_);
  tension_force_.setZero();
  inertia_.setZero();
  for (int e = 0; e < num_elements_; ++e) {
    const double h = h_[static_cast<std::size_t>(e)];
    for (int k = 0; k < 2; ++k) {
      const Vec<dim> d = derivative(x, e, k);
      for (int a = 0; a < 3; ++a) tension_force_.col(2 * e + a) -= tension_[2 * e + k] * shape_derivative(a, kGauss[k]) * d;
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) inertia_.col(2 * e + a) += density_ * h * kMass[a][b] * a_.col(2 * e + b);
  }
}

template <int dim>
void QuadraticString<dim>::linearize(const Points<dim>& x, const Points<dim>& v, double alpha, double beta2) {
  const int ng = 2 * num_elements_;
  for (Points<dim>* p : {&dx_lin_, &cx_lin_, &cv_lin_}) p->resize(dim, ng);
  t_lin_ = tension_;
  for (int e = 0; e < num_elements_; ++e)
    for (int k = 0; k < 2; ++k) {
      const int g = 2 * e + k;
      const Vec<dim> dx = derivative(x, e, k), dv = derivative(v, e, k), da = derivative(a_, e, k);
      dx_lin_.col(g) = dx;
      cx_lin_.col(g) = 2 * alpha * dv + beta2 * dx + da;
      cv_lin_.col(g) = 2 * dv + 2 * alpha * dx;
    }
  xl_ = x;
}

template <int dim>
void QuadraticString<dim>::newton_factor(double gamma) {
  if (xl_.cols() != num_nodes_) throw RecoverableError("the quadratic elements have no linearisation yet");
  gamma_ = gamma;
  assemble_and_factor(xl_, gamma);
}

template <int dim>
void QuadraticString<dim>::newton_solve(const Points<dim>& rx, const Points<dim>& rv, Points<dim>& zv) {
  const double gamma = gamma_;
  rhs_.setZero();
  for (int e = 0; e < num_elements_; ++e) {
    const double h = h_[static_cast<std::size_t>(e)];
    for (int a = 0; a < 3; ++a) {
      const int na = 2 * e + a;
      if (prescribed_[static_cast<std::size_t>(na)]) continue;
      for (int b = 0; b < 3; ++b) {
        const int nb = 2 * e + b;
        double kt = 0;
        for (int k = 0; k < 2; ++k)
          kt += t_lin_[2 * e + k] * shape_derivative(a, kGauss[k]) * shape_derivative(b, kGauss[k]) * (2.0 / h);
        rhs_.col(na) += density_ * h * kMass[a][b] * rv.col(nb) - gamma * kt * rx.col(nb);  // M r_v − γ K_T r_x
      }
    }
    for (int k = 0; k < 2; ++k) {
      const int g = 2 * e + k;
      double rk = 0;  // B r_v + γ C_x r_x
      for (int b = 0; b < 3; ++b) {
        const int nb = 2 * e + b;
        if (prescribed_[static_cast<std::size_t>(nb)]) continue;
        rk += shape_derivative(b, kGauss[k]) * (dx_lin_.col(g).dot(rv.col(nb)) - gamma * cx_lin_.col(g).dot(rx.col(nb)));
      }
      r_[g] = rk;
    }
  }
  zv.resize(dim, num_nodes_);
  solve(rhs_, r_, zv, nullptr, true);
}

template <int dim>
Eigen::VectorXd QuadraticString<dim>::link_tensions() const {
  Eigen::VectorXd T(2 * num_elements_);
  for (int e = 0; e < num_elements_; ++e) {
    const double t0 = tension_[2 * e], t1 = tension_[2 * e + 1];
    for (int k = 0; k < 2; ++k) {
      const double xi = k == 0 ? -0.5 : 0.5;
      T[2 * e + k] = t0 + (t1 - t0) * (xi - kGauss[0]) / (kGauss[1] - kGauss[0]);
    }
  }
  return T;
}

template <int dim>
void QuadraticString<dim>::project(double t, Points<dim>& x, Points<dim>& v) {
  const Points<dim> zero = Points<dim>::Zero(dim, num_nodes_);
  Points<dim> d(dim, num_nodes_);
  const double eps = std::numeric_limits<double>::epsilon();
  const double tol = kRoundoffUlps * eps * std::max(1.0, x.cwiseAbs().maxCoeff() / h_min_);
  double worst = 0, previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    worst = 0;
    for (int e = 0; e < num_elements_; ++e)
      for (int k = 0; k < 2; ++k) {
        const double c = 0.5 * (derivative(x, e, k).squaredNorm() - 1.0);
        worst = std::max(worst, std::abs(c));
        r_[2 * e + k] = -0.5 * h_[static_cast<std::size_t>(e)] * c;
      }
    // Converged; or stalled at a few times the round-off (Newton no longer halves it).
    if (worst <= tol || (worst < 1e3 * tol && worst > 0.5 * previous)) break;
    if (it == kMaxProjection || !std::isfinite(worst))
      throw NumericalError(fmt::format("at t = {:.9g} s the quadratic elements cannot be projected onto their length: |x'|² − 1 = "
                                       "{:.3g} at a Gauss point after {} Newton steps",
                                       t,
                                       2 * worst, it),
                           t);
    previous = worst;
    assemble_and_factor(x);
    solve(zero, r_, d, nullptr);
    x += d;
  }
  assemble_and_factor(x);
  for (int e = 0; e < num_elements_; ++e)
    for (int k = 0; k < 2; ++k)
      r_[2 * e + k] = -0.5 * h_[static_cast<std::size_t>(e)] * derivative(x, e, k).dot(derivative(v, e, k));
  solve(zero, r_, d, nullptr);
  v += d;
}

template <int dim>
double QuadraticString<dim>::kinetic_energy(const Points<dim>& v) const {
  double k = 0;
  for (int e = 0; e < num_elements_; ++e)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        k += h_[static_cast<std::size_t>(e)] * kMass[a][b] * v.col(2 * e + a).dot(v.col(2 * e + b));
  return 0.5 * density_ * k;
}

template <int dim>
double QuadraticString<dim>::max_constraint_violation(const Points<dim>& x) const {
  double worst = 0;
  for (int e = 0; e < num_elements_; ++e)
    for (int k = 0; k < 2; ++k) worst = std::max(worst, std::abs(derivative(x, e, k).norm() - 1.0));
  return worst;
}

template <int dim>
double QuadraticString<dim>::max_rate_violation(const Points<dim>& x, const Points<dim>& v) const {
  double worst = 0;
  for (int e = 0; e < num_elements_; ++e)
    for (int k = 0; k < 2; ++k) worst = std::max(worst, std::abs(derivative(x, e, k).dot(derivative(v, e, k))));
  return worst;
}

template <int dim>
Vec<dim> QuadraticString<dim>::position_at(const Points<dim>& x, double s) const {
  int e = 0;
  while (e + 1 < num_elements_ && s > s_[2 * e + 2]) ++e;
  const double xi = 2 * (s - s_[2 * e]) / h_[static_cast<std::size_t>(e)] - 1;
  return 0.5 * xi * (xi - 1) * x.col(2 * e) + (1 - xi * xi) * x.col(2 * e + 1) + 0.5 * xi * (xi + 1) * x.col(2 * e + 2);
}

template class QuadraticString<2>;
template class QuadraticString<3>;

}  // namespace chainsim
