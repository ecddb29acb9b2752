// Public facade: reading and writing the contract's files (docs/formats.md).
//   io::ReadManifest, io::ReadRunFile (endpoint or trajectory CSV),
//   io::ReadEndpointCsv, io::ReadTrajectoryCsv, io::ReadRobotToml,
//   io::WriteCampaign, io::FormatTrajectoryCsv, io::FormatEndpointCsv,
//   io::FormatManifest, io::WriteFileAtomically.
// Errors are umbmark::InputError (file, line, column).
#pragma once

#include "core/errors.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "io/atomic_write.hpp"
#include "io/campaign_writer.hpp"
#include "io/data_file.hpp"
#include "io/endpoint_csv.hpp"
#include "io/manifest.hpp"
#include "io/robot_toml.hpp"
#include "io/trajectory_csv.hpp"
#include "umbmark/version.hpp"
