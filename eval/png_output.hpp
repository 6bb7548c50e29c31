#pragma once
// Writing a picture so that a failed or interrupted write never leaves a file that looks complete.

#include <opencv2/core.hpp>

#include <string>

namespace dynavins::eval {

/// Encodes `img` as PNG (compression `level`, 0-9) into `png_path` + ".partial" and renames it to
/// `png_path` when complete. Throws std::runtime_error naming the path when the name does not end
/// in .png (any case), the image is empty, or encoding / writing / renaming fails.
void write_png_atomically(const std::string& png_path, const cv::Mat& img, int level = 9);

}  // namespace dynavins::eval
