// Public API: `umbmark import` as calls.
//   api::ImportRosbag2(api::ImportRosbag2Options) -> api::ImportRosbag2Result
//   (a ROS 2 recording into a campaign folder; ground truth from one source
//   of ground_truth/source.hpp, which a program may add to with
//   io::rosbag2::RegisterGroundTruthSource);
//   api::ImportOptiOdom(api::ImportOptiOdomOptions) -> api::ImportOptiOdomResult;
//   io::rosbag2::ListRosbag2 (the topics, --list); api::ToJson of each.
#pragma once

#include "api/import.hpp"
#include "ground_truth/source.hpp"
#include "import/rosbag2_import.hpp"
#include "umbmark/io.hpp"
