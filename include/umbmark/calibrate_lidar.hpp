// Public API: `umbmark calibrate-lidar` as one call.
//   api::CalibrateLidar(api::CalibrateLidarOptions) ->
//   api::CalibrateLidarResult; api::ToJson(result) is the command's --json
//   document; api::CalibrateLidarRos2 / api::WriteCalibrateLidarRos2 its
//   --ros2 file.
#pragma once

#include "api/calibrate_lidar.hpp"
#include "api/robot_source.hpp"
#include "umbmark/io.hpp"
