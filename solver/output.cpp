#include "output.hpp"

#include <atomic>
#include <cerrno>
#include <cmath>
#include <algorithm>
#include <cstring>
#include <system_error>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"

namespace chainsim {

namespace {
/// Temporary files written by this process so far: with the pid, a name no other writer uses.
std::atomic<unsigned long> g_temp_files{0};
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_.replace_filename(fmt::format(".{}.{}.{}.tmp", target_.filename().string(), static_cast<long>(::getpid()),
                                     g_temp_files.fetch_add(1)));
  errno = 0;
  out_.open(temp_, std::ios::out | std::ios::trunc);
  if (!out_)
    throw InputError(fmt::format("cannot write the output file '{}'{}", temp_.string(),
                                 errno ? std::string(": ") + std::strerror(errno) : std::string()));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw Error(fmt::format("writing '{}' failed (disk full?)", temp_.string()));
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec)
    throw Error(fmt::format("cannot move '{}' to '{}': {}", temp_.string(), target_.string(), ec.message()));
  committed_ = true;
}

void CsvTable::add_row(const std::vector<double>& row) {
  CHAINSIM_VERIFY(label_column_.empty(), "this CSV table needs a label in every row");
  CHAINSIM_VERIFY(row.size() == columns_.size(), "CSV row length differs from the header");
  data_.push_back(row);
}

void CsvTable::add_row(const std::string& label, const std::vector<double>& row) {
  CHAINSIM_VERIFY(!label_column_.empty(), "this CSV table has no label column");
  CHAINSIM_VERIFY(row.size() == columns_.size(), "CSV row length differs from the header");
  CHAINSIM_VERIFY(label.find_first_of(",\"\n") == std::string::npos, "CSV labels hold no commas or quotes");
  labels_.push_back(label);
  data_.push_back(row);
}

std::vector<double> CsvTable::column(const std::string& name) const {
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    if (columns_[j] != name) continue;
    std::vector<double> out;
    out.reserve(data_.size());
    for (const auto& row : data_) out.push_back(row[j]);
    return out;
  }
  throw Error(fmt::format("internal error: no CSV column '{}'", name));
}

void CsvTable::write(const std::filesystem::path& path, int significant_digits) const {
  CsvWriter file(path, columns_, label_column_, significant_digits);
  for (std::size_t i = 0; i < data_.size(); ++i)
    file.row(data_[i].data(), data_[i].size(), label_column_.empty() ? nullptr : &labels_[i]);
  file.commit();
}

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
                     const std::string& label_column, int significant_digits)
    : file_(path), columns_(columns.size()), labelled_(!label_column.empty()), digits_(significant_digits) {
  auto& out = file_.stream();
  if (labelled_) out << label_column << ',';
  for (std::size_t j = 0; j < columns.size(); ++j) out << (j ? "," : "") << columns[j];
  out << '\n';
  buffer_.resize(kFlushBytes + 4096);
}

namespace {
/// The longest text of a number in "{}" (shortest round trip: "-2.2250738585072014e-308" is 24
/// characters; an integer below 10^15, 16), with room to spare; "{:.{digits}g}" adds digits.
constexpr std::size_t kMaxNumberText = 32;

/// Writes a finite, non-zero `value` at `out` exactly as fmt's "{}" does, and returns the end: the
/// shortest digits that read back to the same double (fmt's own Dragonbox, to_decimal), laid out by
/// fmt's rules for "{}" (fmt/format.h, do_write_float with the general format and no precision):
/// exponent notation when the decimal exponent of the first digit is below -4 or at least 16
/// ("1.5e-05", "1e+16", two exponent digits at least), plain digits otherwise ("1234500", "12.345",
/// "0.00012"). fmt's generic writer spends most of its time on specs that "{}" never has (width,
/// locale, grouping, showpoint); this is the same text at about a third of the cost.
char* write_shortest(char* out, double value) {
  if (std::signbit(value)) {
    *out++ = '-';
    value = -value;
  }
  static constexpr char kPairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  const auto decimal = fmt::detail::dragonbox::to_decimal(value);
  char digits[24];
  char* const end = digits + sizeof digits;
  char* first = end;
  auto significand = decimal.significand;  // > 0, at most 17 digits
  for (; significand >= 100; significand /= 100) {  // two digits at a time
    first -= 2;
    std::memcpy(first, kPairs + 2 * (significand % 100), 2);
  }
  if (significand >= 10) {
    first -= 2;
    std::memcpy(first, kPairs + 2 * significand, 2);
  } else {
    *--first = static_cast<char>('0' + significand);
  }
  const int count = static_cast<int>(end - first);
  const int exponent = decimal.exponent;  // value = significand × 10^exponent
  const int leading = exponent + count - 1;  // the decimal exponent of the first digit
  if (leading < -4 || leading >= 16) {
    *out++ = *first;
    if (count > 1) {
      *out++ = '.';
      out = std::copy(first + 1, end, out);
    }
    *out++ = 'e';
    int e = leading;
    *out++ = e < 0 ? '-' : '+';
    if (e < 0) e = -e;
    if (e >= 100) {
      *out++ = static_cast<char>('0' + e / 100);
      e %= 100;
    }
    *out++ = static_cast<char>('0' + e / 10);
    *out++ = static_cast<char>('0' + e % 10);
    return out;
  }
  if (exponent >= 0) {  // 1234e2 -> 123400
    out = std::copy(first, end, out);
    return std::fill_n(out, exponent, '0');
  }
  const int whole = count + exponent;  // digits before the point
  if (whole > 0) {  // 1234e-2 -> 12.34
    out = std::copy(first, first + whole, out);
    *out++ = '.';
    return std::copy(first + whole, end, out);
  }
  *out++ = '0';  // 1234e-6 -> 0.001234
  *out++ = '.';
  out = std::fill_n(out, -whole, '0');
  return std::copy(first, end, out);
}

/// Writes `value` at `out` as fmt's "{}" writes it (the shortest text that reads back to the same
/// double), or as "{:.{digits}g}" when digits > 0, and returns the end. An integer of magnitude below
/// 10^15 (which "{}" writes as its plain digits) takes the integer path, any other finite non-zero
/// number write_shortest: the same text, several times faster. The caller provides
/// kMaxNumberText + digits bytes.
char* write_number(char* out, double value, int digits) {
  if (digits > 0) return fmt::format_to(out, FMT_COMPILE("{:.{}g}"), value, digits);
  if (std::fabs(value) < 1e15 && value == std::trunc(value) && !(value == 0 && std::signbit(value)))
    return fmt::format_to(out, FMT_COMPILE("{}"), static_cast<long long>(value));
  if (value != 0 && std::isfinite(value)) return write_shortest(out, value);
  return fmt::format_to(out, FMT_COMPILE("{}"), value);  // -0, inf, nan
}
}  // namespace

void CsvWriter::row(const double* values, std::size_t count, const std::string* label) {
  CHAINSIM_VERIFY(count == columns_, "CSV row length differs from the header");
  CHAINSIM_VERIFY(labelled_ == (label != nullptr), "a CSV row has a label exactly when its file has a label column");
  // The row's largest text, then the numbers formatted in place.
  const std::size_t digits = digits_ > 0 ? static_cast<std::size_t>(digits_) : 0;
  const std::size_t need = (label ? label->size() + 1 : 0) + count * (kMaxNumberText + digits + 1) + 1;
  if (used_ + need > buffer_.size()) {
    flush();
    if (need > buffer_.size()) buffer_.resize(need);
  }
  char* const start = buffer_.data();
  char* p = start + used_;
  if (label) {
    p = std::copy(label->begin(), label->end(), p);
    *p++ = ',';
  }
  for (std::size_t j = 0; j < count; ++j) {
    if (j) *p++ = ',';
    if (j == 0) {
      // The same bits as the last row's first value (a frame's time): the same text.
      if (!first_known_ || std::memcmp(&values[0], &first_value_, sizeof(double)) != 0) {
        first_text_.resize(kMaxNumberText + digits);
        first_text_.resize(static_cast<std::size_t>(write_number(first_text_.data(), values[0], digits_) -
                                                    first_text_.data()));
        first_value_ = values[0];
        first_known_ = true;
      }
      p = std::copy(first_text_.begin(), first_text_.end(), p);
    } else {
      p = write_number(p, values[j], digits_);
    }
  }
  *p++ = '\n';
  used_ = static_cast<std::size_t>(p - start);
  if (used_ >= kFlushBytes) flush();
}

void CsvWriter::flush() {
  file_.stream().write(buffer_.data(), static_cast<std::streamsize>(used_));
  used_ = 0;
}

void write_json(const std::filesystem::path& path, const nlohmann::json& doc) {
  AtomicFile file(path);
  file.stream() << json_text(doc, 2) << '\n';
  file.commit();
}

std::string json_text(const nlohmann::json& doc, int indent) {
  return doc.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

void ensure_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(fmt::format("--out = '{}' cannot be used as an output directory: {}", dir.string(),
                                 ec ? ec.message() : "not a directory"));
}

void ensure_writable_directory(const std::filesystem::path& dir) {
  ensure_directory(dir);
  const std::filesystem::path probe = dir / "chainsim_write_probe";
  try {
    AtomicFile file(probe);
    file.stream() << "probe\n";
    file.commit();
  } catch (const Error& e) {
    throw InputError(fmt::format("--out = '{}' is not writable: {}", dir.string(), e.what()));
  }
  std::error_code ec;
  std::filesystem::remove(probe, ec);
}

namespace {

namespace fs = std::filesystem;

/// `text` matches `pattern`, where '*' matches any run of characters (none included).
bool matches(const std::string& pattern, const std::string& text) {
  std::size_t p = 0, t = 0, star = std::string::npos, resume = 0;
  while (t < text.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = t;
    } else if (p < pattern.size() && pattern[p] == text[t]) {
      ++p;
      ++t;
    } else if (star != std::string::npos) {
      p = star + 1;
      t = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

/// The target of an AtomicFile temporary name (".NAME.PID.N.tmp", or ".NAME.tmp" as earlier versions
/// wrote it), or "" if `file` is no such name.
std::string temp_target(const std::string& file) {
  const std::string suffix = ".tmp";
  if (file.size() <= 1 + suffix.size() || file[0] != '.' || file.compare(file.size() - suffix.size(), suffix.size(), suffix))
    return "";
  std::string name = file.substr(1, file.size() - 1 - suffix.size());
  // Strip ".PID.N" when present.
  auto strip_number = [](std::string& s) {
    const std::size_t dot = s.rfind('.');
    if (dot == std::string::npos || dot + 1 == s.size()) return false;
    for (std::size_t k = dot + 1; k < s.size(); ++k)
      if (s[k] < '0' || s[k] > '9') return false;
    s.erase(dot);
    return true;
  };
  std::string stripped = name;
  if (strip_number(stripped) && strip_number(stripped)) return stripped;
  return name;
}

/// Removes from `dir` the files named by `patterns` and the temporary files of AtomicFile for them.
void remove_matching(const fs::path& dir, const std::vector<std::string>& patterns) {
  std::error_code ec;
  std::vector<fs::path> doomed;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) continue;
    const std::string file = it->path().filename().string(), target = temp_target(file);
    for (const std::string& pattern : patterns)
      if (matches(pattern, file) || (!target.empty() && matches(pattern, target))) {
        doomed.push_back(it->path());
        break;
      }
  }
  for (const fs::path& path : doomed) fs::remove(path, ec);
}

std::string read_holder(int fd) {
  char buffer[32] = {};
  const ssize_t n = ::pread(fd, buffer, sizeof buffer - 1, 0);
  std::string pid = n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string();
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid;
}

}  // namespace

const std::vector<OutputName>& run_output_names() {
  using N = OutputName;
  static const std::vector<OutputName> names = {
      // chainsim run (string and reduced models), in the order its summary lists them
      {"nodes.csv"}, {"tension.csv"}, {"energy.csv"}, {"series.csv"}, {"forces.csv"}, {"string.pvd"},
      {"frames", N::kDirectory, {"frame_*.vtp", "fronts_*.vtp", "obstacles.vtp"}, "a directory of ParaView frames"},
      {"stats.json"},
      // chainsim compare, reduced, canonical, sweep
      {"string_series.csv"}, {"reduced_series.csv"}, {"summary.csv"}, {"summary.json"}, {"sweep.csv"},
      {"figure_data", N::kDirectory, {"*.csv"}, "a directory of figure data"},
      {"falling", N::kRunDirectory, {}, "a run directory"},
      {"folded", N::kRunDirectory, {}, "a run directory"},
      {"sliding", N::kRunDirectory, {}, "a run directory"},
      // chainsim plot
      {"figures", N::kDirectory, {"*.png", "animation.mp4", "animation.gif"}, "a directory of figures"},
      // the write probe of ensure_writable_directory()
      {"chainsim_write_probe"}};
  return names;
}

const std::vector<std::string>& run_output_files() {
  static const std::vector<std::string> files = [] {
    std::vector<std::string> out;
    for (const OutputName& n : run_output_names())
      if (n.kind == OutputName::kFile) out.push_back(n.name);
    return out;
  }();
  return files;
}

void clear_run_outputs(const fs::path& dir) {
  std::error_code ec;
  // 1. Refuse, before removing anything, a name taken by something chainsim would not write there.
  for (const OutputName& n : run_output_names()) {
    const fs::path path = dir / n.name;
    if (!fs::exists(path, ec)) continue;
    const bool is_dir = fs::is_directory(path, ec);
    if (is_dir == (n.kind == OutputName::kFile))
      throw InputError(fmt::format("--out = '{}': '{}' is {}, where a run writes {}; remove or rename it, or "
                                   "choose another --out",
                                   dir.string(), path.string(), is_dir ? "a directory" : "a file", n.what));
  }
  // 2. The files (and their stray temporary files), then the directories' files, each directory
  //    removed when nothing else is left in it.
  std::vector<std::string> top;
  for (const OutputName& n : run_output_names())
    if (n.kind == OutputName::kFile) top.push_back(n.name);
  remove_matching(dir, top);
  for (const OutputName& n : run_output_names()) {
    const fs::path path = dir / n.name;
    if (n.kind == OutputName::kFile || !fs::is_directory(path, ec)) continue;
    if (n.kind == OutputName::kRunDirectory) {
      RunDirectory nested(path);  // refused if a run is writing there
      nested.clear();
    } else {
      remove_matching(path, n.patterns);
    }
    fs::remove(path, ec);  // only if empty: a user's own file keeps it
  }
}

std::vector<std::string> outputs_present(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const OutputName& n : run_output_names()) {
    const fs::path path = dir / n.name;
    if (n.kind == OutputName::kFile) {
      if (fs::is_regular_file(path, ec)) out.push_back(n.name);
      continue;
    }
    // A directory counts when it holds an output (not only a user's files).
    bool holds = false;
    if (!fs::is_directory(path, ec)) continue;
    if (n.kind == OutputName::kRunDirectory) {
      holds = !outputs_present(path).empty();
    } else {
      for (fs::directory_iterator it(path, ec), end; !ec && it != end && !holds; it.increment(ec))
        for (const std::string& pattern : n.patterns) holds = holds || matches(pattern, it->path().filename().string());
    }
    if (holds) out.push_back(n.name + "/");
  }
  return out;
}

RunDirectory::RunDirectory(fs::path dir) : dir_(std::move(dir)) {
  ensure_directory(dir_);
  const fs::path lock = dir_ / kLockName;
  // Open, lock and check that the file locked is still the one the name points to: the holder
  // before us removes the name after its run, and a lock on the removed file would guard nothing.
  for (;;) {
    fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw InputError(fmt::format("--out = '{}' is not writable: cannot create '{}': {}", dir_.string(),
                                   lock.string(), std::strerror(errno)));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      const std::string holder = read_holder(fd_);
      ::close(fd_);
      fd_ = -1;
      if (error != EWOULDBLOCK)
        throw InputError(fmt::format("--out = '{}': cannot lock '{}': {}", dir_.string(), lock.string(),
                                     std::strerror(error)));
      const bool self = holder == std::to_string(static_cast<long>(::getpid()));
      throw InputError(fmt::format(
          "--out = '{}' is in use by {} (pid {}), which holds '{}': a directory holds one run at a time; wait "
          "for that run to end or choose another --out",
          dir_.string(), self ? "another run in this process" : "another chainsim process",
          holder.empty() ? "not yet recorded" : holder, lock.string()));
    }
    struct stat held {}, named {};
    if (::fstat(fd_, &held) == 0 && ::stat(lock.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
      break;
    ::close(fd_);  // the name was removed or replaced meanwhile: lock the current one
    fd_ = -1;
  }
  const std::string pid = std::to_string(static_cast<long>(::getpid())) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    const int error = errno;
    ::unlink(lock.c_str());
    ::close(fd_);
    throw InputError(fmt::format("--out = '{}' is not writable: cannot write '{}': {}", dir_.string(), lock.string(),
                                 std::strerror(error)));
  }
  try {
    ensure_writable_directory(dir_);
  } catch (...) {
    ::unlink(lock.c_str());
    ::close(fd_);
    throw;
  }
}

RunDirectory::~RunDirectory() {
  if (fd_ < 0) return;
  ::unlink((dir_ / kLockName).c_str());  // while still held: see the constructor
  ::close(fd_);
}

nlohmann::json to_json(const IntegratorStats& s) {
  return {{"method", s.method},
          {"order", s.order},
          {"implicit", s.implicit},
          {"steps", s.steps},
          {"step_attempts", s.step_attempts},
          {"error_test_fails", s.error_test_fails},
          {"rhs_evals", s.rhs_evals},
          {"event_evals", s.event_evals},
          {"nonlin_iters", s.nonlin_iters},
          {"nonlin_conv_fails", s.nonlin_conv_fails},
          {"jac_evals", s.jac_evals},
          {"lin_setups", s.lin_setups},
          {"lin_iters", s.lin_iters},
          {"lin_solves", s.lin_solves},
          {"recoverable_failures", s.recoverable_failures},
          {"last_step", s.last_step}};
}

}  // namespace chainsim
