#pragma once
// Reading and writing trajectory files: TUM text and EuRoC-style csv, optionally gzip-compressed.

#include "eval/trajectory.hpp"

#include <stdexcept>
#include <string>

namespace dynavins::eval {

/// File layouts understood by read_trajectory().
enum class TrajectoryFormat {
  Auto,      ///< a comma in the first data row means EuRoC csv, otherwise TUM
  Tum,       ///< `t[s] x y z qx qy qz qw`, whitespace-separated, `#` comments
  EurocCsv,  ///< `t[ns], px, py, pz, qw, qx, qy, qz[, extra columns...]`, `#` header
};

/// Bad trajectory input; what() reads "<file>:<line>: <problem>" (line 0 when no line applies).
class TrajectoryFileError : public std::runtime_error {
 public:
  TrajectoryFileError(const std::string& file, std::size_t line, const std::string& problem);
  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::string file_;
  std::size_t line_;
};

/// Reads a whole file into memory, transparently gunzipping `.gz` (or any gzip) content.
/// Throws TrajectoryFileError if the file is missing, unreadable or a corrupt gzip stream.
std::string read_text_file(const std::string& path);

/// Reads a TUM or EuRoC csv trajectory (plain or gzip). Every malformed row throws
/// TrajectoryFileError naming the file and line; nothing is skipped silently.
Trajectory read_trajectory(const std::string& path, TrajectoryFormat format = TrajectoryFormat::Auto);

/// Parses trajectory text already in memory; `source` is the name used in error messages.
Trajectory parse_trajectory(const std::string& text, const std::string& source,
                            TrajectoryFormat format = TrajectoryFormat::Auto);

/// Writes `traj` as TUM text (`t x y z qx qy qz qw`, one header line); throws on I/O failure.
void write_tum(const std::string& path, const Trajectory& traj);

/// Short name of a format for messages ("TUM", "EuRoC csv", "auto").
const char* format_name(TrajectoryFormat format);

}  // namespace dynavins::eval
