#pragma once
// A recorded multi-robot session, rendered from real laser logs: each robot
// maps its share of a run at its own resolution in its own frame, its map
// growing step by step, published as full nav_msgs/OccupancyGrid maps and as
// map_msgs/OccupancyGridUpdate regions in between (as SLAM nodes do). What
// the fleet demo plays and the map_merge rostest replays.
#include <multires_map_merge/GroundTruthPair.h>

#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
struct FleetBagRobot
{
	std::string name;  //!< namespace: topics <name>/map, <name>/map_updates; frame <name>/map
	std::string log;  //!< a laser log loadScans() reads
	double begin = 0, end = 1;  //!< its share of the run
	double resolution = 0.05;
	mrpt::poses::CPose2D frame;  //!< its map frame in the run's frame (the truth)
	int join_step = 0;  //!< the step its first map comes
};

/** Writes `steps` steps `period_s` apart: at a robot's first step and at
 * every even step its full map (the extent of its whole share, so updates fit),
 * at odd steps an update of the region that changed. Origins are off the cell
 * lattice. Throws std::runtime_error naming the bag or the log on failure. */
void writeFleetBag(const std::string& bag_path, const std::vector<FleetBagRobot>& robots, int steps, double period_s);

}  // namespace multires_map_merge::ros1
