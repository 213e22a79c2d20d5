#pragma once
// Fleets of fr079 robots at their own resolutions and frames (N maps into
// one), placed and fused in a fresh child process each: time, peak memory,
// and every placement against the exact truth.

#include "context.h"

#include <cmath>
#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
struct FleetCase
{
	std::string name;
	int maps = 0;
	std::string sizes;  //!< "w×h @ res" of each map
	double seconds = 0, placing_seconds = 0, peak_mb = 0;  //!< placing: placeFleet alone (the rest is fuseFleet)
	size_t aligned = 0, skipped = 0, building = 0, placed_right = 0, placed_wrong = 0, others_placed = 0;
	double max_err = NAN;  //!< worst placement error, cells of the coarser map of its pair with the reference
};

/** N = 2..8 (quick: 3), one robot beyond the reference with another
 * building's, and 8 maps of 1000×1000 cells. */
std::vector<FleetCase> runFleets(const BenchContext& ctx);
void writeFleetSection(std::ostream& md, const std::vector<FleetCase>& cases);

/** Places the fleet map_0.yaml, map_1.yaml, … of `dir` in a fresh process
 * (fleetChild); returns the file holding what it printed. */
std::string placeFleetInChild(const BenchContext& ctx, const std::string& dir);
/** Child mode (--fleet-child): places and fuses the fleet of `dir` (map_0
 * the reference); prints the time, the pairs and each placement. */
int fleetChild(const BenchContext& ctx, const std::string& dir);

}  // namespace multires_bench
