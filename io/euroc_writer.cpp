#include "io/euroc_writer.hpp"

#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "io/input_error.hpp"

namespace dynavins::io {
namespace fs = std::filesystem;
namespace {

void write_png(const cv::Mat& img, const fs::path& path) {
  if (!cv::imwrite(path.string(), img)) throw InputError(path.string(), 0, "cannot write the image");
}

}  // namespace

EurocWriter::EurocWriter(const std::string& dir) {
  const fs::path root = fs::path(dir) / "mav0";
  if (fs::exists(root / "cam0" / "data.csv")) throw InputError(root.string(), 0, "already holds an EuRoC data set");
  for (const char* sub : {"cam0/data", "cam0/labels", "cam1/data", "imu0", "state_groundtruth_estimate0"})
    fs::create_directories(root / sub);
  mav0_ = root.string();
  cam0_.open(root / "cam0/data.csv");
  cam1_.open(root / "cam1/data.csv");
  imu_.open(root / "imu0/data.csv");
  gt_.open(root / "state_groundtruth_estimate0/data.csv");
  if (!cam0_ || !cam1_ || !imu_ || !gt_) throw InputError(mav0_, 0, "cannot create the CSV files");
  cam0_ << "#timestamp [ns],filename\n";
  cam1_ << "#timestamp [ns],filename\n";
  imu_ << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
          "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  gt_ << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
         "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
         "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  imu_.precision(17);
  gt_.precision(17);
}

void EurocWriter::write(const SensorEvent& event) {
  const fs::path root(mav0_);
  if (const auto* f = std::get_if<StereoFrame>(&event)) {
    const std::string name = std::to_string(f->t_ns) + ".png";
    write_png(f->left, root / "cam0/data" / name);
    cam0_ << f->t_ns << "," << name << "\n";
    if (!f->right.empty()) {
      write_png(f->right, root / "cam1/data" / name);
      cam1_ << f->t_ns << "," << name << "\n";
    }
    if (!f->labels.empty()) write_png(f->labels, root / "cam0/labels" / name);
  } else if (const auto* s = std::get_if<ImuSample>(&event)) {
    imu_ << s->t_ns << "," << s->gyr.x() << "," << s->gyr.y() << "," << s->gyr.z() << "," << s->acc.x() << ","
         << s->acc.y() << "," << s->acc.z() << "\n";
  } else {
    const auto& g = std::get<GroundTruthState>(event);
    gt_ << g.t_ns << "," << g.p_wb.x() << "," << g.p_wb.y() << "," << g.p_wb.z() << "," << g.q_wb.w() << ","
        << g.q_wb.x() << "," << g.q_wb.y() << "," << g.q_wb.z() << "," << g.v_wb.x() << "," << g.v_wb.y() << ","
        << g.v_wb.z() << "," << g.bias_gyr.x() << "," << g.bias_gyr.y() << "," << g.bias_gyr.z() << ","
        << g.bias_acc.x() << "," << g.bias_acc.y() << "," << g.bias_acc.z() << "\n";
  }
}

void EurocWriter::close() {
  for (auto* f : {&cam0_, &cam1_, &imu_, &gt_}) {
    f->flush();
    if (!*f) throw InputError(mav0_, 0, "writing the CSV files failed");
    f->close();
  }
}

}  // namespace dynavins::io
