#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>

#include "io/csv_table.hpp"
#include "io/input_error.hpp"

using namespace dynavins::io;
namespace fs = std::filesystem;

namespace {
std::string write_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_csv";
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << text;
  return (dir / name).string();
}
}  // namespace

TEST_CASE("read_csv: comments, blank lines and CRLF, rows keep their line numbers", "[csv]") {
  const auto path = write_file("ok.csv", "#timestamp [ns],filename\r\n1,a.png\r\n\r\n2, b.png\r\n");
  const auto rows = read_csv(path, 2);
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].line == 2);
  CHECK(rows[1].line == 4);
  CHECK(rows[1].fields[1] == "b.png");
}

TEST_CASE("read_csv: a wrong column count names the file and line", "[csv]") {
  const auto path = write_file("bad.csv", "#h\n1,2,3\n4,5\n");
  CHECK_THROWS_WITH(read_csv(path, 3), path + ":3: expected 3 columns, found 2");
  CHECK_THROWS_WITH(read_csv("/nonexistent.csv", 3), Catch::StartsWith("/nonexistent.csv: cannot open"));
}

TEST_CASE("parse_int64 / parse_double reject what is not a number", "[csv]") {
  CHECK(parse_int64("1403715273262142976", "f", 1, "timestamp") == 1403715273262142976);
  CHECK_THROWS_WITH(parse_int64("12a", "f.csv", 7, "timestamp"), "f.csv:7: timestamp '12a' is not an integer");
  CHECK(parse_double("-3.5e-2", "f", 1, "x") == -0.035);
  CHECK_THROWS_AS(parse_double("nan", "f", 1, "x"), InputError);
  CHECK_THROWS_AS(parse_double("", "f", 1, "x"), InputError);
}
