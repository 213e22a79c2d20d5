#pragma once
// The graph of a fleet's aligned pairs (FleetMerge's placement step): every
// map placed through its most confident path from the reference (a maximum
// spanning tree), a pair that contradicts the tree around a cycle taken as a
// sign that one pair of that cycle is wrong (its weakest is dropped), and
// which maps hang on one pair, with no second path to check them.
#include <multires_map_merge/FleetEdge.h>
#include <multires_map_merge/FleetParams.h>
#include <multires_map_merge/WallSpread.h>

#include <vector>

namespace multires_map_merge
{
struct PlacementTree
{
	std::vector<FleetPlacement> maps;  //!< one per map
	std::vector<int> via_edge;  //!< the tree edge placing each map (-1: none)
	/** Per map, the largest tolerance of a cycle it lies on (0: none): how
	 * far the cycle check let the pairs around it disagree, so how far the
	 * joint refinement may move it. */
	std::vector<double> cycle_tolerance;
};

/** Builds the tree over the confident edges not dropped; while a kept
 * non-tree edge contradicts it (its `from` map's walls, `spread`, put
 * farther apart than the cycle's tolerance, FleetParams::cycleTolerance),
 * marks the weakest edge of that cycle `dropped` and rebuilds. */
PlacementTree consistentTree(
	const std::vector<GridInFrame>& maps, const std::vector<WallSpread>& spread, size_t reference,
	std::vector<FleetEdge>& edges, const FleetParams& params);

/** Per map: whether its placement hangs on one pair, i.e. one confident pair
 * kept, taken out, leaves it connected to the reference by nothing (a
 * bridge). Then no second, independent path checks it around a cycle or
 * refines it jointly: a wrong or imprecise pair would go unseen. */
std::vector<bool> hangsOnOnePair(
	const std::vector<FleetPlacement>& placements, const std::vector<FleetEdge>& edges, size_t reference);

}  // namespace multires_map_merge
