// The scene text: positions, values as written, and the closest valid word (scene_text.hpp).
#include "cases/scene/scene_text.hpp"

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

namespace chainsim::scene_text {

std::string join(const std::vector<std::string>& words, const char* separator) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : separator) + w;
  return out;
}

namespace {

/// Appends `c` to a quote, collapsing runs of white space; false once the quote, trailing space
/// trimmed, is longer than kQuoteLength (it will be cut: the rest is not needed).
bool append(std::string& out, char c) {
  const bool space = c == ' ' || c == '\t' || c == '\r' || c == '\n';
  if (space && (out.empty() || out.back() == ' ')) return true;
  out += space ? ' ' : c;
  return out.size() <= kQuoteLength || out.back() == ' ';
}

/// A collapsed quote, trimmed and cut to kQuoteLength characters.
std::string finish(std::string out) {
  while (!out.empty() && out.back() == ' ') out.pop_back();
  if (out.size() > kQuoteLength) out = out.substr(0, kQuoteLength - 3) + "...";
  return out;
}

}  // namespace

std::vector<SourceText::Line> SourceText::split_lines(std::string_view text) {
  std::vector<Line> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t stop = std::min(text.find('\n', start), text.size());
    Line line{std::string(text.substr(start, stop - start)), {}};
    const bool ascii = std::all_of(line.text.begin(), line.text.end(),
                                   [](char c) { return (static_cast<unsigned char>(c) & 0x80) == 0; });
    if (!ascii)
      for (std::size_t i = 0; i < line.text.size(); ++i)
        if ((static_cast<unsigned char>(line.text[i]) & 0xC0) != 0x80) line.starts.push_back(i);
    lines.push_back(std::move(line));
    start = stop + 1;
  }
  return lines;
}

SourceText::SourceText(std::string name, std::string_view text) { texts_.push_back({std::move(name), split_lines(text)}); }

void SourceText::add(std::string path, std::string_view text) { texts_.push_back({std::move(path), split_lines(text)}); }

std::size_t SourceText::text_of(const toml::source_region& region) const {
  if (region.path)
    for (std::size_t k = 1; k < texts_.size(); ++k)
      if (texts_[k].path == *region.path) return k;
  return 0;
}

std::string SourceText::where(const toml::source_region& region) const {
  if (region.begin.line == 0) return name() + ":1:1";
  const std::size_t k = text_of(region);
  if (k > 0) return texts_[k].path;
  return fmt::format("{}:{}:{}", name(), region.begin.line, region.begin.column);
}

std::tuple<std::size_t, std::size_t, std::size_t> SourceText::order(const toml::source_region& region) const {
  return {text_of(region), region.begin.line, region.begin.column};
}

std::string SourceText::quote(const toml::node& node) const {
  std::string out;
  if (changed_.count(&node)) {
    std::ostringstream now;
    node.visit([&](const auto& concrete) { now << concrete; });
    for (char c : now.str())
      if (!append(out, c)) break;
    return finish(out);
  }
  const toml::source_region& region = node.source();
  const std::vector<Line>& lines = texts_[text_of(region)].lines;
  if (region.begin.line == 0 || region.begin.line > lines.size()) return "";
  const auto last = std::min<std::size_t>(region.end.line, lines.size());
  for (std::size_t line = region.begin.line; line <= last; ++line) {
    const Line& text = lines[line - 1];
    const std::size_t from = line == region.begin.line ? byte_offset(text, region.begin.column) : 0;
    const std::size_t to = line == region.end.line ? byte_offset(text, region.end.column) : text.text.size();
    for (std::size_t i = from; i < to; ++i)
      if (!append(out, text.text[i])) return finish(out);
    if (!append(out, ' ')) break;
  }
  return finish(out);
}

std::size_t SourceText::byte_offset(const Line& line, std::size_t column) {
  if (column == 0) return line.text.size();
  if (line.starts.empty()) return std::min(column - 1, line.text.size());
  return column <= line.starts.size() ? line.starts[column - 1] : line.text.size();
}

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

}  // namespace chainsim::scene_text
