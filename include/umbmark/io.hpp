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
#include "output/atomic_write.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/data_file.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_toml.hpp"
#include "formats/trajectory_csv.hpp"
#include "umbmark/version.hpp"
