#pragma once
// CScalingGridMapAligner parameters for a ROS node: first the defaults, then
// an MRPT ini file if ~config_file names one (section ~config_section,
// default "aligner"), then every private parameter named like an ini key.
// The fleet's parameters likewise, from section [fleet].

#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>

#include <ros/node_handle.h>

namespace multires_map_merge::ros1
{
/** Throws std::invalid_argument naming the parameter or file at fault: a
 * missing config file, a value of the wrong type, an out-of-range value.
 * Private parameters that are neither aligner nor fleet keys are listed in a warning, so
 * a misspelt key does not pass silently. `node_keys` are the node's own. */
CScalingGridMapAligner::TConfigParams alignerParamsFromRos(
	const ros::NodeHandle& private_nh, const std::vector<std::string>& node_keys = {});

/** FleetParams: the defaults, then section [fleet] of ~config_file, then
 * every private parameter named like a fleet key (fleetParamFields()).
 * Throws std::invalid_argument naming the file or parameter at fault. */
FleetParams fleetParamsFromRos(const ros::NodeHandle& private_nh);

}  // namespace multires_map_merge::ros1
