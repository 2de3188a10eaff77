// solver/string_model.hpp: the ODE layout, the initial projection onto the constraints, the power
// of the applied forces, and the model's input checks.
#include <cmath>

#include <catch2/catch.hpp>

#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "solver/string_model.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
/// Newton's projection stops at ~1e-14 relative link error (round-off of the coordinates).
constexpr double kProjected = 1e-13;
/// Round-off of O(n) sums.
constexpr double kRoundOff = 1e-12;
}  // namespace

TEST_CASE("the initial projection makes a regular polygon of a sampled circle", "[unit][model]") {
  const int n = 12;
  Chain<2> chain = discretize(*circle_curve<2>(Vec<2>(0, 0), 1.0, Vec<2>(1, 0), Vec<2>(0, 1)), 2 * kPi, 1.0, n, true);
  // Nodes on the circle have chords 2 sin(π/n) < h = 2π/n: the projection expands the polygon.
  CHECK(chain.max_length_violation() > 1e-3);
  StringModel<2> model(std::move(chain), {}, {}, {});
  const double moved = model.make_consistent(0.0);
  const double h = 2 * kPi / n, r = h / (2 * std::sin(kPi / n));
  CHECK_THAT(moved, WithinRel(r - 1.0, 1e-9));
  CHECK(model.chain().max_length_violation() < kProjected);
  for (int i = 0; i < n; ++i) CHECK_THAT(model.chain().positions().col(i).norm(), WithinRel(r, kProjected));
}

TEST_CASE("the projection keeps prescribed nodes and removes the velocities that stretch links", "[unit][model]") {
  // A sagging polyline between fixed points with arbitrary velocities.
  Points<2> v(2, 3);
  v << 0.0, 0.5, 1.0, 0.0, -0.6, 0.0;
  const double length = 2 * std::sqrt(0.25 + 0.36);
  Chain<2> chain = discretize(*polyline_curve<2>(v), length, 1.0, 9, false);
  for (int i = 0; i < chain.num_nodes(); ++i) chain.velocities().col(i) = Vec<2>(std::cos(3.0 * i), std::sin(5.0 * i));
  const Vec<2> driven_velocity(0.2, 0.3);
  std::vector<PrescribedNode<2>> ends = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))},
                                         {9, std::make_shared<LinearPath<2>>(Vec<2>(1, 0), driven_velocity)}};
  StringModel<2> model(std::move(chain), {}, ends, {});
  model.make_consistent(0.0);
  const auto& c = model.chain();
  CHECK(c.positions().col(0) == Vec<2>(0, 0));
  CHECK(c.positions().col(9) == Vec<2>(1, 0));
  CHECK(c.velocities().col(0) == Vec<2>(0, 0));
  CHECK(c.velocities().col(9) == driven_velocity);
  CHECK(c.max_length_violation() < kProjected);
  for (int j = 0; j < c.num_links(); ++j) {
    const Vec<2> dx = c.positions().col(j + 1) - c.positions().col(j);
    const Vec<2> dv = c.velocities().col(j + 1) - c.velocities().col(j);
    CHECK_THAT(dx.normalized().dot(dv), WithinAbs(0.0, kRoundOff));
  }
  // The ODE state holds the free nodes only, plus W_applied.
  CHECK(model.num_free_nodes() == 8);
  CHECK(model.size() == 2 * 2 * 8 + 1);
  const Eigen::VectorXd y = model.state_from_chain();
  Points<2> x, vel;
  model.unpack(0.5, y, x, vel);
  CHECK((x.col(9) - Vec<2>(1.1, 0.15)).norm() < kRoundOff);  // the driven node on its path at t = 0.5
  CHECK(x.col(4) == c.positions().col(4));
}

TEST_CASE("the power booked in W_applied: drag, loads and drivers, not gravity", "[unit][model]") {
  Chain<3> chain = Chain<3>::uniform(2.0, 1.0, 4, false);
  for (int i = 0; i <= 4; ++i) {
    chain.positions().col(i) = Vec<3>(0.25 * i, 0.0, 0.0);
    chain.velocities().col(i) = Vec<3>(0.0, 0.1 * i, 0.0);  // a rigid rotation about node 0: consistent
  }
  std::vector<std::unique_ptr<Force<3>>> forces;
  forces.push_back(std::make_unique<Gravity<3>>(Vec<3>(0, 0, -9.81)));
  forces.push_back(std::make_unique<Drag<3>>(0.5));
  forces.push_back(std::make_unique<EndLoad<3>>(4, Vec<3>(0.0, 1.0, 0.0)));
  std::vector<PrescribedNode<3>> fixed = {{0, std::make_shared<FixedPoint<3>>(Vec<3>(0, 0, 0))}};
  StringModel<3> model(std::move(chain), std::move(forces), fixed, {});
  const auto& c = model.chain();
  const double power = model.evaluate(0.0, c.positions(), c.velocities());
  // Drag: −c Σ m_i |v_i|² over the free nodes; load: F·v_end; the fixed node does no work.
  double drag = 0;
  for (int i = 1; i <= 4; ++i) drag -= 0.5 * c.mass(i) * c.velocities().col(i).squaredNorm();
  CHECK_THAT(power, WithinRel(drag + 1.0 * 0.4, kRoundOff));
  // Momentum balance of every free node: m a = F + T_i e_i − T_{i−1} e_{i−1}.
  const Eigen::VectorXd& T = model.tensions();
  for (int i = 1; i <= 4; ++i) {
    Vec<3> f = c.mass(i) * Vec<3>(0, 0, -9.81) - 0.5 * c.mass(i) * c.velocities().col(i);
    if (i == 4) f += Vec<3>(0, 1, 0);
    if (i < 4) f += T[i] * Vec<3>(1, 0, 0);
    f -= T[i - 1] * Vec<3>(1, 0, 0);
    CHECK((c.mass(i) * model.accelerations().col(i) - f).norm() < kRoundOff);
  }
}

TEST_CASE("the model refuses inconsistent set-ups", "[unit][model]") {
  auto chain = [] {
    Chain<2> c = Chain<2>::uniform(1.0, 1.0, 1, false);
    c.positions().col(1) = Vec<2>(1, 0);
    return c;
  };
  std::vector<PrescribedNode<2>> both = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))},
                                         {1, std::make_shared<FixedPoint<2>>(Vec<2>(1, 0))}};
  CHECK_THROWS_WITH(StringModel<2>(chain(), {}, both, {}), Contains("link 0 joins two prescribed nodes"));
  std::vector<std::unique_ptr<Force<2>>> load;
  load.push_back(std::make_unique<EndLoad<2>>(0, Vec<2>(1, 0)));
  std::vector<PrescribedNode<2>> first = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}};
  CHECK_THROWS_WITH(StringModel<2>(chain(), std::move(load), first, {}), Contains("both loaded and prescribed"));
  StringModelOptions bad;
  bad.backend = "cholmod";
  CHECK_THROWS_WITH(StringModel<2>(chain(), {}, {}, bad), Contains("backend = \"cholmod\""));
  bad.backend = "auto";
  bad.stabilization_time = -1;
  CHECK_THROWS_WITH(StringModel<2>(chain(), {}, {}, bad), Contains("stabilization_time"));
}

namespace {
/// A chain of 10 links (h = 0.1 m, λ = 0.7 kg/m) in an L over the point (0, 0): nodes 0..a along the
/// x axis towards the point, nodes a+1.. hanging straight down; link a runs over the point with
/// l⁻ = 0.04 m before it and l⁺ = 0.06 m after it. Every node moves at speed v along the path.
Chain<2> chain_over_edge(int a, double v) {
  const double h = 0.1;
  Chain<2> c = Chain<2>::uniform(0.7, 1.0, 10, false);
  for (int i = 0; i <= 10; ++i) {
    if (i <= a) {
      c.positions().col(i) = Vec<2>(-0.04 - (a - i) * h, 0);
      c.velocities().col(i) = Vec<2>(v, 0);
    } else {
      c.positions().col(i) = Vec<2>(0, -0.06 - (i - a - 1) * h);
      c.velocities().col(i) = Vec<2>(0, -v);
    }
  }
  return c;
}
}  // namespace

TEST_CASE("a link bent over a fixed point: the string runs over it as over a smooth edge", "[unit][model][edge]") {
  // Pulled by a load F on its hanging end (no gravity), the whole chain accelerates along its path at
  // F/M (M = λℓ), whatever its speed: the straight parts move along themselves, and the bent link's
  // ends move along its two halves. Link j carries the force that accelerates the nodes before it,
  // T_j = (m_0 + … + m_j) F/M, the bent one included, and the point pushes with T_a (e_x + e_y): the
  // discrete system's exact solution.
  const int a = 6;
  const double F = 2.3;
  for (double v : {0.0, 1.7}) {
    CAPTURE(v);
    std::vector<std::unique_ptr<Force<2>>> forces;
    forces.push_back(std::make_unique<EndLoad<2>>(10, Vec<2>(0, -F)));
    StringModel<2> model(chain_over_edge(a, v), std::move(forces), {}, {});
    model.bend_link(a, Vec<2>(0, 0));
    const auto& c = model.chain();
    model.evaluate(0.0, c.positions(), c.velocities());
    double M = 0;
    for (int i = 0; i <= 10; ++i) M += c.mass(i);
    CHECK_THAT(M, WithinRel(0.7, kRoundOff));
    for (int i = 0; i <= 10; ++i) {
      const Vec<2> t = i <= a ? Vec<2>(1, 0) : Vec<2>(0, -1);
      CHECK((model.accelerations().col(i) - F / M * t).norm() < kRoundOff);
    }
    double before = 0;
    for (int j = 0; j < 10; ++j) {
      before += c.mass(j);
      CHECK_THAT(model.tensions()[j], WithinAbs(before * F / M, kRoundOff));
    }
    CHECK((model.bend_reaction() - model.tensions()[a] * Vec<2>(1, 1)).norm() < kRoundOff);
  }
}

TEST_CASE("a link bent over a fixed point: the projection keeps l- + l+ = h and its rate zero", "[unit][model][edge]") {
  Chain<2> c = chain_over_edge(4, 0.8);
  // Disturb the shape and the velocities off the constraints.
  for (int i = 0; i <= 10; ++i) {
    c.positions().col(i) += Vec<2>(0.003 * std::sin(1.3 * i), 0.002 * std::cos(0.7 * i));
    c.velocities().col(i) += Vec<2>(0.05 * std::cos(0.9 * i), -0.04 * std::sin(1.1 * i));
  }
  std::vector<PrescribedNode<2>> none;
  StringModel<2> model(c, {}, none, {});
  model.bend_link(4, Vec<2>(0, 0));
  model.make_consistent(0.0);
  const Points<2>& x = model.chain().positions();
  const Points<2>& v = model.chain().velocities();
  for (int j = 0; j < 10; ++j) {
    if (j == 4) continue;
    CHECK_THAT((x.col(j + 1) - x.col(j)).norm(), WithinRel(0.1, 1e-12));
  }
  const Vec<2> em = (-x.col(4)).normalized(), ep = x.col(5).normalized();
  CHECK_THAT(x.col(4).norm() + x.col(5).norm(), WithinRel(0.1, 1e-12));
  CHECK_THAT(ep.dot(v.col(5)) - em.dot(v.col(4)), WithinAbs(0.0, 1e-12));
  // Straightened, the same link is a chord again.
  model.clear_bends();
  model.make_consistent(0.0);
  CHECK_THAT((model.chain().positions().col(5) - model.chain().positions().col(4)).norm(), WithinRel(0.1, 1e-12));
}

TEST_CASE("a link bent over a fixed point: integrated in time, the chain slides over it at F/M", "[unit][model][edge]") {
  // The discrete motion of the first test is exact until node a reaches the point: the path
  // coordinate is ½ (F/M) t². Run to 90% of that time with the default method at rtol 1e-10.
  const int a = 6;
  const double F = 2.3, M = 0.7;
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<EndLoad<2>>(10, Vec<2>(0, -F)));
  StringModelOptions mo;
  mo.stabilization_time = 0.03;
  StringModel<2> model(chain_over_edge(a, 0.0), std::move(forces), {}, mo);
  model.bend_link(a, Vec<2>(0, 0));
  model.make_consistent(0.0);
  IntegratorOptions io;
  io.rtol = 1e-10;
  io.atol = 1e-13;
  const double t_end = 0.9 * std::sqrt(2 * 0.04 * M / F);
  Integrator integrator(model, 0.0, model.state_from_chain(), io);
  integrator.advance(t_end);
  Points<2> x, v;
  model.unpack(t_end, integrator.state(), x, v);
  const double s = 0.5 * F / M * t_end * t_end;
  for (int i = 0; i <= 10; ++i) {
    const Vec<2> t = i <= a ? Vec<2>(1, 0) : Vec<2>(0, -1);
    CHECK((x.col(i) - chain_over_edge(a, 0.0).positions().col(i) - s * t).norm() < 1e-9);
    CHECK((v.col(i) - F / M * t_end * t).norm() < 1e-9);
  }
}

TEST_CASE("an impact with a driven end: the supports' work is returned apart from Carnot's loss", "[unit][model]") {
  // A sagging polyline, one end driven at constant velocity, the other free, with arbitrary velocities that
  // the links do not allow; impact() projects them (slack = stop: the mass-weighted projection; allow: the
  // complementarity problem at e = 0, links that would be pushed going slack). Independently of the model:
  //  - the only external impulse is the driven support's, so it is the string's change of momentum Δp,
  //    and its work is Δp · v_d (the driven node keeps its velocity);
  //  - what the impact dissipates is Carnot's loss −½ Σ m_i |Δv_i|², so ΔK = Δp · v_d − ½ Σ m_i |Δv_i|².
  for (const SlackPolicy slack : {SlackPolicy::kStop, SlackPolicy::kAllow}) {
    Points<2> shape(2, 3);
    shape << 0.0, 0.5, 1.0, 0.0, -0.6, 0.0;
    const double length = 2 * std::sqrt(0.25 + 0.36);
    Chain<2> chain = discretize(*polyline_curve<2>(shape), length, 1.0, 12, false);
    const Vec<2> driven_velocity(-0.6, 0.8);  // away from node 1: the first link is pulled (lengthens)
    std::vector<PrescribedNode<2>> ends = {{0, std::make_shared<LinearPath<2>>(Vec<2>(0, 0), driven_velocity)}};
    StringModelOptions options;
    options.slack = slack;
    StringModel<2> model(std::move(chain), {}, ends, options);
    model.make_consistent(0.0);
    for (int i = 1; i < model.chain().num_nodes(); ++i)
      model.v().col(i) = Vec<2>(std::cos(3.0 * i) - 0.5, std::sin(5.0 * i) + 0.8);
    model.v().col(0) = driven_velocity;
    const Points<2> v_before = model.v();
    Vec<2> p_before = Vec<2>::Zero();
    double K_before = 0;
    for (int i = 0; i < model.chain().num_nodes(); ++i) {
      p_before += model.chain().mass(i) * v_before.col(i);
      K_before += 0.5 * model.chain().mass(i) * v_before.col(i).squaredNorm();
    }
    const double work = model.impact(0.0);
    Vec<2> p_after = Vec<2>::Zero();
    double K_after = 0, carnot = 0;
    for (int i = 0; i < model.chain().num_nodes(); ++i) {
      const double m = model.chain().mass(i);
      p_after += m * model.v().col(i);
      K_after += 0.5 * m * model.v().col(i).squaredNorm();
      carnot -= 0.5 * m * (model.v().col(i) - v_before.col(i)).squaredNorm();
    }
    INFO("slack = " << to_string(slack) << ": work " << work << " J, Δp·v_d " << (p_after - p_before).dot(driven_velocity)
                    << " J, ΔK " << K_after - K_before << " J, Carnot " << carnot << " J");
    CHECK(model.v().col(0) == driven_velocity);
    CHECK(std::abs(work) > 0.05);  // the test is not vacuous: the support works
    CHECK_THAT(work, WithinAbs((p_after - p_before).dot(driven_velocity), kRoundOff));
    CHECK_THAT(K_after - K_before - work, WithinAbs(carnot, kRoundOff));
    CHECK(carnot < -0.05);
  }
}
