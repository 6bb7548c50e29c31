#pragma once
// Strict reader for the comma-separated sensor files of EuRoC ASL folders: `#` header/comment
// lines, CRLF tolerated, every data row must have exactly the expected number of columns.

#include <cstdint>
#include <string>
#include <vector>

namespace dynavins::io {

struct CsvRow {
  std::size_t line = 0;  ///< 1-based line number in the file
  std::vector<std::string> fields;
};

/// Reads every data row of `path`; throws InputError naming file and line on a wrong column count,
/// or naming the file if it cannot be read.
std::vector<CsvRow> read_csv(const std::string& path, std::size_t columns);

/// Parses a field as an integer / a finite number; throws InputError naming file, line and `what`.
int64_t parse_int64(const std::string& field, const std::string& path, std::size_t line, const char* what);
double parse_double(const std::string& field, const std::string& path, std::size_t line, const char* what);

}  // namespace dynavins::io
