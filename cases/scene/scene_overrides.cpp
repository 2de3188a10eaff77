// Overrides of scene keys from the command line (scene_overrides.hpp).
#include "cases/scene/scene_overrides.hpp"

#include <cctype>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "mesh/errors.hpp"

namespace chainsim::scene_parse {

namespace {

/// One part of a dotted key: a name and the indices that follow it (effects.heap[0] -> heap, {0}).
struct Step {
  std::string name;
  std::vector<std::size_t> indices;
};

bool key_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

/// A bare word is taken as a string (unless it is a TOML keyword): a letter, then letters, digits, _ - . +.
bool bare_word(const std::string& value) {
  if (value.empty() || !std::isalpha(static_cast<unsigned char>(value[0]))) return false;
  for (char c : value)
    if (!(key_char(c) || c == '.' || c == '+')) return false;
  return true;
}

/// One override: its argument, key path and value, parsed from "KEY=VALUE".
class Override {
 public:
  Override(const std::string& argument, scene_text::SourceText& text)
      : origin_("--set " + argument), path_(std::make_shared<const std::string>(origin_)), text_(text) {
    const auto eq = argument.find('=');
    if (eq == std::string::npos || eq == 0)
      fail(fmt::format("expected KEY=VALUE, e.g. --set string.nodes=201"));
    key_ = argument.substr(0, eq);
    steps_ = split_key();
    const std::string value = argument.substr(eq + 1);
    if (value.empty()) fail(fmt::format("{} has no value after '='", key_));
    const bool word = bare_word(value) && value != "true" && value != "false" && value != "inf" && value != "nan";
    const std::string document = word ? "v = \"" + value + "\"" : "v = " + value;
    text_.add(origin_, document);
    try {
      value_ = toml::parse(std::string_view(document), std::string_view(origin_));
    } catch (const toml::parse_error& e) {
      fail(fmt::format("{} is not a TOML value ({}): write a number, true or false, a \"string\", an [array] or a "
                       "{{ table }}",
                       value, e.description()));
    }
    if (value_.size() != 1) fail(fmt::format("{} is more than one TOML value", value));
  }

  /// Sets the key in `root`, creating what it runs through.
  void apply(toml::table& root) {
    toml::node* current = &root;
    std::string at;  // the key so far, as the user wrote it
    for (std::size_t i = 0; i < steps_.size(); ++i) {
      const Step& step = steps_[i];
      toml::table* table = current->as_table();
      if (!table) fail(fmt::format("{} = {} is not a table, so it has no key '{}'", at, text_.quote(*current), step.name));
      at = at.empty() ? step.name : at + "." + step.name;
      text_.mark_changed(table);
      const bool last = i + 1 == steps_.size();
      if (last && step.indices.empty()) {
        drop_file_alternatives(*table, at);
        take_value([&](auto&& value) { table->insert_or_assign(toml::key(step.name, region()), std::move(value)); });
        return;
      }
      current = table->get(step.name);
      if (!current) {
        if (step.indices.empty())
          current = &table->insert(toml::key(step.name, region()), new_container<toml::table>()).first->second;
        else
          current = &table->insert(toml::key(step.name, region()), new_container<toml::array>()).first->second;
      }
      for (std::size_t j = 0; j < step.indices.size(); ++j) {
        const std::size_t index = step.indices[j];
        toml::array* array = current->as_array();
        if (!array)
          fail(fmt::format("{} = {} is not an array, so it has no element [{}]", at, text_.quote(*current), index));
        const std::size_t size = array->size();
        if (index > size)
          fail(size == 0 ? fmt::format("{}[{}] does not exist: {} is empty; --set may add [0]", at, index, at)
                         : fmt::format("{}[{}] does not exist: {} has {} element{}; --set may change [0] to [{}] or "
                                       "add [{}]",
                                       at, index, at, size, size == 1 ? "" : "s", size - 1, size));
        at += fmt::format("[{}]", index);
        text_.mark_changed(array);
        if (last && j + 1 == step.indices.size()) {
          take_value([&](auto&& value) {
            if (index == size)
              array->push_back(std::move(value));
            else
              array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(index), std::move(value));
          });
          return;
        }
        if (index == size) {
          if (j + 1 < step.indices.size())
            array->push_back(new_container<toml::array>());
          else
            array->push_back(new_container<toml::table>());
        }
        current = array->get(index);
      }
    }
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(fmt::format("{}: {}", origin_, message));
  }

  /// The scene keys that set what `key` sets under another name, which the parser refuses together
  /// ("give one of them"): the slack policy and its older form, the resolution as nodes or as a link length.
  static std::vector<std::string> alternatives(const std::string& key) {
    if (key == "solver.slack") return {"check_slack"};
    if (key == "solver.check_slack") return {"slack"};
    if (key == "string.nodes") return {"link_length"};
    if (key == "string.link_length") return {"nodes"};
    return {};
  }

  /// The scene keys that the value being set leaves nothing to apply to: a slack policy other than "allow"
  /// (check_slack is never "allow") and the restitution of the snaps that only "allow" makes.
  std::vector<std::string> mooted(const std::string& key) const {
    const toml::node* value = value_.get("v");
    const bool allow = value && value->value<std::string>() == std::optional<std::string>("allow");
    if ((key == "solver.slack" && !allow) || key == "solver.check_slack") return {"snap_restitution"};
    return {};
  }

  /// The command line is later than the file: setting `key` (in `table`) removes what the file says of the
  /// same thing under another name (--set solver.slack=allow on a scene with check_slack = true, --set
  /// string.link_length on one with nodes), and what the new value leaves nothing to apply to (--set
  /// solver.slack=stop on a scene with slack = "allow" and snap_restitution). Two overrides that do so still
  /// meet the parser's refusal.
  void drop_file_alternatives(toml::table& table, const std::string& key) const {
    std::vector<std::string> others = alternatives(key);
    for (std::string& other : mooted(key)) others.push_back(std::move(other));
    for (const std::string& other : others) {
      const toml::node* node = table.get(other);
      if (node == nullptr) continue;
      const auto& path = node->source().path;
      if (path && path->rfind("--set ", 0) == 0) continue;  // set by an override: the parser says both
      table.erase(other);
    }
  }

  /// The parts of the key; throws if it is no dotted key.
  std::vector<Step> split_key() const {
    auto bad = [&] {
      fail(fmt::format("'{}' is not a scene key: write a dotted key such as string.nodes or effects.heap[0].f", key_));
    };
    std::vector<Step> steps;
    std::size_t i = 0;
    while (true) {
      Step step;
      while (i < key_.size() && key_char(key_[i])) step.name += key_[i++];
      if (step.name.empty()) bad();
      while (i < key_.size() && key_[i] == '[') {
        const std::size_t from = ++i;
        while (i < key_.size() && std::isdigit(static_cast<unsigned char>(key_[i]))) ++i;
        if (i == from || i - from > 9 || i == key_.size() || key_[i] != ']') bad();
        step.indices.push_back(std::stoul(key_.substr(from, i - from)));
        ++i;
      }
      steps.push_back(std::move(step));
      if (i == key_.size()) return steps;
      if (key_[i++] != '.') bad();
    }
  }

  /// A region of this override (for the keys it creates).
  toml::source_region region() const { return {{1, 1}, {1, 1}, path_}; }

  /// An empty table or array that carries this override's region (parsed, since toml++ sets regions
  /// only when parsing).
  template <class Container>
  Container new_container() {
    constexpr bool table = std::is_same_v<Container, toml::table>;
    toml::table document = toml::parse(std::string_view(table ? "c = {}" : "c = []"), std::string_view(origin_));
    Container out(std::move(*document.get("c")->template as<Container>()));
    return out;
  }

  /// Calls set(value) with the parsed value moved out as its own type (moving keeps its region).
  template <class F>
  void take_value(F&& set) {
    value_.get("v")->visit([&](auto&& value) { set(std::move(value)); });
  }

  std::string origin_;
  std::shared_ptr<const std::string> path_;
  scene_text::SourceText& text_;
  std::string key_;
  std::vector<Step> steps_;
  toml::table value_;
};

}  // namespace

void apply_overrides(toml::table& root, const std::vector<std::string>& overrides, scene_text::SourceText& text) {
  for (const std::string& argument : overrides) Override(argument, text).apply(root);
}

}  // namespace chainsim::scene_parse
