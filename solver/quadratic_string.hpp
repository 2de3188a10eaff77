#pragma once
/// @file quadratic_string.hpp
/// A fourth-order discretization of the inextensible string for smooth arcs: quadratic elements
/// (docs/string_solver.md, "Quadratic elements").
///
/// The chain's nodes are read as E elements of three nodes each: element e runs from node 2e to node
/// 2e+2 with node 2e+1 at its material midpoint, material length h_e. On [−1, 1] ∋ ξ,
///     x(s) = N_L(ξ) x_2e + N_M(ξ) x_2e+1 + N_R(ξ) x_2e+2,   N_L = ξ(ξ−1)/2, N_M = 1−ξ², N_R = ξ(ξ+1)/2.
/// Mass: consistent, M_ab = λ ∫ N_a N_b ds (λ h/30 [4 2 −1; 2 16 2; −1 2 4] per element); the weight is
/// the consistent load M g.
///
/// Inextensibility and tension. The constraint |x'|² = 1 holds at the two Gauss points of every
/// element, ξ_k = ∓1/√3, and the tension lives there: T_ek is the Lagrange multiplier of
/// c_ek = (|x'(ξ_k)|² − 1)/2. This is the mixed element "continuous quadratic positions, discontinuous
/// linear tension": the constraint ∫ (|x'|² − 1) q ds = 0 for every q linear on each element, with the
/// two-point Gauss rule, which is exact for T x'·δx' (the virtual work of a linear tension). So the
/// string's length in the scheme's own quadrature, Σ_e Σ_k (h_e/2)|x'(ξ_k)|, is exactly ℓ, and a linear
/// tension (the hanging chain's) is represented exactly. Force of the tensions on node a:
///     f_a = −Σ_ek T_ek N_a'(ξ_k) x'_ek   (N_a' = dN_a/dξ).
///
/// Equations of motion, one linear solve per right-hand side:
///     [ M  Bᵀ ] [ a ]   [ M g                                                     ]
///     [ B  0  ] [ T ] = [ −(h/2) (|v'_k|² + 2α x'_k·v'_k + β² (|x'_k|² − 1)/2)      ],
/// B_ek,a = N_a'(ξ_k) x'_ekᵀ; a prescribed node's momentum rows are replaced by a = a_path(t) (its
/// reaction is not an unknown). α = β = 1/τ_b: Baumgarte's stabilisation of c_ek, as on the links.
/// Ordered by element ([a_2e−1, a_2e, T_e−1,0, T_e−1,1] per element, node 0 first, at the place of
/// a_2e), the matrix is block
/// tridiagonal with blocks of 2·dim+2: the solve is a block Thomas algorithm (pivot blocks inverted
/// with partial pivoting), O(E).
///
/// StringModel (string_model.hpp) runs it when StringModelOptions::elements = "quadratic": the state,
/// the forces (evaluated with the masses Σ_b M_ab, so that gravity is the consistent load M g), the
/// ledgers and the outputs are the string's; the chain's links are the half-elements. What it does
/// not hold: closed strings and fronts (StringModel refuses them).
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "mesh/chain.hpp"
#include "forces.hpp"

namespace chainsim {

/// A block-tridiagonal system with K×K blocks: row block i couples to blocks i−1 (lower), i (diag),
/// i+1 (upper), the neighbours only through the W unknowns at offset O of each block (a lower block
/// is zero outside its columns O..O+W−1, an upper block outside its rows O..O+W−1; W = K: any
/// coupling). factor() eliminates forward (block Thomas), inverting each pivot block with partial
/// pivoting; solve() then costs O(number of blocks), in fixed-size Eigen products.
template <int K, int O = 0, int W = K>
class BlockTridiagonal {
 public:
  using Block = Eigen::Matrix<double, K, K>;
  using Column = Eigen::Matrix<double, K, 1>;
  void resize(int blocks);
  int blocks() const { return static_cast<int>(diag.size()); }
  void set_zero();
  /// Factors the current blocks (overwrites diag with the inverses of the pivot blocks).
  void factor();
  /// A pivot block of the last factor() was singular.
  bool singular() const { return singular_; }
  /// Solves in place: rhs holds blocks() columns of K values.
  void solve(std::vector<Column>& rhs) const;

  std::vector<Block> lower, diag, upper;

 private:
  std::vector<Block> y_;  // (pivot block i)⁻¹ upper_i
  bool singular_ = false;
};

template <int dim>
class QuadraticString {
 public:
  static constexpr int kBlock = 2 * dim + 2;

  /// The elements of `chain` (open, an odd number of nodes, each odd node at the material midpoint of
  /// its neighbours) with the listed nodes prescribed. Throws InputError.
  QuadraticString(const Chain<dim>& chain, const std::vector<PrescribedNode<dim>>& prescribed);

  int num_elements() const { return num_elements_; }
  /// Σ_b M_ab per node (kg): the consistent load of a uniform acceleration (the weight M g), the
  /// momentum 1ᵀ M v and the mass of the string (Σ = λ ℓ).
  const Eigen::VectorXd& mass_rows() const { return mass_row_; }

  /// Accelerations and Gauss-point tensions at all-node x, v, under the applied forces load + load2
  /// (N per node; the free nodes' are used), with the accelerations `prescribed_a` at the prescribed
  /// nodes, and Baumgarte's coefficients α and β² (one block-tridiagonal solve).
  void evaluate(const Points<dim>& x, const Points<dim>& v, const Points<dim>& load, const Points<dim>& load2,
                const Points<dim>& prescribed_a, double alpha, double beta2);
  const Points<dim>& accelerations() const { return a_; }
  /// The tensions' force on every node, f_a = −Σ_ek T_ek N_a'(ξ_k) x'_ek (N), and M a (N), of the last
  /// evaluation: a support's reaction is M a − F − f at its node.
  const Points<dim>& tension_forces() const { return tension_force_; }
  const Points<dim>& inertia() const { return inertia_; }
  /// T_ek (N) of the last evaluation, element-major: index 2e + k.
  const Eigen::VectorXd& tensions() const { return tension_; }
  /// The element's linear tension at the midpoints of its two half-elements (ξ = ∓½): the tension of
  /// "link" 2e + k, the chain's links being the half-elements (N).
  Eigen::VectorXd link_tensions() const;
  /// Material coordinate of Gauss point k of element e (m).
  double gauss_coordinate(int e, int k) const;

  /// Projects x onto the Gauss-point constraints (Newton: the smallest M-weighted correction, until
  /// max |c| is at the round-off of the coordinates) and then v onto their tangent space; prescribed
  /// nodes are kept. Throws NumericalError if Newton does not converge.
  void project(double t, Points<dim>& x, Points<dim>& v);
  /// ½ vᵀ M v (J).
  double kinetic_energy(const Points<dim>& v) const;
  /// max over Gauss points of | |x'| − 1 | (relative length error) and of |x'·v'| (1/s).
  double max_constraint_violation(const Points<dim>& x) const;
  double max_rate_violation(const Points<dim>& x, const Points<dim>& v) const;
  /// x(s) on the quadratic interpolant, s in [0, ℓ].
  Vec<dim> position_at(const Points<dim>& x, double s) const;
  long solves() const { return solves_; }

  // --- Newton systems of implicit methods -----------------------------------------------------
  /// Keeps the linearisation at the last evaluate() (its x', v', a' and T at the Gauss points, α, β²).
  void linearize(const Points<dim>& x, const Points<dim>& v, double alpha, double beta2);
  /// Factors the Newton system of a stage, (I − γ J) z = r, as the saddle-point system in (z_v, γ δT)
  ///     [ M + γ² K_T           Bᵀ ] [ z_v  ]   [ M r_v − γ K_T r_x    ]
  ///     [ B − γ² C_x − γ C_v   0  ] [ γ δT ] = [ B r_v + γ C_x r_x    ],   z_x = r_x + γ z_v,
  /// K_T = Σ_ek T_ek N_a' N_b' (2/h) I (the tensions' stiffness), C_x, C_v the derivatives of the
  /// constraint rows' right-hand side less (δB) a: the same block-tridiagonal structure, O(N).
  void newton_factor(double gamma);
  /// z_v of the factored Newton system for r_x, r_v (all nodes; the prescribed ones' are ignored).
  void newton_solve(const Points<dim>& rx, const Points<dim>& rv, Points<dim>& zv);
  /// γ of the last newton_factor().
  double newton_gamma() const { return gamma_; }

 private:
  /// Neighbouring elements share one node, the last of a block (offset dim): the coupling window.
  using Blocks = BlockTridiagonal<kBlock, dim, dim>;
  using Column = typename Blocks::Column;
  /// The saddle-point matrix at x (mass, constraint gradients, prescribed rows) into blocks_, factored;
  /// with γ > 0, the Newton system's into newton_ (newton_factor, at the linearisation's state).
  void assemble_and_factor(const Points<dim>& x, double gamma = 0);
  /// Block and offset of node a's rows / columns.
  int block_of_node(int a) const { return (a + 1) / 2; }
  int offset_of_node(int a) const { return a % 2 == 1 ? 0 : dim; }
  /// x' (per unit s) at Gauss point k of element e.
  Vec<dim> derivative(const Points<dim>& x, int e, int k) const;
  /// Solves [M Bᵀ; B 0] [d; μ] = [f; r] at the last factorisation (f per node, r per Gauss point), or
  /// the Newton system's.
  void solve(const Points<dim>& f, const Eigen::VectorXd& r, Points<dim>& d, Eigen::VectorXd* mu,
             bool newton = false);

  double density_ = 0;
  std::vector<double> s_;  // node coordinates
  std::vector<bool> prescribed_;
  int num_nodes_ = 0, num_elements_ = 0;
  std::vector<double> h_;
  double h_min_ = 0;
  Eigen::VectorXd mass_row_;
  Blocks blocks_, newton_;
  std::vector<Column> work_;
  Points<dim> a_, rhs_, tension_force_, inertia_;
  Eigen::VectorXd tension_, r_;
  long solves_ = 0;
  // The linearisation (Newton systems): per Gauss point 2e + k, x', and the constraint rows' extra
  // terms γ² (2α v' + β² x' + a') + γ (2 v' + 2α x') as their two vectors; T; γ.
  Points<dim> xl_, dx_lin_, cx_lin_, cv_lin_;  // xl_: the positions
  Eigen::VectorXd t_lin_;
  double gamma_ = 0;
};

}  // namespace chainsim
