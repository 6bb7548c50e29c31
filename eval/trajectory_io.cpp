#include "eval/trajectory_io.hpp"

#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

namespace dynavins::eval {

namespace {

std::string located(const std::string& file, std::size_t line, const std::string& problem) {
  return line > 0 ? file + ":" + std::to_string(line) + ": " + problem : file + ": " + problem;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_whitespace(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_space(s[i])) ++i;
    std::size_t j = i;
    while (j < s.size() && !is_space(s[j])) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

std::vector<std::string_view> split_commas(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = s.find(',', start);
    out.push_back(trim(s.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  // VINS-Fusion style writers end every row with a comma: tolerate exactly one empty last field.
  if (out.size() > 1 && out.back().empty()) out.pop_back();
  return out;
}

// Parses data rows of one file and accumulates poses; owns the file name for every message.
class RowParser {
 public:
  RowParser(const std::string& source, TrajectoryFormat format) : source_(source), format_(format) {}

  void parse_row(std::string_view row, std::size_t line_no) {
    line_ = line_no;
    StampedPose pose;
    if (format_ == TrajectoryFormat::Tum) {
      parse_tum(row, pose);
    } else {
      parse_euroc(row, pose);
    }
    check_pose(pose);
    poses_.push_back(pose);
    prev_line_ = line_no;
  }

  std::vector<StampedPose> take() { return std::move(poses_); }

 private:
  [[noreturn]] void fail(const std::string& problem) const { throw TrajectoryFileError(source_, line_, problem); }

  double number(std::string_view tok, std::size_t column) const {
    if (tok.empty()) fail("column " + std::to_string(column) + " is empty");
    double v = 0.0;
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (res.ec != std::errc() || res.ptr != tok.data() + tok.size()) {
      fail("column " + std::to_string(column) + ": '" + std::string(tok) + "' is not a number");
    }
    if (!std::isfinite(v)) fail("column " + std::to_string(column) + ": '" + std::string(tok) + "' is not finite");
    return v;
  }

  // TUM stamps are decimal seconds; derive exact nanoseconds from the digits so that ordering
  // checks and TUM output do not suffer from the ~0.2 us resolution of a double near 1.3e9 s.
  void tum_time(std::string_view tok, StampedPose& pose) const {
    pose.t = number(tok, 1);
    if (std::fabs(pose.t) > 9.0e9) fail("time stamp '" + std::string(tok) + "' is out of range");
    const std::size_t dot = tok.find('.');
    const std::string_view whole = tok.substr(0, dot);
    const std::string_view frac = dot == std::string_view::npos ? std::string_view() : tok.substr(dot + 1);
    const auto all_digits = [](std::string_view s) {
      for (char c : s) {
        if (c < '0' || c > '9') return false;
      }
      return true;
    };
    if (!whole.empty() && all_digits(whole) && all_digits(frac)) {
      std::int64_t sec = 0;
      std::from_chars(whole.data(), whole.data() + whole.size(), sec);
      std::int64_t ns = 0;
      for (std::size_t i = 0; i < 9; ++i) ns = ns * 10 + (i < frac.size() ? frac[i] - '0' : 0);
      if (frac.size() > 9 && frac[9] >= '5') ++ns;  // round to nearest nanosecond
      pose.t_ns = sec * 1000000000LL + ns;
    } else {
      pose.t_ns = std::llround(pose.t * 1e9);  // signed or exponent notation
    }
  }

  void parse_tum(std::string_view row, StampedPose& pose) const {
    const auto tok = split_whitespace(row);
    if (tok.size() != 8) {
      fail("expected 8 columns 't x y z qx qy qz qw' (TUM), found " + std::to_string(tok.size()));
    }
    tum_time(tok[0], pose);
    pose.p = {number(tok[1], 2), number(tok[2], 3), number(tok[3], 4)};
    // TUM stores the quaternion x y z w.
    pose.q = Eigen::Quaterniond(number(tok[7], 8), number(tok[4], 5), number(tok[5], 6), number(tok[6], 7));
  }

  void parse_euroc(std::string_view row, StampedPose& pose) {
    const auto tok = split_commas(row);
    if (columns_ == 0) {
      if (tok.size() < 8) {
        fail("expected at least 8 comma-separated columns 't[ns], px, py, pz, qw, qx, qy, qz' (EuRoC csv), found " +
             std::to_string(tok.size()));
      }
      columns_ = tok.size();
    } else if (tok.size() != columns_) {
      fail("expected " + std::to_string(columns_) + " columns like the first data row, found " +
           std::to_string(tok.size()));
    }
    const std::string_view ts = tok[0];
    std::int64_t ns = 0;
    const auto res = std::from_chars(ts.data(), ts.data() + ts.size(), ns);
    if (ts.empty() || res.ec != std::errc() || res.ptr != ts.data() + ts.size()) {
      fail("column 1: time stamp '" + std::string(ts) + "' is not an integer number of nanoseconds");
    }
    pose.t_ns = ns;
    pose.t = static_cast<double>(ns) / 1e9;  // same conversion as evo's EuRoC reader
    for (std::size_t c = 1; c < tok.size(); ++c) number(tok[c], c + 1);  // extra columns must be numbers too
    pose.p = {number(tok[1], 2), number(tok[2], 3), number(tok[3], 4)};
    // EuRoC stores the quaternion w x y z.
    pose.q = Eigen::Quaterniond(number(tok[4], 5), number(tok[5], 6), number(tok[6], 7), number(tok[7], 8));
  }

  void check_pose(StampedPose& pose) const {
    const double n = pose.q.norm();
    // A norm far from 1 almost always means the columns are in another order than assumed.
    if (!(std::fabs(n - 1.0) <= 0.1)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.6g", n);
      fail(std::string("quaternion norm ") + buf + " is far from 1 (wrong " + format_name(format_) +
           " column order?)");
    }
    pose.q.normalize();
    if (!poses_.empty() && pose.t_ns <= poses_.back().t_ns) {
      fail(std::string("time stamp ") + (pose.t_ns == poses_.back().t_ns ? "duplicates" : "goes back before") +
           " the one on line " + std::to_string(prev_line_) + " (time stamps must strictly increase)");
    }
  }

  const std::string& source_;
  TrajectoryFormat format_;
  std::size_t line_ = 0;
  std::size_t prev_line_ = 0;
  std::size_t columns_ = 0;
  std::vector<StampedPose> poses_;
};

}  // namespace

TrajectoryFileError::TrajectoryFileError(const std::string& file, std::size_t line, const std::string& problem)
    : std::runtime_error(located(file, line, problem)), file_(file), line_(line) {}

const char* format_name(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::Tum:
      return "TUM";
    case TrajectoryFormat::EurocCsv:
      return "EuRoC csv";
    case TrajectoryFormat::Auto:
      break;
  }
  return "auto";
}

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw TrajectoryFileError(path, 0, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw TrajectoryFileError(path, 0, "is a directory, not a file");
  // gzopen reads uncompressed files unchanged, so one code path serves both.
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw TrajectoryFileError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::string text;
  std::vector<char> buf(1 << 16);
  while (true) {
    const int got = gzread(f, buf.data(), static_cast<unsigned>(buf.size()));
    if (got > 0) text.append(buf.data(), static_cast<std::size_t>(got));
    int err = Z_OK;
    const char* msg = gzerror(f, &err);
    // Z_BUF_ERROR at the end means a truncated gzip stream; report it rather than use partial data.
    if (got < 0 || (err != Z_OK && err != Z_STREAM_END)) {
      const std::string what = std::string("read error: ") + (msg != nullptr ? msg : "unknown zlib error");
      gzclose(f);
      throw TrajectoryFileError(path, 0, what);
    }
    if (got == 0) break;
  }
  gzclose(f);
  return text;
}

Trajectory read_trajectory(const std::string& path, TrajectoryFormat format) {
  return parse_trajectory(read_text_file(path), path, format);
}

Trajectory parse_trajectory(const std::string& text, const std::string& source, TrajectoryFormat format) {
  Trajectory traj;
  traj.source = source;
  std::unique_ptr<RowParser> parser;
  std::size_t line_no = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view row = trim(std::string_view(text).substr(start, end - start));
    start = end + 1;
    ++line_no;
    if (row.empty() || row.front() == '#') continue;
    if (row.find('\0') != std::string_view::npos) throw TrajectoryFileError(source, line_no, "binary data in a text file");
    if (!parser) {
      if (format == TrajectoryFormat::Auto) {
        format = row.find(',') != std::string_view::npos ? TrajectoryFormat::EurocCsv : TrajectoryFormat::Tum;
      }
      parser = std::make_unique<RowParser>(traj.source, format);
    }
    parser->parse_row(row, line_no);
  }
  if (!parser) throw TrajectoryFileError(source, 0, "contains no poses");
  traj.poses = parser->take();
  return traj;
}

void write_tum(const std::string& path, const Trajectory& traj) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
  std::fprintf(f, "# timestamp tx ty tz qx qy qz qw\n");
  for (const StampedPose& s : traj.poses) {
    // Print the stamp from the exact nanoseconds so that a TUM round trip keeps it bit for bit.
    if (s.t_ns >= 0) {
      std::fprintf(f, "%lld.%09lld", static_cast<long long>(s.t_ns / 1000000000LL),
                   static_cast<long long>(s.t_ns % 1000000000LL));
    } else {
      std::fprintf(f, "%.9f", s.t);
    }
    std::fprintf(f, " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", s.p.x(), s.p.y(), s.p.z(), s.q.x(), s.q.y(), s.q.z(),
                 s.q.w());
  }
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
}

}  // namespace dynavins::eval
