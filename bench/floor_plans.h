#pragma once
// Floor plans (issue 35): a robot's sensor map placed on its building's floor
// plan, the Halmstad `layout` PNGs saved for map_server as drawn (black walls,
// white inside, transparent outside, which map_server's trinary rule reads as
// unknown). REF = the plan, OTHER = a sensor map, both stated at 0.05 m: the
// scale between them (0.63–1.59) is unknown to the aligner. Negatives: every
// sensor map against the other sites' plans.

#include "halmstad.h"

#include <multires_map_merge/CScalingGridMapAligner.h>

#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
struct FloorPlanRun
{
	std::string site, plan, sensor;
	bool positive = true;  //!< the sensor map's own building's plan
	bool merged = false;
	HalmstadOutcome outcome;  //!< of the reported transform (positives)
	double seconds = 0, confidence = 0;
};

/** Every sensor map of `sites` against its site's plan, and against the plans
 * of every other site of the data (negatives), aligned with `options`. */
std::vector<FloorPlanRun> runFloorPlans(
	const HalmstadData& data, const std::vector<std::string>& sites,
	const multires_map_merge::CScalingGridMapAligner::TConfigParams& options, const std::string& dir);

/** Per site: pairs, merged right, refused, merged wrong; the negatives. */
struct FloorPlanTotals
{
	size_t calibration_pairs = 0, calibration_right = 0, acceptance_pairs = 0, acceptance_right = 0;
	size_t merged_wrong = 0;  //!< positives merged off the annotation
	size_t negatives = 0, negatives_merged = 0;
};
FloorPlanTotals floorPlanTotals(const std::vector<FloorPlanRun>& runs);

/** The report's section: a row per site, then the negatives. */
void writeFloorPlanSection(std::ostream& md, const std::vector<FloorPlanRun>& runs);

}  // namespace multires_bench
