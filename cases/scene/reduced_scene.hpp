#pragma once
/// @file reduced_scene.hpp
/// model = "reduced": a scene may be solved by the reduced ODE (cases/reduced/reduced_models.hpp) only when
/// it IS one of the paper's three canonical problems, where the reduced model is exact. Which one is
/// read from the scene; anything else is refused with the reason, located at the `model` key.
///
/// The scene must first be a valid scene with fronts (build_front_scene accepts it), then:
///   common   [effects.gravity] declared (any direction ĝ, |g| > 0), no [effects.drag], exactly one
///            front, the moving part of the string at rest;
///   falling  a heap with side = "end", on_plane = true on a plane perpendicular to gravity; the
///            material s ∈ [0, s0] straight along gravity above the heap point (x(s) = x0 − (s0 − s) ĝ);
///            ends.start free; a cutoff [[stop.front]] front = "heap_end", 0 < s0 < the heap's s0.
///            η0 = s0/ℓ, ε = (cutoff s0)/ℓ.
///   folded   a fold; ends.start fixed; the resting arm s ∈ [0, s0] hanging straight along gravity from
///            the fixed end and the moving arm s ∈ [s0, ℓ] going straight back up from the fold;
///            ends.end free or loaded by a constant force −F ĝ, F ≥ 0; a cutoff [[stop.front]]
///            front = "fold", the fold's s0 < s0 < ℓ. η0 = s0/ℓ, ε = 1 − (cutoff s0)/ℓ.
///   sliding  a heap with side = "start", pinned (on_plane = false) at the hole; the hanging part
///            s ∈ [s0, ℓ] straight along gravity below the hole (x(s) = x0 + (s − s0) ĝ); ends.end
///            free; no [[stop.front]] (the reduced run stops when the heap is empty, η = 1).
///            η0 = (ℓ − s0)/ℓ, from rest (the η0 = 0 branch has no scene: `chainsim reduced
///            sliding --eta0 0`).
/// In all three: ℓ = the string's length, λ = string.density, g = |effects.gravity.g|, f = the
/// front's f, and the safety stop t_max = stop.t_end. The scene's [solver] is not used: the reduced
/// ODE keeps its own tolerances (ReducedSetup::default_integrator()).
#include "cases/reduced/reduced_models.hpp"
#include "cases/scene/scene.hpp"

namespace chainsim {

/// The reduced problem a scene is (see the file comment), or InputError at the `model` key:
/// "model = \"reduced\" needs …: <why the scene is not that problem>".
ReducedSetup match_canonical_problem(const SceneSpec& spec);

}  // namespace chainsim
