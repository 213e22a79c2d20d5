#pragma once
// The live node's latency, without a master: LiveFleet (what the map_merge
// node runs) fed robots' growing maps step by step, one estimation per step,
// against when the maps first *can* be merged (placeFleet on that step's maps,
// offline). Robots of fr079 at 5 / 3 / 8 cm in their own frames and one of
// intel (another building).

#include <multires_map_merge/GroundTruthPair.h>

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
	int offline_step = -1;  //!< first step placeFleet places it (-1: never)
	int live_step = -1;  //!< first step LiveFleet has it placed within 2 coarse cells (-1: never)
	int wrong_steps = 0;  //!< steps LiveFleet had it placed more than 2 coarse cells off (or placed at all, for another building)
	double final_error_cells = -1;  //!< at the last step, in coarse cells (-1: not placed)
};

struct LiveLatency
{
	int steps = 0;
	double period_s = 2.0;  //!< the estimation period the node's default (0.5 Hz) gives
	double max_estimate_s = 0, max_merged_s = 0;  //!< slowest estimate() and merged() of the run
	std::vector<LiveRobotRow> robots;
	/** Every robot of the building placed live no later than one step after it
	 * can be, never wrong, the other building never placed, and an
	 * estimation plus a fusion within one period: the merged map and TF then
	 * follow within two estimation periods of the maps overlapping. */
	bool met() const;
};

using ScansOf = std::function<const multires_map_merge::ScanSequence&(const std::string& log)>;

/** `steps` steps; at step k every robot's map covers k/steps of its share. */
LiveLatency runLiveLatency(const ScansOf& scans, int steps);

void writeLiveSection(std::ostream& md, const LiveLatency& l);

}  // namespace multires_bench
