#pragma once
/// @file jump_conditions.hpp
/// The jump conditions at a shock (docs/model.md §2–3) as pure pointwise functions of
/// the states on the two sides. No mesh, no time integration: every kind of front
/// (front_kind.hpp) computes its tensions, powers and reaction with these, and the tests check them
/// against hand-derived states and against the running fronts.
///
/// Conventions. s is the material coordinate; "+" is the side of larger s, "−" the side of smaller
/// s; [ψ] = ψ⁺ − ψ⁻. ṡ0 is the speed of the front in the material (m/s); t± the unit tangents,
/// v± the velocities, τ± the tensions on the two sides; λ the linear density; f ∈ [0, 1] the
/// shock's dissipation parameter (`dissipation`; a pot, a start heap that pushes, has −½ ≤ f < 0:
/// heap_shock_power).
///
///   kinematic compatibility   v0 = v⁺ + ṡ0 t⁺ = v⁻ + ṡ0 t⁻        ⇔  [v] = −ṡ0 [t]
///   momentum balance          [τ t] + F0 + λ ṡ0 [v] = 0            (F0: force concentrated at x0)
///   tension jump (energy)     [τ] = −½ f λ sgn(ṡ0) |[v]|²
///   dissipated power          D = ½ f λ |ṡ0| |[v]|² ≥ 0,   W_s = −D
///
/// External shock at a quiescent heap (a string moving along itself, v = v t, v uniform):
///   Φ*± = ±(τ*± − λ v²) t*±,   W*± = ±(τ*± − ½ λ v²) v
/// (+: the string runs into the heap at its + end; −: it is drawn out of the heap at its − end).
///
/// The forms the fronts use (a fold, a heap seen from a string of any shape):
///   end tensions   τ∓ = λ ṡ0² (1 ± f sgn ṡ0)  (a front whose sides move apart at [v] = 2 ṡ0 e,
///                  [τ] = τ⁺ − τ⁻ = −2 f λ sgn(ṡ0) ṡ0² as above; τ⁻ + τ⁺ = 2 λ ṡ0², the momentum balance)
///   shock power    W_s = −k f λ |ṡ0|³ for k internal shocks of |[v]|² = 2 ṡ0² each (k = 2: a fold,
///                  whose |[v]|² = 4 ṡ0²; k = 1: the contact of a heap)
///   heap reaction  R = τ e + λ w v_k   (e the tangent from the arc into the heap, w = dl/dt the rate
///                  at which the arc gains material, v_k its end's velocity)
///   heap power     W* = τ e·v_k + ½ λ w |v_k|² − W_s
/// For a string moving along itself (v_k = v t) R = Φ*± and W* = W*± − W_s at the arc's end tension τ,
/// which is W*± at the heap's own τ* = λ v² (tested).
///
/// Reversing the orientation of s (s → ℓ − s) flips t and ṡ0 and swaps the sides; every formula
/// here is invariant under that change (tested).
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace chainsim::jump {

template <int dim>
using Vector = Eigen::Matrix<double, dim, 1>;

/// The state of the string on one side of a front.
template <int dim>
struct Side {
  Vector<dim> tangent;   ///< unit tangent t (points towards larger s)
  Vector<dim> velocity;  ///< v (m/s)
  double tension = 0;    ///< τ (N)
};

inline double sign(double x) { return (x > 0) - (x < 0); }

/// [v] = −ṡ0 [t]: the velocity jump kinematic compatibility allows for given tangents.
template <int dim>
Vector<dim> velocity_jump(const Vector<dim>& t_minus, const Vector<dim>& t_plus, double s0_dot) {
  return -s0_dot * (t_plus - t_minus);
}

/// v0 = v⁺ + ṡ0 t⁺: the velocity of the singular point itself (not of any material point).
template <int dim>
Vector<dim> front_velocity(const Side<dim>& plus, double s0_dot) {
  return plus.velocity + s0_dot * plus.tangent;
}

/// |v⁺ + ṡ0 t⁺ − v⁻ − ṡ0 t⁻|: zero when the two sides are kinematically compatible (m/s).
template <int dim>
double compatibility_residual(const Side<dim>& minus, const Side<dim>& plus, double s0_dot) {
  return (plus.velocity + s0_dot * plus.tangent - minus.velocity - s0_dot * minus.tangent).norm();
}

/// [τ] = −½ f λ sgn(ṡ0) |[v]|² (N).
inline double tension_jump(double dissipation, double density, double s0_dot, double jump_v_squared) {
  return -0.5 * dissipation * density * sign(s0_dot) * jump_v_squared;
}

/// D = ½ f λ |ṡ0| |[v]|² (W): the power the shock dissipates; the shock's power is W_s = −D.
inline double dissipation_rate(double dissipation, double density, double s0_dot, double jump_v_squared) {
  return 0.5 * dissipation * density * std::abs(s0_dot) * jump_v_squared;
}

/// [τ t] + F0 + λ ṡ0 [v] (N): zero when the momentum balance at the front holds.
template <int dim>
Vector<dim> momentum_residual(const Side<dim>& minus, const Side<dim>& plus, const Vector<dim>& concentrated_force,
                              double density, double s0_dot) {
  return plus.tension * plus.tangent - minus.tension * minus.tangent + concentrated_force +
         density * s0_dot * (plus.velocity - minus.velocity);
}

/// F0 = −[τ t] − λ ṡ0 [v]: the concentrated force (e.g. a table's reaction) the front needs (N).
template <int dim>
Vector<dim> required_force(const Side<dim>& minus, const Side<dim>& plus, double density, double s0_dot) {
  return -momentum_residual(minus, plus, Vector<dim>::Zero().eval(), density, s0_dot);
}

/// Φ*± = ±(τ* − λ v²) t*: the force a quiescent heap exerts on a string moving along itself with
/// speed v (m/s) at the external shock; `into_heap` selects + (the string runs into the heap).
template <int dim>
Vector<dim> heap_force(bool into_heap, double tension, double density, double speed, const Vector<dim>& tangent) {
  return (into_heap ? 1.0 : -1.0) * (tension - density * speed * speed) * tangent;
}

/// W*± = ±(τ* − ½ λ v²) v: the power the heap supplies at the external shock (W; negative: a loss).
inline double heap_power(bool into_heap, double tension, double density, double speed) {
  return (into_heap ? 1.0 : -1.0) * (tension - 0.5 * density * speed * speed) * speed;
}

/// τ∓ = λ ṡ0² (1 ± f sgn ṡ0): the end tension on the − side (`side` < 0) or the + side (`side` > 0)
/// of a front moving at ṡ0 through the material (N).
inline double end_tension(double dissipation, double density, double s0_dot, int side) {
  return side < 0 ? density * s0_dot * s0_dot * (1 + dissipation * sign(s0_dot))
                  : density * s0_dot * s0_dot * (1 - dissipation * sign(s0_dot));
}

/// W_s = −k f λ |ṡ0|³ (W): the power of `shocks` internal shocks of |[v]|² = 2 ṡ0² each at a front
/// moving at ṡ0 (−Σ dissipation_rate).
inline double shock_power(double dissipation, double density, double s0_dot, int shocks) {
  return -shocks * dissipation * density * std::abs(s0_dot) * s0_dot * s0_dot;
}

/// The lowest f a heap's contact may have: a pot (a start heap that pushes the string out, f < 0;
/// Biggins & Warner's chain fountain) draws material at τ = (1 + f) λ v² < λ v², and loses
/// (½ + f) λ v³ in all (pot_dissipation_rate), which must not be negative.
inline constexpr double kPotMinDissipation = -0.5;

/// W_s of the internal shock at a heap's contact (W): shock_power with k = 1 for f ≥ 0. A pot's f < 0
/// is no internal shock (that would be D < 0, energy made at a point): its contact books no shock
/// power, and heap_power then books its whole exchange, −(½ + f) λ v³ ≤ 0 for a string moving along
/// itself.
inline double heap_shock_power(double dissipation, double density, double s0_dot) {
  return dissipation >= 0 ? shock_power(dissipation, density, s0_dot, 1) : 0.0;
}

/// (½ + f) λ |v|³ (W): the power a heap's contact loses in all (internal and external shock) while it
/// gives out a string moving along itself at speed v, drawn at τ = (1 + f) λ v² (end_tension);
/// ≥ 0 for f ≥ −½. (A string running into a heap loses (f − ½) λ |v|³: the falling chain's f ≥ ½.)
inline double pot_dissipation_rate(double dissipation, double density, double speed) {
  return (0.5 + dissipation) * density * std::abs(speed) * speed * speed;
}

/// R = τ e + λ w v_k: the force the support of a quiescent heap exerts on the string (N). `tangent`
/// e points from the arc into the heap, `inflow` w is the rate at which the arc gains material,
/// `end_velocity` v_k is the velocity of the arc's end.
template <int dim>
Vector<dim> heap_reaction(double tension, const Vector<dim>& tangent, const Vector<dim>& end_velocity, double density,
                          double inflow) {
  return tension * tangent + density * inflow * end_velocity;
}

/// W* = τ e·v_k + ½ λ w |v_k|² − W_s: the power a quiescent heap exchanges with the string (W), the
/// arguments as heap_reaction's and W_s the power of the internal shock at its contact.
template <int dim>
double heap_power(double tension, const Vector<dim>& tangent, const Vector<dim>& end_velocity, double density,
                  double inflow, double shock_power) {
  return tension * tangent.dot(end_velocity) + 0.5 * density * inflow * end_velocity.squaredNorm() - shock_power;
}

// --- A front pinned in space (an edge, a peg): v0 = 0 ---------------------------------------------
// Material flows through a point fixed in space, turning from t⁻ to t⁺. With v0 = 0, v± = −ṡ0 t±, so
// [v] = −ṡ0 [t] and |[v]|² = ṡ0² |[t]|²; the tension jumps by [τ] = −½ f λ sgn(ṡ0) ṡ0² |[t]|², and the
// obstacle must supply F0 = −[τ t] + λ ṡ0² [t] (docs/model.md §8). It can only push: F0 must lie in
// its normal cone, spanned by the outward normals n∓ of the obstacle's faces at the point (pinned_cone).

/// τ⁺ at a pinned front, from τ⁻, the tangents on the two sides and the speed ṡ0 (N).
template <int dim>
double pinned_tension_plus(double tension_minus, const Vector<dim>& t_minus, const Vector<dim>& t_plus,
                           double dissipation, double density, double s0_dot) {
  return tension_minus + tension_jump(dissipation, density, s0_dot, s0_dot * s0_dot * (t_plus - t_minus).squaredNorm());
}

/// D = ½ f λ |ṡ0|³ |[t]|² (W): the power a pinned front's kink dissipates (W_s = −D).
template <int dim>
double pinned_dissipation_rate(const Vector<dim>& t_minus, const Vector<dim>& t_plus, double dissipation,
                               double density, double s0_dot) {
  return dissipation_rate(dissipation, density, s0_dot, s0_dot * s0_dot * (t_plus - t_minus).squaredNorm());
}

/// F0 = −[τ t] + λ ṡ0² [t]: the force the obstacle exerts on the string at a pinned front (N); it is
/// required_force with v± = −ṡ0 t±.
template <int dim>
Vector<dim> pinned_reaction(const Vector<dim>& t_minus, const Vector<dim>& t_plus, double tension_minus,
                            double tension_plus, double density, double s0_dot) {
  return -(tension_plus * t_plus - tension_minus * t_minus) + density * s0_dot * s0_dot * (t_plus - t_minus);
}

/// The outward normal of the obstacle's face that the string on the side of tangent `t_side` lies on,
/// when the string turns by [t] = t⁺ − t⁻ ≠ 0 over the obstacle: the unit vector normal to t_side on
/// the side away from the bend (the obstacle lies where [t] points).
template <int dim>
Vector<dim> face_normal(const Vector<dim>& t_side, const Vector<dim>& jump_t) {
  const Vector<dim> n = -(jump_t - jump_t.dot(t_side) * t_side);
  return n / n.norm();
}

/// The coordinates (α, β) of F in the normal cone spanned by the faces' outward normals n⁻, n⁺
/// (F = α n⁻ + β n⁺ + a part normal to both, which a 3D edge's line carries): F lies in the cone while
/// both are ≥ 0; min(α, β) is the margin whose zero is lift-off. n⁻ and n⁺ must not be parallel.
template <int dim>
Eigen::Vector2d pinned_cone(const Vector<dim>& force, const Vector<dim>& n_minus, const Vector<dim>& n_plus) {
  const double c = n_minus.dot(n_plus), fm = force.dot(n_minus), fp = force.dot(n_plus), det = 1 - c * c;
  return Eigen::Vector2d((fm - c * fp) / det, (fp - c * fm) / det);
}

/// The lift-off margin of a pinned front: min(F·P t⁻, −F·P t⁺), P = I − d dᵀ the projection normal to
/// the edge's line d (`axis`; in 2D the out-of-plane axis, P t = t). F lies in the normal cone of
/// pinned_cone exactly where both are ≥ 0: P t⁻ is normal to n⁻ and points to n⁺'s side, −P t⁺ is
/// normal to n⁺ and points to n⁻'s side, so the two have the signs of β and α (pinned_cone) with
/// positive factors (sin θ). Unlike pinned_cone it stays defined at a 180° kink (a peg: n⁻ = −n⁺, the
/// cone the half-space F·t⁻ ≥ 0, lift-off where F0 reaches zero) and needs no face normals.
template <int dim>
double pinned_lift_off_margin(const Vector<dim>& force, const Vector<dim>& t_minus, const Vector<dim>& t_plus,
                              const Vector<dim>& axis) {
  const Vector<dim> pm = t_minus - t_minus.dot(axis) * axis, pp = t_plus - t_plus.dot(axis) * axis;
  return std::min(force.dot(pm), -force.dot(pp));
}

// --- A touchdown front: a string leaving or landing on a smooth plane (docs/model.md §10) ------------
// The lying side (s < s0) runs along the plane in the direction e, the arc (s > s0) leaves it along t at the
// angle θ (cos θ = t·e); [v] = v⁺ − v⁻ is the jump of the velocities across the front (in the discrete front,
// of its two nodes). On a compatible state, [v] = −ṡ0 (t − e), the three give the closed forms
//   τ⁺ = (1 − f sgn ṡ0) λ ṡ0²,  τ⁻ = λ ṡ0² (1 − f sgn ṡ0 cos θ),  R = f λ ṡ0 |ṡ0| sin θ n
// (R normal to the plane, n on the arc's side), and the loads −τ⁺ t, τ⁻ e work at exactly −½ f λ |ṡ0| |[v]|².

/// τ⁺ = (1 − f sgn ṡ0) λ ṡ0 |[v]|² / (2 (−t·[v])), the arc's tension at a touchdown front (N): the value that
/// makes the loads' power −½ f λ |ṡ0| |[v]|² for any [v]; (1 − f sgn ṡ0) λ ṡ0² where −t·[v] vanishes (no jump,
/// or one normal to t).
template <int dim>
double touchdown_tension_plus(const Vector<dim>& t, double cos_theta, const Vector<dim>& jump_v, double dissipation,
                              double density, double s0_dot) {
  const double jump2 = jump_v.squaredNorm(), t_jump = -t.dot(jump_v);
  const double weight = 1 - dissipation * sign(s0_dot);
  return std::abs(t_jump) > 1e-9 * std::sqrt(jump2) * (1 - cos_theta)
             ? weight * 0.5 * density * s0_dot * jump2 / t_jump
             : weight * density * s0_dot * s0_dot;
}

/// τ⁻ = λ ṡ0 [v]·e + τ⁺ cos θ, the lying side's tension at a touchdown front (N): the value that keeps the
/// momentum along the plane (e) exact.
template <int dim>
double touchdown_tension_minus(double tension_plus, const Vector<dim>& e, double cos_theta, const Vector<dim>& jump_v,
                               double density, double s0_dot) {
  return density * s0_dot * jump_v.dot(e) + tension_plus * cos_theta;
}

/// R = τ⁻ e − τ⁺ t − λ ṡ0 [v]: the plane's force on the string at a touchdown front (N), the momentum the
/// loads and the material moved across the front change; normal to the plane by τ⁻'s choice.
template <int dim>
Vector<dim> touchdown_reaction(const Vector<dim>& e, const Vector<dim>& t, double tension_minus, double tension_plus,
                               const Vector<dim>& jump_v, double density, double s0_dot) {
  return tension_minus * e - tension_plus * t - density * s0_dot * jump_v;
}

}  // namespace chainsim::jump
