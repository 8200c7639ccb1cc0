#pragma once
// CsvWriter: a time-series table (history.csv, walls.csv, ...). Only the active rank (rank 0)
// touches the file; on the others every call is a no-op, so callers need not branch on rank.
// Numbers are printed with %.17g (they parse back to the same double); a row is flushed as soon
// as it is written so that a run killed at any point leaves a readable file.
#include <mpi.h>

#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace fdem {

class CsvWriter {
 public:
  CsvWriter() = default;
  /// Open `path` and write the header row, on the active rank only.
  /// append == false: truncate the file. append == true (restart): keep the existing rows whose
  /// first column (the step) is <= keep_up_to (later rows came from after the checkpoint and are
  /// dropped); the header is written only if the file is missing or empty, and an existing
  /// header that differs from `columns` is an error.
  /// Throws std::runtime_error naming the file if it cannot be opened/written.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns,
            bool append = false, bool active = true,
            double keep_up_to = std::numeric_limits<double>::infinity());
  /// The same with the active rank being rank 0 of `comm`; the rows kept on append are those
  /// whose column `key_column` (default the first) is <= keep_up_to.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns, MPI_Comm comm,
            bool append = false, double keep_up_to = std::numeric_limits<double>::infinity(),
            int key_column = 0);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  CsvWriter(CsvWriter&& o) noexcept;
  CsvWriter& operator=(CsvWriter&& o) noexcept;

  /// Append one row; values.size() must equal the number of columns (std::invalid_argument).
  void row(const std::vector<double>& values);
  /// The same with a last column of text (quoted, RFC 4180, when it holds a comma, quote or line break).
  void row(const std::vector<double>& values, const std::string& text);
  void close();

  bool active() const { return file_ != nullptr; }
  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  void row(const std::vector<double>& values, const std::string* text);
  void open(bool append, double keep_up_to);
  std::string path_;
  std::vector<std::string> columns_;
  int key_column_ = 0;  // the column compared with keep_up_to on append
  std::FILE* file_ = nullptr;
};

/// Formats a double with %.17g ("nan", "inf", "-inf" for non-finite values).
std::string csv_number(double v);

}  // namespace fdem
