#include "io/csv.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fdem {

namespace {

std::string join(const std::vector<std::string>& cols) {
  std::string s;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (i) s += ',';
    s += cols[i];
  }
  return s;
}

std::string strip_cr(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n')) s.pop_back();
  return s;
}

}  // namespace

std::string csv_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns,
                     bool append, bool active, double keep_up_to)
    : path_(path), columns_(columns) {
  if (active) open(append, keep_up_to);
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns,
                     MPI_Comm comm, bool append, double keep_up_to, int key_column)
    : path_(path), columns_(columns), key_column_(key_column) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) open(append, keep_up_to);
}

CsvWriter::~CsvWriter() { close(); }

CsvWriter::CsvWriter(CsvWriter&& o) noexcept
    : path_(std::move(o.path_)), columns_(std::move(o.columns_)), file_(o.file_) {
  o.file_ = nullptr;
}

CsvWriter& CsvWriter::operator=(CsvWriter&& o) noexcept {
  if (this != &o) {
    close();
    path_ = std::move(o.path_);
    columns_ = std::move(o.columns_);
    file_ = o.file_;
    o.file_ = nullptr;
  }
  return *this;
}

void CsvWriter::open(bool append, double keep_up_to) {
  const std::string header = join(columns_);
  if (append) {
    // Read what is there, keep the header and the rows up to the restart step.
    std::ifstream in(path_);
    std::vector<std::string> keep;
    bool have_header = false;
    if (in) {
      std::string line;
      while (std::getline(in, line)) {
        line = strip_cr(line);
        if (line.empty()) continue;
        if (!have_header) {
          if (line != header)
            throw std::runtime_error(path_ + ": cannot append: its header \"" + line +
                                     "\" differs from \"" + header + "\"");
          have_header = true;
          continue;
        }
        const char* p = line.c_str();
        for (int k = 0; k < key_column_ && p; ++k) {  // to the key column
          p = std::strchr(p, ',');
          if (p) ++p;
        }
        const double key = p ? std::strtod(p, nullptr) : std::numeric_limits<double>::infinity();
        if (key <= keep_up_to) keep.push_back(line);
      }
    }
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
      throw std::runtime_error(path_ + ": cannot open for writing: " + std::strerror(errno));
    std::fprintf(file_, "%s\n", header.c_str());
    for (const std::string& l : keep) std::fprintf(file_, "%s\n", l.c_str());
  } else {
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
      throw std::runtime_error(path_ + ": cannot open for writing: " + std::strerror(errno));
    std::fprintf(file_, "%s\n", header.c_str());
  }
  if (std::fflush(file_) != 0) throw std::runtime_error(path_ + ": write failed");
}

void CsvWriter::row(const std::vector<double>& values) { row(values, nullptr); }

void CsvWriter::row(const std::vector<double>& values, const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return row(values, &text);
  // a name with a comma or a quote (a mesh or wall name in held_by): quoted as RFC 4180 says,
  // which Python's csv module and spreadsheets read back as written
  std::string q = "\"";
  for (char ch : text) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  q += '"';
  row(values, &q);
}

void CsvWriter::row(const std::vector<double>& values, const std::string* text) {
  const std::size_t n = values.size() + (text ? 1 : 0);
  if (n != columns_.size())
    throw std::invalid_argument(path_ + ": row has " + std::to_string(n) +
                                " values, the header has " + std::to_string(columns_.size()) +
                                " columns");
  if (!file_) return;
  std::string line;
  line.reserve(values.size() * 24 + (text ? text->size() + 1 : 0));
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    line += csv_number(values[i]);
  }
  if (text) {
    if (!values.empty()) line += ',';
    line += *text;
  }
  line += '\n';
  if (std::fputs(line.c_str(), file_) < 0 || std::fflush(file_) != 0)
    throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
}

void CsvWriter::close() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
}

}  // namespace fdem
