#pragma once
/// @file defaults.hpp
/// Every default of chainsim in one table. The library's option structs (IntegratorOptions,
/// StringModelOptions, StringSolverOptions), the scene format (cases/scene/scene.hpp, and through it
/// the CLI's `run` and `sweep` and Python's Scene), the canonical set-ups (`compare`, `canonical`,
/// Python's compare) and the reduced ODEs (`reduced`, Python's reduced) take their defaults from
/// here. Where two contexts differ, each has its own named entry and the reason is given.
namespace chainsim {

/// What a run does when the tension goes negative beyond round-off (slack: an inextensible string
/// cannot push, so the model no longer applies): stop with a NumericalError, record the first
/// occurrence and go on, or not check at all; or allow it: links are unilateral, a slack link flies
/// freely and snaps taut with an impulse (docs/model.md "Slack and snap-taut").
enum class SlackPolicy { kStop, kWarn, kIgnore, kAllow };

namespace defaults {

/// An integrator set-up: ARKODE method (alias), relative and absolute tolerance (the absolute one
/// relative to the state's natural scale, OdeSystem::state_scale).
struct Integration {
  const char* method;
  double rtol, atol;
};

/// A C++ caller that sets nothing (IntegratorOptions{}): the most accurate explicit method at a
/// tolerance near the round-off of a string's link lengths, for the library's unit uses (tests,
/// benchmarks), which ask for their own figures when it matters.
inline constexpr Integration kLibrary{"erk8", 1e-10, 1e-12};
/// A scene ([solver] method, rtol, atol; `chainsim run`, `sweep`, Python's Scene; docs/scenes.md,
/// [solver]): a string of many nodes, whose spatial discretization error is the larger part of a
/// scene's error at the node counts scenes use (docs/work-precision.md); the example scenes close
/// their energy ledger to 1e-9 of its scale at this tolerance (tests/unit/test_scene.cpp).
inline constexpr Integration kScene{"erk8", 1e-8, 1e-10};
/// The canonical problems on the string solver (`chainsim compare`, `canonical`): straight-line
/// motions that the string reproduces exactly for every node count, compared with their reduced ODE;
/// for these scenes with fronts erk5 is the cheapest method at most accuracies measured
/// (docs/work-precision.md), and rtol 1e-9 keeps the comparison far below the figures' resolution.
inline constexpr Integration kCanonicalString{"erk5", 1e-9, 1e-11};
/// The reduced ODEs (`chainsim reduced`, the reference of `compare`; docs/reduced.md, "Method"): one
/// or two unknowns, cheap at any tolerance, checked against exact quadratures: the tolerance sits near
/// round-off so that the reference is never the larger error.
inline constexpr Integration kReduced{"erk8", 1e-13, 1e-15};

/// Accepted steps allowed over a whole run (IntegratorOptions::max_steps, [solver] max_steps).
inline constexpr long kMaxSteps = 500000;
/// Tension backend (StringModelOptions::backend, [solver] backend).
inline constexpr const char* kBackend = "auto";
/// Factorisation of the Newton systems of implicit methods (StringModelOptions::linear_solver,
/// [solver] linear_solver): "auto" (banded for a string without fronts, KLU otherwise), "banded", "klu".
inline constexpr const char* kLinearSolver = "auto";
/// The discretization (StringModelOptions::elements, [string] elements): "links" (order 2) until the
/// quadratic elements carry fronts and closed strings (docs/work-precision.md).
inline constexpr const char* kElements = "links";
/// Slack means T_j < −kSlackTolerance · (tension scale) ([solver] slack_tolerance).
inline constexpr double kSlackTolerance = 1e-8;
/// A scene checks slack and stops at it ([solver] slack = "stop"): a scene's result past a slack
/// link is not a string's. A C++ caller (StringModelOptions{}) checks nothing unless asked: the
/// library's unit uses build strings that are slack on purpose (free fall, a string at rest
/// without weight).
inline constexpr const char* kSceneSlack = "stop";
inline constexpr SlackPolicy kLibrarySlack = SlackPolicy::kIgnore;
/// A scene's Baumgarte time is this fraction of its characteristic time ([solver]
/// stabilization_time); a C++ caller's is 0 (off) unless asked.
inline constexpr double kSceneStabilizationFraction = 0.1;
inline constexpr double kLibraryStabilizationTime = 0;
/// Time between frames (s): a scene's ([output] interval) and a C++ caller's
/// (StringSolverOptions::output_interval, whose runs are short unit runs).
inline constexpr double kSceneOutputInterval = 0.05;
inline constexpr double kLibraryOutputInterval = 0.1;

}  // namespace defaults
}  // namespace chainsim
