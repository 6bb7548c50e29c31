#include "eval/png_output.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace dynavins::eval {

void write_png_atomically(const std::string& png_path, const cv::Mat& img, int level) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(png_path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".png") throw std::runtime_error(png_path + ": the file name must end in .png");
  if (img.empty()) throw std::runtime_error(png_path + ": nothing to write (empty image)");
  std::vector<unsigned char> bytes;
  try {
    if (!cv::imencode(".png", img, bytes, {cv::IMWRITE_PNG_COMPRESSION, std::clamp(level, 0, 9)}))
      throw std::runtime_error(png_path + ": PNG encoding failed");
  } catch (const cv::Exception& e) {
    throw std::runtime_error(png_path + ": PNG encoding failed: " + e.err);
  }
  const std::string partial = png_path + ".partial";
  {
    std::ofstream f(partial, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error(partial + ": cannot write: " + std::strerror(errno));
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) {
      f.close();
      std::error_code ignored;
      fs::remove(partial, ignored);
      throw std::runtime_error(partial + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(partial, png_path, ec);
  if (ec) throw std::runtime_error(png_path + ": cannot rename from .partial: " + ec.message());
}

}  // namespace dynavins::eval
