#include "common/csv_table.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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

}  // namespace
}  // namespace talus
