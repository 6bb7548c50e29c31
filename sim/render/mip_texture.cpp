#include "sim/render/mip_texture.hpp"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace dynavins::sim {

MipTexture::MipTexture(const cv::Mat& level0) {
  if (level0.empty() || level0.type() != CV_8UC1) {
    throw std::invalid_argument("MipTexture: level 0 must be a non-empty CV_8UC1 image");
  }
  cv::Mat cur = level0;
  while (true) {
    cv::Mat padded;
    cv::copyMakeBorder(cur, padded, 1, 1, 1, 1, cv::BORDER_REPLICATE);
    mats_.push_back(padded);
    if (cur.cols == 1 && cur.rows == 1) break;
    cv::Mat down;
    // Area averaging is the box prefilter the mip chain assumes; deterministic at any thread count.
    cv::resize(cur, down, cv::Size((cur.cols + 1) / 2, (cur.rows + 1) / 2), 0.0, 0.0, cv::INTER_AREA);
    cur = down;
  }
  for (const cv::Mat& m : mats_) {
    const int w = m.cols - 2, h = m.rows - 2;
    levels_.push_back(Level{m.ptr<uint8_t>(1) + 1, w, h, m.step[0], static_cast<float>(w), static_cast<float>(h)});
  }
  max_lod_ = static_cast<float>(levels_.size() - 1);
}

cv::Mat MipTexture::level_mat(int k) const {
  const cv::Mat& m = mats_.at(static_cast<size_t>(k));
  return m(cv::Rect(1, 1, m.cols - 2, m.rows - 2));
}

size_t MipTexture::bytes() const {
  size_t b = 0;
  for (const cv::Mat& m : mats_) b += m.total() * m.elemSize();
  return b;
}

}  // namespace dynavins::sim
