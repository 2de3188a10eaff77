#include "mesh/errors.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace chainsim {

namespace {
std::string bare_name(std::string_view name) {
  // "--f" -> "f", "--t-max" -> "t_max", "string.length" -> "length": the symbol used in the range
  // expression (an option's inner dashes are part of its name).
  const auto start = name.find_first_not_of('-');
  if (start != std::string_view::npos) name.remove_prefix(start);
  const auto dot = name.find_last_of('.');
  std::string sym(dot == std::string_view::npos ? name : name.substr(dot + 1));
  std::replace(sym.begin(), sym.end(), '-', '_');
  return sym;
}
}  // namespace

void require_in_range(std::string_view name, double value, double lo, double hi, Bound lo_bound,
                      Bound hi_bound) {
  const bool lo_ok = lo_bound == Bound::kClosed ? value >= lo : value > lo;
  const bool hi_ok = hi_bound == Bound::kClosed ? value <= hi : value < hi;
  if (std::isfinite(value) && lo_ok && hi_ok) return;
  const std::string sym = bare_name(name);
  std::string range;
  // Values and bounds in their shortest round-trip form: a value just outside a bound never prints
  // as the bound (10000001 is not "1e+07", 1.0000000000000002 is not "1").
  if (std::isfinite(lo) && std::isfinite(hi))
    range = fmt::format("{} {} {} {} {}", lo, lo_bound == Bound::kClosed ? "<=" : "<", sym,
                        hi_bound == Bound::kClosed ? "<=" : "<", hi);
  else if (std::isfinite(lo))
    range = fmt::format("{} {} {}", sym, lo_bound == Bound::kClosed ? ">=" : ">", lo);
  else
    range = fmt::format("{} {} {}", sym, hi_bound == Bound::kClosed ? "<=" : "<", hi);
  throw InputError(fmt::format("{} = {} is out of range: allowed {}", name, value, range));
}

void require_positive(std::string_view name, double value) {
  require_in_range(name, value, 0.0, INFINITY, Bound::kOpen, Bound::kOpen);
}

void require_finite(std::string_view name, double value) {
  if (!std::isfinite(value))
    throw InputError(fmt::format("{} = {} is not a finite number", name, value));
}

void verify_failed(const char* condition, const char* file, int line, const std::string& msg) {
  throw Error(fmt::format("internal error (please report): {} [{} failed at {}:{}]", msg, condition,
                          file, line));
}

}  // namespace chainsim
