#include "output.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <iterator>
#include <system_error>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"

namespace chainsim {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_.replace_filename("." + target_.filename().string() + ".tmp");
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
}

void CsvWriter::row(const double* values, std::size_t count, const std::string* label) {
  CHAINSIM_VERIFY(count == columns_, "CSV row length differs from the header");
  CHAINSIM_VERIFY(labelled_ == (label != nullptr), "a CSV row has a label exactly when its file has a label column");
  line_.clear();
  auto it = std::back_inserter(line_);
  if (label) fmt::format_to(it, "{},", *label);
  for (std::size_t j = 0; j < count; ++j) {
    if (j) line_.push_back(',');
    if (digits_ > 0)
      fmt::format_to(it, "{:.{}g}", values[j], digits_);
    else
      fmt::format_to(it, "{}", values[j]);
  }
  line_.push_back('\n');
  file_.stream().write(line_.data(), static_cast<std::streamsize>(line_.size()));
}

void write_json(const std::filesystem::path& path, const nlohmann::json& doc) {
  AtomicFile file(path);
  file.stream() << doc.dump(2) << '\n';
  file.commit();
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
          {"recoverable_failures", s.recoverable_failures},
          {"last_step", s.last_step}};
}

}  // namespace chainsim
