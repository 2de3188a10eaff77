// String scenes: parser (TOML -> SceneSpec) and builder (SceneSpec -> StringModel).
// See scene.hpp for the outline and docs/scenes.md for every key.
//
// Steps: 1. the scene text (positions and values as written), 2. a checked view of one TOML table,
// 3. one parse function per section, 4. the builder, which re-locates every error it raises at the
// key that caused it.
#include "cases/scene/scene.hpp"

#include "cases/scene/scene_build.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

using scene_build::as_vec;
using scene_build::at_key;
using scene_build::fail_at;

namespace {

/// The largest number of nodes a scene may ask for (memory: a few hundred bytes per node).
constexpr long long kMaxNodes = 10000000;
/// Prescribed ends closer than this fraction of the string's length to being pulled taut are refused.
constexpr double kTautFraction = 1e-9;
/// Instants at which two prescribed end paths are sampled for their distance (over [0, t_end]).
constexpr int kEndPathSamples = 2001;
/// A value quoted in a message is cut to this many characters.
constexpr std::size_t kQuoteLength = 60;

std::string join(const std::vector<std::string>& words, const char* separator = ", ") {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : separator) + w;
  return out;
}

// ================================================================================================
// 1. The scene text: "file:line:column" of a region and the value as the user wrote it.
// ================================================================================================
class SourceText {
 public:
  SourceText(std::string name, std::string_view text) : name_(std::move(name)) {
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t stop = std::min(text.find('\n', start), text.size());
      lines_.emplace_back(text.substr(start, stop - start));
      start = stop + 1;
    }
  }
  const std::string& name() const { return name_; }

  std::string where(const toml::source_region& region) const {
    if (region.begin.line == 0) return name_ + ":1:1";
    return fmt::format("{}:{}:{}", name_, region.begin.line, region.begin.column);
  }

  /// The text of `region` with runs of white space collapsed (cut to kQuoteLength characters).
  std::string quote(const toml::source_region& region) const {
    if (region.begin.line == 0 || region.begin.line > lines_.size()) return "";
    std::string raw;
    const auto last = std::min<std::size_t>(region.end.line, lines_.size());
    for (std::size_t line = region.begin.line; line <= last; ++line) {
      const std::string& text = lines_[line - 1];
      const std::size_t from = line == region.begin.line ? byte_offset(text, region.begin.column) : 0;
      const std::size_t to = line == region.end.line ? byte_offset(text, region.end.column) : text.size();
      if (to > from) raw += text.substr(from, to - from);
      raw += ' ';
    }
    std::string out;
    for (char c : raw) {
      const bool space = c == ' ' || c == '\t' || c == '\r';
      if (space && (out.empty() || out.back() == ' ')) continue;
      out += space ? ' ' : c;
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    if (out.size() > kQuoteLength) out = out.substr(0, kQuoteLength - 3) + "...";
    return out;
  }

 private:
  /// Byte offset of the 1-based column `column` (toml++ counts code points) in a UTF-8 line.
  static std::size_t byte_offset(const std::string& line, std::size_t column) {
    std::size_t seen = 0;
    for (std::size_t i = 0; i < line.size(); ++i)
      if ((static_cast<unsigned char>(line[i]) & 0xC0) != 0x80 && ++seen == column) return i;
    return line.size();
  }

  std::string name_;
  std::vector<std::string> lines_;
};

/// Plain keys (not sections) allowed at the top level of a scene.
const std::vector<std::string> kTopLevelKeys = {"model"};
bool is_top_level_key(const std::string& key) {
  return std::find(kTopLevelKeys.begin(), kTopLevelKeys.end(), key) != kTopLevelKeys.end();
}

/// Optimal-string-alignment distance (a swap of two neighbours counts one edit).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

/// The valid word closest to `word` if it is close enough to be a typo (at most 2 edits, and fewer
/// than half its letters), or one that `word` begins (a truncated key); "" otherwise.
std::string closest(const std::string& word, const std::vector<std::string>& valid) {
  std::string best;
  std::size_t best_distance = 3;
  for (const auto& v : valid) {
    const std::size_t d = edit_distance(word, v);
    if (d < best_distance && 2 * d < std::max(word.size(), v.size())) {
      best = v;
      best_distance = d;
    }
  }
  if (best.empty() && word.size() >= 3)
    for (const auto& v : valid)
      if (v.rfind(word, 0) == 0) return v;
  return best;
}

// ================================================================================================
// 2. A checked view of one TOML table.
// ================================================================================================
struct Context {
  const SourceText& text;
  SceneSpec& spec;
};

class Section {
 public:
  /// Keys that used to live elsewhere: key -> where it is written now.
  using Moved = std::vector<std::pair<std::string, std::string>>;

  /// Checks that every key of `table` is in `allowed` and records where each one was written.
  /// `name` is the section's dotted name ("" for the top level); `noun` is what its keys are
  /// ("key", "section", "effect").
  Section(const toml::table& table, std::string name, Context& ctx, std::vector<std::string> allowed,
          const Moved& moved = {}, std::string noun = "key")
      : table_(table), name_(std::move(name)), ctx_(ctx) {
    if (!name_.empty() && table.source().begin.line > 0)
      ctx_.spec.locations[name_] = {ctx_.text.where(table.source()), ""};
    // The first unknown key in file order (toml++ iterates in key order).
    const toml::key* unknown = nullptr;
    for (const auto& [key, node] : table) {
      const std::string k(key.str());
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) {
        ctx_.spec.locations[full(k)] = {ctx_.text.where(node.source()), ctx_.text.quote(node.source())};
        continue;
      }
      const auto& p = key.source().begin;
      if (!unknown || std::pair(p.line, p.column) < std::pair(unknown->source().begin.line, unknown->source().begin.column))
        unknown = &key;
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

  bool has(const std::string& key) const { return table_.contains(key); }
  const toml::node* node(const std::string& key) const { return table_.get(key); }
  std::string full(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }
  /// Location of the key's value, or of the section when the key is absent.
  std::string at(const std::string& key) const {
    const toml::node* n = node(key);
    return ctx_.text.where(n ? n->source() : table_.source());
  }
  std::string text(const std::string& key) const {
    const toml::node* n = node(key);
    return n ? ctx_.text.quote(n->source()) : "";
  }
  const std::string& name() const { return name_; }

  /// Throws "<location of key>: <message>".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InputError(fmt::format("{}: {}", at(key), message));
  }
  [[noreturn]] void wrong_type(const std::string& key, const std::string& expected) const {
    fail(key, fmt::format("{} = {} must be {}", full(key), text(key), expected));
  }
  /// A required key is absent: "<location of the section>: [name] needs <key> (<what>)".
  [[noreturn]] void missing(const std::string& key, const std::string& what) const {
    throw InputError(fmt::format("{}: {} needs {} ({})", ctx_.text.where(table_.source()), shown_name(), key, what));
  }
  /// The section as messages show it: "[effects.gravity]", or "effects.heap[0]" for an element of
  /// an array of tables.
  std::string shown_name() const { return name_.back() == ']' ? name_ : "[" + name_ + "]"; }
  /// The key does not apply to `context` (e.g. kind = "circle").
  void forbid(const std::string& key, bool applies, const std::string& context) const {
    if (has(key) && !applies) fail(key, fmt::format("{} does not apply to {}", full(key), context));
  }
  /// Runs `check` (which may throw InputError worded for the bare key "short_name = value …") and
  /// re-throws its message at this key's location, naming the key in full.
  template <class F>
  void located(const std::string& key, const std::string& short_name, F&& check) const {
    try {
      check();
    } catch (const InputError& e) {
      std::string message = e.what();
      if (message.rfind(short_name + " = ", 0) == 0) message = full(key) + message.substr(short_name.size());
      fail(key, message);
    }
  }

  std::optional<double> number(const std::string& key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!(n->is_floating_point() || n->is_integer())) wrong_type(key, "a number");
    const double v = *n->value<double>();
    if (!std::isfinite(v)) wrong_type(key, "a finite number");
    return v;
  }
  /// A number checked against a range (worded like require_in_range); `fallback` if absent.
  double number_in(const std::string& key, double fallback, double lo, double hi, Bound lo_bound = Bound::kClosed,
                   Bound hi_bound = Bound::kClosed) const {
    const auto v = number(key);
    if (!v) return fallback;
    located(key, full(key), [&] { require_in_range(full(key), *v, lo, hi, lo_bound, hi_bound); });
    return *v;
  }
  std::optional<double> positive(const std::string& key) const {
    const auto v = number(key);
    if (v) located(key, full(key), [&] { require_positive(full(key), *v); });
    return v;
  }

  std::optional<long long> integer(const std::string& key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_integer()) wrong_type(key, "an integer");
    return n->value<long long>();
  }

  std::optional<bool> boolean(const std::string& key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_boolean()) wrong_type(key, "true or false");
    return n->value<bool>();
  }

  std::optional<std::string> string(const std::string& key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_string()) wrong_type(key, "a string");
    return n->value<std::string>();
  }
  /// A string that must be one of `choices`.
  std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& fallback) const {
    const auto value = string(key);
    if (!value) return fallback;
    check_choice(key, full(key), *value, choices);
    return *value;
  }
  void check_choice(const std::string& key, const std::string& shown, const std::string& value,
                    const std::vector<std::string>& choices) const {
    if (std::find(choices.begin(), choices.end(), value) != choices.end()) return;
    const std::string guess = closest(value, choices);
    fail(key, fmt::format("{} = \"{}\" is not allowed; valid values: {}{}", shown, value, join(choices),
                          guess.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", guess)));
  }

  std::vector<double> vector(const std::string& key) const {
    const toml::node* n = node(key);
    if (!n) return {};
    const toml::array* arr = n->as_array();
    if (!arr || arr->empty()) wrong_type(key, "a non-empty array of numbers, e.g. [0.0, -9.81]");
    return numbers(*arr, key);
  }

  /// An array of points; the location of each is recorded as key[k].
  std::vector<std::vector<double>> matrix(const std::string& key) const {
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
                                                                          ctx_.text.quote(row.source())};
      out.push_back(numbers(*r, key));
    }
    return out;
  }

  /// A non-empty array of distinct strings, each one of `choices`.
  std::vector<std::string> string_list(const std::string& key, const std::vector<std::string>& choices) const {
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

 private:
  std::vector<double> numbers(const toml::array& arr, const std::string& key) const {
    std::vector<double> out;
    for (const auto& item : arr) {
      if (!(item.is_floating_point() || item.is_integer())) wrong_type(key, "an array of numbers");
      const double v = *item.value<double>();
      if (!std::isfinite(v)) wrong_type(key, "an array of finite numbers");
      out.push_back(v);
    }
    return out;
  }

  const toml::table& table_;
  std::string name_;
  Context& ctx_;
};

/// The sub-table `name` of `parent` (an empty table if it is absent).
const toml::table& subtable(const Section& parent, const std::string& name) {
  static const toml::table empty;
  const toml::node* n = parent.node(name);
  if (!n) return empty;
  if (!n->is_table())
    parent.fail(name, fmt::format("{} = {} must be a table: write [{}] and its keys below it", parent.full(name),
                                  parent.text(name), parent.full(name)));
  return *n->as_table();
}

/// The elements of the array of tables `name` of `parent` ([[name]]; none if it is absent).
std::vector<const toml::table*> table_array(const Section& parent, const std::string& name, const std::string& what) {
  std::vector<const toml::table*> out;
  const toml::node* n = parent.node(name);
  if (!n) return out;
  const toml::array* arr = n->as_array();
  if (!arr || !arr->is_array_of_tables())
    parent.fail(name, fmt::format("{} must be an array of tables: write [[{}]] once per {}", parent.full(name),
                                  parent.full(name), what));
  for (const auto& item : *arr) out.push_back(item.as_table());
  return out;
}

// ================================================================================================
// 3. One parse function per section.
// ================================================================================================
void parse_string(const Section& top, Context& ctx) {
  SceneSpec& spec = ctx.spec;
  Section s(subtable(top, "string"), "string", ctx, {"length", "density", "nodes", "link_length", "closed", "dimension"});
  spec.length = s.positive("length");
  spec.density = s.positive("density").value_or(spec.density);
  if (auto n = s.integer("nodes")) {
    s.located("nodes", "string.nodes",
              [&] { require_in_range("string.nodes", static_cast<double>(*n), 2, static_cast<double>(kMaxNodes)); });
    spec.nodes = static_cast<int>(*n);
  }
  spec.link_length = s.positive("link_length");
  if (spec.nodes && spec.link_length)
    s.fail("link_length", fmt::format("string.link_length = {} and string.nodes = {} both set the resolution: give "
                                      "one of them",
                                      s.text("link_length"), s.text("nodes")));
  spec.closed = s.boolean("closed");
  if (auto d = s.integer("dimension")) {
    if (*d != 2 && *d != 3) s.fail("dimension", fmt::format("string.dimension = {} is not allowed; valid values: 2, 3", *d));
    spec.dimension = static_cast<int>(*d);
  }
}

void parse_shape(const Section& top, Context& ctx) {
  auto& sh = ctx.spec.shape;
  const std::vector<std::string> kinds = {"polyline", "points", "arc", "circle", "catenary"};
  if (!top.has("shape"))
    throw InputError(fmt::format("{}:1:1: the scene needs a [shape] section with kind = one of {}", ctx.text.name(),
                                 join(kinds)));
  Section s(subtable(top, "shape"), "shape", ctx,
            {"kind", "points", "corner_radius", "center", "radius", "start_angle_deg", "sweep_deg", "axis1", "axis2",
             "start", "end", "length_tolerance"});
  if (!s.has("kind")) s.missing("kind", "one of " + join(kinds));
  sh.kind = s.choice("kind", kinds, "");
  sh.points = s.matrix("points");
  sh.corner_radius = s.positive("corner_radius");
  sh.center = s.vector("center");
  sh.radius = s.positive("radius").value_or(0.0);
  sh.start_angle_deg = s.number("start_angle_deg").value_or(0.0);
  sh.sweep_deg = s.number("sweep_deg").value_or(0.0);
  if (s.has("sweep_deg") && !(sh.sweep_deg != 0 && std::abs(sh.sweep_deg) <= 360))
    s.fail("sweep_deg", fmt::format("shape.sweep_deg = {} is out of range: allowed 0 < |sweep_deg| <= 360",
                                    s.text("sweep_deg")));
  sh.axis1 = s.vector("axis1");
  sh.axis2 = s.vector("axis2");
  sh.start = s.vector("start");
  sh.end = s.vector("end");
  sh.length_tolerance = s.number_in("length_tolerance", sh.length_tolerance, 0, 1, Bound::kOpen);
  // Keys the chosen kind needs, and keys that do not apply to it.
  const std::string context = fmt::format("kind = \"{}\"", sh.kind);
  auto need = [&](const char* key, const char* what) {
    if (!s.has(key)) s.missing(key, fmt::format("{}, for kind = \"{}\"", what, sh.kind));
  };
  const bool line = sh.kind == "polyline" || sh.kind == "points", round = sh.kind == "arc" || sh.kind == "circle";
  const bool arc = sh.kind == "arc", catenary = sh.kind == "catenary";
  if (line) need("points", "the vertices, e.g. [[0.0, 0.0], [1.0, 0.0]] (m)");
  if (round) need("center", "a point (m)");
  if (round) need("radius", "m, > 0");
  if (arc) need("sweep_deg", "degrees, 0 < |sweep_deg| <= 360");
  if (catenary) need("start", "the first suspension point (m)");
  if (catenary) need("end", "the second suspension point (m)");
  if (line && sh.points.size() < 2)
    s.fail("points", fmt::format("shape.points = {} has {} point: a shape needs at least 2", s.text("points"),
                                 sh.points.size()));
  s.forbid("points", line, context);
  s.forbid("corner_radius", line, context);
  for (const char* key : {"center", "radius", "start_angle_deg", "axis1", "axis2"}) s.forbid(key, round, context);
  s.forbid("sweep_deg", arc, context);
  s.forbid("start", catenary, context);
  s.forbid("end", catenary, context);
}

void parse_velocity(const Section& top, Context& ctx) {
  auto& v = ctx.spec.velocity;
  Section s(subtable(top, "velocity"), "velocity", ctx, {"kind", "value", "speed", "values"});
  v.kind = s.choice("kind", {"rest", "uniform", "tangential", "nodes"}, "rest");
  v.value = s.vector("value");
  v.speed = s.number("speed").value_or(0.0);
  v.values = s.matrix("values");
  const std::string context = fmt::format("kind = \"{}\"", v.kind);
  if (v.kind == "uniform" && !s.has("value")) s.missing("value", "m/s, the velocity of every node, for kind = \"uniform\"");
  if (v.kind == "tangential" && !s.has("speed")) s.missing("speed", "m/s, along the string, for kind = \"tangential\"");
  if (v.kind == "nodes" && !s.has("values")) s.missing("values", "m/s, one vector per node, for kind = \"nodes\"");
  s.forbid("value", v.kind == "uniform", context);
  s.forbid("speed", v.kind == "tangential", context);
  s.forbid("values", v.kind == "nodes", context);
}

EndSpec parse_end(const Section& ends, const std::string& key, Context& ctx) {
  EndSpec spec;
  const toml::node* n = ends.node(key);
  if (!n) return spec;
  const std::vector<std::string> kinds = {"free", "fixed", "loaded", "driven"};
  const std::string name = ends.full(key);
  if (n->is_string()) {
    spec.kind = ends.choice(key, kinds, "free");
    if (spec.kind == "loaded" || spec.kind == "driven")
      ends.fail(key, fmt::format("{} = \"{}\" needs parameters: write it as a table, e.g. {}", name, spec.kind,
                                 spec.kind == "loaded"
                                     ? "{ kind = \"loaded\", force = [0.0, -1.0] }"
                                     : "{ kind = \"driven\", path = \"shake\", amplitude = [0.05, 0.0], omega = 10.0 }"));
    return spec;
  }
  if (!n->is_table()) ends.wrong_type(key, "a string (free, fixed) or a table with kind = ...");
  Section s(*n->as_table(), name, ctx, {"kind", "force", "amplitude", "omega", "path", "velocity"});
  if (!s.has("kind")) s.missing("kind", "one of " + join(kinds));
  spec.kind = s.choice("kind", kinds, "free");
  spec.path = s.choice("path", {"shake", "sine", "linear"}, "shake");
  spec.force = s.vector("force");
  spec.amplitude = s.vector("amplitude");
  spec.velocity = s.vector("velocity");
  const bool loaded = spec.kind == "loaded", driven = spec.kind == "driven";
  const bool harmonic = driven && spec.path != "linear";
  const std::string context =
      driven ? fmt::format("kind = \"driven\", path = \"{}\"", spec.path) : fmt::format("kind = \"{}\"", spec.kind);
  s.forbid("force", loaded, context);
  s.forbid("amplitude", loaded || harmonic, context);
  s.forbid("omega", (loaded && s.has("amplitude")) || harmonic, context + (loaded ? " without amplitude" : ""));
  s.forbid("path", driven, context);
  s.forbid("velocity", driven && spec.path == "linear", context);
  if (loaded && !s.has("force") && !s.has("amplitude"))
    s.missing("force", "N: F(t) = force + amplitude sin(omega t); give force and/or amplitude");
  if (harmonic && !s.has("amplitude")) s.missing("amplitude", fmt::format("m, for {}", context));
  if (driven && spec.path == "linear" && !s.has("velocity")) s.missing("velocity", fmt::format("m/s, for {}", context));
  if ((harmonic || (loaded && s.has("amplitude"))) && !s.has("omega"))
    s.missing("omega", fmt::format("rad/s, > 0, for {}{}", context, loaded ? " with amplitude" : ""));
  if (s.has("omega")) {
    spec.omega = *s.number("omega");
    s.located("omega", s.full("omega"), [&] { require_positive(s.full("omega"), spec.omega); });
  }
  return spec;
}

void parse_ends(const Section& top, Context& ctx) {
  Section s(subtable(top, "ends"), "ends", ctx, {"start", "end"});
  ctx.spec.start = parse_end(s, "start", ctx);
  ctx.spec.end = parse_end(s, "end", ctx);
}

/// [[effects.heap]]: one table per heap, at most one per side.
void parse_heaps(const Section& effects, Context& ctx) {
  auto& heaps = ctx.spec.effects.heaps;
  const auto tables = table_array(effects, "heap", "heap");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section h(*tables[k], fmt::format("effects.heap[{}]", k), ctx, {"side", "s0", "f", "point", "on_plane"});
    if (!h.has("side")) h.missing("side", "\"start\" (the heap holds s < s0 and feeds the string) or \"end\" (it holds s > s0)");
    if (!h.has("s0")) h.missing("s0", "m, the material coordinate of the front at t = 0");
    if (!h.has("point")) h.missing("point", "m, the hole or edge the front sits at, or the contact point on the plane at t = 0");
    HeapEntry heap;
    heap.side = h.choice("side", {"start", "end"}, "");
    for (std::size_t j = 0; j < heaps.size(); ++j)
      if (heaps[j].side == heap.side)
        h.fail("side", fmt::format("effects.heap[{}].side = \"{}\": effects.heap[{}] already holds that side of the "
                                   "string; allowed at most one heap per side",
                                   k, heap.side, j));
    heap.s0 = *h.number("s0");
    heap.dissipation = h.number_in("f", 0.0, 0.0, 1.0);
    heap.point = h.vector("point");
    heap.on_plane = h.boolean("on_plane").value_or(false);
    heaps.push_back(heap);
  }
}

void parse_effects(const Section& top, Context& ctx) {
  auto& fx = ctx.spec.effects;
  Section s(subtable(top, "effects"), "effects", ctx, {"gravity", "drag", "heap", "fold", "plane"}, {}, "effect");
  if (s.has("gravity")) {
    Section g(subtable(s, "gravity"), "effects.gravity", ctx, {"g"});
    if (!g.has("g")) g.missing("g", "m/s^2, a vector [gx, gy] or [gx, gy, gz]");
    fx.gravity = g.vector("g");
  }
  if (s.has("drag")) {
    Section d(subtable(s, "drag"), "effects.drag", ctx, {"coefficient"});
    if (!d.has("coefficient")) d.missing("coefficient", "1/s, >= 0: the force -coefficient m v on every node");
    fx.drag = d.number_in("coefficient", 0.0, 0.0, INFINITY);
  }
  parse_heaps(s, ctx);
  if (s.has("fold")) {
    Section f(subtable(s, "fold"), "effects.fold", ctx, {"s0", "f"});
    if (!f.has("s0")) f.missing("s0", "m, the material coordinate of the fold at t = 0");
    fx.fold = FoldEntry{*f.number("s0"), f.number_in("f", 0.0, 0.0, 1.0)};
  }
  if (s.has("plane")) {
    Section p(subtable(s, "plane"), "effects.plane", ctx, {"point", "normal"});
    if (!p.has("point")) p.missing("point", "m, a point of the plane");
    if (!p.has("normal")) p.missing("normal", "a vector normal to the plane, pointing to the string's side");
    fx.plane = PlaneEntry{p.vector("point"), p.vector("normal")};
  }
  // The plane is the table of a heap: it exists for on_plane heaps only (the string itself does not
  // collide with it), and an on_plane heap needs it.
  bool on_plane = false;
  for (std::size_t k = 0; k < fx.heaps.size(); ++k) {
    on_plane = on_plane || fx.heaps[k].on_plane;
    if (fx.heaps[k].on_plane && !fx.plane)
      throw InputError(fmt::format("{}: effects.heap[{}].on_plane = true needs [effects.plane] (point, normal): the "
                                   "table the heap lies on",
                                   ctx.spec.where(fmt::format("effects.heap[{}].on_plane", k)), k));
  }
  if (fx.plane && !on_plane)
    throw InputError(fmt::format("{}: [effects.plane] is the table under a heap, but no [[effects.heap]] has on_plane = "
                                 "true (the string itself does not collide with the plane)",
                                 ctx.spec.where("effects.plane")));
}

void parse_solver(const Section& top, Context& ctx) {
  auto& so = ctx.spec.solver;
  Section s(subtable(top, "solver"), "solver", ctx,
            {"method", "rtol", "atol", "max_step", "initial_step", "max_steps", "stabilization_time", "backend",
             "check_slack", "slack_tolerance"},
            {{"t_end", "in [stop]"}, {"output_interval", "as interval in [output]"}, {"vtk", "as formats in [output]"}});
  // Each value is checked by the option struct that owns its range, one field at a time.
  auto integrator = [&](const char* key, auto set) {
    s.located(key, key, [&] {
      IntegratorOptions o;
      set(o);
      o.validate();
    });
  };
  so.method = s.string("method").value_or(so.method);
  integrator("method", [&](IntegratorOptions& o) { o.method = so.method; });
  so.rtol = s.number("rtol").value_or(so.rtol);
  integrator("rtol", [&](IntegratorOptions& o) { o.rtol = so.rtol; });
  so.atol = s.number("atol").value_or(so.atol);
  integrator("atol", [&](IntegratorOptions& o) { o.atol = so.atol; });
  so.max_step = s.number("max_step").value_or(so.max_step);
  integrator("max_step", [&](IntegratorOptions& o) { o.max_step = so.max_step; });
  so.initial_step = s.number("initial_step").value_or(so.initial_step);
  integrator("initial_step", [&](IntegratorOptions& o) { o.initial_step = so.initial_step; });
  so.max_steps = static_cast<long>(s.integer("max_steps").value_or(so.max_steps));
  integrator("max_steps", [&](IntegratorOptions& o) { o.max_steps = so.max_steps; });
  auto model = [&](const char* key, auto set) {
    s.located(key, key, [&] {
      StringModelOptions o;
      set(o);
      o.validate();
    });
  };
  so.stabilization_time = s.number("stabilization_time");
  if (so.stabilization_time)
    model("stabilization_time", [&](StringModelOptions& o) { o.stabilization_time = *so.stabilization_time; });
  so.backend = s.string("backend").value_or(so.backend);
  model("backend", [&](StringModelOptions& o) { o.backend = so.backend; });
  so.check_slack = s.boolean("check_slack").value_or(so.check_slack);
  so.slack_tolerance = s.number("slack_tolerance").value_or(so.slack_tolerance);
  model("slack_tolerance", [&](StringModelOptions& o) { o.slack_tolerance = so.slack_tolerance; });
}

void parse_output(const Section& top, Context& ctx) {
  auto& out = ctx.spec.output;
  Section s(subtable(top, "output"), "output", ctx, {"interval", "fields", "formats"});
  out.interval = s.positive("interval").value_or(out.interval);
  if (s.has("fields")) {
    const auto fields = s.string_list("fields", {"nodes", "tension", "energy", "stats"});
    auto has = [&](const char* f) { return std::find(fields.begin(), fields.end(), f) != fields.end(); };
    out.select.nodes = has("nodes");
    out.select.tension = has("tension");
    out.select.energy = has("energy");
    out.select.stats = has("stats");
  }
  if (s.has("formats")) {
    const auto formats = s.string_list("formats", {"csv", "vtk"});
    out.select.csv = std::find(formats.begin(), formats.end(), "csv") != formats.end();
    out.select.vtk = std::find(formats.begin(), formats.end(), "vtk") != formats.end();
  }
  if (out.select.vtk && !out.select.nodes)
    s.fail(s.has("fields") ? "fields" : "formats",
           fmt::format("output.formats includes \"vtk\" (the default), which draws the string from its nodes: "
                       "output.fields must include \"nodes\" (or set formats = [\"csv\"])"));
}

void parse_stop(const Section& top, Context& ctx) {
  if (!top.has("stop"))
    throw InputError(fmt::format("{}:1:1: the scene needs a [stop] section with t_end (the end time, s, > 0)",
                                 ctx.text.name()));
  Section s(subtable(top, "stop"), "stop", ctx, {"t_end", "front"});
  if (!s.has("t_end")) s.missing("t_end", "the end time, s, > 0");
  ctx.spec.stop.t_end = *s.positive("t_end");
  const auto tables = table_array(s, "front", "stop event");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section f(*tables[k], fmt::format("stop.front[{}]", k), ctx, {"front", "s0"});
    if (!f.has("front")) f.missing("front", "which front: fold, heap_start or heap_end");
    if (!f.has("s0")) f.missing("s0", "m, stop when that front reaches this material coordinate");
    ctx.spec.stop.fronts.push_back({f.choice("front", {"fold", "heap_start", "heap_end"}, ""), *f.number("s0")});
  }
}

void parse_model(const Section& top, Context& ctx) {
  ctx.spec.model = top.choice("model", {"string", "reduced"}, "string");
}

SceneSpec parse_table(const toml::table& root, const SourceText& text) {
  SceneSpec spec;
  spec.source = text.name();
  Context ctx{text, spec};
  const Section top(root, "", ctx,
                    {"string", "shape", "velocity", "ends", "effects", "solver", "output", "stop", "model"},
                    {{"gravity", "[effects.gravity]"}, {"drag", "[effects.drag]"}, {"heap", "[[effects.heap]]"},
                     {"fold", "[effects.fold]"}, {"plane", "[effects.plane]"}},
                    "section");
  parse_model(top, ctx);
  parse_string(top, ctx);
  parse_shape(top, ctx);
  parse_velocity(top, ctx);
  parse_ends(top, ctx);
  parse_effects(top, ctx);
  parse_solver(top, ctx);
  parse_output(top, ctx);
  parse_stop(top, ctx);
  return spec;
}

// ================================================================================================
// 4. Building: SceneSpec -> model. Every InputError names the location of the key at fault.
// ================================================================================================
template <int dim>
Points<dim> as_points(const SceneSpec& spec, const std::vector<std::vector<double>>& rows, const std::string& key) {
  Points<dim> out(dim, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = as_vec<dim>(spec, rows[k], fmt::format("{}[{}]", key, k));
  return out;
}

template <int dim>
Vec<dim> unit(int axis) {
  Vec<dim> e = Vec<dim>::Zero();
  e[axis] = 1;
  return e;
}

/// The initial shape as a curve.
template <int dim>
std::unique_ptr<Curve<dim>> build_curve(const SceneSpec& spec, bool closed, const Vec<dim>& down) {
  const auto& sh = spec.shape;
  if (sh.kind == "polyline" || sh.kind == "points") {
    const Points<dim> points = as_points<dim>(spec, sh.points, "shape.points");
    auto polyline = at_key(spec, "shape.points", [&] { return polyline_curve<dim>(points, closed); });
    if (!sh.corner_radius) return polyline;
    if (closed)
      fail_at(spec, "shape.corner_radius",
              "shape.corner_radius does not apply to a closed string (string.closed = true): only the interior "
              "points of an open polyline are rounded");
    return at_key(spec, "shape.corner_radius", [&] { return rounded_polyline_curve<dim>(points, *sh.corner_radius); });
  }
  if (sh.kind == "arc" || sh.kind == "circle") {
    const Vec<dim> center = as_vec<dim>(spec, sh.center, "shape.center");
    const Vec<dim> axis1 = sh.axis1.empty() ? unit<dim>(0) : as_vec<dim>(spec, sh.axis1, "shape.axis1");
    const Vec<dim> axis2 = sh.axis2.empty() ? unit<dim>(1) : as_vec<dim>(spec, sh.axis2, "shape.axis2");
    const std::string axes = sh.axis2.empty() ? "shape.axis1" : "shape.axis2";
    if (sh.kind == "circle")
      return at_key(spec, axes, [&] { return circle_curve<dim>(center, sh.radius, axis1, axis2); });
    return at_key(spec, axes, [&] {
      return circle_arc_curve<dim>(center, sh.radius, sh.start_angle_deg * kPi / 180, sh.sweep_deg * kPi / 180, axis1,
                                   axis2);
    });
  }
  CHAINSIM_VERIFY(sh.kind == "catenary", "parse_shape admits only the kinds built here");
  if (!spec.length) fail_at(spec, "shape.kind", "a catenary shape needs string.length (the sag follows from it)");
  const Vec<dim> start = as_vec<dim>(spec, sh.start, "shape.start");
  const Vec<dim> end = as_vec<dim>(spec, sh.end, "shape.end");
  return at_key(spec, "shape.end", [&] { return catenary_curve<dim>(start, end, *spec.length, down); });
}

/// The number of links: string.nodes, or the length over string.link_length rounded (default 41 nodes).
int link_count(const SceneSpec& spec, double length, bool closed) {
  const int minimum = closed ? 3 : 1;
  if (spec.link_length) {
    const double links = std::round(length / *spec.link_length);
    if (links > kMaxNodes)
      fail_at(spec, "string.link_length",
              fmt::format("string.link_length = {:g} m asks for {:.3g} links on {:g} m: allowed at most {} nodes",
                          *spec.link_length, links, length, kMaxNodes));
    return std::max(minimum, static_cast<int>(links));
  }
  const int nodes = spec.nodes.value_or(41);
  const int links = closed ? nodes : nodes - 1;
  if (links < minimum)
    fail_at(spec, "string.nodes", fmt::format("string.nodes = {} is too small: a closed string needs at least 3 nodes",
                                              nodes));
  return links;
}

/// Two prescribed ends may never be pulled as far apart as the string is long (it would have to
/// stretch); sampled over [0, t_end].
template <int dim>
void check_prescribed_ends(const SceneSpec& spec, const std::vector<PrescribedNode<dim>>& prescribed, double length) {
  if (prescribed.size() < 2) return;
  const EndPath<dim>& a = *prescribed[0].path;
  const EndPath<dim>& b = *prescribed[1].path;
  for (int k = 0; k < kEndPathSamples; ++k) {
    const double t = spec.stop.t_end * k / (kEndPathSamples - 1);
    const double distance = (b.position(t) - a.position(t)).norm();
    if (distance > (1 - kTautFraction) * length)
      fail_at(spec, "ends.end",
              fmt::format("ends.start ({}) and ends.end ({}) are {:.6g} m apart at t = {:.6g} s, but the string is "
                          "{:.6g} m long: prescribed ends may not pull an inextensible string taut",
                          a.description(), b.description(), distance, t, length));
  }
}

}  // namespace

std::string SceneSpec::where(const std::string& key) const {
  for (std::string k = key; !k.empty();) {
    if (const auto it = locations.find(k); it != locations.end()) return it->second.where;
    const auto cut = k.find_last_of(".[");
    k = cut == std::string::npos ? "" : k.substr(0, cut);
  }
  return source + ":1:1";
}

SceneSpec parse_scene_text(std::string_view text, const std::string& source) {
  const SourceText src(source, text);
  try {
    toml::table root = toml::parse(text, source);
    return parse_table(root, src);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", src.where(e.source()), e.description()));
  }
}

SceneSpec parse_scene(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("cannot read the scene file '{}'", file.string()));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_scene_text(buffer.str(), file.string());
}

namespace scene_build {

template <int dim>
SceneParts<dim> build_scene_parts(const SceneSpec& spec) {
  CHAINSIM_VERIFY(spec.dimension == dim, "build_scene_parts<dim> called for another dimension");
  const auto& sh = spec.shape;

  // 1. Gravity (its direction also orients a catenary).
  Vec<dim> g = Vec<dim>::Zero();
  if (spec.effects.gravity) g = as_vec<dim>(spec, *spec.effects.gravity, "effects.gravity.g");
  const Vec<dim> down = g.norm() > 0 ? Vec<dim>(g) : Vec<dim>(-unit<dim>(1));

  // 2. The shape, and the string on it.
  const bool closed = spec.closed.value_or(sh.kind == "circle");
  std::unique_ptr<Curve<dim>> curve = build_curve<dim>(spec, closed, down);
  if (curve->closed() != closed)
    fail_at(spec, spec.closed ? "string.closed" : "shape.kind",
            fmt::format("string.closed = {} but the shape ({}) is {}", closed, curve->description(),
                        curve->closed() ? "a closed curve" : "an open curve"));
  const double length = spec.length.value_or(curve->length());
  if (std::abs(curve->length() - length) > sh.length_tolerance * length)
    fail_at(spec, "string.length",
            fmt::format("string.length = {:.9g} m but the shape ({}) is {:.9g} m long: they differ by {:.3g} m, more "
                        "than shape.length_tolerance = {:g} (relative)",
                        length, curve->description(), curve->length(), curve->length() - length,
                        sh.length_tolerance));
  const int links = link_count(spec, length, closed);
  Chain<dim> chain =
      at_key(spec, "shape", [&] { return discretize(*curve, length, spec.density, links, closed, sh.length_tolerance); });
  const auto& vel = spec.velocity;
  if (vel.kind == "uniform") set_uniform_velocity(chain, as_vec<dim>(spec, vel.value, "velocity.value"));
  if (vel.kind == "tangential") at_key(spec, "velocity.speed", [&] { set_tangential_velocity(chain, vel.speed); });
  if (vel.kind == "nodes") {
    const Points<dim> values = as_points<dim>(spec, vel.values, "velocity.values");
    at_key(spec, "velocity.values", [&] { set_node_velocities(chain, values); });
  }

  // 3. Effects and ends: exactly those the scene declares.
  std::vector<std::unique_ptr<Force<dim>>> forces;
  std::vector<PrescribedNode<dim>> prescribed;
  if (spec.effects.gravity) forces.push_back(std::make_unique<Gravity<dim>>(g));
  if (spec.effects.drag) forces.push_back(std::make_unique<Drag<dim>>(*spec.effects.drag));
  double forcing_period = INFINITY;
  auto add_end = [&](const EndSpec& end, int node, const std::string& key) {
    if (end.kind == "free") return;
    if (closed)
      fail_at(spec, key, fmt::format("{} = \"{}\": a closed string has no ends (string.closed = true)", key, end.kind));
    const Vec<dim> x0 = chain.positions().col(node);
    if (end.kind == "fixed") {
      prescribed.push_back({node, std::make_shared<FixedPoint<dim>>(x0)});
    } else if (end.kind == "driven" && end.path == "linear") {
      prescribed.push_back({node, std::make_shared<LinearPath<dim>>(x0, as_vec<dim>(spec, end.velocity, key + ".velocity"))});
    } else if (end.kind == "driven") {
      const Vec<dim> amplitude = as_vec<dim>(spec, end.amplitude, key + ".amplitude");
      prescribed.push_back({node, std::make_shared<HarmonicPath<dim>>(x0, amplitude, end.omega, end.path == "shake")});
      forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
    } else {
      CHAINSIM_VERIFY(end.kind == "loaded", "parse_end admits only the kinds built here");
      const Vec<dim> f0 = end.force.empty() ? Vec<dim>::Zero() : as_vec<dim>(spec, end.force, key + ".force");
      const Vec<dim> amp = end.amplitude.empty() ? Vec<dim>::Zero() : as_vec<dim>(spec, end.amplitude, key + ".amplitude");
      if (!end.amplitude.empty()) forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
      forces.push_back(std::make_unique<EndLoad<dim>>(node, f0, amp, end.omega));
    }
  };
  add_end(spec.start, 0, "ends.start");
  add_end(spec.end, chain.num_nodes() - 1, "ends.end");
  if (prescribed.size() == 2 && chain.num_nodes() < 3)
    fail_at(spec, "string.nodes",
            fmt::format("string.nodes = {} but both ends are prescribed: the link between them could not move and "
                        "its tension would be undetermined; allowed nodes >= 3",
                        chain.num_nodes()));
  check_prescribed_ends<dim>(spec, prescribed, length);

  // 4. Options. Default Baumgarte time: a tenth of the shortest physical time scale.
  const auto& so = spec.solver;
  double t_char = spec.stop.t_end;
  if (g.norm() > 0) t_char = std::min(t_char, std::sqrt(length / g.norm()));
  const double v_max = chain.velocities().colwise().norm().maxCoeff();
  if (v_max > 0) t_char = std::min(t_char, length / v_max);
  t_char = std::min(t_char, forcing_period);
  IntegratorOptions io;
  io.method = so.method;
  io.rtol = so.rtol;
  io.atol = so.atol;
  io.max_step = so.max_step;
  io.initial_step = so.initial_step;
  io.max_steps = so.max_steps;
  at_key(spec, "solver", [&] { io.validate(); });
  return SceneParts<dim>{std::move(curve), std::move(chain),      length, g, std::move(forces), std::move(prescribed),
                         t_char,           io, so.stabilization_time.value_or(0.1 * t_char)};
}

template SceneParts<2> build_scene_parts<2>(const SceneSpec&);
template SceneParts<3> build_scene_parts<3>(const SceneSpec&);

std::vector<std::string> front_names(const SceneSpec& spec) {
  auto has_heap = [&](const char* side) {
    return std::any_of(spec.effects.heaps.begin(), spec.effects.heaps.end(),
                       [&](const HeapEntry& heap) { return heap.side == side; });
  };
  std::vector<std::string> names;
  if (has_heap("start")) names.push_back("heap_start");
  if (spec.effects.fold) names.push_back("fold");
  if (has_heap("end")) names.push_back("heap_end");
  return names;
}

std::vector<int> front_stop_indices(const SceneSpec& spec) {
  const std::vector<std::string> names = front_names(spec);
  std::vector<int> out;
  for (std::size_t k = 0; k < spec.stop.fronts.size(); ++k) {
    const std::string& front = spec.stop.fronts[k].front;
    const auto it = std::find(names.begin(), names.end(), front);
    if (it == names.end()) {
      const std::string what = front == "fold" ? "fold ([effects.fold])"
                                               : fmt::format("heap on side \"{}\"", front.substr(5));
      fail_at(spec, fmt::format("stop.front[{}].front", k),
              fmt::format("stop.front[{}].front = \"{}\" but the scene has no {}; {}", k, front, what,
                          names.empty() ? "it has no fronts" : "its fronts: " + join(names)));
    }
    out.push_back(static_cast<int>(it - names.begin()));
  }
  return out;
}

}  // namespace scene_build

template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec) {
  CHAINSIM_VERIFY(!spec.has_fronts(), "a scene with fronts runs on FrontModel (build_front_scene)");
  scene_build::front_stop_indices(spec);  // refuses a stop event on a front the scene lacks
  scene_build::SceneParts<dim> parts = scene_build::build_scene_parts<dim>(spec);
  const auto& so = spec.solver;
  StringScene<dim> scene;
  scene.characteristic_time = parts.characteristic_time;
  StringModelOptions mo;
  mo.stabilization_time = parts.stabilization_time;
  mo.backend = so.backend;
  mo.slack = so.check_slack ? SlackPolicy::kStop : SlackPolicy::kIgnore;
  mo.slack_tolerance = so.slack_tolerance;
  scene.solver.integrator = parts.integrator;
  scene.solver.t_end = spec.stop.t_end;
  scene.solver.output_interval = spec.output.interval;
  at_key(spec, "solver", [&] { scene.solver.validate(); });
  at_key(spec, "output.interval", [&] { scene.solver.check_frame_budget(parts.chain.num_nodes()); });
  scene.output = spec.output.select;

  // The model, its initial state projected onto the constraints now, so that a shape that cannot be
  // fitted (e.g. fixed ends further apart than the string is long) is refused before the run.
  std::string fit_key = "shape";
  if (spec.start.prescribed()) fit_key = "ends.start";
  if (spec.end.prescribed()) fit_key = "ends.end";
  scene.model = at_key(spec, fit_key, [&] {
    auto model = std::make_unique<StringModel<dim>>(std::move(parts.chain), std::move(parts.forces),
                                                    std::move(parts.prescribed), mo);
    model->make_consistent(0.0);
    return model;
  });
  return scene;
}

template StringScene<2> build_string_scene<2>(const SceneSpec&);
template StringScene<3> build_string_scene<3>(const SceneSpec&);

}  // namespace chainsim
