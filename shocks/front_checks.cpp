// The physical checks of the fronts' input: see front_checks.hpp.
#include "shocks/front_checks.hpp"

#include <cmath>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "shocks/jump_conditions.hpp"

namespace chainsim {

namespace {

std::string dot(const std::string& base, const std::string& field) { return field.empty() ? base : base + "." + field; }

/// require_in_range, its refusal located at `key`.
void in_range(const FrontKeys& keys, const std::string& key, double value, double lo, double hi) {
  try {
    require_in_range(key, value, lo, hi);
  } catch (const InputError& e) {
    keys.fail(key, e.what());
  }
}

}  // namespace

std::string FrontKeys::heap(std::size_t /*k*/, const std::string& field) const {
  return dot(heap_, field == "f" ? "dissipation" : field);
}

std::string FrontKeys::fold(const std::string& field) const { return dot(fold_, field == "f" ? "dissipation" : field); }

std::string FrontKeys::side(bool after) const {
  return after ? "a heap the string runs into" : "a start heap (side before s0)";
}

void FrontKeys::fail(const std::string& /*key*/, const std::string& message) const { throw InputError(message); }

void check_open_string(bool closed, bool heaps, const FrontKeys& keys) {
  if (closed)
    keys.fail(heaps ? keys.heap(0, "") : keys.fold(""),
              fmt::format("{} on a closed string: fronts are tracked on open strings only (string.closed = true)",
                          keys.declared(heaps)));
}

void check_one_heap_per_side(std::size_t k, bool after, std::optional<std::size_t> other, const FrontKeys& keys) {
  if (!other) return;
  const std::string key = keys.heap(k, "side");
  keys.fail(key, fmt::format("{} = {}: {} already holds that side of the string; allowed at most one heap per side",
                             key, keys.text(key, after ? "after" : "before"), keys.heap(*other, "")));
}

void check_heap_dissipation(std::size_t k, bool after, bool pot, double f, const FrontKeys& keys) {
  if (pot && after) {
    const std::string key = keys.heap(k, "pot");
    keys.fail(key, fmt::format("{} = true on {}: a pot feeds the string; allowed only for {}", key, keys.side(true),
                               keys.side(false)));
  }
  const std::string key = keys.heap(k, "f");
  const double lowest = jump::kPotMinDissipation;
  const std::string bare = key.substr(key.find_last_of('.') + 1);
  if (pot && !(f >= lowest && f <= 1))
    keys.fail(key, fmt::format("{} = {} is out of range: allowed {} <= {} <= 1 for a pot (it loses (1/2 + f) lambda "
                               "v^3, which must not be negative)",
                               key, keys.text(key, fmt::format("{}", f)), lowest, bare));
  if (pot) return;
  if (keys.hints() && f < 0 && f >= lowest)
    keys.fail(key, fmt::format("{} = {} is out of range: allowed 0 <= {} <= 1; a heap that pushes the string out "
                               "(f < 0, down to {}) must be a pot: {} with pot = true",
                               key, keys.text(key, fmt::format("{}", f)), bare, lowest, keys.side(false)));
  in_range(keys, key, f, 0.0, 1.0);
}

void check_heap_s0(std::size_t k, bool after, double s0, double ell, const FrontKeys& keys) {
  const bool inside = after ? (s0 > 0 && s0 <= ell * (1 + 1e-12)) : (s0 >= 0 && s0 < ell);
  if (inside) return;
  const std::string key = keys.heap(k, "s0");
  keys.fail(key, fmt::format("{} = {} is outside the string: allowed {} for {} (the string is {} m long)", key,
                             keys.text(key, fmt::format("{}", s0)),
                             after ? fmt::format("0 < s0 <= {}", ell) : fmt::format("0 <= s0 < {}", ell),
                             keys.side(after), ell));
}

void check_end_free(std::size_t k, bool after, double s0, const std::string& held, const FrontKeys& keys) {
  if (held.empty()) return;
  const std::string key = keys.end(after);
  keys.fail(key, fmt::format("{} = {} is inside the heap of {} ({}, s0 = {:g} m): an end held by a heap cannot be "
                             "fixed, loaded or driven",
                             key, held, keys.heap(k, ""), keys.side(after), s0));
}

void check_fold_dissipation(double f, const FrontKeys& keys) { in_range(keys, keys.fold("f"), f, 0.0, 1.0); }

void check_fold_s0(double s0, double ell, std::optional<double> start_heap, std::optional<double> end_heap,
                   const FrontKeys& keys) {
  const double lo = start_heap.value_or(0.0), hi = end_heap.value_or(ell);
  if ((start_heap ? s0 > lo : s0 >= 0) && s0 < hi) return;
  const std::string key = keys.fold("s0");
  keys.fail(key, fmt::format("{} = {} is {}: allowed {} {} s0 < {}", key, keys.text(key, fmt::format("{}", s0)),
                             start_heap || end_heap ? "not between the heaps" : "outside the string", lo,
                             start_heap ? "<" : "<=", hi));
}

void check_plane_normal(const Eigen::VectorXd& n, const std::string& shown, const FrontKeys& keys) {
  const std::string key = keys.plane_normal();
  if (!n.allFinite())
    keys.fail(key, fmt::format("{} = {} is not finite: a plane needs a finite normal", key, keys.text(key, shown)));
  if (n.isZero(0.0)) keys.fail(key, fmt::format("{} = {} is zero: a plane needs a normal", key, keys.text(key, shown)));
}

}  // namespace chainsim
