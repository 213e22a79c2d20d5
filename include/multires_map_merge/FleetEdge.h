#pragma once
// A fleet's aligned pair (FleetEdge) and a map's placement (FleetPlacement):
// what the fleet's graph, its joint refinement and the live node pass around.
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/Similarity2D.h>
#include <multires_map_merge/WallSpread.h>

#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge
{
/** One aligned pair: `from`'s frame placed in `to`'s (between map frames). */
struct FleetEdge
{
	size_t from = 0, to = 0;
	bool merged = false;  //!< the aligner was confident
	Similarity2D from_to_to;
	double confidence = 0;
	/** The aligner's edge RMSE (cells of the coarser map of the pair): how
	 * precisely the pair agrees. Renderings of one corrected log fit below a
	 * cell; two SLAM runs of one building bend apart and fit at 1–10. */
	double rmse_coarse_cells = 0;
	std::string message;  //!< the aligner's
	/** The spread (WallSpread, `from`'s frame) of `from`'s walls that the
	 * pair puts on space `to` saw: where the pair measured. A pair fits two
	 * bent maps at their overlap; away from it, it says little (a small
	 * overlap, little about the turn), so the joint refinement weighs it
	 * there. None: not aligned here (the whole map's walls stand in). */
	std::optional<WallSpread> overlap;
	bool dropped = false;  //!< contradicted the others around a cycle
	bool reused = false;  //!< an earlier result (FleetHints::known), not aligned in this call
	bool tracked = false;  //!< refined from the earlier transform only (no global search)
	/** What became of it: the aligner's message, or why it was dropped. */
	std::string describe() const;
};

struct FleetPlacement
{
	bool placed = false;
	/** The pose (with scale) of this map's frame in the reference's frame. */
	Similarity2D in_reference;
	/** The weakest edge on its path (1 for the reference itself). */
	double confidence = 0;
	int parent = -1;  //!< the map it was placed through (-1: reference or none)
	/** A second path of confident pairs kept reaches the reference: no one
	 * pair, taken out, leaves this map unconnected, so a cycle checked every
	 * pair it was placed by. False: it hangs on one pair. */
	bool checked_by_cycle = false;
	std::string message;  //!< how it was placed, or why not
};

/** The cells of the coarser map of the pair `e`, in `e.to`'s metres. */
double coarseCellInTo(const std::vector<GridInFrame>& maps, const FleetEdge& e);
/** The cells of the coarser map of the pair `e` in the reference's metres,
 * `e.to` placed by `placements`: what the pair's RMSE and tolerance count. */
double coarseCellInReference(
	const std::vector<GridInFrame>& maps, const std::vector<FleetPlacement>& placements, const FleetEdge& e);

}  // namespace multires_map_merge
