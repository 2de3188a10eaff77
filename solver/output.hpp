#pragma once
/// @file output.hpp
/// Output files that are either complete or absent.
///
/// Every file chainsim writes goes through AtomicFile: the content is written to a hidden
/// temporary file beside the target, named for the process and the file (".NAME.PID.N.tmp", so two
/// writers never share one), and renamed over it only by commit(). A run that stops early (an
/// exception, a signal) leaves at most a stray ".tmp" file, never a half-written CSV that looks
/// complete; the next clean-up of the directory (clear_run_outputs) removes it.
///
/// A run directory belongs to one run: a command that writes one holds a RunDirectory, an exclusive
/// lock on DIR/.chainsim.lock for the whole run, and first removes what any chainsim command may have
/// written there before (run_output_names()), never another file.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "integrator.hpp"

namespace chainsim {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  ///< removes the temporary file unless commit() succeeded
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  /// Flushes, closes and renames the temporary file onto the target. Throws Error on I/O failure.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// A CSV file written row by row through an AtomicFile (nothing held in memory but a buffer of
/// kFlushBytes): the header at construction, then rows of numbers, each optionally led by a text
/// label; commit() publishes it. significant_digits = 0: the shortest text that reads back to the
/// same double (an integer below 10^15 as its digits, the same text by a faster path).
class CsvWriter {
 public:
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
            const std::string& label_column = "", int significant_digits = 0);
  /// Appends a row; it must have one value per column.
  void row(const double* values, std::size_t count, const std::string* label = nullptr);
  void row(const std::vector<double>& values) { row(values.data(), values.size()); }
  void commit() {
    flush();
    file_.commit();
  }

  /// The size of the formatted rows written to the file at once.
  static constexpr std::size_t kFlushBytes = 1u << 20;

 private:
  /// Writes the buffered rows to the file (at kFlushBytes and at commit()).
  void flush();

  AtomicFile file_;
  std::size_t columns_;
  bool labelled_;
  int digits_;
  /// Formatted rows not yet written (the first used_ bytes): one write per kFlushBytes. The numbers
  /// are formatted straight into it (fmt::format_to on a char pointer), never through a stream or a
  /// growing string.
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  /// The first column's last value and its text: a frame's time repeats on each of its rows.
  double first_value_ = 0;
  std::string first_text_;
  bool first_known_ = false;
};

/// A CSV table built in memory and written atomically: one header row, then numeric rows, each
/// optionally led by a text label (e.g. the problem's name) when a label column is named.
class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns, std::string label_column = "")
      : columns_(std::move(columns)), label_column_(std::move(label_column)) {}
  /// Appends a row; it must have one value per column.
  void add_row(const std::vector<double>& row);
  /// Appends a labelled row (only for a table constructed with a label column).
  void add_row(const std::string& label, const std::vector<double>& row);
  std::size_t rows() const { return data_.size(); }
  const std::vector<std::string>& columns() const { return columns_; }
  /// Column by name (throws Error if absent).
  std::vector<double> column(const std::string& name) const;
  /// significant_digits = 0: the shortest text that reads back to the same double.
  void write(const std::filesystem::path& path, int significant_digits = 0) const;

 private:
  std::vector<std::string> columns_;
  std::string label_column_;
  std::vector<std::string> labels_;
  std::vector<std::vector<double>> data_;
};

/// Writes a JSON document atomically, pretty-printed (as json_text(doc, 2)).
void write_json(const std::filesystem::path& path, const nlohmann::json& doc);

/// The text of a JSON document; indent < 0: one line. Text that is not UTF-8 (a path or a message
/// holding such bytes) has each invalid byte replaced by U+FFFD instead of failing: every JSON that
/// chainsim prints or writes goes through here.
std::string json_text(const nlohmann::json& doc, int indent = -1);

/// Creates `dir` (and parents) or throws InputError naming the directory and the OS error.
void ensure_directory(const std::filesystem::path& dir);

/// ensure_directory(), then checks that a file can be created and renamed in `dir` (by writing and
/// removing a probe through AtomicFile); throws InputError naming the directory and the OS error.
/// Call it before a long run, so that a read-only --out fails at once rather than at the end.
void ensure_writable_directory(const std::filesystem::path& dir);

/// A name that a chainsim command may write in a run directory: a file, or a directory holding files
/// whose names match `patterns` ('*' matches any run of characters), or (`run_directory`) a directory
/// that is itself a run directory (`chainsim canonical`'s problems).
struct OutputName {
  enum Kind { kFile, kDirectory, kRunDirectory };
  OutputName(std::string name_, Kind kind_ = kFile, std::vector<std::string> patterns_ = {},
             std::string what_ = "a file")
      : name(std::move(name_)), kind(kind_), patterns(std::move(patterns_)), what(std::move(what_)) {}
  std::string name;
  Kind kind;
  std::vector<std::string> patterns;  ///< kDirectory: the files chainsim writes inside
  std::string what;                   ///< what it is, for messages ("a directory of ParaView frames")
};

/// Every name any chainsim command (run, compare, reduced, canonical, sweep, plot) may write at the
/// top of a run directory, in the order a run's summary lists them. The one list every clean-up uses.
const std::vector<OutputName>& run_output_names();

/// The file names of run_output_names() (the kFile entries).
const std::vector<std::string>& run_output_files();

/// Removes from `dir` what any chainsim command may have written there (run_output_names(), the
/// run directories among them after locking each, and stray temporary files of AtomicFile beside
/// any of them), so that the directory never mixes two runs or two commands; nothing else is
/// removed (a directory of chainsim's stays if it holds other files). Call it before integrating, so
/// that a run killed on the way leaves no earlier stats.json that would pass for its own. Throws
/// InputError, before anything is removed, if one of those names is taken by something chainsim
/// would not write there (a directory named like an output file, or a file named like one of its
/// directories).
void clear_run_outputs(const std::filesystem::path& dir);

/// The names of run_output_names() present in `dir` (a directory with a trailing '/', when it holds
/// one of its outputs), in that list's order: after a clean-up and a run, exactly what the run wrote.
std::vector<std::string> outputs_present(const std::filesystem::path& dir);

/// A run directory held by this process: created if needed, locked, and checked for writing.
///
/// The lock is an flock() on DIR/.chainsim.lock, which holds the holder's pid: exclusive, held until
/// the RunDirectory is destroyed, and released by the kernel when the process ends in any way (a
/// crash, SIGKILL), so a stale lock file never blocks a later run. A second RunDirectory on the
/// same directory, in this process or another, is refused at once with InputError naming the
/// directory and the holder's pid. The lock file is removed when the lock is released.
class RunDirectory {
 public:
  /// Throws InputError: `dir` cannot be created, is not writable, or is in use.
  explicit RunDirectory(std::filesystem::path dir);
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  /// clear_run_outputs(path()).
  void clear() const { clear_run_outputs(dir_); }

  /// The name of the lock file inside a run directory.
  static constexpr const char* kLockName = ".chainsim.lock";

 private:
  std::filesystem::path dir_;
  int fd_ = -1;
};

/// ARKODE's statistics as a JSON object (keys as in IntegratorStats).
nlohmann::json to_json(const IntegratorStats& stats);

}  // namespace chainsim
