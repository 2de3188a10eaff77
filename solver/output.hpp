#pragma once
/// @file output.hpp
/// Output files that are either complete or absent.
///
/// Every file chainsim writes goes through AtomicFile: the content is written to a hidden
/// temporary file beside the target and renamed over it only by commit(). A run that stops early
/// (an exception, a signal) leaves at most a stray ".tmp" file, never a half-written CSV that looks
/// complete.
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

/// A CSV file written row by row through an AtomicFile (nothing held in memory): the header at
/// construction, then rows of numbers, each optionally led by a text label; commit() publishes it.
/// significant_digits = 0: the shortest text that reads back to the same double.
class CsvWriter {
 public:
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
            const std::string& label_column = "", int significant_digits = 0);
  /// Appends a row; it must have one value per column.
  void row(const double* values, std::size_t count, const std::string* label = nullptr);
  void row(const std::vector<double>& values) { row(values.data(), values.size()); }
  void commit() { file_.commit(); }

 private:
  AtomicFile file_;
  std::size_t columns_;
  bool labelled_;
  int digits_;
  std::string line_;
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

/// Writes a JSON document atomically, pretty-printed.
void write_json(const std::filesystem::path& path, const nlohmann::json& doc);

/// Creates `dir` (and parents) or throws InputError naming the directory and the OS error.
void ensure_directory(const std::filesystem::path& dir);

/// ensure_directory(), then checks that a file can be created and renamed in `dir` (by writing and
/// removing a probe through AtomicFile); throws InputError naming the directory and the OS error.
/// Call it before a long run, so that a read-only --out fails at once rather than at the end.
void ensure_writable_directory(const std::filesystem::path& dir);

/// ARKODE's statistics as a JSON object (keys as in IntegratorStats).
nlohmann::json to_json(const IntegratorStats& stats);

}  // namespace chainsim
