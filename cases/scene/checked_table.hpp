#pragma once
/// @file checked_table.hpp
/// A checked view of one TOML table of a scene (internal to cases/scene/): every key is checked
/// against the section's valid keys (an unknown one is refused with the valid keys and a "did you
/// mean"), the position of each key read is recorded in SceneSpec::locations, and each value is
/// read with its type and range checked, every error located at the key's value in the file.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include "cases/scene/toml.hpp"

#include "cases/scene/scene.hpp"
#include "cases/scene/scene_text.hpp"
#include "mesh/errors.hpp"

namespace chainsim::scene_parse {

using scene_text::SourceText;

/// What every section parser shares: the scene's text (for positions) and the spec being filled.
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
          const Moved& moved = {}, std::string noun = "key");

  bool has(const std::string& key) const { return table_.contains(key); }
  const toml::node* node(const std::string& key) const { return table_.get(key); }
  std::string full(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }
  /// Location of the key's value, or of the section when the key is absent.
  std::string at(const std::string& key) const;
  /// The key's value as written ("" if absent).
  std::string text(const std::string& key) const;
  const std::string& name() const { return name_; }
  /// The scene's text (positions and values as written).
  const SourceText& source_text() const { return ctx_.text; }

  /// Throws "<location of key>: <message>".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  [[noreturn]] void wrong_type(const std::string& key, const std::string& expected) const;
  /// A required key is absent: "<location of the section>: [name] needs <key> (<what>)".
  [[noreturn]] void missing(const std::string& key, const std::string& what) const;
  /// The section as messages show it: "[effects.gravity]", or "effects.heap[0]" for an element of
  /// an array of tables.
  std::string shown_name() const { return name_.back() == ']' ? name_ : "[" + name_ + "]"; }
  /// The key does not apply to `context` (e.g. kind = "circle").
  void forbid(const std::string& key, bool applies, const std::string& context) const;
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

  std::optional<double> number(const std::string& key) const;
  /// A number checked against a range (worded like require_in_range); `fallback` if absent.
  double number_in(const std::string& key, double fallback, double lo, double hi, Bound lo_bound = Bound::kClosed,
                   Bound hi_bound = Bound::kClosed) const;
  std::optional<double> positive(const std::string& key) const;
  std::optional<long long> integer(const std::string& key) const;
  /// An integer in [lo, hi], the message printing it and the bounds as integers.
  std::optional<long long> integer_in(const std::string& key, long long lo, long long hi) const;
  std::optional<bool> boolean(const std::string& key) const;
  std::optional<std::string> string(const std::string& key) const;
  /// A string that must be one of `choices`.
  std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& fallback) const;
  void check_choice(const std::string& key, const std::string& shown, const std::string& value,
                    const std::vector<std::string>& choices) const;
  /// A non-empty array of numbers ({} if absent).
  std::vector<double> vector(const std::string& key) const;
  /// An array of points; the location of each is recorded as key[k].
  std::vector<std::vector<double>> matrix(const std::string& key) const;
  /// A non-empty array of distinct strings, each one of `choices`.
  std::vector<std::string> string_list(const std::string& key, const std::vector<std::string>& choices) const;

 private:
  std::vector<double> numbers(const toml::array& arr, const std::string& key) const;

  const toml::table& table_;
  std::string name_;
  Context& ctx_;
};

/// The sub-table `name` of `parent` (an empty table if it is absent).
const toml::table& subtable(const Section& parent, const std::string& name);

/// The elements of the array of tables `name` of `parent` ([[name]]; none if it is absent).
std::vector<const toml::table*> table_array(const Section& parent, const std::string& name, const std::string& what);

}  // namespace chainsim::scene_parse
