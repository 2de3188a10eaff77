#pragma once
/// @file scene_text.hpp
/// The text of a scene (internal to cases/scene/): the "file:line:column" of a region of the TOML,
/// the value as the user wrote it (for messages), and the closest valid word to a typo.
///
/// A scene's values come from its file and from the command line's overrides (`--set KEY=VALUE`,
/// scene_overrides.hpp). Each override is a text of its own, named by toml++ in the source regions
/// of the nodes parsed from it: a region of the file is shown "file:line:column", one of an
/// override "--set KEY=VALUE".
#include <cstddef>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "cases/scene/toml.hpp"

namespace chainsim::scene_text {

/// A value quoted in a message is cut to this many characters.
constexpr std::size_t kQuoteLength = 60;

/// The words separated by `separator`.
std::string join(const std::vector<std::string>& words, const char* separator = ", ");

/// The scene text: "file:line:column" of a region and the value as the user wrote it.
class SourceText {
 public:
  SourceText(std::string name, std::string_view text);
  /// The file's name (the source path of its regions).
  const std::string& name() const { return texts_.front().path; }

  /// Adds the text of an override: `path` is the source path its regions carry (and how messages
  /// name it, e.g. "--set string.nodes=201"), `text` the TOML document it was parsed from.
  void add(std::string path, std::string_view text);

  /// "file:line:column" of the start of `region` ("file:1:1" if it has no position), or the name of
  /// the override it comes from.
  std::string where(const toml::source_region& region) const;

  /// The text of `node` as written, with runs of white space collapsed (cut to kQuoteLength
  /// characters); a table or array an override changed is shown as it is now. Reads only the
  /// characters it shows: its cost does not grow with the length of the value or of its line.
  std::string quote(const toml::node& node) const;

  /// Sorts regions in the order they were given: the file by line and column, then each override.
  std::tuple<std::size_t, std::size_t, std::size_t> order(const toml::source_region& region) const;

  /// Records that an override changed the contents of `node` (a table or an array).
  void mark_changed(const toml::node* node) { changed_.insert(node); }

 private:
  struct Line {
    std::string text;
    /// Byte offset of each code point, for a line that is not all ASCII (empty otherwise: the
    /// column is the byte offset + 1), so that finding a column costs O(1), not O(line).
    std::vector<std::size_t> starts;
  };
  struct Text {
    std::string path;         ///< source path of its regions
    std::vector<Line> lines;  ///< the text, by line
  };
  static std::vector<Line> split_lines(std::string_view text);
  /// The text a region comes from (the file's if none matches).
  std::size_t text_of(const toml::source_region& region) const;
  /// Byte offset of the 1-based column `column` (toml++ counts code points) in a line.
  static std::size_t byte_offset(const Line& line, std::size_t column);

  std::vector<Text> texts_;  ///< the file, then the overrides
  std::set<const toml::node*> changed_;
};

/// Optimal-string-alignment distance (a swap of two neighbours counts one edit).
std::size_t edit_distance(const std::string& a, const std::string& b);

/// The valid word closest to `word` if it is close enough to be a typo (at most 2 edits, and fewer
/// than half its letters), or one that `word` begins (a truncated key); "" otherwise.
std::string closest(const std::string& word, const std::vector<std::string>& valid);

}  // namespace chainsim::scene_text
