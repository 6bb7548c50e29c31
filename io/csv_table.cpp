#include "io/csv_table.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "io/input_error.hpp"

namespace dynavins::io {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

}  // namespace

std::vector<CsvRow> read_csv(const std::string& path, std::size_t columns) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::vector<CsvRow> rows;
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    CsvRow row;
    row.line = n;
    std::size_t start = 0;
    for (;;) {
      const auto comma = t.find(',', start);
      row.fields.push_back(trim(t.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (row.fields.size() != columns)
      throw InputError(path, n, "expected " + std::to_string(columns) + " columns, found " +
                                    std::to_string(row.fields.size()));
    rows.push_back(std::move(row));
  }
  if (in.bad()) throw InputError(path, 0, "read error");
  return rows;
}

int64_t parse_int64(const std::string& field, const std::string& path, std::size_t line, const char* what) {
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  if (ec != std::errc() || end != field.data() + field.size() || field.empty())
    throw InputError(path, line, std::string(what) + " '" + field + "' is not an integer");
  return v;
}

double parse_double(const std::string& field, const std::string& path, std::size_t line, const char* what) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(field.c_str(), &end);
  if (field.empty() || end != field.c_str() + field.size() || errno == ERANGE || !std::isfinite(v))
    throw InputError(path, line, std::string(what) + " '" + field + "' is not a finite number");
  return v;
}

}  // namespace dynavins::io
