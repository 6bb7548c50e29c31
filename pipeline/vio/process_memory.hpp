#pragma once
// Memory use of this process, for run summaries.

namespace dynavins::pipeline {

/// Peak resident set size of the process so far [MB] (getrusage ru_maxrss); 0 if unavailable.
double peak_rss_mb();

}  // namespace dynavins::pipeline
