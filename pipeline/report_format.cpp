#include "pipeline/report_format.hpp"

#include <cstdio>
#include <sstream>

namespace dynavins::pipeline {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string format_report(const RunReport& r) {
  std::ostringstream os;
  char line[256];
  std::snprintf(line, sizeof line, "%-18s %10s %24s %20s\n", "thread", "processed", "process ms mean/p95/max",
                "queue wait ms mean/p95");
  os << line;
  for (const auto& s : r.stages) {
    std::snprintf(line, sizeof line, "%-18s %10llu %8.3f/%7.3f/%7.3f %12.3f/%7.3f\n", s.name.c_str(),
                  static_cast<unsigned long long>(s.processed), s.process.mean_ms, s.process.p95_ms,
                  s.process.max_ms, s.wait.mean_ms, s.wait.p95_ms);
    os << line;
  }
  std::snprintf(line, sizeof line, "%-18s %8s %9s %10s %10s %10s\n", "queue", "capacity", "max depth", "pushed",
                "delivered", "dropped");
  os << line;
  for (const auto& q : r.queues) {
    std::snprintf(line, sizeof line, "%-18s %8zu %9zu %10llu %10llu %10llu\n", q.name.c_str(), q.capacity,
                  q.max_depth, static_cast<unsigned long long>(q.pushed),
                  static_cast<unsigned long long>(q.delivered), static_cast<unsigned long long>(q.dropped));
    os << line;
  }
  return os.str();
}

std::string report_to_json(const RunReport& r) {
  std::ostringstream os;
  os.precision(6);
  os << "{\"ok\":" << (r.ok ? "true" : "false") << ",\"interrupted\":" << (r.interrupted ? "true" : "false")
     << ",\"error\":" << json_string(r.error) << ",\"failed_thread\":" << json_string(r.failed_thread)
     << ",\"wall_s\":" << r.wall_s << ",\"stages\":[";
  for (std::size_t i = 0; i < r.stages.size(); ++i) {
    const auto& s = r.stages[i];
    os << (i ? "," : "") << "{\"name\":" << json_string(s.name) << ",\"processed\":" << s.processed
       << ",\"process_ms_mean\":" << s.process.mean_ms << ",\"process_ms_p95\":" << s.process.p95_ms
       << ",\"process_ms_max\":" << s.process.max_ms << ",\"wait_ms_mean\":" << s.wait.mean_ms
       << ",\"wait_ms_p95\":" << s.wait.p95_ms << "}";
  }
  os << "],\"queues\":[";
  for (std::size_t i = 0; i < r.queues.size(); ++i) {
    const auto& q = r.queues[i];
    os << (i ? "," : "") << "{\"name\":" << json_string(q.name) << ",\"capacity\":" << q.capacity
       << ",\"max_depth\":" << q.max_depth << ",\"pushed\":" << q.pushed << ",\"delivered\":" << q.delivered
       << ",\"dropped\":" << q.dropped << "}";
  }
  os << "]}";
  return os.str();
}

}  // namespace dynavins::pipeline
