#pragma once
// The full run's results, and REPORT.md (+ pairs.csv and the figures) written
// from them: every number in the report comes from the run that wrote it.

#include "carmen.h"
#include "carpin_maps.h"
#include "coarser_other.h"
#include "partial_maps.h"
#include "fleets.h"
#include "floor_plans.h"
#include "halmstad_fleets.h"
#include "halmstad_pairs.h"
#include "live_fleet.h"
#include "ros_maps.h"
#include "scaling.h"

#include <string>
#include <vector>

namespace multires_bench
{
struct FullRun
{
	// The accuracy matrices: fr079 over these resolutions (Fig. 8) and
	// rotations (Fig. 9), and the other logs; MRPT beside.
	std::vector<double> res, rot_res, yaws;
	std::vector<PairResult> pairs;
	std::vector<Negative> negatives;
	std::vector<HalmstadRun> halmstad;
	std::vector<FloorPlanRun> floor_plans;
	std::vector<CoarserRun> coarser;
	std::vector<PartialRun> partial;
	std::vector<RosMapsRun> ros_maps;
	CarpinResult carpin;
	CScalingGridMapAligner::TReturnInfo willow;
	std::vector<ScalingCase> scaling;
	std::vector<WholeProcessRow> processes;
	std::vector<FleetCase> fleets;
	std::vector<HalmstadFleetRun> halmstad_fleets;
	LiveLatency live;
	std::vector<double> basin_dyaws, basin_dscales;
	std::vector<BasinCell> basin_same, basin_ratio;
	double seconds = 0;  //!< the whole run
};

/** pairs.csv, the PNG figures and REPORT.md into `out`. */
void writeReport(const BenchContext& ctx, const std::string& out, const FullRun& run);

}  // namespace multires_bench
