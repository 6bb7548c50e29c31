#include "pipeline/sensor_log.hpp"

#include <spdlog/spdlog.h>

#include "io/input_error.hpp"
#include "pipeline/lcm_channels.hpp"

namespace dynavins::pipeline {

void write_sensor_event(LcmLogWriter& log, const SensorEvent& event, ImageEncoding encoding) {
  if (const auto* f = std::get_if<StereoFrame>(&event)) {
    const int64_t utime = ns_to_utime(f->t_ns);
    if (!f->labels.empty())  // lossless, so always PNG
      log.write(channels::kSimLabels, utime, image_to_lcm(f->labels, f->t_ns, ImageEncoding::Png));
    log.write(channels::kStereo, utime, to_lcm(*f, encoding));
  } else if (const auto* s = std::get_if<ImuSample>(&event)) {
    log.write(channels::kImu, ns_to_utime(s->t_ns), to_lcm(*s));
  } else {
    const auto& gt = std::get<GroundTruthState>(event);
    log.write(channels::kGroundTruth, ns_to_utime(gt.t_ns), to_lcm(gt));
  }
}

LcmLogSource::LcmLogSource(const std::string& path, int64_t reorder_window_ns)
    : reader_(path), reorder_window_ns_(reorder_window_ns) {}

bool LcmLogSource::read_one() {
  LogRecord r;
  while (reader_.next(r)) {
    // decode() names the log event itself; conversion errors (bad images, quaternions) get it here.
    auto convert = [&](auto&& msg) {
      try {
        return from_lcm(msg);
      } catch (const std::exception& e) {
        throw io::InputError(reader_.path(), 0, LcmLogReader::event_name(r) + ": " + e.what());
      }
    };
    SensorEvent event;
    if (r.channel == channels::kStereo) {
      StereoFrame f = convert(reader_.decode<dynavins_lcm::stereo_image_t>(r));
      if (auto it = labels_.find(f.t_ns); it != labels_.end()) {
        f.labels = std::move(it->second);
        labels_.erase(labels_.begin(), std::next(it));
      }
      event = std::move(f);
    } else if (r.channel == channels::kImu) {
      event = convert(reader_.decode<dynavins_lcm::imu_t>(r));
    } else if (r.channel == channels::kGroundTruth) {
      event = convert(reader_.decode<dynavins_lcm::ground_truth_t>(r));
    } else if (r.channel == channels::kSimLabels) {
      const auto msg = reader_.decode<dynavins_lcm::image_t>(r);
      try {
        labels_[utime_to_ns(msg.utime)] = image_from_lcm(msg);
      } catch (const std::exception& e) {
        throw io::InputError(reader_.path(), 0, LcmLogReader::event_name(r) + ": " + e.what());
      }
      continue;
    } else {
      ++skipped_[r.channel];
      continue;
    }
    const int64_t t = event_time_ns(event);
    auto [last, fresh] = last_time_.emplace(r.channel, t);
    if (!fresh) {
      if (t <= last->second)
        throw io::InputError(reader_.path(), 0,
                             LcmLogReader::event_name(r) + ": timestamp " + std::to_string(t) +
                                 (t == last->second ? " repeats" : " goes back in time") + " on its channel");
      last->second = t;
    }
    if (t < newest_ns_ - reorder_window_ns_)
      throw io::InputError(reader_.path(), 0,
                           LcmLogReader::event_name(r) + ": arrives " +
                               std::to_string((newest_ns_ - t) / 1'000'000) +
                               " ms after newer data on other channels (more than the reorder window)");
    newest_ns_ = std::max(newest_ns_, t);
    pending_.push({t, order_++, std::make_shared<SensorEvent>(std::move(event))});
    return true;
  }
  return false;
}

bool LcmLogSource::next(SensorEvent& out) {
  // Keep reading until the oldest pending event can no longer be overtaken.
  while (!eof_ && (pending_.empty() || pending_.top().t_ns >= newest_ns_ - reorder_window_ns_)) {
    if (!read_one()) eof_ = true;
  }
  if (pending_.empty()) {
    if (!skips_reported_)
      for (const auto& [channel, n] : skipped_)
        spdlog::info("{}: skipped {} events on channel {} (not sensor data)", reader_.path(), n, channel);
    skips_reported_ = true;
    return false;
  }
  out = std::move(*pending_.top().event);
  pending_.pop();
  return true;
}

double LcmLogSource::progress() const {
  return reader_.file_size() > 0 ? static_cast<double>(reader_.position()) / static_cast<double>(reader_.file_size())
                                 : 1.0;
}

std::string LcmLogSource::describe() const { return reader_.path() + " (LCM log)"; }

}  // namespace dynavins::pipeline
