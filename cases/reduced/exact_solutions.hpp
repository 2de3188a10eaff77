#pragma once
/// @file exact_solutions.hpp
/// Exact references for the reduced models of the three canonical chain problems (docs/model.md §4),
/// in scaled, dimensionless variables:
///
///   η = y/ℓ,   ξ = t/t0,   t0 = sqrt(2ℓ/g),   P0 = λℓg,   ' = d/dξ,   f ∈ [0, 1] the shock dissipation.
///
/// Each reduced equation of motion is autonomous; with u = η'² (so η'' = ½ du/dη) it becomes a linear
/// first-order ODE in η whose solution, released from rest at η0, is the "first integral" below. The
/// time then follows from the quadrature ξ(η) = ∫ dη / |η'|.
///
///  (a) falling chain:  (1−f) η'² + (η'' + 2) η = 0,        η(0) = η0 ∈ (0, 1], η decreasing to 0
///        η'² = 4/(3−2f) (η0^(3−2f) η^(2f−2) − η)
///        ξ(η) = ½ sqrt(3−2f) ∫_η^η0 dx / sqrt(η0^(3−2f) x^(2f−2) − x)
///        P/P0 = ½ f η'² + 1 − η
///  (b) folded chain (F = 0):  (1−f) η'² + 2 (1 − η'')(1 − η) = 0,   η(0) = η0 ∈ [0, 1), η increasing to 1
///        η'² = 2/(2−f) ((1−η0)^(2−f) (1−η)^(f−1) − 1 + η)
///        ξ(η) = sqrt(1 − f/2) ∫_η0^η dx / sqrt((1−η0)^(2−f) (1−x)^(f−1) − 1 + x)
///        P/P0 = (1+f)/(2−f) [(1−η0)^(2−f) (1−η)^(f−1) − 1 + η] + η   (= ½ (1+f) η'² + η)
///  (c) sliding chain:  (1+f) η'² + (η'' − 2) η = 0,       η(0) = η0 ∈ [0, 1], η increasing to 1
///        η'² = 4/(3+2f) (η − η0^(3+2f) η^(−2−2f))
///        ξ(η) = ½ sqrt(3+2f) ∫_η0^η x^(1+f) dx / sqrt(x^(3+2f) − η0^(3+2f))      (η0 > 0)
///        ξ(η) = sqrt((3+2f) η)   (η0 = 0: the special solution y = ½ g t² / (3+2f))
///        P/P0 = ½ f η'² + 1 − η
///
/// Each quadrature has an inverse-square-root singularity at the release point. The implementation
/// removes it analytically (sin/cosh substitutions, see exact_solutions.cpp) and integrates the
/// remaining bounded integrand with Boost.Math's tanh-sinh rule; results are accurate to about
/// 1e-14 relative. The inverses η(ξ) use Boost's TOMS 748 bracketing root finder on the monotone ξ(η).
///
/// Every argument is checked: a value out of range throws chainsim::InputError naming the argument
/// ("f", "eta", "eta0", "xi"), its value and the allowed range.

namespace chainsim::exact {

// ---------------------------------------------------------------------------------------------------
// (a) Falling chain onto a table, released from rest at height η0; η = height of the falling part.
// ---------------------------------------------------------------------------------------------------

/// η'² = 4/(3−2f) (η0^(3−2f) η^(2f−2) − η): the squared scaled speed (dimensionless) at height η.
/// Ranges: 0 <= f <= 1, 0 < eta0 <= 1, 0 <= eta <= eta0. Returns +infinity at η = 0 when f < 1
/// (the speed diverges there; for f = 1 it is the free-fall value 4 η0).
double falling_eta_prime_squared(double f, double eta, double eta0 = 1.0);

/// ξ(η) = ½ sqrt(3−2f) ∫_η^η0 dx / sqrt(η0^(3−2f) x^(2f−2) − x): the scaled time t/t0 at which the
/// falling part has height η. Ranges: 0 <= f <= 1, 0 < eta0 <= 1, 0 <= eta <= eta0; ξ(η0) = 0.
/// Classical value: f = 1 gives free fall, ξ = sqrt(η0 − η).
double falling_xi(double f, double eta, double eta0 = 1.0);

/// t_f/t0 = ξ(0): the scaled time for the whole chain to land. Ranges as falling_xi.
/// Equals sqrt(η0) for f = 1 and grows as f decreases.
double falling_fall_time(double f, double eta0 = 1.0);

/// P/P0 = ½ f η'² + 1 − η: the dynamic weight on the table in units of the static weight λℓg.
/// Ranges as falling_eta_prime_squared; +infinity at η = 0 when 0 < f < 1. For η0 = 1 this is
/// 1 + (2 f η^(2f−2) − 3η)/(3−2f): f = 0 gives 1 − η, f = 1 gives 3 (1 − η).
double falling_P(double f, double eta, double eta0 = 1.0);

// ---------------------------------------------------------------------------------------------------
// (b) Folded chain, one end fixed, F = 0, released from rest with resting-arm length η0.
// ---------------------------------------------------------------------------------------------------

/// η'² = 2/(2−f) ((1−η0)^(2−f) (1−η)^(f−1) − 1 + η): the squared scaled speed of the bight
/// (the free end moves at 2η'). Ranges: 0 <= f <= 1, 0 <= eta0 < 1, eta0 <= eta <= 1.
/// Returns +infinity at η = 1 when f < 1 (the tip speed diverges); for f = 1 it is 2 (η − η0).
double folded_eta_prime_squared(double f, double eta, double eta0 = 0.0);

/// ξ(η) = sqrt(1 − f/2) ∫_η0^η dx / sqrt((1−η0)^(2−f) (1−x)^(f−1) − 1 + x): the scaled time t/t0 at
/// which the resting arm has length η. Ranges as folded_eta_prime_squared; ξ(η0) = 0.
/// Classical value: f = 1 gives free fall of the tip through 2(η − η0), ξ = sqrt(2 (η − η0)).
double folded_xi(double f, double eta, double eta0 = 0.0);

/// t_f/t0 = ξ(1): the scaled time for the chain to straighten. Ranges: 0 <= f <= 1, 0 <= eta0 < 1.
/// Equals sqrt(2 (1 − η0)) for f = 1 (not 1: the tip falls through twice the free arm's length).
double folded_fall_time(double f, double eta0 = 0.0);

/// P/P0 = (1+f)/(2−f) [(1−η0)^(2−f) (1−η)^(f−1) − 1 + η] + η: the dynamic weight on the support in
/// units of λℓg. Ranges as folded_eta_prime_squared; +infinity at η = 1 when f < 1.
/// Classical value: f = 1, η0 = 0 gives 3 η.
double folded_P(double f, double eta, double eta0 = 0.0);

// ---------------------------------------------------------------------------------------------------
// (c) Sliding chain from a heap through a hole, released from rest with hanging length η0.
// ---------------------------------------------------------------------------------------------------

/// η'² = 4/(3+2f) (η − η0^(3+2f) η^(−2−2f)) (η0 > 0), 4 η/(3+2f) (η0 = 0): the squared scaled speed.
/// Ranges: 0 <= f <= 1, 0 <= eta0 <= 1, eta0 <= eta <= 1.
double sliding_eta_prime_squared(double f, double eta, double eta0);

/// ξ(η) = ½ sqrt(3+2f) ∫_η0^η x^(1+f) dx / sqrt(x^(3+2f) − η0^(3+2f)) for η0 > 0, and
/// ξ(η) = sqrt((3+2f) η) for η0 = 0: the scaled time t/t0 at which the hanging length is η.
/// Ranges as sliding_eta_prime_squared; ξ(η0) = 0, and ξ tends to sqrt((3+2f) η) as η0 → 0.
double sliding_xi(double f, double eta, double eta0);

/// t_f/t0 = ξ(1): the scaled time for the whole chain to hang. Ranges: 0 <= f <= 1, 0 <= eta0 <= 1.
/// Equals sqrt(3+2f) for η0 = 0.
double sliding_fall_time(double f, double eta0);

/// P/P0 = ½ f η'² + 1 − η: the dynamic weight on the table in units of λℓg.
/// Ranges as sliding_eta_prime_squared.
double sliding_P(double f, double eta, double eta0);

// ---------------------------------------------------------------------------------------------------
// Inverses η(ξ), for drawing the references against time. Each solves ξ(η) = xi by TOMS 748
// bracketing on the monotone ξ(η), to a relative tolerance of about 1e-14 in η.
// ---------------------------------------------------------------------------------------------------

/// The height η of the falling part at scaled time ξ. Ranges: 0 <= f <= 1, 0 < eta0 <= 1,
/// 0 <= xi <= falling_fall_time(f, eta0). Returns η0 at ξ = 0 and 0 at the fall time.
double falling_eta(double f, double xi, double eta0 = 1.0);

/// The resting-arm length η of the folded chain at scaled time ξ. Ranges: 0 <= f <= 1,
/// 0 <= eta0 < 1, 0 <= xi <= folded_fall_time(f, eta0). Returns η0 at ξ = 0 and 1 at the fall time.
double folded_eta(double f, double xi, double eta0 = 0.0);

/// The hanging length η of the sliding chain at scaled time ξ. Ranges: 0 <= f <= 1, 0 <= eta0 <= 1,
/// 0 <= xi <= sliding_fall_time(f, eta0). For η0 = 0 this is the closed form ξ²/(3+2f).
double sliding_eta(double f, double xi, double eta0);

// ---------------------------------------------------------------------------------------------------
// A chain sliding off a smooth table over a sharp edge (docs/model.md §8), physical units: length ℓ (m),
// gravity g (m/s²), x (m) the hanging length, released at rest from x0 ∈ (0, ℓ); f ∈ [0, 1] the edge's
// dissipation. Energy with the kink's loss f λ ẋ³ gives ℓ ẍ = g x − f ẋ², and with X = x/ℓ,
// Δ = X − X0, z = 2 f Δ:
//   ẋ² = g ℓ (2 X0 Δ ψ1(z) + 2 Δ² ψ2(z)),   ψ1(z) = (1 − e^−z)/z,  ψ2(z) = (z − 1 + e^−z)/z²
// (f = 0: ẋ² = (g/ℓ)(x² − x0²), x = x0 cosh(√(g/ℓ) t)). The table part is pulled by
// τ⁻ = λ (ℓ − x) ẍ, the hanging part by τ⁺ = τ⁻ + f λ ẋ²; the edge pushes while τ⁻ ≥ λ ẋ², and the
// chain lifts off where ẋ² (ℓ + f (ℓ − x)) = g x (ℓ − x) (f = 0: x* = (ℓ + √(ℓ² + 8 x0²))/4).
// ---------------------------------------------------------------------------------------------------

/// ẋ² (m²/s²) at hanging length x ∈ [x0, ℓ]. Ranges: 0 ≤ f ≤ 1, ℓ > 0, g > 0, 0 < x0 < ℓ.
double edge_speed_squared(double f, double x, double x0, double ell, double g);
/// ẍ (m/s²) at hanging length x: (g x − f ẋ²)/ℓ.
double edge_acceleration(double f, double x, double x0, double ell, double g);
/// t(x) = ∫_x0^x dx/ẋ (s), x ∈ [x0, ℓ].
double edge_time(double f, double x, double x0, double ell, double g);
/// x(t) (m), 0 ≤ t ≤ edge_time(f, ℓ, …).
double edge_x(double f, double t, double x0, double ell, double g);
/// The hanging length x* ∈ (x0, ℓ) at which the chain lifts off the edge (τ⁻ = λ ẋ²).
double edge_lift_off_x(double f, double x0, double ell, double g);

// ---------------------------------------------------------------------------------------------------
// The heavy Atwood chain over a sharp peg (docs/model.md §8), physical units: a chain of length ℓ (m)
// hangs over a peg, x (m) on the longer (falling) side, ℓ − x on the other, released at rest from
// x0 ∈ (ℓ/2, ℓ); f ∈ [0, 1] the kink's dissipation (a 180° turn: [τ] = 2 f λ ẋ², D = 2 f λ ẋ³). The sides
// give ℓ ẍ = g (2x − ℓ) − 2 f ẋ², and with Δ = x − x0, z = 4 f Δ/ℓ (ψ1, ψ2 as for the edge):
//   ẋ² = (2g/ℓ) ((2 x0 − ℓ) Δ ψ1(z) + 2 Δ² ψ2(z))
// (f = 0: x − ℓ/2 = (x0 − ℓ/2) cosh(√(2g/ℓ) t)). The rising side is pulled by τ⁻ = λ (ℓ − x)(g + ẍ),
// the falling side by τ⁺ = τ⁻ + 2 f λ ẋ²; the peg's reaction is (τ⁻ + τ⁺ − 2 λ ẋ²) upwards and the
// chain lifts off where it reaches zero: (ℓ − x)(g + ẍ) = (1 − f) ẋ² (f = 0: (x − ℓ/2)² = ℓ²/8 +
// (x0 − ℓ/2)²/2); for f < 1 always before the shorter end reaches the peg (x = ℓ).
// ---------------------------------------------------------------------------------------------------

/// ẋ² (m²/s²) at the longer side's length x ∈ [x0, ℓ]. Ranges: 0 ≤ f ≤ 1, ℓ > 0, g > 0, ℓ/2 < x0 < ℓ.
double peg_speed_squared(double f, double x, double x0, double ell, double g);
/// ẍ (m/s²) at x: (g (2x − ℓ) − 2 f ẋ²)/ℓ.
double peg_acceleration(double f, double x, double x0, double ell, double g);
/// t(x) = ∫_x0^x dx/ẋ (s), x ∈ [x0, ℓ]; t(ℓ) is when the shorter end reaches the peg.
double peg_time(double f, double x, double x0, double ell, double g);
/// x(t) (m), 0 ≤ t ≤ peg_time(f, ℓ, …).
double peg_x(double f, double t, double x0, double ell, double g);
/// The longer side's length x* ∈ (x0, ℓ] at which the chain lifts off the peg (the reaction reaches
/// zero); ℓ if it stays on the peg until the shorter end reaches it (possible only for f = 1).
double peg_lift_off_x(double f, double x0, double ell, double g);

// ---------------------------------------------------------------------------------------------------
// The heavy Atwood chain over a smooth pulley of radius R (docs/model.md §10), physical units: a chain of
// length ℓ (m) hangs over a pulley, x1 on the longer side, x2 on the shorter, the half circle πR between
// (x1 + x2 = ℓ_free = ℓ − πR); the whole chain moves along itself, so ℓ ẍ1 = g (x1 − x2), and with
// u = x1 − ℓ_free/2 released at rest from u0 ∈ (0, ℓ_free/2), ω = √(2g/ℓ):
//   u = u0 cosh(ω t),   ẋ² = ω² (u² − u0²),   ẍ = ω² u.
// The shorter side meets the pulley (φ = 0) with τ2 = λ x2 (g + ẍ), the longer leaves it (φ = π) with
// τ1 = λ x1 (g − ẍ); the contact force per length on the wrapped arc is (τ2 − λ ẋ²)/R + λ ẍ φ + 2 λ g sin φ,
// smallest at φ = 0, and the shorter side lifts off where τ2 = λ ẋ²:
//   4 u² + π R u − (ℓ ℓ_free/2 + 2 u0²) = 0,   u* = (−πR + √(π²R² + 8 ℓ ℓ_free + 32 u0²))/8,
//   t* = arccosh(u*/u0)/ω   (R → 0: the sharp peg's u*² = ℓ²/8 + u0²/2 at f = 0).
// ---------------------------------------------------------------------------------------------------

/// u(t) = u0 cosh(ω t) (m). Ranges: ℓ > 0, g > 0, u0 > 0.
double pulley_u(double t, double u0, double ell, double g);
/// u̇(t) = u0 ω sinh(ω t) (m/s).
double pulley_u_dot(double t, double u0, double ell, double g);
/// The time at which u reaches u ≥ u0 (s): arccosh(u/u0)/ω.
double pulley_time(double u, double u0, double ell, double g);
/// u* (m), the lift-off of the shorter side (the positive root above). Ranges: R > 0, πR < ℓ,
/// 0 < u0 < ℓ_free/2; u* < ℓ_free/2 (the shorter end has not reached the pulley).
double pulley_lift_off_u(double u0, double radius, double ell);

}  // namespace chainsim::exact
