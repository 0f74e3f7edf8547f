#include "common/csv_table.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "common/error.hpp"
#include "tests/test_tmp.hpp"

namespace talus {
namespace {

std::string WriteFile(const std::string& name, const std::string& text) {
  const auto dir = talus::testing::TestTmpRoot();
  std::filesystem::create_directories(dir);
  const auto path = dir / ("talus_csv_reader_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

TEST(CsvReader, ReadsRecordsWithQuotesLineBreaksAndCrlf) {
  const std::string path = WriteFile(
      "ok.csv", "\xEF\xBB\xBFrock,run,x\r\n0,\"a, \"\"b\"\"\",1.5\r\n\r\n1,\"two\nlines\",2\n");
  CsvReader in(path);
  ASSERT_EQ(in.header().size(), 3u);
  EXPECT_EQ(in.header()[0], "rock");  // the byte-order mark is skipped
  EXPECT_EQ(in.Column("x"), 2u);
  std::vector<std::string> fields;
  ASSERT_TRUE(in.Next(&fields));
  EXPECT_EQ(fields[1], "a, \"b\"");
  EXPECT_EQ(fields[2], "1.5");
  EXPECT_EQ(in.line(), 2);
  ASSERT_TRUE(in.Next(&fields));  // the blank line is skipped
  EXPECT_EQ(fields[1], "two\nlines");
  EXPECT_EQ(in.line(), 4);
  EXPECT_FALSE(in.Next(&fields));
}

TEST(CsvReader, ErrorsNameTheFileLineAndColumn) {
  const std::string path = WriteFile("short.csv", "a,b\n1,2\n3\n");
  CsvReader in(path);
  std::vector<std::string> fields;
  EXPECT_TRUE(in.Next(&fields));
  try {
    in.Next(&fields);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:3: 1 fields, the header has 2"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(in.Column("c"), InputError);
  EXPECT_THROW(CsvReader("/nonexistent/rocks.csv"), InputError);
  EXPECT_THROW(CsvReader(WriteFile("empty.csv", "")), InputError);
}

TEST(CsvTable, NonNegativeNumbersNameTheCellOfANegativeOne) {
  const CsvTable t = CsvTable::Parse("a,b\n0,2.5\n-1,x\n", "t.csv");
  EXPECT_EQ(t.NonNegativeNumber(0, "a"), 0);
  EXPECT_EQ(t.NonNegativeNumber(0, "b"), 2.5);
  try {
    t.NonNegativeNumber(1, "a");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "t.csv:3: column 'a': -1 must be >= 0");
  }
  EXPECT_THROW(t.NonNegativeNumber(1, "b"), InputError);  // not a number
}

// The message of the InputError that reading `path` throws ("" when it reads).
std::string RefusalOf(const std::string& path) {
  try {
    CsvTable::Read(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A run table, [blocks] file or observation table naming /dev/zero was read until memory ran out:
// devices, directories and pipes are refused at once (a pipe could not be read a second time for
// the inputs' hash), also behind a symbolic link, naming the file.
TEST(CsvTable, ANonRegularFileIsRefusedBeforeReading) {
  namespace fs = std::filesystem;
  const fs::path dir = talus::testing::TestTmpRoot() / "csv_devices";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string fifo = (dir / "runs.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir / "zero.csv");
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"/dev/zero", "/dev/zero: not a regular file (a character device)"},
      {"/dev/urandom", "/dev/urandom: not a regular file (a character device)"},
      {(dir / "zero.csv").string(), "zero.csv: not a regular file (a character device)"},
      {fifo, "runs.csv: not a regular file (a pipe)"},
      {dir.string(), "csv_devices: not a regular file (a directory)"},
      {(dir / "none.csv").string(), "none.csv: cannot open"}};
  for (const auto& [path, says] : refused)
    EXPECT_NE(RefusalOf(path).find(says), std::string::npos) << path << ": " << RefusalOf(path);
}

// Larger than the bound: refused from its size, before reading (a sparse file of that size); a line
// longer than its bound (a binary file, zeros without a line break) names the line.
TEST(CsvTable, AFileOrALineBeyondItsBoundIsRefused) {
  namespace fs = std::filesystem;
  const std::string big = WriteFile("big.csv", "a,b\n1,2\n");
  fs::resize_file(big, kMaxCsvBytes + 1);
  EXPECT_NE(RefusalOf(big).find("big.csv: " + std::to_string(kMaxCsvBytes + 1) +
                                " bytes, more than a table may have (256 MiB)"),
            std::string::npos)
      << RefusalOf(big);
  const std::string at_bound = WriteFile("long_ok.csv", "a\n" + std::string(kMaxCsvLineBytes, 'x'));
  EXPECT_EQ(RefusalOf(at_bound), "");
  const std::string zeros =
      WriteFile("zeros.csv", "a,b\n1,2\n" + std::string(kMaxCsvLineBytes + 1, '\0') + "\n3,4\n");
  EXPECT_NE(RefusalOf(zeros).find("zeros.csv:3: a line longer than 1 MiB"), std::string::npos)
      << RefusalOf(zeros);
}

}  // namespace
}  // namespace talus
