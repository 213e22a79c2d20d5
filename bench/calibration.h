#pragma once
// The decision's calibration data (multires_bench --calibration-data):
// every candidate of every pair the decision is fitted on, with its evidence
// and whether it was right, into candidates.csv for
// decision-fit. Calibration sites only (Halmstad E5, HIH),
// their cross-site negatives in both orders, CARMEN negatives, mirror images,
// the live fleet's growing maps, OTHER recorded coarser, the sensor maps
// on the floor plans, the independent ROS maps (ros_maps.h) and halves of
// the E5 and HIH maps (partial_maps.h).

#include "context.h"

namespace multires_bench
{
/** Which parts; all of them when none is set. */
struct CalibrationParts
{
	bool extra_negatives = false, live_pairs = false, coarser_pairs = false, floor_plan_pairs = false, ros_pairs = false,
		 partial_pairs = false;
	size_t negatives_per_map = 8;
};

/** Writes the candidates of every part asked for to ctx.candidates (which
 * must be set; its options refine every hypothesis). */
void writeCalibrationData(const BenchContext& ctx, const CalibrationParts& parts);

}  // namespace multires_bench
