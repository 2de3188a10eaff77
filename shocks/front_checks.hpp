#pragma once
/// @file front_checks.hpp
/// The physical checks of the fronts' input, one implementation each: a string with fronts is open,
/// a heap's s0 lies inside the string, at most one heap holds each side, its f is in range (a pot's
/// too), its held end is free, a fold lies between the heaps with its f in range, a plane's normal
/// is nonzero. The front tracker runs them on its specs (HeapSpec, FoldSpec); the scene layer runs
/// the same functions on the scene's keys, earlier, so that each refusal names the key at fault and
/// where it was written. Where a value came from is a FrontKeys: the checks ask it for the key's
/// name, the value as written and the location, and never spell a key themselves.
#include <cstddef>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace chainsim {

/// How a refusal of the fronts' input names the key at fault and where it was written. This default
/// names the fields of the C++ specs ("heap.s0", "heap.dissipation", "fold.s0") and locates nothing;
/// the scene layer names the scene's keys ("effects.heap[0].s0") and prefixes their file:line:column
/// (cases/scene/scene_front_keys.hpp).
class FrontKeys {
 public:
  explicit FrontKeys(std::string heap = "heap", std::string fold = "fold")
      : heap_(std::move(heap)), fold_(std::move(fold)) {}
  virtual ~FrontKeys() = default;

  /// Heap k's field: "" (the heap itself), "side", "s0", "f" (its dissipation) or "pot".
  virtual std::string heap(std::size_t k, const std::string& field) const;
  /// The fold's field: "" (the fold itself), "s0" or "f".
  virtual std::string fold(const std::string& field) const;
  /// The normal of the heaps' plane.
  virtual std::string plane_normal() const { return "the normal of a heap's plane"; }
  /// What declares heaps (or a fold) in the input: a closed string refuses it.
  virtual std::string declared(bool heaps) const { return heaps ? "a heap" : "a fold"; }
  /// The string's start (after = false) or end: held there, it is inside a heap on that side.
  virtual std::string end(bool after) const { return after ? "the string's last node" : "the string's first node"; }
  /// A heap's side as the input spells it ("a heap the string runs into" / side = "end").
  virtual std::string side(bool after) const;
  /// The value of `key` as written (`shown`: as the checks print it when the input has no text).
  virtual std::string text(const std::string& /*key*/, const std::string& shown) const { return shown; }
  /// Whether a refusal also says how to fix the input (the scene's do).
  virtual bool hints() const { return false; }
  /// Throws InputError(message), located at `key` by a located input.
  [[noreturn]] virtual void fail(const std::string& key, const std::string& message) const;

 private:
  std::string heap_, fold_;
};

/// A string with fronts is open: refuses `closed` (at the first heap, or the fold).
void check_open_string(bool closed, bool heaps, const FrontKeys& keys = FrontKeys());

/// At most one heap holds each side: refuses heap k on a side heap `other` already holds.
void check_one_heap_per_side(std::size_t k, bool after, std::optional<std::size_t> other,
                             const FrontKeys& keys = FrontKeys());

/// A heap's f: 0 ≤ f ≤ 1, or jump::kPotMinDissipation ≤ f ≤ 1 for a pot, which only a start heap
/// (after = false) may be.
void check_heap_dissipation(std::size_t k, bool after, bool pot, double f, const FrontKeys& keys = FrontKeys());

/// A heap's s0 lies inside the string of length ell: 0 ≤ s0 < ℓ at the start, 0 < s0 ≤ ℓ at the end
/// (ℓ up to 1e-12 ℓ: it is a sum of link lengths).
void check_heap_s0(std::size_t k, bool after, double s0, double ell, const FrontKeys& keys = FrontKeys());

/// An end on a heap's side is inside the heap: it cannot be held (fixed, loaded or driven).
/// `held`: how it is held, as the input spells it; empty when the end is free.
void check_end_free(std::size_t k, bool after, double s0, const std::string& held, const FrontKeys& keys = FrontKeys());

/// A fold's f is in [0, 1].
void check_fold_dissipation(double f, const FrontKeys& keys = FrontKeys());

/// A fold's s0 lies in the moving part: between the heaps (s0 > the start heap's s0, s0 < the end
/// heap's), or inside the string (0 ≤ s0 < ℓ) where there is no heap.
void check_fold_s0(double s0, double ell, std::optional<double> start_heap, std::optional<double> end_heap,
                   const FrontKeys& keys = FrontKeys());

/// A plane's normal is a finite nonzero vector (`n`: its components).
void check_plane_normal(const Eigen::VectorXd& n, const std::string& shown, const FrontKeys& keys = FrontKeys());

}  // namespace chainsim
