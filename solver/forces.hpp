#pragma once
/// @file forces.hpp
/// Effects a scene can add to a string (opt-in: a model holds only the forces its scene declares),
/// and the prescribed motions of fixed and driven ends.
///
///   Gravity   f_i = m_i g                 conservative: booked in V = −Σ m_i g·x_i
///   UniformField  f_i = m_i a             any other uniform field (a UniformField, as gravity is)
///   Drag      f_i = −c m_i v_i            c in 1/s (a relaxation rate), its power goes to W_applied
///   EndLoad   f_node = F0 + A sin(ω t)    on one free node, its power goes to W_applied
///
/// Prescribed motions (EndPath) give the position, velocity and acceleration of a node as functions of
/// time: fixed point, "shake" x0 + A (1 − cos ωt) (starts from rest), "sine" x0 + A sin ωt, and
/// "linear" x0 + V t. A node with a prescribed motion has no momentum equation: it enters the tension
/// system with its acceleration (see tension_system.hpp).
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "mesh/chain.hpp"

namespace chainsim {

/// The nodes at time t (all nodes, prescribed ones included).
template <int dim>
struct NodeState {
  double t;                        ///< time (s)
  const Points<dim>& x;            ///< positions (m)
  const Points<dim>& v;            ///< velocities (m/s)
  const Eigen::VectorXd& mass;     ///< lumped masses (kg)
};

/// A force field acting on the nodes.
template <int dim>
class Force {
 public:
  virtual ~Force() = default;
  virtual std::string name() const = 0;
  /// Adds the force (N) this effect applies on every node to `force` (dim × n).
  virtual void add_force(const NodeState<dim>& s, Points<dim>& force) const = 0;
  /// True if the force derives from a potential booked in V (its work is then not in W_applied).
  virtual bool conservative() const { return false; }
  /// Potential energy (J) of the configuration; 0 for non-conservative forces.
  virtual double potential(const NodeState<dim>& /*s*/) const { return 0; }
  /// A conservative force declares here what material anywhere on the string has of its potential,
  /// not only the nodes: a uniform field a (m/s²) gives every mass m the force m a and the potential
  /// energy −m a·x, so its energy per unit length of string at x is −λ a·x, and the potential of any
  /// piece of material is −a·(its first moment ∫ x dm). That is what a module needs where material
  /// is not lumped on nodes (a front's partial link, the material a front holds off the arcs): the fronts book
  /// every declared field (StringModel::uniform_field). Nothing for a force that is not a uniform
  /// field; a module that cannot book such a conservative force refuses it (InputError).
  virtual std::optional<Vec<dim>> uniform_field() const { return std::nullopt; }
};

/// A uniform field a (m/s²): f_i = m_i a, V = −Σ m_i a·x_i (gravity is one, Gravity).
template <int dim>
class UniformField : public Force<dim> {
 public:
  UniformField(const Vec<dim>& a, std::string name) : a_(a), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  const Vec<dim>& field() const { return a_; }
  void add_force(const NodeState<dim>& s, Points<dim>& force) const override {
    for (int i = 0; i < force.cols(); ++i) force.col(i) += s.mass[i] * a_;
  }
  bool conservative() const override { return true; }
  double potential(const NodeState<dim>& s) const override {
    double v = 0;
    for (int i = 0; i < s.x.cols(); ++i) v -= s.mass[i] * a_.dot(s.x.col(i));
    return v;
  }
  std::optional<Vec<dim>> uniform_field() const override { return a_; }

 private:
  Vec<dim> a_;
  std::string name_;
};

/// Uniform gravity g (m/s²): f_i = m_i g, V = −Σ m_i g·x_i.
template <int dim>
class Gravity final : public UniformField<dim> {
 public:
  explicit Gravity(const Vec<dim>& g) : UniformField<dim>(g, "gravity") {}
  const Vec<dim>& g() const { return this->field(); }
};

/// Linear drag against the velocity: f_i = −c m_i v_i, c (1/s) >= 0.
template <int dim>
class Drag final : public Force<dim> {
 public:
  explicit Drag(double coefficient) : c_(coefficient) {}
  std::string name() const override { return "drag"; }
  double coefficient() const { return c_; }
  void add_force(const NodeState<dim>& s, Points<dim>& force) const override {
    for (int i = 0; i < force.cols(); ++i) force.col(i) -= c_ * s.mass[i] * s.v.col(i);
  }

 private:
  double c_;
};

/// A force on one node: F(t) = F0 + A sin(ω t) (N); only the part along the end link is carried by
/// the string (the rest accelerates the end node).
template <int dim>
class EndLoad final : public Force<dim> {
 public:
  EndLoad(int node, const Vec<dim>& force, const Vec<dim>& amplitude = Vec<dim>::Zero(), double omega = 0)
      : node_(node), force_(force), amplitude_(amplitude), omega_(omega) {}
  std::string name() const override { return fmt::format("load on node {}", node_); }
  int node() const { return node_; }
  Vec<dim> at(double t) const { return force_ + amplitude_ * std::sin(omega_ * t); }
  void add_force(const NodeState<dim>& s, Points<dim>& force) const override { force.col(node_) += at(s.t); }

 private:
  int node_;
  Vec<dim> force_, amplitude_;
  double omega_;
};

/// Prescribed motion of a node: x(t), v(t), a(t).
template <int dim>
class EndPath {
 public:
  virtual ~EndPath() = default;
  virtual Vec<dim> position(double t) const = 0;
  virtual Vec<dim> velocity(double t) const = 0;
  virtual Vec<dim> acceleration(double t) const = 0;
  virtual std::string description() const = 0;
};

/// A fixed point.
template <int dim>
class FixedPoint final : public EndPath<dim> {
 public:
  explicit FixedPoint(const Vec<dim>& x0) : x0_(x0) {}
  Vec<dim> position(double) const override { return x0_; }
  Vec<dim> velocity(double) const override { return Vec<dim>::Zero(); }
  Vec<dim> acceleration(double) const override { return Vec<dim>::Zero(); }
  std::string description() const override { return "fixed"; }

 private:
  Vec<dim> x0_;
};

/// Harmonic shaking. kind "shake": x0 + A (1 − cos ωt) (starts at rest); kind "sine": x0 + A sin ωt
/// (starts with velocity A ω: the string's initial velocities are projected onto the constraints).
template <int dim>
class HarmonicPath final : public EndPath<dim> {
 public:
  HarmonicPath(const Vec<dim>& x0, const Vec<dim>& amplitude, double omega, bool from_rest)
      : x0_(x0), a_(amplitude), w_(omega), from_rest_(from_rest) {}
  Vec<dim> position(double t) const override {
    return from_rest_ ? Vec<dim>(x0_ + a_ * (1 - std::cos(w_ * t))) : Vec<dim>(x0_ + a_ * std::sin(w_ * t));
  }
  Vec<dim> velocity(double t) const override {
    return from_rest_ ? Vec<dim>(a_ * w_ * std::sin(w_ * t)) : Vec<dim>(a_ * w_ * std::cos(w_ * t));
  }
  Vec<dim> acceleration(double t) const override {
    return from_rest_ ? Vec<dim>(a_ * w_ * w_ * std::cos(w_ * t)) : Vec<dim>(-a_ * w_ * w_ * std::sin(w_ * t));
  }
  std::string description() const override { return from_rest_ ? "shake" : "sine"; }

 private:
  Vec<dim> x0_, a_;
  double w_;
  bool from_rest_;
};

/// Motion at constant velocity: x0 + V t.
template <int dim>
class LinearPath final : public EndPath<dim> {
 public:
  LinearPath(const Vec<dim>& x0, const Vec<dim>& velocity) : x0_(x0), v_(velocity) {}
  Vec<dim> position(double t) const override { return x0_ + v_ * t; }
  Vec<dim> velocity(double) const override { return v_; }
  Vec<dim> acceleration(double) const override { return Vec<dim>::Zero(); }
  std::string description() const override { return "linear"; }

 private:
  Vec<dim> x0_, v_;
};

/// A node whose motion is prescribed.
template <int dim>
struct PrescribedNode {
  int node = 0;
  std::shared_ptr<const EndPath<dim>> path;
};

}  // namespace chainsim
