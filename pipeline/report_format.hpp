#pragma once
// Human and machine renderings of a run's counters: a fixed-width table for the terminal and
// JSON for summary files.

#include <string>

#include "pipeline/pipeline.hpp"

namespace dynavins::pipeline {

/// Stage and queue table, one line each (ms: mean / p95 / max).
std::string format_report(const RunReport& report);

/// {"ok":..,"wall_s":..,"stages":[..],"queues":[..]} — no trailing newline.
std::string report_to_json(const RunReport& report);

/// Escapes a string for inclusion in JSON (quotes included).
std::string json_string(const std::string& s);

}  // namespace dynavins::pipeline
