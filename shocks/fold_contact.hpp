#pragma once
/// @file fold_contact.hpp
/// The tight fold: the constraint that keeps both halves of a folded link on one line.
///
/// At a fold the two arcs meet antiparallel (docs/shocks.md): the folded link (a, b) of material
/// length h is doubled over at the fold point, both halves along the fold line e. The fold line is
/// the *reference link* p → r: arc A's last link (p = a − 1, r = a) or, when arc A has no full link,
/// arc B's first link taken backwards (p = b + 1, r = b). The node across the fold, o, must lie on
/// that line:
///
///     g = q · (u × w) / h = 0,     u = x_o − x_r,   w = x_r − x_p   (|w| = h)
///
/// for q = ẑ in 2D (one row) and q ∈ {q1, q2}, an orthonormal pair normal to w, in 3D (two rows;
/// u × w has no component along w). g is bilinear in the positions, so its Jacobian and the
/// velocity term of its second time derivative are exact and cheap:
///
///     ∇_o g = (w × q)/h,   ∇_r g = (q × u − w × q)/h,   ∇_p g = −(q × u)/h,
///     g̈ = Σ ∇_i g · a_i + 2 q · (u̇ × ẇ)/h.
///
/// The gradients sum to zero and g is invariant under rotations, so the constraint force −μ ∇g
/// keeps momentum and angular momentum; it is ideal (workless). Physically it is the contact of the
/// two arms at a tight bight: it holds the folded link's nodes on the fold line when the arms leave
/// the fold in different directions (a folded chain whose ends are apart). In the paper's geometry
/// (arms on one line) g ≡ 0 and μ = 0.
///
/// The constraint adds dim − 1 unknowns μ to the tension system (solver/junction.hpp), with rows
/// written like the link rows: the matrix is −J W Jᵀ over links and fold rows together.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

#include "mesh/chain.hpp"
#include "solver/junction.hpp"

namespace chainsim {

template <int dim>
class FoldContact final : public Junction {
 public:
  static constexpr int kRows = dim - 1;
  using Rows = Eigen::Matrix<double, kRows, 1>;
  /// A link of the tension system that touches p, r or o: its unknown and its start node (it joins
  /// start and start + 1).
  struct Link {
    int unknown = 0;
    int start = 0;
  };

  /// p, r: the reference link's nodes (r next to the fold); o: the node across the fold; `links`:
  /// every link of the system touching p, r or o; h: the link length (m).
  FoldContact(int p, int r, int o, std::vector<Link> links, double h);

  // --- Junction -----------------------------------------------------------------------------
  std::string name() const override { return "fold contact"; }
  int num_unknowns() const override { return kRows; }
  void declare_entries(TensionPatternBuilder& builder) override;
  void bind(TensionSystem& system) override;
  void add_rows(double, TensionSystem&) const override {}  // written by write_matrix / rows (below)

  // --- geometry (call set_geometry first) -----------------------------------------------------
  int reference_start() const { return p_; }
  int reference_end() const { return r_; }
  int across() const { return o_; }
  /// Computes q, the constraint values and the gradients at positions x.
  void set_geometry(const Points<dim>& x);
  /// g (m), one per row.
  Rows value() const { return g_; }
  /// ġ (m/s) at velocities v.
  Rows rate(const Points<dim>& v) const;
  /// The velocity term of g̈, 2 q·(u̇ × ẇ)/h (m/s²).
  Rows curvature_term(const Points<dim>& v) const;
  /// Σ_i ∇_i g · z_i for a field z (one value per row).
  Rows apply(const Points<dim>& z) const;

  /// Writes its entries of −J W Jᵀ: the coupling with every link in `links` (unit vectors e.col(j)
  /// of link j) and its own block; `inv_mass(i)` is 1/m_i (0 for a prescribed node).
  template <class InvMass>
  void write_matrix(TensionSystem& system, const Points<dim>& e, const InvMass& inv_mass) const;
  /// Adds −Σ_k μ_k ∇g_k to `force` (μ read from `solution`).
  void add_force(const Eigen::VectorXd& solution, Points<dim>& force) const;
  /// Adds W Jᵀ μ (the correction of a projection step, same sign as the links') to `target`.
  template <class InvMass>
  void add_correction(const Eigen::VectorXd& solution, const InvMass& inv_mass, Points<dim>& target) const;
  /// Its unknowns' indices in the system.
  int unknown(int row) const { return first_ + row; }

 private:
  using V3 = Eigen::Vector3d;
  static V3 lift(const Vec<dim>& a);
  static Vec<dim> drop(const V3& a);
  Vec<dim> gradient(int row, int node) const;  // ∇_node g_row (zero for other nodes)

  int p_, r_, o_;
  std::vector<Link> links_;
  double h_;
  int first_ = -1;
  std::array<V3, kRows> q_{};
  std::array<std::array<Vec<dim>, 3>, kRows> grad_{};  // [row][p, r, o]
  Rows g_ = Rows::Zero();
  V3 u_ = V3::Zero(), w_ = V3::Zero();
  // slots: [link][row] coupling (both orders), [row][row] own block
  std::vector<std::array<std::array<int, 2>, kRows>> link_slots_;
  std::array<std::array<int, kRows>, kRows> own_slots_{};
};

template <int dim>
template <class InvMass>
void FoldContact<dim>::write_matrix(TensionSystem& system, const Points<dim>& e, const InvMass& inv_mass) const {
  const std::array<int, 3> nodes{p_, r_, o_};
  auto grad_at = [&](int row, int node) -> Vec<dim> {
    for (int c = 0; c < 3; ++c)
      if (nodes[static_cast<std::size_t>(c)] == node) return grad_[static_cast<std::size_t>(row)][static_cast<std::size_t>(c)];
    return Vec<dim>::Zero();
  };
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const int j = links_[l].start;
    const Vec<dim> ej = e.col(j);
    for (int k = 0; k < kRows; ++k) {
      // −J_link W ∇g: the link's Jacobian is −e_j at node j, +e_j at node j + 1.
      const double value = -(inv_mass(j + 1) * ej.dot(grad_at(k, j + 1)) - inv_mass(j) * ej.dot(grad_at(k, j)));
      system.value(link_slots_[l][static_cast<std::size_t>(k)][0]) = value;
      system.value(link_slots_[l][static_cast<std::size_t>(k)][1]) = value;
    }
  }
  for (int k = 0; k < kRows; ++k)
    for (int m = 0; m < kRows; ++m) {
      double value = 0;
      for (int c = 0; c < 3; ++c)
        value -= inv_mass(nodes[static_cast<std::size_t>(c)]) *
                 grad_[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)].dot(grad_[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)]);
      system.value(own_slots_[static_cast<std::size_t>(k)][static_cast<std::size_t>(m)]) = value;
    }
}

template <int dim>
template <class InvMass>
void FoldContact<dim>::add_correction(const Eigen::VectorXd& solution, const InvMass& inv_mass,
                                      Points<dim>& target) const {
  const std::array<int, 3> nodes{p_, r_, o_};
  for (int k = 0; k < kRows; ++k) {
    const double mu = solution[first_ + k];
    for (int c = 0; c < 3; ++c) {
      const int i = nodes[static_cast<std::size_t>(c)];
      target.col(i) += inv_mass(i) * mu * grad_[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
    }
  }
}

}  // namespace chainsim
