#include "common/csv_table.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/error.hpp"

namespace talus {
namespace {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

// What a file that is not a regular file is, for messages.
std::string KindOf(const std::filesystem::file_status& status) {
  namespace fs = std::filesystem;
  switch (status.type()) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::fifo:
      return "a pipe";
    case fs::file_type::socket:
      return "a socket";
    case fs::file_type::not_found:
      return "no such file";
    default:
      return "not a file";
  }
}

// Throws naming the line when a line of `text` is longer than kMaxCsvLineBytes.
void CheckLineLengths(const std::string& text, const std::string& path) {
  int line = 1;
  for (std::size_t start = 0; start < text.size(); ++line) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    if (end - start > kMaxCsvLineBytes)
      throw InputError(path + ":" + std::to_string(line) + ": a line longer than " +
                       std::to_string(kMaxCsvLineBytes >> 20) +
                       " MiB: not a CSV table (a binary file?)");
    start = end + 1;
  }
}

}  // namespace

CsvTable CsvTable::Read(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // follows symbolic links
  if (error) throw InputError(path + ": cannot open (" + error.message() + ")");
  if (!fs::is_regular_file(status))
    throw InputError(path + ": not a regular file (" + KindOf(status) +
                     "); a table must be a CSV file");
  if (const std::uintmax_t size = fs::file_size(path, error); !error && size > kMaxCsvBytes)
    throw InputError(path + ": " + std::to_string(size) + " bytes, more than a table may have (" +
                     std::to_string(kMaxCsvBytes >> 20) + " MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open (" + std::strerror(errno) + ")");
  // Read in chunks up to the bound: a file that grew since its size was asked is refused too.
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxCsvBytes)
      throw InputError(path + ": more bytes than a table may have (" +
                       std::to_string(kMaxCsvBytes >> 20) + " MiB)");
  }
  if (in.bad()) throw InputError(path + ": read error");
  return Parse(text, path);
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& path) {
  CheckLineLengths(text, path);
  CsvTable table;
  table.path_ = path;
  std::size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  int line = 1;
  // Splits one record (which may span lines inside quotes) into fields.
  auto record = [&](std::vector<std::string>& fields, int& first_line) {
    fields.clear();
    first_line = line;
    std::string field;
    bool quoted = false, was_quoted = false;
    while (pos < text.size()) {
      const char c = text[pos++];
      if (quoted) {
        if (c == '"') {
          if (pos < text.size() && text[pos] == '"') {
            field += '"';
            ++pos;
          } else {
            quoted = false;
          }
        } else {
          if (c == '\n') ++line;
          field += c;
        }
      } else if (c == '"' && Trim(field).empty()) {
        quoted = was_quoted = true;
        field.clear();
      } else if (c == ',') {
        fields.push_back(was_quoted ? field : Trim(field));
        field.clear();
        was_quoted = false;
      } else if (c == '\n') {
        ++line;
        break;
      } else {
        field += c;
      }
    }
    if (quoted) throw InputError(path + ":" + std::to_string(first_line) + ": unclosed quote");
    fields.push_back(was_quoted ? field : Trim(field));
  };

  std::vector<std::string> fields;
  int first = 0;
  while (pos < text.size()) {
    record(fields, first);
    const bool blank = fields.size() == 1 && fields[0].empty();
    if (blank || (!fields.empty() && !fields[0].empty() && fields[0][0] == '#')) continue;
    if (table.header_.empty()) {
      table.header_ = fields;
      for (std::size_t k = 0; k < fields.size(); ++k) {
        if (fields[k].empty())
          throw InputError(path + ":" + std::to_string(first) + ": header column " +
                           std::to_string(k + 1) + " has no name");
        for (std::size_t q = 0; q < k; ++q)
          if (fields[q] == fields[k])
            throw InputError(path + ":" + std::to_string(first) + ": header names column '" +
                             fields[k] + "' twice");
      }
      continue;
    }
    if (fields.size() != table.header_.size())
      throw InputError(path + ":" + std::to_string(first) + ": " + std::to_string(fields.size()) +
                       " fields, but the header has " + std::to_string(table.header_.size()));
    table.cells_.push_back(fields);
    table.lines_.push_back(first);
  }
  if (table.header_.empty()) throw InputError(path + ": empty file (no header line)");
  return table;
}

int CsvTable::Column(const std::string& name) const {
  for (std::size_t k = 0; k < header_.size(); ++k)
    if (header_[k] == name) return static_cast<int>(k);
  return -1;
}

void CsvTable::Require(const std::vector<std::string>& columns) const {
  for (const std::string& c : columns) {
    if (Has(c)) continue;
    std::string have;
    for (const std::string& h : header_) have += (have.empty() ? "" : ", ") + h;
    throw InputError(path_ + ": missing column '" + c + "' (the header has: " + have + ")");
  }
}

std::string CsvTable::Where(int row, const std::string& column) const {
  return path_ + ":" + std::to_string(line(row)) + ": column '" + column + "'";
}

std::string CsvTable::Text(int row, const std::string& column) const {
  const int c = Column(column);
  if (c < 0) Require({column});
  return cells_[static_cast<std::size_t>(row)][static_cast<std::size_t>(c)];
}

bool CsvTable::Empty(int row, const std::string& column) const {
  if (!Has(column)) return true;
  const std::string t = Text(row, column);
  return t.empty() || t == "NA" || t == "NaN" || t == "nan" || t == "NAN";
}

double CsvTable::Number(int row, const std::string& column) const {
  const std::string t = Text(row, column);
  double v = 0;
  const char* begin = t.data();
  const char* end = t.data() + t.size();
  if (!t.empty() && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, v);
  if (t.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
    throw InputError(Where(row, column) + ": '" + t + "' is not a finite number");
  return v;
}

double CsvTable::NonNegativeNumber(int row, const std::string& column) const {
  const double v = Number(row, column);
  if (v < 0) throw InputError(Where(row, column) + ": " + Text(row, column) + " must be >= 0");
  return v;
}

std::optional<double> CsvTable::OptionalNumber(int row, const std::string& column) const {
  if (Empty(row, column)) return std::nullopt;
  return Number(row, column);
}

namespace {

// Splits one record (RFC 4180 quoting; the record may hold line breaks inside quotes).
std::vector<std::string> SplitRecord(const std::string& record) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t k = 0; k < record.size(); ++k) {
    const char c = record[k];
    if (quoted && c == '"' && k + 1 < record.size() && record[k + 1] == '"') {
      fields.back() += '"';
      ++k;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace

CsvReader::CsvReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw InputError(path + ": cannot open (" + std::strerror(errno) + ")");
  if (!ReadRecord(&header_)) throw InputError(path + ": no header");
  if (!header_.empty() && header_[0].compare(0, 3, "\xEF\xBB\xBF") == 0)
    header_[0].erase(0, 3);
}

std::size_t CsvReader::Column(const std::string& name) const {
  for (std::size_t c = 0; c < header_.size(); ++c)
    if (header_[c] == name) return c;
  throw InputError(path_ + ": no column '" + name + "'");
}

bool CsvReader::ReadRecord(std::vector<std::string>* fields) {
  std::string record, text;
  do {
    if (!std::getline(in_, text)) {
      if (in_.bad()) throw InputError(path_ + ": read error");
      return false;
    }
    line_ = next_line_++;
  } while (text.empty() || text == "\r");
  record = text;
  // A quoted field may hold a line break: read on until the quotes balance.
  while (std::count(record.begin(), record.end(), '"') % 2 == 1 && std::getline(in_, text)) {
    ++next_line_;
    record += "\n" + text;
  }
  if (!record.empty() && record.back() == '\r') record.pop_back();
  *fields = SplitRecord(record);
  return true;
}

bool CsvReader::Next(std::vector<std::string>* fields) {
  if (!ReadRecord(fields)) return false;
  if (fields->size() != header_.size())
    throw InputError(path_ + ":" + std::to_string(line_) + ": " + std::to_string(fields->size()) +
                     " fields, the header has " + std::to_string(header_.size()));
  return true;
}

double CsvFieldNumber(const std::string& text, const std::string& where, const std::string& column) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size())
    throw InputError(where + ": column '" + column + "': '" + text + "' is not a number");
  return v;
}

}  // namespace talus
