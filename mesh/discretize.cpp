// Initial shapes and velocity fields: see discretize.hpp.
#include "mesh/discretize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <boost/math/tools/toms748_solve.hpp>
#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim {

namespace {


// mesh sits below solver (mesh <- solver) and so cannot link errors.cpp: it throws the header-only
// InputError through these local checks, worded like solver's require_in_range().
void check_positive(const char* name, double value) {
  if (!(value > 0) || !std::isfinite(value))
    throw InputError(fmt::format("{} = {:g} is out of range: allowed {} > 0", name, value, name));
}
void check_finite(const char* name, double value) {
  if (!std::isfinite(value)) throw InputError(fmt::format("{} = {:g} is not a finite number", name, value));
}

/// Orthonormal pair (e1, e2) from two user axes, or InputError.
template <int dim>
std::pair<Vec<dim>, Vec<dim>> orthonormal_axes(const Vec<dim>& axis1, const Vec<dim>& axis2) {
  const double n1 = axis1.norm();
  if (!(n1 > 0)) throw InputError("shape.axis1 must be a non-zero vector");
  Vec<dim> e1 = axis1 / n1;
  Vec<dim> e2 = axis2 - axis2.dot(e1) * e1;
  const double n2 = e2.norm();
  if (!(n2 > 1e-12 * axis2.norm()) || !(n2 > 0))
    throw InputError("shape.axis2 must be a non-zero vector not parallel to shape.axis1");
  return {e1, e2 / n2};
}

template <int dim>
class Polyline final : public Curve<dim> {
 public:
  Polyline(const Points<dim>& vertices, bool closed) : closed_(closed) {
    if (vertices.cols() < 2)
      throw InputError(fmt::format("a polyline needs at least 2 points, got {}", vertices.cols()));
    if (!vertices.allFinite()) throw InputError("the polyline's points must be finite numbers");
    vertices_ = vertices;
    if (closed) {
      const double gap = (vertices.col(0) - vertices.col(vertices.cols() - 1)).norm();
      if (gap > 0) {
        vertices_.conservativeResize(dim, vertices.cols() + 1);
        vertices_.col(vertices.cols()) = vertices.col(0);
      }
      if (vertices_.cols() < 4) throw InputError("a closed polyline needs at least 3 distinct points");
    }
    cumulative_.assign(static_cast<std::size_t>(vertices_.cols()), 0.0);
    for (int k = 1; k < vertices_.cols(); ++k) {
      const double seg = (vertices_.col(k) - vertices_.col(k - 1)).norm();
      if (!(seg > 0))
        throw InputError(fmt::format("the polyline's points {} and {} coincide (zero-length segment)", k - 1, k));
      cumulative_[static_cast<std::size_t>(k)] = cumulative_[static_cast<std::size_t>(k - 1)] + seg;
    }
  }
  double length() const override { return cumulative_.back(); }
  bool closed() const override { return closed_; }
  Vec<dim> point(double s) const override {
    s = std::clamp(s, 0.0, length());
    auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
    std::size_t k = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - cumulative_.begin()));
    k = std::min(k, cumulative_.size() - 1);
    const double s0 = cumulative_[k - 1], s1 = cumulative_[k];
    const double w = (s - s0) / (s1 - s0);
    const int kk = static_cast<int>(k);
    return (1 - w) * vertices_.col(kk - 1) + w * vertices_.col(kk);
  }
  std::string description() const override {
    return fmt::format("{}polyline through {} points", closed_ ? "closed " : "", vertices_.cols());
  }

 private:
  Points<dim> vertices_;
  std::vector<double> cumulative_;
  bool closed_;
};

/// An open polyline whose interior vertices are rounded by fillets (rounded_polyline_curve).
///
/// At vertex k with unit directions a (incoming) and b (outgoing), cos θ = a·b and the unit normal
/// towards the fillet's centre is n = (b − (a·b) a) / sin θ. The fillet starts at the tangent point
/// T = x_k − t a, t = r tan(θ/2), and, σ ∈ [0, r θ] along it,
///   p(σ) = T + r sin(σ/r) a + r (1 − cos(σ/r)) n,
/// which is well conditioned even for small θ (no centre is formed) and ends at x_k + t b with the
/// direction b. The curve is a list of pieces, straight or circular, each starting at arc length
/// start_.
template <int dim>
class RoundedPolyline final : public Curve<dim> {
 public:
  RoundedPolyline(const Points<dim>& vertices, double radius) : vertex_count_(vertices.cols()), radius_(radius) {
    // The vertices are checked as for a plain polyline (and with the same messages).
    Polyline<dim> plain(vertices, false);
    check_positive("shape.corner_radius", radius);
    const int n = static_cast<int>(vertices.cols());
    const auto vertex = [&](int k) -> Vec<dim> { return vertices.col(k); };
    std::vector<Vec<dim>> direction(static_cast<std::size_t>(n - 1));  // of segment k: x_k -> x_{k+1}
    std::vector<double> segment(static_cast<std::size_t>(n - 1));
    for (int k = 0; k + 1 < n; ++k) {
      const Vec<dim> d = vertex(k + 1) - vertex(k);
      segment[static_cast<std::size_t>(k)] = d.norm();
      direction[static_cast<std::size_t>(k)] = d / d.norm();
    }
    // 1. The turn θ_k at every interior vertex, its normal, and its tangent factor tan(θ_k/2).
    std::vector<double> turn(static_cast<std::size_t>(n), 0.0), factor(static_cast<std::size_t>(n), 0.0);
    std::vector<Vec<dim>> normal(static_cast<std::size_t>(n), Vec<dim>::Zero());
    for (int k = 1; k + 1 < n; ++k) {
      const auto K = static_cast<std::size_t>(k);
      const Vec<dim>& a = direction[K - 1];
      const Vec<dim>& b = direction[K];
      const double cos_turn = a.dot(b);
      const Vec<dim> w = b - cos_turn * a;
      const double sin_turn = w.norm();
      const double theta = std::atan2(sin_turn, cos_turn);
      if (kPi - theta < kTurnBack)
        throw InputError(fmt::format(
            "shape.corner_radius = {:g} m cannot round point {} = {}: the polyline turns back on itself there (it "
            "turns by {:.9g} deg, to within {:g} rad of 180 deg), and no arc is tangent to both of its segments",
            radius, k, show_point<dim>(vertex(k)), theta * 180 / kPi, kTurnBack));
      if (theta < kStraight) continue;  // straight through: no arc
      turn[K] = theta;
      factor[K] = std::tan(0.5 * theta);
      normal[K] = w / sin_turn;
    }
    // 2. Every segment must hold the tangent lengths of the fillets at its two ends. The segment
    //    with the smallest radius that fits decides: if it fails, it is named with that radius.
    int tightest = -1;
    double largest_fit = INFINITY;
    for (int k = 0; k + 1 < n; ++k) {
      const auto K = static_cast<std::size_t>(k);
      const double need = factor[K] + factor[K + 1];
      if (need > 0 && segment[K] / need < largest_fit) {
        largest_fit = segment[K] / need;
        tightest = k;
      }
    }
    if (tightest >= 0) {
      const auto K = static_cast<std::size_t>(tightest);
      const double t0 = radius * factor[K], t1 = radius * factor[K + 1];
      if (t0 + t1 > segment[K] * (1 + kFitTolerance))
        throw InputError(fmt::format(
            "shape.corner_radius = {:g} m is too large for the segment from point {} = {} to point {} = {}: it is "
            "{:.9g} m long but the fillets at its ends need {:.9g} m of it (tangent lengths {:.9g} m + {:.9g} m); the "
            "largest corner_radius that fits every segment is {:.9g} m",
            radius, tightest, show_point<dim>(vertex(tightest)), tightest + 1, show_point<dim>(vertex(tightest + 1)),
            segment[K], t0 + t1, t0, t1, largest_fit));
    }
    // 3. The pieces: segment k without its tangent lengths, then the fillet at vertex k + 1.
    double s = 0;
    for (int k = 0; k + 1 < n; ++k) {
      const auto K = static_cast<std::size_t>(k);
      const double t0 = radius * factor[K], t1 = radius * factor[K + 1];
      const double straight = segment[K] - t0 - t1;
      if (straight > 0) {
        pieces_.push_back({s, straight, 0.0, vertex(k) + t0 * direction[K], direction[K], Vec<dim>::Zero()});
        s += straight;
      }
      if (turn[K + 1] > 0) {
        const double arc = radius * turn[K + 1];
        pieces_.push_back({s, arc, radius, vertex(k + 1) - t1 * direction[K], direction[K], normal[K + 1]});
        s += arc;
      }
    }
    length_ = s;
  }
  double length() const override { return length_; }
  Vec<dim> point(double s) const override {
    s = std::clamp(s, 0.0, length_);
    auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s, [](double v, const Piece& p) { return v < p.start; });
    const Piece& p = it == pieces_.begin() ? pieces_.front() : *std::prev(it);  // the last piece starting <= s
    const double sigma = std::min(s - p.start, p.length);
    if (p.radius == 0) return p.origin + sigma * p.direction;
    const double phi = sigma / p.radius;
    return p.origin + p.radius * std::sin(phi) * p.direction + p.radius * (1 - std::cos(phi)) * p.normal;
  }
  std::string description() const override {
    return fmt::format("polyline through {} points with corners rounded to radius {:g} m", vertex_count_, radius_);
  }

 private:
  /// Within this angle (rad) of π a vertex turns back on itself: it has no fillet.
  static constexpr double kTurnBack = 1e-9;
  /// Below this turn (rad) a vertex is straight through: its fillet would differ from the corner by
  /// r θ²/8 < 1e-24 r.
  static constexpr double kStraight = 1e-12;
  /// Relative excess of the tangent lengths over a segment still accepted (an exact fit, in floating point).
  static constexpr double kFitTolerance = 1e-12;

  /// A straight piece (radius 0): origin + σ direction; a fillet: origin + r sin(σ/r) direction +
  /// r (1 − cos(σ/r)) normal; σ ∈ [0, length].
  struct Piece {
    double start, length, radius;
    Vec<dim> origin, direction, normal;
  };
  std::vector<Piece> pieces_;
  Eigen::Index vertex_count_;
  double radius_, length_ = 0;
};

template <int dim>
class CircleArc final : public Curve<dim> {
 public:
  CircleArc(const Vec<dim>& center, double radius, double start, double sweep, const Vec<dim>& axis1,
            const Vec<dim>& axis2, bool closed)
      : center_(center), radius_(radius), start_(start), sweep_(sweep), closed_(closed) {
    check_positive("shape.radius", radius);
    check_finite("shape.start_angle", start);
    if (!center.allFinite()) throw InputError("shape.center must be finite");
    if (!closed) {
      check_finite("shape.sweep", sweep);
      if (!(std::abs(sweep) > 0) || std::abs(sweep) > 2 * kPi + 1e-12)
        throw InputError(fmt::format("shape.sweep = {:g} rad is out of range: allowed 0 < |sweep| <= 2 pi", sweep));
    }
    std::tie(e1_, e2_) = orthonormal_axes<dim>(axis1, axis2);
  }
  double length() const override { return radius_ * std::abs(sweep_); }
  bool closed() const override { return closed_; }
  Vec<dim> point(double s) const override {
    s = std::clamp(s, 0.0, length());
    const double theta = start_ + (sweep_ > 0 ? 1.0 : -1.0) * s / radius_;
    return center_ + radius_ * (std::cos(theta) * e1_ + std::sin(theta) * e2_);
  }
  std::string description() const override {
    return closed_ ? fmt::format("circle of radius {:g} m", radius_)
                   : fmt::format("circular arc of radius {:g} m through {:g} rad", radius_, sweep_);
  }

 private:
  Vec<dim> center_;
  double radius_, start_, sweep_;
  bool closed_;
  Vec<dim> e1_, e2_;
};

template <int dim>
class Catenary final : public Curve<dim> {
 public:
  Catenary(const Vec<dim>& p0, const Vec<dim>& p1, double length, const Vec<dim>& down)
      : p0_(p0), length_(length) {
    check_positive("string.length", length);
    if (!p0.allFinite() || !p1.allFinite()) throw InputError("the catenary's end points must be finite");
    const double dn = down.norm();
    if (!(dn > 0)) throw InputError("a catenary needs a gravity direction: the gravity vector is zero");
    up_ = -down / dn;
    const Vec<dim> d = p1 - p0;
    const double distance = d.norm();
    if (!(length > distance))
      throw InputError(fmt::format(
          "the catenary between shape.start and shape.end needs a string longer than the distance "
          "between them: string.length = {:.9g} m but the points are {:.9g} m apart",
          length, distance));
    rise_ = d.dot(up_);
    Vec<dim> horizontal = d - rise_ * up_;
    span_ = horizontal.norm();
    if (!(span_ > 1e-12 * distance))
      throw InputError("the catenary's end points shape.start and shape.end lie on one vertical line");
    u_ = horizontal / span_;
    p_ = solve_catenary(span_, rise_, length);
  }
  double length() const override { return length_; }
  Vec<dim> point(double s) const override {
    s = std::clamp(s, 0.0, length_);
    const double a = p_.a;
    const double x = p_.x_m + a * std::asinh(s / a - std::sinh(p_.x_m / a));
    const double y = a * std::cosh((x - p_.x_m) / a) + p_.c;
    return p0_ + x * u_ + y * up_;
  }
  std::string description() const override {
    return fmt::format("catenary with parameter a = {:.6g} m over a span of {:.6g} m", p_.a, span_);
  }

 private:
  Vec<dim> p0_, up_, u_;
  double length_, rise_ = 0, span_ = 0;
  CatenaryParameters p_;
};

}  // namespace

CatenaryParameters solve_catenary(double span, double rise, double length) {
  if (!(span > 0) || !(length * length > span * span + rise * rise))
    throw InputError(fmt::format("a catenary of length {:g} m cannot span {:g} m horizontally and {:g} m "
                                 "vertically: the length must exceed the chord", length, span, rise));
  // With z = span / (2a): sinh(z)/z = r, r = sqrt(length² − rise²)/span > 1. Solved in log form
  // (log sinh z = z + log1p(−e^{−2z}) − log 2) so large sags do not overflow.
  const double r = std::sqrt(length * length - rise * rise) / span;
  const double log_r = std::log(r);
  auto g = [&](double z) {
    const double log_sinh_over_z =
        z < 1e-4 ? std::log1p(z * z / 6.0) : z + std::log1p(-std::exp(-2 * z)) - std::log(2.0) - std::log(z);
    return log_sinh_over_z - log_r;
  };
  double lo = 1e-8, hi = 1.0;
  while (g(hi) < 0) hi *= 2;
  boost::uintmax_t iterations = 200;
  auto root = boost::math::tools::toms748_solve(g, lo, hi, boost::math::tools::eps_tolerance<double>(52),
                                                iterations);
  const double z = 0.5 * (root.first + root.second);
  CatenaryParameters p;
  p.a = span / (2 * z);
  const double chord_length = std::sqrt(length * length - rise * rise);  // = 2 a sinh(span / 2a)
  p.x_m = 0.5 * span - p.a * std::asinh(rise / chord_length);
  p.c = -p.a * std::cosh(p.x_m / p.a);
  return p;
}

template <int dim>
std::unique_ptr<Curve<dim>> polyline_curve(const Points<dim>& vertices, bool closed) {
  return std::make_unique<Polyline<dim>>(vertices, closed);
}

template <int dim>
std::unique_ptr<Curve<dim>> rounded_polyline_curve(const Points<dim>& vertices, double corner_radius) {
  return std::make_unique<RoundedPolyline<dim>>(vertices, corner_radius);
}

template <int dim>
std::unique_ptr<Curve<dim>> circle_arc_curve(const Vec<dim>& center, double radius, double start_angle,
                                             double sweep, const Vec<dim>& axis1, const Vec<dim>& axis2) {
  return std::make_unique<CircleArc<dim>>(center, radius, start_angle, sweep, axis1, axis2, false);
}

template <int dim>
std::unique_ptr<Curve<dim>> circle_curve(const Vec<dim>& center, double radius, const Vec<dim>& axis1,
                                         const Vec<dim>& axis2) {
  return std::make_unique<CircleArc<dim>>(center, radius, 0.0, 2 * kPi, axis1, axis2, true);
}

template <int dim>
std::unique_ptr<Curve<dim>> catenary_curve(const Vec<dim>& p0, const Vec<dim>& p1, double length,
                                           const Vec<dim>& down) {
  return std::make_unique<Catenary<dim>>(p0, p1, length, down);
}

template <int dim>
Chain<dim> discretize(const Curve<dim>& curve, double length, double density, int links, bool closed,
                      double length_tolerance) {
  check_positive("string.length", length);
  if (!(length_tolerance > 0 && length_tolerance <= 1))
    throw InputError(fmt::format("shape.length_tolerance = {:g} is out of range: allowed 0 < length_tolerance <= 1",
                                 length_tolerance));
  if (links < (closed ? 3 : 1))
    throw InputError(fmt::format("string.nodes = {} is too small: a {} string needs at least {} nodes",
                                 closed ? links : links + 1, closed ? "closed" : "open", closed ? 3 : 2));
  if (curve.closed() != closed)
    throw InputError(fmt::format("the shape ({}) is {} but string.closed = {}", curve.description(),
                                 curve.closed() ? "a closed curve" : "an open curve", closed));
  const double shape_length = curve.length();
  if (!(std::abs(shape_length - length) <= length_tolerance * length))
    throw InputError(fmt::format(
        "the shape ({}) is {:.9g} m long but string.length = {:.9g} m: they differ by {:.3g} m, more than "
        "shape.length_tolerance = {:g} (relative)",
        curve.description(), shape_length, length, shape_length - length, length_tolerance));
  Chain<dim> chain = Chain<dim>::uniform(density, length, links, closed);
  for (int i = 0; i < chain.num_nodes(); ++i) chain.positions().col(i) = curve.point(shape_length * i / links);
  return chain;
}

template <int dim>
Points<dim> node_tangents(const Chain<dim>& chain) {
  const int n = chain.num_nodes();
  const auto& x = chain.positions();
  Points<dim> t(dim, n);
  for (int i = 0; i < n; ++i) {
    int prev = i - 1, next = i + 1;
    if (chain.closed()) {
      prev = (i + n - 1) % n;
      next = (i + 1) % n;
    } else {
      prev = std::max(prev, 0);
      next = std::min(next, n - 1);
    }
    Vec<dim> d = x.col(next) - x.col(prev);
    const double norm = d.norm();
    if (!(norm > 0)) throw InputError(fmt::format("the tangent at node {} is undefined (coincident nodes)", i));
    t.col(i) = d / norm;
  }
  return t;
}

template <int dim>
void set_uniform_velocity(Chain<dim>& chain, const Vec<dim>& velocity) {
  if (!velocity.allFinite()) throw InputError("velocity.value must be finite");
  chain.velocities().colwise() = velocity;
}

template <int dim>
void set_tangential_velocity(Chain<dim>& chain, double speed) {
  check_finite("velocity.speed", speed);
  chain.velocities() = speed * node_tangents(chain);
}

template <int dim>
void set_node_velocities(Chain<dim>& chain, const Points<dim>& velocities) {
  if (velocities.cols() != chain.num_nodes())
    throw InputError(fmt::format("velocity.values has {} entries but the string has {} nodes", velocities.cols(),
                                 chain.num_nodes()));
  if (!velocities.allFinite()) throw InputError("velocity.values must be finite");
  chain.velocities() = velocities;
}

#define CHAINSIM_INSTANTIATE(D)                                                                         \
  template std::unique_ptr<Curve<D>> polyline_curve<D>(const Points<D>&, bool);                        \
  template std::unique_ptr<Curve<D>> rounded_polyline_curve<D>(const Points<D>&, double);              \
  template std::unique_ptr<Curve<D>> circle_arc_curve<D>(const Vec<D>&, double, double, double,       \
                                                         const Vec<D>&, const Vec<D>&);                \
  template std::unique_ptr<Curve<D>> circle_curve<D>(const Vec<D>&, double, const Vec<D>&, const Vec<D>&); \
  template std::unique_ptr<Curve<D>> catenary_curve<D>(const Vec<D>&, const Vec<D>&, double, const Vec<D>&); \
  template Chain<D> discretize<D>(const Curve<D>&, double, double, int, bool, double);                 \
  template Points<D> node_tangents<D>(const Chain<D>&);                                                \
  template void set_uniform_velocity<D>(Chain<D>&, const Vec<D>&);                                     \
  template void set_tangential_velocity<D>(Chain<D>&, double);                                         \
  template void set_node_velocities<D>(Chain<D>&, const Points<D>&);
CHAINSIM_INSTANTIATE(2)
CHAINSIM_INSTANTIATE(3)
#undef CHAINSIM_INSTANTIATE

}  // namespace chainsim
