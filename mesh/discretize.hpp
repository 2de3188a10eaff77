#pragma once
/// @file discretize.hpp
/// Initial shapes and velocity fields of a string.
///
/// A shape is a curve parametrised by arc length (Curve): a polyline (or any list of points), a
/// circular arc, a full circle, or the catenary hanging between two points. discretize() places
/// the chain's nodes on the curve at equal arc length and gives every link the same material length
/// h = ℓ / (number of links). It first checks that the curve is as long as the chain
/// (|L_curve − ℓ| <= tolerance · ℓ), else throws InputError naming both lengths.
///
/// Nodes at equal arc length on a curved shape make chords slightly shorter than h (by O(h³ κ²)
/// per link); the string model projects the initial positions and velocities onto the link
/// constraints before it starts (StringModel::make_consistent), holding the prescribed end nodes.
#include <memory>
#include <string>

#include "mesh/chain.hpp"

namespace chainsim {

/// A curve in R^dim parametrised by arc length s ∈ [0, length()].
template <int dim>
class Curve {
 public:
  virtual ~Curve() = default;
  /// Arc length of the curve (m).
  virtual double length() const = 0;
  /// The point at arc length s from the start (m), s clamped to [0, length()].
  virtual Vec<dim> point(double s) const = 0;
  /// A closed curve: point(length()) == point(0).
  virtual bool closed() const { return false; }
  /// What the curve is, for messages ("circle of radius 0.5 m").
  virtual std::string description() const = 0;
};

/// The polyline through `vertices` (one column per vertex, at least 2, no zero-length segments).
/// closed = true adds the segment from the last vertex back to the first (unless they coincide).
template <int dim>
std::unique_ptr<Curve<dim>> polyline_curve(const Points<dim>& vertices, bool closed = false);

/// The open polyline through `vertices` (as polyline_curve) with every interior vertex rounded by a
/// fillet: the circular arc of radius `corner_radius` (m, > 0) tangent to both adjacent segments.
/// At a vertex where the direction turns by θ (the angle between the incoming and the outgoing
/// segment), the arc starts and ends r·tan(θ/2) from the vertex and is r·θ long, so the curve is
/// Σ segments − Σ (2 r tan(θ/2) − r θ) long and has a continuous tangent. A straight-through
/// vertex (θ ≈ 0) keeps no arc. Fillets may use a whole segment (the two tangent lengths on it
/// summing to its length, to a relative 1e-12): then two arcs meet there.
/// Throws InputError (naming the vertex or segment, zero-based as in the list of vertices) if the
/// polyline turns back on itself at a vertex (θ within 1e-9 of π), or if a segment is too short for
/// the fillets at its two ends (with the largest corner_radius that fits every segment).
template <int dim>
std::unique_ptr<Curve<dim>> rounded_polyline_curve(const Points<dim>& vertices, double corner_radius);

/// The circular arc of the given radius (m) around `center`, in the plane spanned by the unit
/// vectors axis1, axis2 (orthonormalised), from angle `start_angle` through the signed angle
/// `sweep` (radians, counter-clockwise from axis1 towards axis2). Its length is radius · |sweep|.
template <int dim>
std::unique_ptr<Curve<dim>> circle_arc_curve(const Vec<dim>& center, double radius, double start_angle,
                                             double sweep, const Vec<dim>& axis1, const Vec<dim>& axis2);

/// The full circle (closed), starting at center + radius · axis1, counter-clockwise.
template <int dim>
std::unique_ptr<Curve<dim>> circle_curve(const Vec<dim>& center, double radius, const Vec<dim>& axis1,
                                         const Vec<dim>& axis2);

/// The catenary of an inextensible string of the given length (m) hanging between the points p0 and
/// p1 under a uniform field pointing along `down` (any non-zero vector; only its direction matters).
/// Throws InputError if the length does not exceed the distance |p1 − p0| or if p0 and p1 lie on one
/// vertical.
template <int dim>
std::unique_ptr<Curve<dim>> catenary_curve(const Vec<dim>& p0, const Vec<dim>& p1, double length,
                                           const Vec<dim>& down);

/// The catenary in its own plane: horizontal coordinate X from p0 towards p1, Y up from p0,
///   Y(X) = a cosh((X − x_m)/a) + c, with Y(0) = 0 and Y(span) = rise.
struct CatenaryParameters {
  double a = 0;    ///< catenary parameter H / (λ g) (m)
  double x_m = 0;  ///< abscissa of the lowest point (m)
  double c = 0;    ///< offset (m): c = −a cosh(x_m / a)
};
/// Solves 2 a sinh(span / (2a)) = sqrt(length² − rise²) for a (Boost TOMS 748) and fixes x_m, c.
CatenaryParameters solve_catenary(double span, double rise, double length);

/// A chain of `links` equal links of material length `length` / links whose nodes sit on `curve`
/// at equal arc length (a closed curve needs closed = true and vice versa). Throws InputError if
/// |curve.length() − length| > length_tolerance · length, naming both lengths.
template <int dim>
Chain<dim> discretize(const Curve<dim>& curve, double length, double density, int links, bool closed,
                      double length_tolerance = 1e-6);

/// Unit tangents at the nodes: the direction of x_{i+1} − x_{i−1} (one-sided at open ends).
template <int dim>
Points<dim> node_tangents(const Chain<dim>& chain);

/// Every node moves with the velocity `velocity` (m/s).
template <int dim>
void set_uniform_velocity(Chain<dim>& chain, const Vec<dim>& velocity);

/// Every node moves along its tangent (node_tangents) with speed `speed` (m/s), towards larger s.
template <int dim>
void set_tangential_velocity(Chain<dim>& chain, double speed);

/// Per-node velocities (one column per node; throws InputError on a size mismatch).
template <int dim>
void set_node_velocities(Chain<dim>& chain, const Points<dim>& velocities);

}  // namespace chainsim
