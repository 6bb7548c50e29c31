#pragma once
// Per-loop outcome of a loop-graph optimisation, one row per verified loop, and its CSV form for a run's
// loops.csv: which group and hypothesis (paper IV-B) each loop fell in and the weight it ended with (IV-C).

#include <cstdint>
#include <ostream>
#include <vector>

#include "stages/loop/graph/loop_graph_optimizer.hpp"
#include "stages/loop/graph/loop_mode.hpp"

namespace dynavins::loop {

struct LoopReportRow {
  int64_t query_t_ns = 0;
  int64_t match_t_ns = 0;
  int inliers = 0;
  int group = -1;                 ///< index of the query's group, -1 if it lies in none (dropped group)
  int64_t group_first_t_ns = -1;  ///< C_i of that group, -1 if none
  int hypothesis = -1;            ///< 0 / 1 (H^0, H^1) in dynavins mode, -1 otherwise or outside the top two
  double weight = 0.0;            ///< LoopResult::weight
  bool used = false;
};

/// Joins the optimizer's loops and groups with a result of its optimize().
std::vector<LoopReportRow> loop_report(const LoopGraphOptimizer& optimizer, const LoopGraphResult& result);

/// Header "mode,query_t_ns,match_t_ns,inliers,group,group_first_t_ns,hypothesis,weight,used", one line per row.
void write_loops_csv(std::ostream& out, LoopMode mode, const std::vector<LoopReportRow>& rows);

}  // namespace dynavins::loop
