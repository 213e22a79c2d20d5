#pragma once
// A robot's scans with their corrected poses, read from a log (an MRPT
// simplemap, a CARMEN log), and rendered into an occupancy grid at any
// resolution: what .simplemap inputs are read as, and what the ground-truth
// pairs and the benchmarks are made of.

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose2D.h>

#include <string>
#include <vector>

namespace multires_map_merge
{
/** One laser scan and the corrected robot pose it was taken from. */
struct PosedScan
{
	mrpt::poses::CPose2D robot_pose;
	mrpt::obs::CObservation2DRangeScan::Ptr scan;
};
using ScanSequence = std::vector<PosedScan>;

/** Keyframes of an MRPT simplemap (.simplemap or .simplemap.gz). */
ScanSequence loadSimplemapScans(const std::string& path);

/** FLASER scans of a CARMEN log (.log or .log.gz) whose laser poses are
 * SLAM-corrected (GMapping output logs). */
ScanSequence loadCarmenScans(const std::string& path);

/** By extension: simplemap or CARMEN log. Throws std::runtime_error naming the
 * file when it cannot be read or holds no scans. */
ScanSequence loadScans(const std::string& path);

/** Renders scans [begin, end) at the given resolution with every pose
 * expressed in `frame` (the pose of the map's frame in the run's frame). */
mrpt::maps::COccupancyGridMap2D renderGrid(
	const ScanSequence& scans, size_t begin, size_t end, double resolution,
	const mrpt::poses::CPose2D& frame = {}, float max_range = 15.0f,
	float free_update_certainty = 0.0f);

}  // namespace multires_map_merge
