// Per-loop report and loops.csv rows (see loop_report.hpp).
#include "stages/loop/graph/loop_report.hpp"

#include <iomanip>

namespace dynavins::loop {

std::vector<LoopReportRow> loop_report(const LoopGraphOptimizer& optimizer, const LoopGraphResult& result) {
  std::vector<LoopReportRow> rows;
  const std::vector<VerifiedLoop>& loops = optimizer.loops();
  rows.reserve(result.loops.size());
  for (const LoopResult& r : result.loops) {
    if (r.loop_index >= loops.size()) continue;
    const VerifiedLoop& l = loops[r.loop_index];
    LoopReportRow row;
    row.query_t_ns = l.query_t_ns;
    row.match_t_ns = l.match_t_ns;
    row.inliers = l.inliers;
    row.group = r.group;
    if (r.group >= 0 && static_cast<std::size_t>(r.group) < optimizer.groups().size())
      row.group_first_t_ns = optimizer.groups()[static_cast<std::size_t>(r.group)].first_t_ns();
    row.hypothesis = r.hypothesis;
    row.weight = r.weight;
    row.used = r.used;
    rows.push_back(row);
  }
  return rows;
}

void write_loops_csv(std::ostream& out, LoopMode mode, const std::vector<LoopReportRow>& rows) {
  out << "mode,query_t_ns,match_t_ns,inliers,group,group_first_t_ns,hypothesis,weight,used\n";
  const auto old_flags = out.flags();
  const auto old_precision = out.precision();
  out << std::setprecision(6);
  for (const LoopReportRow& r : rows)
    out << loop_mode_name(mode) << ',' << r.query_t_ns << ',' << r.match_t_ns << ',' << r.inliers << ',' << r.group
        << ',' << r.group_first_t_ns << ',' << r.hypothesis << ',' << r.weight << ',' << (r.used ? 1 : 0) << '\n';
  out.flags(old_flags);
  out.precision(old_precision);
}

}  // namespace dynavins::loop
