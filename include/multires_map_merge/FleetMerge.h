#pragma once
// N maps into one (a fleet). Pairwise scaling alignments form a graph of
// confident similarities; every map is placed through its most confident
// path from the reference (maximum spanning tree, a path as sure as its
// weakest edge); an aligned pair that contradicts the tree around a cycle
// drops the weakest edge of that cycle (FleetGraph.h); then every placement is refined at
// once from all confident pairs kept (JointPlacement.h); the placed maps are
// fused with the two-map cell rule. A map that nothing confident connects is reported by
// name as not placed: never dropped silently, never placed on a guess.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetEdge.h>
#include <multires_map_merge/FleetParams.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/WallSpread.h>

#include <opencv2/core.hpp>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge
{
/** What a caller that places the same fleet again and again (LiveFleet, as
 * the maps grow) knows from before, so that a call costs what changed. */
struct FleetHints
{
	/** Maps already prepared with the aligner's options, per input (missing
	 * or null: prepared in this call). */
	std::vector<CScalingGridMapAligner::PreparedMapPtr> prepared;
	struct Known
	{
		FleetEdge edge;  //!< an earlier result for the pair (either direction)
		/** Still holds (say, neither map changed enough since): taken as is.
		 * Otherwise the pair is aligned again, from `edge`'s transform first
		 * if it was merged (tracking), and `edge` stands in if the deadline
		 * leaves no time to align it. */
		bool holds = false;
		/** How stale it is (say, estimations since): orders the pairs to
		 * align (see `deadline`). */
		size_t age = 0;
		/** Realigned from its transform first (if merged); false: searched
		 * afresh, as a check independent of the earlier result. */
		bool track = true;
	};
	/** The earlier result for the pair of maps (a, b), if any. */
	std::function<std::optional<Known>(size_t a, size_t b)> known;
	/** No alignment starts after this (those started finish): the pairs left
	 * are counted in pairs_deferred. Past it, the first round still starts
	 * one pair (every call progresses), a later round one if it was never
	 * aligned or its result is `overdue_age` old (none starves). Pairs go
	 * never aligned first, then overdue, then placed pairs to track, then the
	 * rest, the stalest first within each. */
	std::optional<std::chrono::steady_clock::time_point> deadline;
	size_t overdue_age = size_t(-1);
};

struct FleetResult
{
	std::vector<FleetPlacement> maps;  //!< one per input, in input order
	std::vector<FleetEdge> edges;  //!< every pair aligned or reused
	size_t pairs_aligned = 0, pairs_skipped = 0;
	size_t pairs_reused = 0;  //!< FleetHints::known results that hold, taken as they are
	size_t pairs_deferred = 0;  //!< not aligned, the deadline passed (an earlier result, if any, stands in)
	/** Each input as prepared (what FleetHints::prepared takes next time). */
	std::vector<CScalingGridMapAligner::PreparedMapPtr> prepared;
	bool allPlaced() const;
};

/** The placement from pairs already aligned (placeFleet's step after each
 * round of alignments): the maximum spanning tree from the reference, cycles
 * that contradict it broken at their weakest pair (marked `dropped`), and for
 * every map not placed the reason. Throws std::invalid_argument on a
 * reference or a pair naming a map out of range. */
FleetResult placeFromPairs(
	const std::vector<GridInFrame>& maps, size_t reference, std::vector<FleetEdge> edges,
	const FleetParams& params = {});

/** Places every map in `maps[reference]`'s frame. Throws std::invalid_argument
 * on fewer than two maps, a reference out of range or parameters that cannot
 * work (FleetParams::invalidReason). */
FleetResult placeFleet(
	const std::vector<GridInFrame>& maps, size_t reference, const CScalingGridMapAligner& aligner,
	const FleetParams& params = {}, const FleetHints& hints = {});

struct FusedFleet
{
	/** In the reference map's frame, on the reference grid's lattice. */
	GridInFrame merged;
	/** Each input's classes sampled on the merged grid (empty if not placed):
	 * what the overlay PNG colours. */
	std::vector<cv::Mat> classes;
};

/** Fuses every placed map (the cell rule of fuseGridMaps) at
 * `output_resolution`. Throws MergedMapTooLarge past `max_cells`. */
FusedFleet fuseFleet(
	const std::vector<GridInFrame>& maps, const FleetResult& placement, size_t reference,
	double output_resolution, size_t max_cells = size_t(1) << 28);

}  // namespace multires_map_merge
