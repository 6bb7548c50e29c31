#pragma once
// LCM channel names used in logs and live (one place, so logs, lcm-spy and subscribers agree).

namespace dynavins::pipeline::channels {

// Inputs (recorded sensor logs, live sensors)
inline constexpr const char* kStereo = "CAM_STEREO";           // stereo_image_t
inline constexpr const char* kImu = "IMU";                     // imu_t
inline constexpr const char* kGroundTruth = "GROUND_TRUTH";    // ground_truth_t
inline constexpr const char* kSimLabels = "SIM_LABELS";        // image_t: per-pixel moving-object labels (simulated data)
// Outputs
inline constexpr const char* kPoseImuRate = "DYNAVINS_POSE_IMU";  // pose_t, IMU rate
inline constexpr const char* kPose = "DYNAVINS_POSE";             // pose_t, window
inline constexpr const char* kPoseCorrected = "DYNAVINS_POSE_CORRECTED";  // pose_t, window pose after loop closure
inline constexpr const char* kFeatures = "DYNAVINS_FEATURES";     // weighted_feature_set_t
inline constexpr const char* kLoops = "DYNAVINS_LOOPS";           // loop_hypotheses_t
inline constexpr const char* kPath = "DYNAVINS_PATH";             // path_t
inline constexpr const char* kStats = "DYNAVINS_STATS";           // pipeline_stats_t, once a second
inline constexpr const char* kStatus = "DYNAVINS_STATUS";         // status_t, on change and once a second

}  // namespace dynavins::pipeline::channels
