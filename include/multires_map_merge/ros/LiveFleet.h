#pragma once
// The live multi-robot merge without the ROS plumbing (no master needed):
// robots' maps and map updates in, re-estimated placements and one merged
// map out. The map_merge node discovers robots and calls this; tests call it
// directly.
//
// Stability (m-explore's maps flicker between robots): a robot keeps its last
// good placement until a new one is confirmed. A new estimate that agrees
// with the kept one (the maps grew) refines it at once; one that disagrees
// must come out the same in two estimations in a row; a failed estimate
// changes nothing. The world is the map frame of the first robot that
// delivered a map, until a second robot is placed in it: if that robot
// overlaps no one while others overlap each other, the world moves to the
// largest such group (with known initial poses: the frame the poses are in).
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
struct LiveFleetParams
{
	CScalingGridMapAligner::TConfigParams aligner;
	/** Merged map cell size in metres; 0 = the world robot's. */
	double output_resolution = 0;
	/** Placements from the given initial poses only (m-explore's known_init_poses). */
	bool known_init_poses = false;
	/** A new estimate within this many coarse cells (RMS over the map's
	 * corners) of the kept placement agrees with it. */
	double agreement_cells = 3.0;
	size_t max_merged_cells = size_t(1) << 26;
};

class LiveFleet
{
   public:
	/** Throws std::invalid_argument on parameters that cannot work. */
	explicit LiveFleet(const LiveFleetParams& params);

	/** A discovered robot. With known_init_poses, `init_pose` (rigid: the
	 * robot's map frame in the world) is required for it to be placed. */
	void addRobot(const std::string& name, const std::optional<Similarity2D>& init_pose = {});
	bool hasRobot(const std::string& name) const;

	/** A full map of a robot. Returns "" when taken, else why it was ignored
	 * (the robot's previous map is kept). Never throws. */
	std::string onMap(const std::string& robot, const nav_msgs::OccupancyGrid& msg);
	/** An update of the robot's last full map. Returns "" or why ignored. */
	std::string onUpdate(const std::string& robot, const map_msgs::OccupancyGridUpdate& msg);

	/** Re-estimates the placements from the current maps (the slow part:
	 * call it from one thread; maps may arrive meanwhile). */
	void estimate();

	/** The merged map of every placed robot in the world frame, or nothing
	 * before the first map (or when only errors remain; `why` says). */
	std::optional<nav_msgs::OccupancyGrid> merged(const std::string& world_frame, std::string* why = nullptr);

	struct RobotStatus
	{
		std::string name, frame_id;  //!< frame_id: its map's header.frame_id
		bool has_map = false, placed = false;
		Similarity2D in_world;  //!< its map frame → the world (scale when metadata lies)
		double confidence = 0;
		std::string message;
	};
	/** Every robot, in the order they were added. */
	std::vector<RobotStatus> status() const;
	/** The robot whose map frame is the world ("" before any map). */
	std::string worldRobot() const;
	/** Estimations run so far. */
	size_t estimations() const;

   private:
	struct Robot
	{
		std::string name;
		std::optional<Similarity2D> init_pose;
		std::optional<nav_msgs::OccupancyGrid> map;  //!< last full map with its updates applied
		bool placed = false;
		Similarity2D in_world;
		double confidence = 0;
		std::optional<Similarity2D> pending;  //!< a disagreeing estimate awaiting confirmation
		std::string message;
	};
	Robot* find(const std::string& name);
	const Robot* find(const std::string& name) const;
	bool agree(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b) const;
	/** A robot besides the world's is placed: the world may no longer move. */
	bool worldCommitted() const;

	LiveFleetParams params_;
	mutable std::mutex mutex_;
	std::vector<Robot> robots_;
	/** Bumped by every change of a map or a placement: merged() fuses again
	 * only then (the node asks at merging_rate, maps change less often). */
	size_t version_ = 0, merged_version_ = size_t(-1);
	std::optional<nav_msgs::OccupancyGrid> merged_cache_;
	std::string merged_why_, merged_frame_;
	std::string world_robot_;
	size_t estimations_ = 0;
};

}  // namespace multires_map_merge::ros1
