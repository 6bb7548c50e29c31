// `dynavins compare RUN_DIR... [--gt FILE] [--plot OUT.png] [--json]`: the runs of `dynavins run`
// side by side — ATE / RPE against one ground truth (as `dynavins eval`), BA time, real-time factor,
// resets and tracking share from each summary.json — with an optional top-view plot of all of them.
#include "bin/commands.hpp"
#include "eval/comparison_plot.hpp"
#include "eval/evaluation.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/report_format.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace dynavins::cli {

namespace {

namespace fs = std::filesystem;
using pipeline::json_string;

struct CompareArgs {
  std::vector<std::string> runs;
  std::string gt;
  std::string plot;
  bool json = false;
  double max_dt = 0.01;
  std::size_t rpe_delta = 1;
};

/// What one run directory contributes to the table.
struct RunRow {
  std::string name;
  std::string dir;
  std::size_t poses = 0;
  bool evaluated = false;
  std::string eval_error;
  eval::EvalResult result;
  std::vector<Eigen::Vector3d> aligned;  // whole estimate in the ground-truth frame
  double ba_ms_mean = NAN, ba_ms_p95 = NAN, real_time = NAN, resets = NAN, tracking = NAN, estimated = NAN;
  std::string ba, cameras;
};

std::string dir_name(const std::string& dir) {
  fs::path p(dir);
  if (p.filename().empty()) p = p.parent_path();  // "runs/x/" -> "runs/x"
  return p.filename().string();
}

// summary.json is flat and written by RunOutputs: a top-level key's value is found by its quoted
// name. Returns NaN for null or a missing key; strings come back without quotes.
std::optional<std::string> json_raw(const std::string& json, const std::string& key) {
  const std::string needle = "\"" + key + "\":";
  const std::size_t at = json.find(needle);
  if (at == std::string::npos) return std::nullopt;
  std::size_t i = at + needle.size();
  while (i < json.size() && std::isspace(static_cast<unsigned char>(json[i]))) ++i;
  if (i < json.size() && json[i] == '"') {
    const std::size_t end = json.find('"', i + 1);
    if (end == std::string::npos) return std::nullopt;
    return json.substr(i + 1, end - i - 1);
  }
  std::size_t end = i;
  while (end < json.size() && json[end] != ',' && json[end] != '\n' && json[end] != '}') ++end;
  return json.substr(i, end - i);
}

double json_number(const std::string& json, const std::string& key, const std::string& file) {
  const auto raw = json_raw(json, key);
  if (!raw || *raw == "null") return NAN;
  char* end = nullptr;
  const double x = std::strtod(raw->c_str(), &end);
  if (end == raw->c_str()) throw CommandError(file + ": field '" + key + "' is not a number: '" + *raw + "'", 1);
  return x;
}

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw CommandError(path + ": cannot read", 1);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void require_file(const fs::path& p, const std::string& what) {
  if (fs::is_regular_file(p)) return;
  std::string hint;
  if (fs::exists(fs::path(p.string() + ".partial"))) hint = " (only " + p.filename().string() + ".partial: the run did not finish)";
  else if (!fs::is_directory(p.parent_path())) hint = " (no such directory)";
  throw CommandError("compare: " + p.string() + ": missing " + what + hint, 1);
}

RunRow load_run(const std::string& dir, const eval::Trajectory& gt, const CompareArgs& a) {
  RunRow r;
  r.dir = dir;
  r.name = dir_name(dir);
  const fs::path odo = fs::path(dir) / "odometry.tum";
  const fs::path sum = fs::path(dir) / "summary.json";
  require_file(odo, "odometry (a `dynavins run` output directory holds odometry.tum)");
  require_file(sum, "summary.json");
  const std::string json = read_text(sum.string());
  r.ba_ms_mean = json_number(json, "ba_ms_mean", sum.string());
  r.ba_ms_p95 = json_number(json, "ba_ms_p95", sum.string());
  r.real_time = json_number(json, "real_time_factor", sum.string());
  r.resets = json_number(json, "resets", sum.string());
  r.tracking = json_number(json, "frames_tracking", sum.string());
  r.estimated = json_number(json, "frames_estimated", sum.string());
  r.ba = json_raw(json, "ba").value_or("?");
  // A run that failed or was interrupted is listed as such, never as a normal one.
  if (json_raw(json, "ok").value_or("true") == "false") r.name += " (FAILED)";
  else if (json_raw(json, "interrupted").value_or("false") == "true") r.name += " (interrupted)";
  r.cameras = json_raw(json, "cameras").value_or("?");

  eval::Trajectory est;
  try {
    est = eval::read_trajectory(odo.string());
  } catch (const std::exception& e) {
    throw CommandError(std::string("compare: ") + e.what(), 1);
  }
  r.poses = est.size();
  try {
    eval::EvalOptions o;
    o.align = eval::Alignment::SE3;
    o.max_dt = a.max_dt;
    o.rpe_delta = a.rpe_delta;
    r.result = eval::evaluate(gt, est, o);
    r.evaluated = true;
    for (const auto& p : eval::transformed(est, r.result.alignment).poses) r.aligned.push_back(p.p);
  } catch (const std::exception& e) {
    r.eval_error = e.what();
    spdlog::warn("compare: {}: not evaluated: {}", r.name, r.eval_error);
  }
  return r;
}

std::string cell(double x, const char* fmt, int width) {
  char buf[64];
  if (std::isfinite(x)) std::snprintf(buf, sizeof buf, fmt, x);
  else std::snprintf(buf, sizeof buf, "-");
  std::string s = buf;
  if (static_cast<int>(s.size()) < width) s.insert(0, static_cast<std::size_t>(width) - s.size(), ' ');
  return s;
}

void print_table(const std::vector<RunRow>& rows, const std::string& gt_path, std::size_t gt_poses, const CompareArgs& a) {
  std::size_t w = 4;
  for (const RunRow& r : rows) w = std::max(w, r.name.size());
  std::printf("ground truth %s (%zu poses); ATE after SE3 alignment, RPE over %zu frame(s)\n", gt_path.c_str(),
              gt_poses, a.rpe_delta);
  std::printf("%-*s %9s %6s %7s %11s %10s %11s %11s %10s %7s %8s %9s\n", static_cast<int>(w), "run", "ba", "cams", "poses",
              "ATE rmse[m]", "ATE max[m]", "RPE rmse[m]", "BA mean[ms]", "BA p95[ms]", "resets", "tracking", "RT factor");
  for (const RunRow& r : rows) {
    const double ate = r.evaluated ? r.result.ate.rmse : NAN, amax = r.evaluated ? r.result.ate.max : NAN;
    const double rpe = r.evaluated ? r.result.rpe.rmse : NAN;
    const double share = r.estimated > 0 ? 100.0 * r.tracking / r.estimated : NAN;
    std::printf("%-*s %9s %6s %7zu %s %s %s %s %s %s %s %s\n", static_cast<int>(w), r.name.c_str(), r.ba.c_str(),
                r.cameras.c_str(), r.poses, cell(ate, "%.4f", 11).c_str(), cell(amax, "%.4f", 10).c_str(),
                cell(rpe, "%.4f", 11).c_str(), cell(r.ba_ms_mean, "%.2f", 11).c_str(),
                cell(r.ba_ms_p95, "%.2f", 10).c_str(), cell(r.resets, "%.0f", 7).c_str(),
                cell(share, "%.1f %%", 8).c_str(), cell(r.real_time, "%.2fx", 9).c_str());
  }
  for (const RunRow& r : rows) {
    if (!r.evaluated) std::printf("%s: not evaluated: %s\n", r.name.c_str(), r.eval_error.c_str());
  }
  std::printf("tracking: share of estimated frames with a pose in odometry.tum; RT factor: data time / wall time\n");
}

std::string jnum(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

void print_json(const std::vector<RunRow>& rows, const std::string& gt_path) {
  std::printf("{\n  \"gt\": %s,\n  \"runs\": [\n", json_string(gt_path).c_str());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const RunRow& r = rows[i];
    std::printf("    {\"name\": %s, \"dir\": %s, \"ba\": %s, \"cameras\": %s, \"poses\": %zu, ", json_string(r.name).c_str(),
                json_string(r.dir).c_str(), json_string(r.ba).c_str(), json_string(r.cameras).c_str(), r.poses);
    if (r.evaluated) {
      std::printf("\"pairs\": %zu, \"ate_rmse_m\": %s, \"ate_max_m\": %s, \"rpe_rmse_m\": %s, ", r.result.association.size(),
                  jnum(r.result.ate.rmse).c_str(), jnum(r.result.ate.max).c_str(), jnum(r.result.rpe.rmse).c_str());
    } else {
      std::printf("\"eval_error\": %s, ", json_string(r.eval_error).c_str());
    }
    std::printf("\"ba_ms_mean\": %s, \"ba_ms_p95\": %s, \"real_time_factor\": %s, \"resets\": %s, "
                "\"frames_tracking\": %s, \"frames_estimated\": %s}%s\n",
                jnum(r.ba_ms_mean).c_str(), jnum(r.ba_ms_p95).c_str(), jnum(r.real_time).c_str(), jnum(r.resets).c_str(),
                jnum(r.tracking).c_str(), jnum(r.estimated).c_str(), i + 1 < rows.size() ? "," : "");
  }
  std::printf("  ]\n}\n");
}

void write_plot(const CompareArgs& a, const eval::Trajectory& gt, const std::vector<RunRow>& rows) {
  std::vector<Eigen::Vector3d> g;
  for (const auto& p : gt.poses) g.push_back(p.p);
  std::vector<eval::NamedPath> paths;
  std::string title = "top view, SE3-aligned:";
  for (const RunRow& r : rows) {
    if (!r.evaluated) continue;
    char label[200];
    std::snprintf(label, sizeof label, "%s  ATE %.3f m", r.name.c_str(), r.result.ate.rmse);
    paths.push_back({label, r.aligned});
    title += " " + r.name;
    if (&r != &rows.back()) title += " |";
  }
  eval::ComparisonPlotOptions o;
  o.title = title;
  o.gt_label = a.gt.empty() ? "ground truth (" + rows.front().name + "/groundtruth.tum)"
                            : "ground truth: " + fs::path(a.gt).filename().string();
  try {
    eval::write_comparison_plot(a.plot, g, paths, o);
  } catch (const std::exception& e) {
    throw CommandError(std::string("compare: ") + e.what(), 1);
  }
  spdlog::info("wrote plot {}", a.plot);
}

void run_compare(const CompareArgs& a) {
  if (!a.plot.empty()) {
    std::string ext = fs::path(a.plot).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png") throw CommandError("compare: --plot " + a.plot + ": the file name must end in .png", 2);
  }
  const std::string gt_path = a.gt.empty() ? (fs::path(a.runs.front()) / "groundtruth.tum").string() : a.gt;
  if (a.gt.empty()) require_file(gt_path, "ground truth (pass --gt FILE when the first run has none)");
  eval::Trajectory gt;
  try {
    gt = eval::read_trajectory(gt_path);
  } catch (const std::exception& e) {
    throw CommandError(std::string("compare: ") + e.what(), 1);
  }
  std::vector<RunRow> rows;
  for (const std::string& dir : a.runs) rows.push_back(load_run(dir, gt, a));
  if (a.json) print_json(rows, gt_path);
  else print_table(rows, gt_path, gt.size(), a);
  if (!a.plot.empty()) write_plot(a, gt, rows);
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* sub = app.add_subcommand(
      "compare", "Runs of `dynavins run` side by side: ATE / RPE, BA time, real-time factor, resets; one plot");
  sub->add_option("runs", args->runs, "run output directories (odometry.tum + summary.json)")->required();
  sub->add_option("--gt", args->gt, "ground truth (TUM or EuRoC csv); default: groundtruth.tum of the first run");
  sub->add_option("--plot", args->plot, "write a top view of all aligned trajectories to this PNG");
  sub->add_flag("--json", args->json, "print JSON instead of the table");
  sub->add_option("--max-dt", args->max_dt, "max time difference for associating poses [s]")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--rpe-delta", args->rpe_delta, "RPE step in associated frames")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  sub->callback([args] { run_compare(*args); });
}

}  // namespace dynavins::cli
