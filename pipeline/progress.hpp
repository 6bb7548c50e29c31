#pragma once
// Progress of a long run on the terminal: one self-overwriting line on a TTY (stderr), or a log
// line every `log_every_s` seconds when stderr is a file or a pipe (CI logs stay readable).

#include <cstdint>
#include <string>

namespace dynavins::pipeline {

class Progress {
 public:
  /// `label` prefixes every line, e.g. "replay".
  explicit Progress(std::string label, double log_every_s = 10.0);
  /// `fraction` in [0, 1]; `detail` is appended as is (frames, x real time, ...). Cheap to call often.
  void update(double fraction, const std::string& detail);
  /// Final line (ends the self-overwriting line on a TTY).
  void done(const std::string& detail);

 private:
  std::string label_;
  double log_every_s_;
  bool tty_;
  int64_t start_ns_;
  int64_t last_print_ns_;
};

}  // namespace dynavins::pipeline
