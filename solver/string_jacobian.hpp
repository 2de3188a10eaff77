#pragma once
/// @file string_jacobian.hpp
/// The exact linearisation of the string's right-hand side and the Newton systems of implicit
/// methods, solved at O(N) cost (docs/string_solver.md, "The implicit path").
///
/// The accelerations are a = b − W Gᵀ T with the tensions from A(x) T = r(x, v) (tension_system.hpp):
/// W the inverse masses, G the constraint Jacobian (row j: −e_jᵀ at node a, +e_jᵀ at node b).
/// A variation (δx, δv) of the free nodes gives
///
///     δa = P δx − W Gᵀ w,    A w = Qx δx + Qv δv,
///
/// with P = ∂a/∂x at frozen tensions (P_v = 0), and Q = ∂r − (∂A) T. P, Qx, Qv, W Gᵀ and A are
/// sparse (a link couples its two nodes and its neighbouring links), so J = P + C A⁻¹ Q is the Schur
/// complement of a sparse matrix and the Newton system (I − γ J) z = r of a DIRK stage, with
/// z = (zx, zv), zx = rx + γ zv, becomes the sparse augmented system in (zv, w)
///
///     [ I − γ² P      γ W Gᵀ ] [zv]   [ rv + γ P rx ]
///     [ γ Qx + Qv     −A     ] [w ] = [ −Qx rx      ]
///
/// factored in O(N): by a band LU (banded_lu.hpp) with the unknowns ordered along the string — zv of
/// a node, then w of its link, … ; a closed string folded (0, n−1, 1, n−2, …) so that its last link
/// is short in the order too — where every coupling is within a few nodes: a string without a module
/// ([solver] linear_solver = "auto" or "banded"); else by KLU (klu_refactor between steps; Eigen's
/// SparseLU when built without KLU), which "klu" asks for everywhere. The ledgers (W_applied, a module's)
/// enter no right-hand side: their Newton rows are taken as identity. A module's masses and loads (a
/// front's partial link and jump conditions) enter through their derivatives
/// (StringModule::load_derivatives): with δa_k = w_k D δy at frozen tensions, D = ∂F_k + (g − a_k) ∂m_k,
/// into P, a velocity block Pv (then the first block is I − γ² P − γ Pv) and the rows of the links at k
/// in Qx and Qv. What the linearisation leaves out: velocity-dependent forces (drag), the derivative of
/// the applied forces, and a module without load derivatives: implicit methods then use the
/// linearisation as the preconditioner of GMRES, whose products J·v come from the right-hand side
/// itself, so those terms are still honoured.
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "string_module.hpp"
#include "tension_system.hpp"

namespace chainsim {

class BandedLU;
template <int dim>
class StringModel;

template <int dim>
class StringJacobian {
 public:
  explicit StringJacobian(StringModel<dim>& model);
  ~StringJacobian();
  StringJacobian(const StringJacobian&) = delete;
  StringJacobian& operator=(const StringJacobian&) = delete;

  /// Evaluates the model at (t, y) and builds P, Qx, Qv, W Gᵀ and A there.
  void linearize(double t, const Eigen::Ref<const Eigen::VectorXd>& y);
  /// J·d for the position and velocity parts of a state-sized d at the last linearisation (the ledger
  /// rows are zero). Exact for forces that depend on neither x nor v (gravity, drivers).
  Eigen::VectorXd apply(const Eigen::Ref<const Eigen::VectorXd>& d) const;
  /// The same into `out` (state-sized), with the factorisation of A made by linearize().
  void apply(const Eigen::Ref<const Eigen::VectorXd>& d, Eigen::Ref<Eigen::VectorXd> out) const;
  /// True if the model's applied forces are all state-independent (gravity, loads, drivers) and it
  /// has no module or one with load derivatives: J is then exact.
  bool exact() const { return exact_; }
  /// Factors the augmented system of I − γ J. Throws RecoverableError if it is singular.
  void factor(double gamma);
  /// z = (I − γ J)⁻¹ r (ledger components: z = r) with the γ of the last factor().
  void solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> z) const;
  /// The augmented matrix of the last factor(), dense, in the unknowns (zv, w) (for tests).
  Eigen::MatrixXd augmented_matrix() const;
  /// True if the last linearize() chose the band LU (else KLU).
  bool banded() const { return banded_; }
  /// The band LU's sub- and super-diagonals in the string's order (0 when KLU factors).
  int lower_bandwidth() const;
  int upper_bandwidth() const;

  int velocity_unknowns() const { return nv_; }
  int tension_unknowns() const { return nt_; }

 private:
  using SpMat = Eigen::SparseMatrix<double>;
  /// The linearisation's blocks, row-major: their products with a vector (every Newton solve's
  /// right-hand side) are then one gather per row.
  using BlockMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  StringModel<dim>& model_;
  int nv_ = 0, nt_ = 0;  // dim · free nodes; tension unknowns
  BlockMat P_, Qx_, Qv_, WGt_, Pv_;  // Pv = ∂a/∂v at frozen tensions: a module's loads only
  std::vector<double> a_values_;  // A, in the tension system's pattern (a_pattern_)
  SparsePattern a_pattern_;
  double gamma_ = 0;
  bool exact_ = false;
  struct Factor;
  std::unique_ptr<Factor> factor_, a_factor_;  // the augmented system (KLU); A alone (for apply)
  mutable bool a_factored_ = false;             // a_factor_ holds this linearisation's A (factored at apply())
  bool banded_ = false;
  std::unique_ptr<BandedLU> band_;              // the augmented system, banded
  /// Calls emit(row, col, value) for every entry of the augmented matrix of γ (duplicates summed).
  template <class Emit>
  void for_each_entry(double gamma, Emit&& emit) const;
  /// The string order of the augmented unknowns and its bandwidths, into band_ (linearize()).
  void order_along_string();
  std::vector<int> ordered_slots_, ordered_links_;  // the layout band_ was ordered for
  std::vector<double*> band_entries_;                // band_'s storage of each entry of for_each_entry
  /// The entries' (row, column) sequence of a block and the slot of each in its compressed values.
  struct Slots {
    std::vector<int> rows, cols, slot;
  };
  Slots slots_[5];  // P, Qx, Qv, W Gᵀ, Pv
  std::vector<LoadDerivative<dim>> load_derivatives_;  // the module's, at the last linearize()
  /// out = the (rows × cols) matrix of `entries` (duplicates summed): only the values when the
  /// sequence of (row, column) is that of the last call, else the pattern anew (returns true).
  static bool assemble(BlockMat& out, int rows, int cols, const std::vector<Eigen::Triplet<double>>& entries, Slots& s);
  std::vector<Eigen::Triplet<double>> entries_;  // the augmented system's assembly (kept: no reallocation)
  mutable Eigen::VectorXd work_;                 // the augmented right-hand side and solution of solve()
};

}  // namespace chainsim
