#pragma once
// Fleets of real maps (issue 36): every sensor map of one Halmstad site in
// ONE placement (placeFleet + fuseFleet in a fresh process, as
// `gridmap-merge MAP_01 … MAP_14` runs it), the first map the reference,
// each map scored against the annotated similarity to it. Also with the maps
// recorded at mixed cell sizes (×1, ×2, ×1.4 in turn, all stated 0.05 m),
// and each placement as the spanning tree alone gives it (joint refinement
// off), from the same pairs.

#include "halmstad.h"

#include <multires_map_merge/FleetMerge.h>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
/** How the maps of a fleet were placed, against the annotation. */
struct FleetPlacing
{
	size_t right = 0, wrong = 0, not_placed = 0;
	std::vector<double> displacement_px;  //!< per map placed (mean over its occupied pixels)
	/** The same against every annotated pair at once (HalmstadData::jointlyToFirst). */
	std::vector<double> displacement_joint_truth_px;
};

struct HalmstadFleetRun
{
	std::string site;
	bool mixed_cells = false;
	size_t maps = 0, pairs_aligned = 0, pairs_skipped = 0;
	size_t pairs_confident = 0, pairs_dropped = 0;  //!< dropped: contradicted a cycle (not used by the placement)
	double seconds = 0, peak_mb = 0;  //!< the whole child process's placement and fusion
	double annotation_disagreement_px = NAN;  //!< annotationDisagreementPx of the site's maps
	FleetPlacing joint, tree;  //!< placeFleet as it is; the spanning tree alone
};

/** Places a fleet of map_0.yaml, map_1.yaml, … in `dir` (map_0 the
 * reference) in a fresh process; returns the file holding what it printed. */
using FleetInChild = std::function<std::string(const std::string& dir)>;

/** Each site's fleet, same cell size and, with `mixed`, mixed cell sizes. */
std::vector<HalmstadFleetRun> runHalmstadFleets(
	const HalmstadData& data, const std::vector<std::string>& sites, bool mixed, const FleetInChild& place,
	const std::string& dir);

/** The report's section: a row per fleet, tree-only beside. */
void writeHalmstadFleetSection(
	std::ostream& md, const std::vector<HalmstadFleetRun>& runs, const multires_map_merge::FleetParams& placed_with);

}  // namespace multires_bench
