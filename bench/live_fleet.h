#pragma once
// The live node's latency, without a master: LiveFleet (what the map_merge
// node runs) fed robots' growing maps on a simulated clock, estimations
// taking the time they take on this machine, against when the maps first
// *can* be merged (placeFleet on those maps, offline). Robots of fr079 at
// 5 / 3 / 8 cm in their own frames and one of intel (another building).

#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <nav_msgs/OccupancyGrid.h>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
struct LiveRobotRow
{
	std::string name, what;  //!< what: resolution, share of the run, building
	bool other_building = false;
	int can_merge_state = -1;  //!< first map state placeFleet places it right (-1: never)
	double can_merge_s = -1;  //!< when that state arrived (simulated seconds)
	double placed_s = -1;  //!< when the node first published it placed right (-1: never)
	int wrong_estimations = 0;  //!< estimations after which it was placed > 2 coarse cells off (or at all, another building)
	double final_error_cells = -1;  //!< after the last estimation, in coarse cells (-1: not placed)
	/** From "can be merged" to "published placed" (-1: not both). */
	double latencySeconds() const { return can_merge_s < 0 || placed_s < 0 ? -1 : placed_s - can_merge_s; }
};

/** One estimation of the simulated run. */
struct LiveEstimationRow
{
	double start_s = 0;  //!< simulated
	int state = 0;  //!< the map state it saw
	double estimate_s = 0, merged_s = 0;  //!< measured
	size_t maps_prepared = 0, pairs_aligned = 0, pairs_reused = 0, pairs_deferred = 0;
};

struct LiveLatency
{
	int states = 0;
	double state_s = 2.0;  //!< a new map from every robot this often (simulated)
	double period_s = 2.0;  //!< the estimation period the node's default (0.5 Hz) gives
	double budget_s = 0;  //!< LiveFleetParams::estimation_budget_s as the node sets it
	std::vector<LiveRobotRow> robots;
	std::vector<LiveEstimationRow> estimations;
	double maxEstimateSeconds() const;
	double medianEstimateSeconds() const;
	double maxLatencySeconds() const;  //!< over the building's robots (-1: one never placed)
	/** Every robot of the building published placed within two estimation
	 * periods of the first map state that can merge it, never wrong, and the
	 * other building never placed. */
	bool met() const;
};

using ScansOf = std::function<const multires_map_merge::ScanSequence&(const std::string& log)>;

/** One robot's map at one state of the live run, as the node receives it
 * (through a `nav_msgs/OccupancyGrid`), with the truth. */
struct LiveMap
{
	std::string robot;
	nav_msgs::OccupancyGrid msg;  //!< what the node receives (header: the robot's map frame, stamp = state)
	multires_map_merge::GridInFrame map;  //!< read back from `msg`, as the node reads it
	multires_map_merge::Similarity2D frame_in_world;  //!< its map frame in robot1's (the truth)
	double resolution = 0;
	bool other_building = false;
};
/** Every robot's map at state `state` (1..`states`) of the live run. */
std::vector<LiveMap> liveMapsAt(const ScansOf& scans, int state, int states);

/** The map_merge node on a simulated clock: every `state_s` seconds each
 * robot's map grows by 1/`states` of its share of the run; an estimation
 * starts every period (or when the previous one ends, if later), sees the
 * latest maps, and takes what it measures on this machine; the live fleet
 * runs `aligner` and `fleet` (the defaults, or --config's). */
LiveLatency runLiveLatency(
	const ScansOf& scans, int states, const multires_map_merge::CScalingGridMapAligner::TConfigParams& aligner,
	const multires_map_merge::FleetParams& fleet);

void writeLiveSection(std::ostream& md, const LiveLatency& l);

}  // namespace multires_bench
