// `dynavins eval`: ATE / RPE of an estimated trajectory against ground truth, evo-compatible,
// with an optional top-down plot and JSON dump of the metrics.
#include "bin/commands.hpp"
#include "eval/evaluation.hpp"
#include "eval/trajectory_io.hpp"
#include "eval/trajectory_plot.hpp"
#include "pipeline/report_format.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

namespace dynavins::cli {

namespace {

using pipeline::json_string;

struct EvalArgs {
  std::string gt;
  std::string est;
  std::string align = "se3";
  double max_dt = 0.01;
  std::size_t rpe_delta = 1;
  std::string plot;
  std::string json;
};

void json_stats(std::FILE* f, const char* name, const eval::ErrorStats& s, const char* tail) {
  std::fprintf(f,
               "  \"%s\": {\"count\": %zu, \"rmse\": %.9g, \"mean\": %.9g, \"median\": %.9g, \"std\": %.9g, "
               "\"min\": %.9g, \"max\": %.9g, \"sse\": %.9g}%s\n",
               name, s.count, s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse, tail);
}

void write_json(const EvalArgs& a, eval::Alignment align, const eval::EvalResult& r) {
  std::FILE* f = std::fopen(a.json.c_str(), "w");
  if (f == nullptr) throw CommandError(a.json + ": cannot write: " + std::strerror(errno));
  const eval::Similarity3& T = r.alignment;
  std::fprintf(f, "{\n  \"gt\": %s,\n  \"est\": %s,\n", json_string(a.gt).c_str(), json_string(a.est).c_str());
  std::fprintf(f, "  \"gt_poses\": %zu,\n  \"est_poses\": %zu,\n  \"pairs\": %zu,\n  \"max_dt\": %.9g,\n", r.gt_poses,
               r.est_poses, r.association.size(), a.max_dt);
  std::fprintf(f, "  \"align\": \"%s\",\n  \"scale\": %.10g,\n", eval::alignment_name(align), T.s);
  std::fprintf(f, "  \"rotation\": [[%.12g, %.12g, %.12g], [%.12g, %.12g, %.12g], [%.12g, %.12g, %.12g]],\n",
               T.R(0, 0), T.R(0, 1), T.R(0, 2), T.R(1, 0), T.R(1, 1), T.R(1, 2), T.R(2, 0), T.R(2, 1), T.R(2, 2));
  std::fprintf(f, "  \"translation\": [%.12g, %.12g, %.12g],\n", T.t.x(), T.t.y(), T.t.z());
  json_stats(f, "ate", r.ate, ",");
  std::fprintf(f, "  \"rpe_delta_frames\": %zu,\n", a.rpe_delta);
  json_stats(f, "rpe", r.rpe, "");
  std::fprintf(f, "}\n");
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw CommandError(a.json + ": write failed");
}

void print_table(const EvalArgs& a, eval::Alignment align, const eval::EvalResult& r) {
  std::printf("ground truth   %s (%zu poses)\n", a.gt.c_str(), r.gt_poses);
  std::printf("estimate       %s (%zu poses)\n", a.est.c_str(), r.est_poses);
  std::printf("pairs matched  %zu (max dt %g s)\n", r.association.size(), a.max_dt);
  if (align == eval::Alignment::Sim3) {
    std::printf("alignment      sim3, scale %.7f\n", r.alignment.s);
  } else {
    std::printf("alignment      %s\n", eval::alignment_name(align));
  }
  std::printf("%-14s %10s %10s %10s %10s %10s %10s\n", "error [m]", "rmse", "mean", "median", "std", "min", "max");
  const auto row = [](const std::string& name, const eval::ErrorStats& s) {
    std::printf("%-14s %10.6f %10.6f %10.6f %10.6f %10.6f %10.6f\n", name.c_str(), s.rmse, s.mean, s.median, s.std,
                s.min, s.max);
  };
  row("ATE", r.ate);
  row("RPE (d=" + std::to_string(a.rpe_delta) + ")", r.rpe);
}

void write_plot(const EvalArgs& a, eval::Alignment align, const eval::Trajectory& gt, const eval::Trajectory& est,
                const eval::EvalResult& r) {
  // Whole paths, the estimate moved into the ground-truth frame by the fitted alignment.
  const eval::Trajectory est_aligned = eval::transformed(est, r.alignment);
  std::vector<Eigen::Vector3d> g, e;
  for (const auto& p : gt.poses) g.push_back(p.p);
  for (const auto& p : est_aligned.poses) e.push_back(p.p);
  eval::PlotOptions o;
  char title[160];
  std::snprintf(title, sizeof title, "ATE (%s) RMSE %.4f m, max %.4f m | RPE RMSE %.4f m | %zu pairs",
                eval::alignment_name(align), r.ate.rmse, r.ate.max, r.rpe.rmse, r.association.size());
  o.title = title;
  o.gt_label = "ground truth: " + std::filesystem::path(a.gt).filename().string();
  o.est_label = "estimate: " + std::filesystem::path(a.est).filename().string();
  eval::write_topdown_plot(a.plot, g, e, o);
  spdlog::info("wrote plot {}", a.plot);
}

void run_eval(const EvalArgs& a) {
  // Catch a wrong plot name before the work, not after printing the results.
  std::string ext = std::filesystem::path(a.plot).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!a.plot.empty() && ext != ".png") {
    throw CommandError("eval: --plot " + a.plot + ": the file name must end in .png", 2);
  }
  try {
    const eval::Alignment align = eval::parse_alignment(a.align);
    const eval::Trajectory gt = eval::read_trajectory(a.gt);
    const eval::Trajectory est = eval::read_trajectory(a.est);
    eval::EvalOptions opt;
    opt.align = align;
    opt.max_dt = a.max_dt;
    opt.rpe_delta = a.rpe_delta;
    const eval::EvalResult r = eval::evaluate(gt, est, opt);
    print_table(a, align, r);
    if (!a.json.empty()) write_json(a, align, r);
    if (!a.plot.empty()) write_plot(a, align, gt, est, r);
  } catch (const CommandError&) {
    throw;
  } catch (const std::exception& e) {
    throw CommandError(std::string("eval: ") + e.what(), 1);
  }
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* sub = app.add_subcommand(
      "eval", "ATE / RPE of an estimated trajectory against ground truth (TUM or EuRoC csv, .gz ok), as evo");
  sub->add_option("--gt", args->gt, "ground-truth trajectory file")->required();
  sub->add_option("--est", args->est, "estimated trajectory file")->required();
  sub->add_option("--align", args->align, "alignment of the estimate: se3, sim3 or none (Umeyama)")
      ->check(CLI::IsMember({"se3", "sim3", "none"}, CLI::ignore_case))
      ->capture_default_str();
  sub->add_option("--max-dt", args->max_dt, "max time difference for associating poses [s]")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--rpe-delta", args->rpe_delta, "RPE step in associated frames")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  sub->add_option("--plot", args->plot, "write a top-down x-y plot to this PNG file");
  sub->add_option("--json", args->json, "write the metrics to this JSON file");
  sub->callback([args] { run_eval(*args); });
}

}  // namespace dynavins::cli
