// A touchdown front: see touchdown_front.hpp (the scheme) and docs/model.md §10 (the physics).
#include "touchdown_front.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

namespace {
/// n × e in 3D (zero in 2D, where no code path uses it).
template <int dim>
Vec<dim> plane_cross(const Vec<dim>& n, const Vec<dim>& e) {
  if constexpr (dim == 3) return n.cross(e);
  else return Vec<dim>::Zero();
}
}  // namespace

template <int dim>
TouchdownFront<dim>::TouchdownFront(const TouchdownSpec<dim>& spec)
    : point_(spec.point), normal_(spec.normal.normalized()), surface_(spec.name) {
  this->dissipation = spec.dissipation;
  this->expected_s0 = spec.s0;
}

template <int dim>
void TouchdownFront<dim>::cut(FrontLayout& layout) {
  SplitLinkFront<dim>::cut(layout);
  lying_last_ = layout.splits.back();
}

template <int dim>
void TouchdownFront<dim>::initialize(StringModel<dim>& model) {
  const Points<dim>& x = model.x();
  const int a = lying_last_, b = a + 1;
  const Vec<dim> d = a > 0 ? Vec<dim>(x.col(a) - x.col(a - 1)) : Vec<dim>(x.col(b) - x.col(a));
  along_ = d - d.dot(normal_) * normal_;
  if (!(along_.norm() > 0))
    throw InputError(fmt::format("{}: the string does not run along the plane where it leaves it", surface_));
  along_.normalize();
}

template <int dim>
typename TouchdownFront<dim>::Geometry TouchdownFront<dim>::nodes(const StringModel<dim>& model) const {
  Geometry g;
  g.a = this->node_a(model);
  g.b = this->node_b(model);
  g.c = g.b + 1;
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  if (B.num_links() < 1) throw RecoverableError("the arc after the touchdown front has no full link");
  return g;
}

template <int dim>
typename TouchdownFront<dim>::Geometry TouchdownFront<dim>::geometry(const StringModel<dim>& model) const {
  if constexpr (dim == 3) return geometry_3d(model);
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  Geometry g = nodes(model);
  const Vec<dim>& e = along_;
  const Vec<dim>& n = normal_;
  const Vec<dim> link = x.col(g.c) - x.col(g.b), w = v.col(g.c) - v.col(g.b);
  g.L = link.norm();
  g.t = link / g.L;
  g.cos = g.t.dot(e);
  g.sin = g.t.dot(n);
  if (!(g.sin > 0)) throw RecoverableError("the arc after the touchdown front does not rise from the plane");
  g.t_perp = g.cos * n - g.sin * e;
  g.theta_dot = g.t_perp.dot(w) / g.L;
  g.t_w = g.t.dot(w);
  g.y = n.dot(x.col(g.b) - point_);
  g.y_dot = n.dot(v.col(g.b));
  g.tan_half = (1 - g.cos) / g.sin;
  g.l_plus = g.y / g.sin;
  g.l_minus = this->m_.h - g.l_plus;
  g.x0 = x.col(g.b) - g.l_plus * g.t;
  g.s0_dot = -g.y_dot / g.sin + g.y * g.cos * g.theta_dot / (g.sin * g.sin);
  return g;
}

template <int dim>
TouchdownConstraint<dim> touchdown_split_constraint(const Vec<dim>& xp, const Vec<dim>& xa, const Vec<dim>& xb,
                                                    const Vec<dim>& xc, const Vec<dim>& vp, const Vec<dim>& va,
                                                    const Vec<dim>& vb, const Vec<dim>& vc, bool has_p,
                                                    const Vec<dim>& e_fixed, const Vec<dim>& point,
                                                    const Vec<dim>& n, double h) {
  using Mat = Eigen::Matrix<double, dim, dim>;
  TouchdownConstraint<dim> k;
  const Mat P = Mat::Identity() - n * n.transpose();  // onto the plane
  // e and its rates at zero accelerations: ė = Q_e u̇/|u|, ë = −2 ė (e·u̇)/|u| − e |ė|² (u = P (x_a − x_p)).
  Vec<dim> e = e_fixed, e_d = Vec<dim>::Zero(), e_dd = Vec<dim>::Zero();
  double ue = 0;
  if (has_p) {
    const Vec<dim> u = P * (xa - xp), wu = P * (va - vp);
    ue = u.norm();
    if (!(ue > 0)) throw RecoverableError("the lying part's last link is normal to the plane at the touchdown front");
    e = u / ue;
    e_d = (wu - e.dot(wu) * e) / ue;
    e_dd = -2 * e.dot(wu) / ue * e_d - e_d.squaredNorm() * e;
  }
  // t and its rates likewise, from arc B's first link (b, c).
  const Vec<dim> link = xc - xb, w = vc - vb;
  const double L = link.norm();
  const Vec<dim> t = link / L, t_d = (w - t.dot(w) * t) / L;
  const Vec<dim> t_dd = -2 * t.dot(w) / L * t_d - t_d.squaredNorm() * t;
  const double c = t.dot(e), s = t.dot(n);
  if (!(s > 0)) throw RecoverableError("the arc after the touchdown front does not rise from the plane");
  const double y = n.dot(xb - point), y_d = n.dot(vb);
  const double F = (1 - c) / s;  // tan(θ/2) in the plane of e and n
  k.e = e;
  k.t = t;
  k.cos = c;
  k.sin = s;
  k.l_plus = y / s;
  k.l_minus = h - k.l_plus;
  k.x0 = xb - k.l_plus * t;
  const double s_d = t_d.dot(n);
  k.s0_dot = -y_d / s + y * s_d / (s * s);
  k.value = (xb - xa).dot(e) + y * F - h;
  // The gradient: ∂F/∂t = −e/s − (1 − c) n/s², ∂t/∂x_c = Q_t/L; ∂C/∂e = x_b − x_a − l⁺ t = x0 − x_a = r, and
  // ∂e/∂x_a = Q_e P/|u|, so that ∂C/∂x_a = −e + (P r − (e·r) e)/|u| (in the plane) and ∂C/∂x_p its opposite.
  const Vec<dim> Ft = -e / s - (1 - c) / (s * s) * n;
  const Vec<dim> QFt = Ft - t.dot(Ft) * t;
  const Vec<dim> r = xb - xa - k.l_plus * t;
  const Vec<dim> ga = has_p ? Vec<dim>((P * r - e.dot(r) * e) / ue) : Vec<dim>::Zero();
  k.gradient.resize(dim, 4);
  k.gradient.col(0) = -ga;
  k.gradient.col(1) = -e + ga;
  k.gradient.col(2) = e + F * n - (y / L) * QFt;
  k.gradient.col(3) = (y / L) * QFt;
  // C̈ at zero accelerations: d²/dt² [(x_b − x_a)·e] + 2 ẏ Ḟ + y F̈ (ÿ = 0 then), F = (1 − c)/s.
  const double c_d = t_d.dot(e) + t.dot(e_d), c_dd = t_dd.dot(e) + 2 * t_d.dot(e_d) + t.dot(e_dd);
  const double s_dd = t_dd.dot(n);
  const double F_d = -c_d / s - (1 - c) * s_d / (s * s);
  const double F_dd = -c_dd / s + 2 * c_d * s_d / (s * s) - (1 - c) * s_dd / (s * s) + 2 * (1 - c) * s_d * s_d / (s * s * s);
  k.curvature = 2 * (vb - va).dot(e_d) + (xb - xa).dot(e_dd) + 2 * y_d * F_d + y * F_dd;
  // The lateral constraint D = (x_b − x_a)·b − y G, G = (t·b)/s, b = n × e: ∂D/∂b = r, and b·δ = (n × δe)·r =
  // δe·(r × n), so that through e ∂D/∂x_a = (P r×n − (e·r×n) e)/|u| and ∂D/∂x_p its opposite; ∂G/∂t = b/s −
  // (t·b) n/s².
  const Vec<dim> bn = plane_cross<dim>(n, e), bn_d = plane_cross<dim>(n, e_d), bn_dd = plane_cross<dim>(n, e_dd);
  const double beta = t.dot(bn), G = beta / s;
  k.lateral_value = (xb - xa).dot(bn) - y * G;
  const Vec<dim> Gt = bn / s - beta / (s * s) * n;
  const Vec<dim> QGt = Gt - t.dot(Gt) * t;
  const Vec<dim> rn = plane_cross<dim>(r, n);
  const Vec<dim> gb = has_p ? Vec<dim>((P * rn - e.dot(rn) * e) / ue) : Vec<dim>::Zero();
  k.lateral_gradient.resize(dim, 4);
  k.lateral_gradient.col(0) = -gb;
  k.lateral_gradient.col(1) = -bn + gb;
  k.lateral_gradient.col(2) = bn - G * n + (y / L) * QGt;
  k.lateral_gradient.col(3) = -(y / L) * QGt;
  const double beta_d = t_d.dot(bn) + t.dot(bn_d), beta_dd = t_dd.dot(bn) + 2 * t_d.dot(bn_d) + t.dot(bn_dd);
  const double G_d = beta_d / s - beta * s_d / (s * s);
  const double G_dd = beta_dd / s - 2 * beta_d * s_d / (s * s) - beta * s_dd / (s * s) + 2 * beta * s_d * s_d / (s * s * s);
  k.lateral_curvature = 2 * (vb - va).dot(bn_d) + (xb - xa).dot(bn_dd) - 2 * y_d * G_d - y * G_dd;
  return k;
}

template <int dim>
typename TouchdownFront<dim>::Geometry TouchdownFront<dim>::geometry_3d(const StringModel<dim>& model) const {
  const Points<dim>& x = model.x();
  const Points<dim>& v = model.v();
  Geometry g = nodes(model);
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  g.p = A.num_links() >= 1 ? g.a - 1 : -1;
  const int p = std::max(g.p, 0);
  g.split = touchdown_split_constraint<dim>(x.col(p), x.col(g.a), x.col(g.b), x.col(g.c), v.col(p), v.col(g.a),
                                            v.col(g.b), v.col(g.c), g.p >= 0, along_, point_, normal_, this->m_.h);
  g.e = g.split.e;
  g.t = g.split.t;
  g.cos = g.split.cos;
  g.sin = g.split.sin;
  g.x0 = g.split.x0;
  g.l_plus = g.split.l_plus;
  g.l_minus = g.split.l_minus;
  g.s0_dot = g.split.s0_dot;
  g.tan_half = (1 - g.cos) / g.sin;
  g.y = normal_.dot(x.col(g.b) - point_);
  g.y_dot = normal_.dot(v.col(g.b));
  g.L = (x.col(g.c) - x.col(g.b)).norm();
  return g;
}

template <int dim>
void TouchdownFront<dim>::set_state(const StringModel<dim>& model, const Geometry& g, const Vec<dim>& e, double tau_m,
                                    double tau_p, FrontState<dim>& s, Eigen::VectorXd& mass) const {
  const double lambda = this->m_.lambda;
  s.s0 = model.chain().node_coordinate(g.a) + g.l_minus;
  s.s0_dot = g.s0_dot;
  s.l_minus = g.l_minus;
  s.l_plus = g.l_plus;
  s.direction = e;
  s.position = g.x0;
  s.tension_minus = tau_m;
  s.tension_plus = tau_p;
  s.opening = theta_;
  s.inflow = 0;
  s.plane_normal = normal_;
  mass[g.a] += lambda * g.l_minus;
  mass[g.b] += lambda * g.l_plus;
}

template <int dim>
void TouchdownFront<dim>::evaluate(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                                   Points<dim>& force) {
  if constexpr (dim == 3) {
    evaluate_3d(model, s, mass, force);
    return;
  }
  const Points<dim>& v = model.v();
  const double lambda = this->m_.lambda, f = this->dissipation;
  const Geometry g = geometry(model);
  const int a = g.a, b = g.b;
  lying_last_ = a;
  theta_ = std::atan2(g.sin, g.cos);
  const Vec<dim>& e = along_;
  const double sd = g.s0_dot;
  // The jump conditions with the discrete [v] = v_b − v_a: the arc's end pulled along its first link t by τ⁺,
  // so that the loads work at −½ f λ |ṡ0| |[v]|² exactly (τ⁺ = (1 − f sgn ṡ0) λ ṡ0² where the sides are
  // compatible, −t·[v] = ṡ0 (1 − cos θ)); the lying end along e by τ⁻, so that the momentum along the
  // plane is exact.
  const Vec<dim> ud = v.col(b) - v.col(a);
  const double jump2 = ud.squaredNorm();
  const double tau_p = jump::touchdown_tension_plus<dim>(g.t, g.cos, ud, f, lambda, sd);
  const double tau_m = jump::touchdown_tension_minus<dim>(tau_p, e, g.cos, ud, lambda, sd);
  set_state(model, g, e, tau_m, tau_p, s, mass);
  force.col(a) += tau_m * e;
  force.col(b) -= tau_p * g.t;
  // The arc's partial link continues its first link (c, b) beyond b to x0: its weight at its midpoint, so that
  // it does the work its potential (potential_moment) says as the link turns. The lying partial link needs no
  // couple: it runs along the plane's fixed e, and its weight on a works as at its midpoint.
  this->add_partial_weight(model, b, g.c, g.l_plus, lambda, force);
  // The front's reaction: what the loads and the material moved from b to a change in the lumped
  // momentum (normal to the plane by τ⁻'s choice); the constraint's share is added where it is known.
  s.reaction = jump::touchdown_reaction<dim>(e, g.t, tau_m, tau_p, ud, lambda, sd);
  s.power_shock = -jump::dissipation_rate(f, lambda, sd, jump2);
  // The reaction's work on node a's drift off the plane (zero on the plane): the loads' power is W_s plus
  // this, exactly.
  s.power_heap = s.reaction.dot(normal_) * normal_.dot(v.col(a));
}

template <int dim>
void TouchdownFront<dim>::evaluate_3d(const StringModel<dim>& model, FrontState<dim>& s, Eigen::VectorXd& mass,
                                      Points<dim>& force) {
  // The 2D scheme with e the lying part's last link projected on the plane (docs/model.md §10, "A touchdown front
  // in 3D"): τ⁺ as in 2D (the loads' power −½ f λ |ṡ0| |[v]|² for any [v] and any load on a), and the load on a the
  // projection on the plane of τ⁺ t + λ ṡ0 [v], τ⁻ e + τ_b b (b = n × e), so that the front's reaction is normal
  // to the plane: τ_b = λ ṡ0 [v]·b + τ⁺ t·b, zero on a compatible state whose arc leaves in the plane of e and n,
  // −f λ ṡ0 |ṡ0| t·b otherwise (the jump conditions' lateral balance, which the lying part's end takes).
  const Points<dim>& v = model.v();
  const double lambda = this->m_.lambda, f = this->dissipation;
  const Geometry g = geometry_3d(model);
  const int a = g.a, b = g.b;
  lying_last_ = a;
  along_ = g.e;
  elevation_ = g.sin;
  off_plane_ = std::abs(g.t.dot(plane_cross<dim>(normal_, g.e)));
  const Vec<dim>& e = g.e;
  const Vec<dim> bn = plane_cross<dim>(normal_, e);
  theta_ = std::atan2((g.t - g.cos * e).norm(), g.cos);
  const double sd = g.s0_dot;
  const Vec<dim> ud = v.col(b) - v.col(a);
  const double jump2 = ud.squaredNorm();
  const double tau_p = jump::touchdown_tension_plus<dim>(g.t, g.cos, ud, f, lambda, sd);
  const double tau_m = jump::touchdown_tension_minus<dim>(tau_p, e, g.cos, ud, lambda, sd);
  const double tau_b = jump::touchdown_tension_minus<dim>(tau_p, bn, g.t.dot(bn), ud, lambda, sd);
  set_state(model, g, e, tau_m, tau_p, s, mass);
  force.col(a) += tau_m * e + tau_b * bn;
  force.col(b) -= tau_p * g.t;
  // Both partial links continue a full link straight: the arc's its first link (c, b) beyond b, the lying one the
  // lying part's last link (p, a) beyond a, which turns in 3D: each weight at its midpoint (the ledger's V).
  this->add_partial_weight(model, b, g.c, g.l_plus, lambda, force);
  if (g.p >= 0) this->add_partial_weight(model, a, g.p, g.l_minus, lambda, force);
  s.reaction = jump::touchdown_reaction<dim>(e, g.t, tau_m, tau_p, ud, lambda, sd) + tau_b * bn;
  s.power_shock = -jump::dissipation_rate(f, lambda, sd, jump2);
  s.power_heap = s.reaction.dot(normal_) * normal_.dot(v.col(a));
}

template <int dim>
void TouchdownFront<dim>::constraints(const StringModel<dim>& model, const FrontState<dim>& /*state*/,
                                      std::vector<NodeConstraint<dim>>& out) const {
  // The split link's material: along the plane from x_a to x0, and on from x0 to x_b along the arc's first
  // link: C = (x_b − x_a)·e + y_b tan(θ/2) − h = l⁻ + l⁺ − h on the plane (y_b the height of b, θ the
  // link's angle to the plane). Its gradient on a is along e (a held node moves along the plane).
  const Geometry g = geometry(model);
  if constexpr (dim == 3) {
    NodeConstraint<dim> c;
    const int first = g.p >= 0 ? 0 : 1;  // the lying part's last link (p, a), if it has one
    for (int q = first; q < 4; ++q) c.nodes.push_back(q == 0 ? g.p : q == 1 ? g.a : q == 2 ? g.b : g.c);
    NodeConstraint<dim> lateral = c;  // the same nodes
    c.gradient = g.split.gradient.rightCols(4 - first);
    c.value = g.split.value;
    c.curvature = g.split.curvature;
    lateral.gradient = g.split.lateral_gradient.rightCols(4 - first);
    lateral.value = g.split.lateral_value;
    lateral.curvature = g.split.lateral_curvature;
    constraint_index_ = out.size();
    out.push_back(std::move(c));
    out.push_back(std::move(lateral));
    return;
  }
  const Points<dim>& x = model.x();
  const Vec<dim>& e = along_;
  const Vec<dim>& n = normal_;
  const double T = g.tan_half, T1 = 1 / (1 + g.cos);  // tan(θ/2) and its derivative in θ
  NodeConstraint<dim> c;
  c.nodes = {g.a, g.b, g.c};
  c.gradient.resize(dim, 3);
  c.gradient.col(0) = -e;
  c.gradient.col(1) = e + T * n - g.y * T1 * g.t_perp / g.L;
  c.gradient.col(2) = g.y * T1 * g.t_perp / g.L;
  c.value = (x.col(g.b) - x.col(g.a)).dot(e) + g.y * T - this->m_.h;
  // C̈ at zero accelerations: 2 ẏ T' θ̇ + y (T' T θ̇² + T' θ̈0), θ̈0 = −2 θ̇ (t·w)/L.
  c.curvature = 2 * g.y_dot * T1 * g.theta_dot +
                g.y * (T1 * T * g.theta_dot * g.theta_dot - 2 * T1 * g.theta_dot * g.t_w / g.L);
  constraint_index_ = out.size();
  out.push_back(std::move(c));
}

template <int dim>
Vec<dim> TouchdownFront<dim>::constraint_force(const StringModel<dim>& model) const {
  // The constraint's forces sum to μ tan(θ/2) n (it ties the string to the plane): the plane's share of the
  // front's reaction that the multiplier carries.
  const auto& cs = model.node_constraints();
  const Eigen::VectorXd& mu = model.constraint_multipliers();
  const std::size_t k = constraint_index_;
  if (k >= cs.size() || static_cast<Eigen::Index>(k) >= mu.size()) return Vec<dim>::Zero();  // none solved yet
  Vec<dim> sum = Vec<dim>::Zero();
  for (Eigen::Index q = 0; q < cs[k].gradient.cols(); ++q) sum += cs[k].gradient.col(q);
  if constexpr (dim == 2) {
    return mu[static_cast<Eigen::Index>(k)] * sum;
  } else {  // the lateral constraint's net force, −μ (t·b)/(t·n) n, is the plane's too
    if (k + 1 >= cs.size() || static_cast<Eigen::Index>(k + 1) >= mu.size()) return mu[static_cast<Eigen::Index>(k)] * sum;
    Vec<dim> lateral = Vec<dim>::Zero();
    for (Eigen::Index q = 0; q < cs[k + 1].gradient.cols(); ++q) lateral += cs[k + 1].gradient.col(q);
    return mu[static_cast<Eigen::Index>(k)] * sum + mu[static_cast<Eigen::Index>(k + 1)] * lateral;
  }
}

template <int dim>
Vec<dim> TouchdownFront<dim>::recorded_reaction(const StringModel<dim>& model, const FrontState<dim>& s) const {
  return s.reaction + constraint_force(model);
}

template <int dim>
void TouchdownFront<dim>::crossings(const StringModel<dim>& /*model*/, const FrontState<dim>& s, double* g) const {
  g[0] = s.l_plus / this->m_.h + kHysteresis;
  g[1] = s.l_minus / this->m_.h + kHysteresis;
}

template <int dim>
EventAction TouchdownFront<dim>::cross(StringModel<dim>& model, const FrontState<dim>& state, int e0) {
  const int a = this->node_a(model), b = this->node_b(model);
  const double h = this->m_.h;
  Points<dim>& x = model.x();
  // Where the crossing node's material is: a landing node b (the front kHysteresis h past it) lies on the
  // plane at h from a, so that the link (a, b) keeps its length and s0 runs on; a lifting node a (the front
  // kHysteresis h behind it) is on the arc's first link at h from b. The node moves by about kHysteresis h
  // (the root's l± = −kHysteresis h), and the new split link's other partial link starts at kHysteresis h.
  Vec<dim> placed = Vec<dim>::Zero();
  if (e0 != 0) {
    Vec<dim> e = along_;
    if constexpr (dim == 3) {  // the lying part's last link projected on the plane, which b continues
      const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
      const Vec<dim> u = A.num_links() >= 1 ? Vec<dim>(x.col(a) - x.col(a - 1)) : Vec<dim>::Zero();
      const Vec<dim> pu = u - normal_.dot(u) * normal_;
      if (pu.norm() > 0) e = pu.normalized();
    }
    placed = x.col(a) - normal_.dot(x.col(a) - point_) * normal_ + h * e;
  } else if (b + 1 < static_cast<int>(x.cols())) {
    const Vec<dim> link = x.col(b + 1) - x.col(b);
    placed = x.col(b) - h * link.normalized();
  }
  // A landing makes the arc's next link (c, d) the new split link's own: its x0 is that link's extension to the plane,
  // l⁺ = y_c / (t_cd·n), and the new l⁻ = h − l⁺ is the front's place past b before the projection. Where the arc's
  // first two links meet at an angle (the arc's end whipping, docs/model.md §10, "A falling arc") it lies behind b;
  // at half a link behind, b would lose its mass in the re-layout: the run stops here, before it, saying why.
  if (e0 != 0 && b + 2 < static_cast<int>(x.cols())) {
    const Vec<dim> first = (x.col(b + 1) - x.col(b)).normalized(), next = (x.col(b + 2) - x.col(b + 1)).normalized();
    const double rise = next.dot(normal_);
    const double l_minus_new = rise > 0 ? h - normal_.dot(x.col(b + 1) - point_) / rise : -h;
    if (l_minus_new < -(0.5 - kMaxBehind) * h) {
      const double kink_deg = std::acos(std::clamp(first.dot(next), -1.0, 1.0)) * 180 / kPi;
      return {EventAction::Kind::kStop,
              fmt::format("the touchdown front on {} lands node {} (s0 = {:.9g} m, ds0/dt = {:.4g} m/s) "
                          "where the arc's first two links meet at {:.4g} deg at node {} (the first at {:.4g} deg to "
                          "the plane, the next at {:.4g} deg): the new split link, the next link's extension to the "
                          "plane, would put the front {:.4g} h behind node {}, more than half a link, and the node "
                          "would lose its mass. The arc's end whips where the lying part does not follow the arc "
                          "(docs/model.md §10, A falling arc)",
                          surface_, b, state.s0, state.s0_dot, kink_deg, b + 1,
                          std::asin(std::clamp(first.dot(normal_), -1.0, 1.0)) * 180 / kPi,
                          std::asin(std::clamp(rise, -1.0, 1.0)) * 180 / kPi, -l_minus_new / h, b)};
    }
  }
  EventAction action = SplitLinkFront<dim>::cross(model, state, e0);
  if (action.kind == EventAction::Kind::kStop) return action;
  this->watch_outside();
  if (e0 != 0) {
    // Node b has joined the lying arc with its velocity: it lies on the plane, where the contact module
    // holds it.
    x.col(b) = placed;
    Points<dim>& v = model.v();
    v.col(b) -= normal_.dot(v.col(b)) * normal_;
    lying_last_ = b;
  } else {
    x.col(a) = placed;
    lying_last_ = a - 1;
  }
  return action;
}

template <int dim>
typename TouchdownFront<dim>::Margins TouchdownFront<dim>::margins(const StringModel<dim>& model,
                                                                   const FrontState<dim>& s) const {
  Margins m;
  if constexpr (dim == 3) {
    // The arc's elevation over the plane, t·n, whatever its turn from e (sideways or back over the lying part).
    m.angle = elevation_ - std::sin(kMinAngleDeg * kPi / 180);
  } else {
    m.angle = std::sin(theta_) - std::sin(kMinAngleDeg * kPi / 180);
    if (theta_ > 0.5 * kPi) m.angle = 1;  // a steep arc is fine; only a grazing one is refused
  }
  const ArcRange& B = model.arcs()[static_cast<std::size_t>(this->arc_plus)];
  for (int i = B.first + 1; i <= B.last; ++i) {
    const double height = normal_.dot(model.x().col(i) - point_) / this->m_.h;
    if (height < m.height) {
      m.height = height;
      m.low_node = i;
    }
  }
  // The plane's push at the front, N = n·(the front's reaction, the constraint's share included), per the
  // scale λ |[v]|² of the jump conditions' forces, less 10⁻⁶ of it (N = 0 for f = 0): a take-off with f > 0
  // (N = −f λ ṡ0² sin θ) and a front whose compatibility would need a pull both stop the run. A round-off floor
  // of 10⁻⁸ of the string's physical tension scale (StringModel::physical_scales) keeps a front with f = 0
  // that comes to rest (ṡ0 → 0, [v] → 0, N the integration error of the constraint's share: 3.4e-11 N on the
  // reversing drawn string of test [touchdown], 1.4e-12 of its scale) from stopping the run.
  const Vec<dim> jump_v = model.v().col(B.first) - model.v().col(B.first - 1);
  const double scale = this->m_.lambda * jump_v.squaredNorm();
  const double floor = 1e-8 * model.physical_scales().tension;
  const double push = normal_.dot(recorded_reaction(model, s));
  m.take_off = scale + floor > 0 ? std::min(1.0, (push + 1e-6 * scale + floor) / (scale + 1e6 * floor)) : 1.0;
  // The lying part's last full link (a − 1, a), next to the front: its tension with the front's constraint's share
  // (the multiplier is imposed after the links' tension solve, so slack = "allow" cannot release it) must not push,
  // per the same scale and floor (docs/model.md §10, "A falling arc": an arc falling onto the table asks a lying part
  // at rest to move back at −ṡ0 (1 − cos θ), which only a push starts).
  const ArcRange& A = model.arcs()[static_cast<std::size_t>(this->arc_minus)];
  if (A.num_links() >= 1) {
    m.pushed_link = A.last - 1;
    m.pushed_tension = model.link_tension(m.pushed_link);
    m.pushed = std::min(1.0, (m.pushed_tension + floor) / (scale + 1e6 * floor));

  }
  // The front outside its split link after a crossing (a landing's re-layout can leave it behind the new node a,
  // docs/model.md §10, "A falling arc"): SplitLinkFront::outside_margin.
  m.inside = this->outside_margin(s);
  // 3D, f > 0: the sideways pull the front puts on the lying end, f λ ṡ0² |t·b|, beyond f λ ṡ0² sin 1°, per
  // f λ ṡ0², with the take-off check's round-off floor: the arc's angle to the plane of e and n where the front
  // moves, nothing where it is at rest (ṡ0 = 0: the balance across holds at any angle).
  if constexpr (dim == 3)
    if (this->dissipation > 0) {
      const double sideways = this->dissipation * this->m_.lambda * s.s0_dot * s.s0_dot;
      m.off_plane = std::min(1.0, (sideways * (std::sin(kMaxOffPlaneDeg * kPi / 180) - off_plane_) + floor) /
                                      (sideways + 1e6 * floor));
    }
  return m;
}

template <int dim>
void TouchdownFront<dim>::checks(const StringModel<dim>& model, const FrontState<dim>& s, double* g) const {
  g[0] = least(margins(model, s));
}

template <int dim>
std::string TouchdownFront<dim>::check_failed(const StringModel<dim>& model, const FrontState<dim>& s, double t, int /*check*/) const {
  const Margins m = margins(model, s);
  const double least = TouchdownFront::least(m);
  const double angle = dim == 3 ? std::asin(std::clamp(elevation_, -1.0, 1.0)) : theta_;  // 3D: the elevation
  if (least == m.inside && m.inside < std::min({m.angle, m.height, m.take_off, m.off_plane, m.pushed}))
    return fmt::format(
        "the touchdown front on {} lies {:.4g} h outside its split link, behind node {}, and moves on away from it at "
        "t = {:.9g} s (s0 = {:.9g} m, ds0/dt = {:.4g} m/s, the arc at {:.4g} deg): a landing's re-layout left it "
        "there (the new split link takes the arc's next link as its own, and where the arc's first two links meet at "
        "an angle its x0 lies off the old one), past the crossing's root, so that the front would run on past the "
        "next node unseen (docs/model.md §10, A falling arc)",
        surface_, -std::min(s.l_minus, s.l_plus) / this->m_.h,
        s.l_minus < s.l_plus ? this->node_a(model) : this->node_b(model), t, s.s0, s.s0_dot, angle * 180 / kPi);
  if (least == m.pushed && m.angle >= 0 && m.pushed < std::min({m.height, m.take_off, m.off_plane}))
    return fmt::format(
        "the lying part would have to be pushed at the touchdown front on {} at t = {:.9g} s: its last link next to "
        "the front (link {}) has the tension T = {:.6g} N < 0 (s0 = {:.9g} m, ds0/dt = {:.4g} m/s, the arc at {:.4g} "
        "deg, f = {:g}). An arc that falls onto the plane lays its material down faster than the lying part moves "
        "away (compatibility asks a lying part at rest to move back at -ds0/dt (1 - cos theta), which only a push "
        "starts): a string cannot push, so the lying part would go slack and pile up at the front, which the "
        "touchdown front does not build (docs/model.md §10, A falling arc). Leave out f: node contact lands a "
        "falling arc",
        surface_, t, m.pushed_link, m.pushed_tension, s.s0, s.s0_dot, angle * 180 / kPi, this->dissipation);
  if (least == m.off_plane && m.off_plane < std::min({m.angle, m.height, m.take_off}))
    return fmt::format(
        "the arc leaves {} at {:.4g} deg to the plane of the lying part's direction and the normal at t = {:.9g} s "
        "(s0 = {:.9g} m, ds0/dt = {:.4g} m/s, f = {:g}): with f > 0 the jump conditions at a moving touchdown front "
        "need the arc in that plane (their balance along b = n x e is f lambda ds0/dt^2 (t.b) = 0: a smooth plane "
        "cannot push sideways), or the lying part turned at the front to the arc's projection, which the front does "
        "not build; at most {:g} deg (docs/model.md §10, A touchdown front in 3D)",
        surface_, std::asin(std::min(off_plane_, 1.0)) * 180 / kPi, t, s.s0, s.s0_dot, this->dissipation,
        kMaxOffPlaneDeg);
  if (least == m.take_off)
    return fmt::format(
        "lifted off {} at t = {:.9g} s: the plane would have to pull the string at the touchdown front (its reaction "
        "N = {:.6g} N; s0 = {:.9g} m, ds0/dt = {:.4g} m/s, the arc at {:.4g} deg, f = {:g}): a take-off with f > 0 "
        "needs N = -f lambda ds0/dt^2 sin theta < 0 (a string peels off a smooth plane only without dissipation, f = 0), "
        "and a lying part whose own motion disagrees with the arc's end needs a pull to stay taut (docs/model.md §10)",
        surface_, t, normal_.dot(recorded_reaction(model, s)), s.s0, s.s0_dot, angle * 180 / kPi, this->dissipation);
  if (least == m.height)
    return fmt::format(
        "node {} of the arc reaches {} at t = {:.9g} s away from its touchdown front (s0 = {:.9g} m): a string that "
        "lands elsewhere than at its front is not supported with f (node contact lands it: leave out f)",
        m.low_node, surface_, t, s.s0);
  return fmt::format(
      "the arc meets {} at {:.4g} deg at t = {:.9g} s (s0 = {:.9g} m, ds0/dt = {:.4g} m/s): a touchdown front needs "
      "at least {:g} deg (a grazing touchdown is no shock, and the split link no longer places it; leave out f: node "
      "contact lands a grazing arc){}",
      surface_, angle * 180 / kPi, t, s.s0, s.s0_dot, kMinAngleDeg,
      m.pushed < 0 ? fmt::format("; the lying part would also have to be pushed at the front (link {}: T = {:.6g} N "
                                 "< 0; docs/model.md §10, A falling arc)",
                                 m.pushed_link, m.pushed_tension)
                   : std::string());
}

template <int dim>
std::optional<RunEvent> TouchdownFront<dim>::check_event(const StringModel<dim>& model, const FrontState<dim>& s,
                                                         double t, int /*check*/) const {
  const Margins m = margins(model, s);
  if (least(m) != m.take_off || m.take_off >= std::min(m.pushed, m.inside)) return std::nullopt;
  RunEvent e;
  e.kind = "lift_off";
  e.t = t;
  e.position.assign(s.position.data(), s.position.data() + dim);
  e.values = {{"s0", s.s0},
              {"s0_dot", s.s0_dot},
              {"tension_minus", s.tension_minus},
              {"tension_plus", s.tension_plus},
              {"angle_deg", theta_ * 180 / kPi}};
  return e;
}

template <int dim>
void touchdown_surface(const TouchdownFront<dim>& front, Obstacle<dim>& surface) {
  const TouchdownFront<dim>* f = &front;
  surface.carries = [f](int i) { return i <= f->lying_last(); };
}

template TouchdownConstraint<2> touchdown_split_constraint<2>(const Vec<2>&, const Vec<2>&, const Vec<2>&,
                                                              const Vec<2>&, const Vec<2>&, const Vec<2>&,
                                                              const Vec<2>&, const Vec<2>&, bool, const Vec<2>&,
                                                              const Vec<2>&, const Vec<2>&, double);
template TouchdownConstraint<3> touchdown_split_constraint<3>(const Vec<3>&, const Vec<3>&, const Vec<3>&,
                                                              const Vec<3>&, const Vec<3>&, const Vec<3>&,
                                                              const Vec<3>&, const Vec<3>&, bool, const Vec<3>&,
                                                              const Vec<3>&, const Vec<3>&, double);
template class TouchdownFront<2>;
template class TouchdownFront<3>;
template void touchdown_surface<2>(const TouchdownFront<2>&, Obstacle<2>&);
template void touchdown_surface<3>(const TouchdownFront<3>&, Obstacle<3>&);

}  // namespace chainsim
