// A checked view of one TOML table of a scene (checked_table.hpp).
#include "cases/scene/checked_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace chainsim::scene_parse {

using scene_text::closest;
using scene_text::join;

namespace {

/// Plain keys (not sections) allowed at the top level of a scene.
const std::vector<std::string> kTopLevelKeys = {"model"};
bool is_top_level_key(const std::string& key) {
  return std::find(kTopLevelKeys.begin(), kTopLevelKeys.end(), key) != kTopLevelKeys.end();
}

}  // namespace

Section::Section(const toml::table& table, std::string name, Context& ctx, std::vector<std::string> allowed,
                 const Moved& moved, std::string noun)
    : table_(table), name_(std::move(name)), ctx_(ctx) {
  if (!name_.empty() && table.source().begin.line > 0)
    ctx_.spec.locations[name_] = {ctx_.text.where(table.source()), ""};
  // The first unknown key in file order, then in the order of the overrides (toml++ iterates in key
  // order).
  const toml::key* unknown = nullptr;
  for (const auto& [key, node] : table) {
    const std::string k(key.str());
    if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) {
      ctx_.spec.locations[full(k)] = {ctx_.text.where(node.source()), ctx_.text.quote(node)};
      continue;
    }
    if (!unknown || ctx_.text.order(key.source()) < ctx_.text.order(unknown->source())) unknown = &key;
  }
  if (!unknown) return;
  const std::string k(unknown->str());
  const std::string loc = ctx_.text.where(unknown->source());
  std::string hint;
  for (const auto& [old_key, now] : moved)
    if (old_key == k) hint = fmt::format("; {} is now written {}", k, now);
  const std::string guess = closest(k, allowed);
  const bool is_table = table.get(k)->is_table();
  if (noun == "section") {
    // The top level holds sections and a few plain keys (kTopLevelKeys), listed apart.
    std::vector<std::string> sections, keys;
    for (const auto& a : allowed) (is_top_level_key(a) ? keys : sections).push_back(a);
    if (hint.empty() && !guess.empty())
      hint = is_top_level_key(guess) ? fmt::format(" (did you mean '{}'?)", guess) : fmt::format(" (did you mean [{}]?)", guess);
    throw InputError(fmt::format("{}: unknown {} {}; valid sections: {}{}{}", loc, is_table ? "section" : "top-level key",
                                 is_table ? "[" + k + "]" : "'" + k + "'", join(sections),
                                 keys.empty() ? "" : "; valid top-level keys: " + join(keys), hint));
  }
  if (noun == "effect") {
    if (hint.empty() && !guess.empty()) hint = fmt::format(" (did you mean [{}.{}]?)", name_, guess);
    throw InputError(fmt::format("{}: unknown effect [{}.{}]; valid effects: {}{}", loc, name_, k, join(allowed), hint));
  }
  if (hint.empty() && !guess.empty()) hint = fmt::format(" (did you mean '{}'?)", guess);
  throw InputError(fmt::format("{}: unknown key '{}' in {}; valid keys: {}{}", loc, k, shown_name(), join(allowed), hint));
}

std::string Section::at(const std::string& key) const {
  const toml::node* n = node(key);
  return ctx_.text.where(n ? n->source() : table_.source());
}

std::string Section::text(const std::string& key) const {
  const toml::node* n = node(key);
  return n ? ctx_.text.quote(*n) : "";
}

void Section::fail(const std::string& key, const std::string& message) const {
  throw InputError(fmt::format("{}: {}", at(key), message));
}

void Section::wrong_type(const std::string& key, const std::string& expected) const {
  fail(key, fmt::format("{} = {} must be {}", full(key), text(key), expected));
}

void Section::missing(const std::string& key, const std::string& what) const {
  throw InputError(fmt::format("{}: {} needs {} ({})", ctx_.text.where(table_.source()), shown_name(), key, what));
}

void Section::forbid(const std::string& key, bool applies, const std::string& context) const {
  if (has(key) && !applies) fail(key, fmt::format("{} does not apply to {}", full(key), context));
}

std::optional<double> Section::number(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  if (!(n->is_floating_point() || n->is_integer())) wrong_type(key, "a number");
  const double v = *n->value<double>();
  if (!std::isfinite(v)) wrong_type(key, "a finite number");
  return v;
}

double Section::number_in(const std::string& key, double fallback, double lo, double hi, Bound lo_bound,
                          Bound hi_bound) const {
  const auto v = number(key);
  if (!v) return fallback;
  located(key, full(key), [&] { require_in_range(full(key), *v, lo, hi, lo_bound, hi_bound); });
  return *v;
}

std::optional<double> Section::positive(const std::string& key) const {
  const auto v = number(key);
  if (v) located(key, full(key), [&] { require_positive(full(key), *v); });
  return v;
}

std::optional<long long> Section::integer(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  if (!n->is_integer()) wrong_type(key, "an integer");
  return n->value<long long>();
}

std::optional<long long> Section::integer_in(const std::string& key, long long lo, long long hi) const {
  const auto v = integer(key);
  if (v && (*v < lo || *v > hi)) {
    const std::string sym = key;
    fail(key, hi == std::numeric_limits<long long>::max() || hi == std::numeric_limits<long>::max()
                  ? fmt::format("{} = {} is out of range: allowed {} >= {}", full(key), *v, sym, lo)
                  : fmt::format("{} = {} is out of range: allowed {} <= {} <= {}", full(key), *v, lo, sym, hi));
  }
  return v;
}

std::optional<bool> Section::boolean(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  if (!n->is_boolean()) wrong_type(key, "true or false");
  return n->value<bool>();
}

std::optional<std::string> Section::string(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  if (!n->is_string()) wrong_type(key, "a string");
  return n->value<std::string>();
}

std::string Section::choice(const std::string& key, const std::vector<std::string>& choices,
                            const std::string& fallback) const {
  const auto value = string(key);
  if (!value) return fallback;
  check_choice(key, full(key), *value, choices);
  return *value;
}

void Section::check_choice(const std::string& key, const std::string& shown, const std::string& value,
                           const std::vector<std::string>& choices) const {
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) return;
  const std::string guess = closest(value, choices);
  fail(key, fmt::format("{} = \"{}\" is not allowed; valid values: {}{}", shown, value, join(choices),
                        guess.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", guess)));
}

std::vector<double> Section::vector(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return {};
  const toml::array* arr = n->as_array();
  if (!arr || arr->empty()) wrong_type(key, "a non-empty array of numbers, e.g. [0.0, -9.81]");
  return numbers(*arr, key);
}

std::vector<std::vector<double>> Section::matrix(const std::string& key) const {
  const toml::node* n = node(key);
  if (!n) return {};
  const toml::array* arr = n->as_array();
  const char* expected = "an array of points, e.g. [[0.0, 0.0], [1.0, 0.0]]";
  if (!arr || arr->empty()) wrong_type(key, expected);
  std::vector<std::vector<double>> out;
  for (const auto& row : *arr) {
    const toml::array* r = row.as_array();
    if (!r || r->empty()) wrong_type(key, expected);
    ctx_.spec.locations[fmt::format("{}[{}]", full(key), out.size())] = {ctx_.text.where(row.source()),
                                                                        ctx_.text.quote(row)};
    out.push_back(numbers(*r, key));
  }
  return out;
}

std::vector<std::string> Section::string_list(const std::string& key, const std::vector<std::string>& choices) const {
  const toml::node* n = node(key);
  if (!n) return {};
  const toml::array* arr = n->as_array();
  const std::string expected = "a non-empty array of strings from: " + join(choices);
  if (!arr || arr->empty()) wrong_type(key, expected);
  std::vector<std::string> out;
  for (std::size_t k = 0; k < arr->size(); ++k) {
    const toml::node& item = *arr->get(k);
    if (!item.is_string()) wrong_type(key, expected);
    const std::string value = *item.value<std::string>();
    const std::string shown = fmt::format("{}[{}]", full(key), k);
    try {
      check_choice(key, shown, value, choices);
      if (std::find(out.begin(), out.end(), value) != out.end())
        fail(key, fmt::format("{} lists \"{}\" twice", full(key), value));
    } catch (const InputError& e) {
      // Point at the element rather than at the array.
      const std::string message = e.what();
      throw InputError(ctx_.text.where(item.source()) + message.substr(message.find(": ")));
    }
    out.push_back(value);
  }
  return out;
}

std::vector<double> Section::numbers(const toml::array& arr, const std::string& key) const {
  std::vector<double> out;
  for (const auto& item : arr) {
    if (!(item.is_floating_point() || item.is_integer())) wrong_type(key, "an array of numbers");
    const double v = *item.value<double>();
    if (!std::isfinite(v)) wrong_type(key, "an array of finite numbers");
    out.push_back(v);
  }
  return out;
}

const toml::table& subtable(const Section& parent, const std::string& name) {
  static const toml::table empty;
  const toml::node* n = parent.node(name);
  if (!n) return empty;
  if (!n->is_table())
    parent.fail(name, fmt::format("{} = {} must be a table: write [{}] and its keys below it", parent.full(name),
                                  parent.text(name), parent.full(name)));
  return *n->as_table();
}

std::vector<const toml::table*> table_array(const Section& parent, const std::string& name, const std::string& what) {
  std::vector<const toml::table*> out;
  const toml::node* n = parent.node(name);
  if (!n) return out;
  const toml::array* arr = n->as_array();
  const std::string full = parent.full(name);
  if (!arr || arr->empty())
    parent.fail(name, fmt::format("{} must be an array of tables: write [[{}]] once per {}", full, full, what));
  for (std::size_t k = 0; k < arr->size(); ++k) {
    const toml::node& item = *arr->get(k);
    if (!item.is_table())  // e.g. an element set by an override: point at the element
      throw InputError(fmt::format("{}: {}[{}] = {} must be a table: write [[{}]] once per {}",
                                   parent.source_text().where(item.source()), full, k,
                                   parent.source_text().quote(item), full, what));
    out.push_back(item.as_table());
  }
  return out;
}

}  // namespace chainsim::scene_parse
