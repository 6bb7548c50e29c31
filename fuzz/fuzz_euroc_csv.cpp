// libFuzzer harness: the EuRoC ASL folder reader (io/euroc_dataset, io/csv_table): the CSV parser,
// number parsing, timestamp checks, stereo pairing, image loading. Input: up to four files separated
// by a line "===": cam0/data.csv, cam1/data.csv, imu0/data.csv, state_groundtruth_estimate0/data.csv
// (a part left out means that file or folder is absent: no cam1 is a mono folder). The images the
// rows may name are made once: cam{0,1}/data/{0,1,2,3}.png (8x6 gray), and bad.png (not an image).
// Contract: the folder is read (every frame loaded) or std::runtime_error (io::InputError) is thrown.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fuzz/fuzz_input_file.hpp"
#include "io/euroc_dataset.hpp"

namespace {
namespace fs = std::filesystem;

const char* const kFiles[] = {"cam0/data.csv", "cam1/data.csv", "imu0/data.csv", "state_groundtruth_estimate0/data.csv"};

/// The folder with its images, made on the first call; the CSV files are removed each time.
fs::path fresh_mav0() {
  static const fs::path mav0 = [] {
    const fs::path m = fs::path(dynavins::fuzz::fuzz_scratch_dir()) / "euroc" / "mav0";
    for (const char* cam : {"cam0", "cam1"}) {
      fs::create_directories(m / cam / "data");
      for (int i = 0; i < 4; ++i) {
        cv::Mat img(6, 8, CV_8UC1, cv::Scalar(40 * i));
        cv::imwrite((m / cam / "data" / (std::to_string(i) + ".png")).string(), img);
      }
      const uint8_t junk[] = {'n', 'o', 't', ' ', 'p', 'n', 'g'};
      dynavins::fuzz::write_fuzz_file(std::string("euroc/mav0/") + cam + "/data/bad.png", junk, sizeof(junk));
    }
    return m;
  }();
  for (const char* f : kFiles) fs::remove(mav0 / f);
  fs::remove_all(mav0 / "state_groundtruth_estimate0");
  fs::remove_all(mav0 / "imu0");
  return mav0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const fs::path mav0 = fresh_mav0();
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string sep = "\n===\n";
  std::size_t begin = 0;
  for (std::size_t part = 0; part < 4 && begin <= text.size(); ++part) {
    std::size_t end = text.find(sep, begin);
    if (end == std::string::npos) end = text.size();
    const std::string body = text.substr(begin, end - begin);
    dynavins::fuzz::write_fuzz_file("euroc/mav0/" + std::string(kFiles[part]),
                                    reinterpret_cast<const uint8_t*>(body.data()), body.size());
    begin = end + sep.size();
  }
  try {
    // Without cam1/data.csv the folder still has cam1/: that is a stereo folder missing its list.
    const dynavins::io::EurocDataset dataset(mav0.parent_path().string());
    for (std::size_t i = 0; i < dataset.frames().size(); ++i) (void)dataset.load(i);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
