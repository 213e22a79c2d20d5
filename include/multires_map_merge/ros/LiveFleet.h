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

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
struct LiveFleetParams
{
	CScalingGridMapAligner::TConfigParams aligner;
	/** How each estimation places the robots' maps (FleetMerge.h). */
	FleetParams placement;
	/** Merged map cell size in metres; 0 = the world robot's. */
	double output_resolution = 0;
	/** Placements from the given initial poses only (m-explore's known_init_poses). */
	bool known_init_poses = false;
	/** A new estimate within this many coarse cells (RMS over the map's
	 * corners) of the kept placement agrees with it. */
	double agreement_cells = 3.0;
	size_t max_merged_cells = size_t(1) << 26;
	/** An estimation aligns again only what changed: a map is prepared again
	 * when it changed; a pair when a map of it changed, from its last
	 * transform first if it was merged (tracking: one refinement instead of
	 * a search). A refused pair is tried again once one of its maps has this
	 * much more known cells than at the refusal... */
	double retry_growth = 0.1;
	/** ...or this many estimations after it, if a map of it changed at all.
	 * A tracked pair is searched afresh as often (and while a move of its
	 * robot awaits confirmation), so that a wrong placement cannot confirm
	 * itself. */
	size_t retry_estimations = 5;
	/** No pair alignment starts after this many seconds of an estimation
	 * (0: no limit); the pairs left wait for the next one, their earlier
	 * results standing in. Keeps an estimation near its period. */
	double estimation_budget_s = 0;
};

/** The estimation budget the node sets at an estimation rate (Hz): half the
 * period, so that with the pairs already started an estimation stays near
 * its period. */
inline double defaultEstimationBudget(double estimation_rate_hz)
{
	return estimation_rate_hz > 0 ? 0.5 / estimation_rate_hz : 0.0;
}

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
		/** The scale departs from 1 by more than the placement can tell (two
		 * coarse cells over the map's extent): its stated resolution is off. */
		bool stated_resolution_off = false;
	};
	/** Every robot, in the order they were added. */
	std::vector<RobotStatus> status() const;
	/** The robot whose map frame is the world ("" before any map). */
	std::string worldRobot() const;
	/** Estimations run so far. */
	size_t estimations() const;
	/** What the last estimation did. */
	struct EstimationStats
	{
		size_t maps = 0, maps_prepared = 0;  //!< maps_prepared: changed since they were last prepared
		size_t pairs_aligned = 0, pairs_reused = 0, pairs_deferred = 0, pairs_skipped = 0;
		double seconds = 0;
	};
	EstimationStats lastEstimation() const;

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
		size_t map_version = 0;  //!< bumped by every map or update taken
		/** `map` as a grid, and its known cells, at `converted_version`:
		 * converted once per map version, not once per estimation. */
		std::shared_ptr<const GridInFrame> grid;
		size_t known_cells = 0, converted_version = size_t(-1);
	};
	/** A pair's last alignment and the maps it came from (estimate() only). */
	struct PairMemory
	{
		FleetEdge edge;  //!< `to` and `from` as robot indices into robots_
		size_t to_version = 0, from_version = 0;
		size_t to_known = 0, from_known = 0;  //!< known cells of each map then
		size_t estimation = 0;  //!< when
		/** When last searched afresh (not tracked); none: never (a pair
		 * tracked from where the fleet put its maps). */
		std::optional<size_t> searched;
	};
	struct PreparedMemory
	{
		size_t map_version = 0;
		CScalingGridMapAligner::PreparedMapPtr prepared;
	};
	/** What one estimation works on: every robot's map as it was when the
	 * estimation started, taken under the lock. Index m: the m-th robot with
	 * a map. */
	struct Snapshot
	{
		std::vector<std::string> names;
		std::vector<GridInFrame> maps;
		std::vector<size_t> robot_of, versions, known_cells;  //!< robot index into robots_, its map's version, known cells
		std::vector<bool> pending;  //!< a disagreeing estimate awaits confirmation
		size_t world = 0, estimation = 0;
	};
	/** The estimation's inputs (lock held); nothing without a world robot. */
	std::optional<Snapshot> takeSnapshot();
	/** With known_init_poses: every robot with a map at its pose (lock held). */
	void placeAtKnownPoses();
	/** What earlier estimations found and still holds, for placeFleet
	 * (LiveFleetParams); `snapshot` must outlive the hints. */
	FleetHints hintsFor(const Snapshot& snapshot, std::chrono::steady_clock::time_point started);
	/** Keeps the prepared maps and every fresh alignment for later estimations. */
	void remember(const Snapshot& snapshot, const FleetResult& result);
	/** The world is provisional until a second robot is placed in it: if its
	 * robot overlaps no one while others overlap each other, it moves to the
	 * largest group. Returns whether it moved (`world`, `result` then updated). */
	bool moveWorldIfAlone(const Snapshot& snapshot, size_t& world, FleetResult& result) const;
	/** Each robot's new state from the estimate, by the confirmation rule
	 * (lock held). */
	void applyEstimate(
		const Snapshot& snapshot, size_t world, const std::optional<FleetResult>& result, const std::string& failure);
	/** `r`'s map as a grid, converted if it changed since (lock held). */
	const GridInFrame& converted(Robot& r);
	Robot* find(const std::string& name);
	const Robot* find(const std::string& name) const;
	bool agree(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b) const;
	/** A robot besides the world's is placed: the world may no longer move. */
	bool worldCommitted() const;
	/** How far its placement's log scale can be trusted (lock held). */
	double scalePrecision(const Robot& r) const;

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
	EstimationStats last_estimation_;
	/** Only estimate() reads or writes these (one thread, by contract). Keyed
	 * by robot index into robots_ (robots are never removed). */
	std::map<std::pair<size_t, size_t>, PairMemory> pair_memory_;  // (lower, higher index)
	std::map<size_t, PreparedMemory> prepared_memory_;
};

}  // namespace multires_map_merge::ros1
