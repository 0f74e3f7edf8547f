#pragma once
// Tables of named columns from CSV files (run tables, observation tables). Columns are read by
// name, extra columns are ignored, and every error names the file, the line and the column.
// RFC 4180 quoting ("a, b" and "" inside quotes); a UTF-8 byte-order mark is skipped; blank lines
// and lines starting with '#' are skipped.

#include <cstddef>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace talus {

// Bounds of an input table: a table is held in memory whole (about four times its bytes), and a
// line is a few hundred bytes at most; so a wrong file (a device, a binary file) is refused at once
// instead of being read until memory runs out.
inline constexpr std::size_t kMaxCsvBytes = std::size_t{256} << 20;    // 256 MiB
inline constexpr std::size_t kMaxCsvLineBytes = std::size_t{1} << 20;  // 1 MiB

class CsvTable {
 public:
  // Reads the whole file. Throws InputError "<path>: <reason>" when it is not a regular file (a
  // device, a directory, or a pipe, which cannot be read again for the inputs' hash), is larger
  // than kMaxCsvBytes, cannot be read, has no header, a line longer than kMaxCsvLineBytes, a
  // header naming a column twice, or a row with more or fewer fields than the header.
  static CsvTable Read(const std::string& path);
  // The same from text already in memory; `path` names it in errors.
  static CsvTable Parse(const std::string& text, const std::string& path);

  const std::string& path() const { return path_; }
  int rows() const { return static_cast<int>(cells_.size()); }
  int line(int row) const { return lines_[static_cast<std::size_t>(row)]; }  // 1-based line
  bool Has(const std::string& column) const { return Column(column) >= 0; }
  const std::vector<std::string>& columns() const { return header_; }

  // Throws naming the first of `columns` the header lacks, and the columns it has.
  void Require(const std::vector<std::string>& columns) const;

  // The cell as text (trimmed of surrounding blanks); throws when the column is absent.
  std::string Text(int row, const std::string& column) const;
  // True when the column is absent or the cell is empty (or NA / NaN / nan, as CSV writers put it).
  bool Empty(int row, const std::string& column) const;
  // A finite number; throws "<path>:<line>: column '<c>': '<text>' is not a finite number".
  double Number(int row, const std::string& column) const;
  // As Number, and >= 0; throws "<path>:<line>: column '<c>': <text> must be >= 0".
  double NonNegativeNumber(int row, const std::string& column) const;
  // nullopt when Empty, else as Number.
  std::optional<double> OptionalNumber(int row, const std::string& column) const;

  // "<path>:<line>: column '<column>'" for messages of the caller's own checks.
  std::string Where(int row, const std::string& column) const;

 private:
  int Column(const std::string& name) const;

  std::string path_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> cells_;
  std::vector<int> lines_;
};

// Reads a large CSV file (rocks.csv of a big run) record by record instead of whole, with the same
// quoting rules; fields are not trimmed.
class CsvReader {
 public:
  // Opens the file and reads the header; throws InputError naming the file.
  explicit CsvReader(const std::string& path);
  const std::vector<std::string>& header() const { return header_; }
  // Index of a header column; throws InputError naming the file and the column when absent.
  std::size_t Column(const std::string& name) const;
  // The next record into *fields (as many as the header has); false at the end. Throws InputError
  // "<path>:<line>: ..." for a record with another number of fields, or a read error.
  bool Next(std::vector<std::string>* fields);
  int line() const { return line_; }  // 1-based line where the last record started
  const std::string& path() const { return path_; }

 private:
  bool ReadRecord(std::vector<std::string>* fields);

  std::string path_;
  std::ifstream in_;
  std::vector<std::string> header_;
  int line_ = 0, next_line_ = 1;
};

// The number a whole CSV field holds (std::stod's syntax), or InputError
// "<where>: column '<column>': '<text>' is not a number" (where: "file:line").
double CsvFieldNumber(const std::string& text, const std::string& where, const std::string& column);

}  // namespace talus
