#pragma once
/// @file scene_text.hpp
/// The text of a scene (internal to cases/scene/): the "file:line:column" of a region of the TOML,
/// the value as the user wrote it (for messages), and the closest valid word to a typo.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

namespace chainsim::scene_text {

/// A value quoted in a message is cut to this many characters.
constexpr std::size_t kQuoteLength = 60;

/// The words separated by `separator`.
std::string join(const std::vector<std::string>& words, const char* separator = ", ");

/// The scene text: "file:line:column" of a region and the value as the user wrote it.
class SourceText {
 public:
  SourceText(std::string name, std::string_view text);
  const std::string& name() const { return name_; }

  /// "file:line:column" of the start of `region` ("file:1:1" if it has no position).
  std::string where(const toml::source_region& region) const;

  /// The text of `region` with runs of white space collapsed (cut to kQuoteLength characters).
  std::string quote(const toml::source_region& region) const;

 private:
  /// Byte offset of the 1-based column `column` (toml++ counts code points) in a UTF-8 line.
  static std::size_t byte_offset(const std::string& line, std::size_t column);

  std::string name_;
  std::vector<std::string> lines_;
};

/// Optimal-string-alignment distance (a swap of two neighbours counts one edit).
std::size_t edit_distance(const std::string& a, const std::string& b);

/// The valid word closest to `word` if it is close enough to be a typo (at most 2 edits, and fewer
/// than half its letters), or one that `word` begins (a truncated key); "" otherwise.
std::string closest(const std::string& word, const std::vector<std::string>& valid);

}  // namespace chainsim::scene_text
