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
#include <multires_map_merge/GridInFrame.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <array>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace mrpt::config
{
class CConfigFileBase;
}

namespace multires_map_merge
{
/** Four points of a map's frame with the mean and the spread (covariance)
 * of its wall cells (occupied; its known cells if it has almost none): the
 * centroid ± √(2λ) along each principal axis. A similarity moves every
 * point affinely, so the RMS of two placements' difference at these four is
 * exactly its RMS over every wall cell: how far apart two placements put
 * what the map saw, as the benchmark measures a placement (the corners of
 * the box around it would count a turn about √3 times over, and a grid's
 * padding of unknown space more). */
using WallSpread = std::array<Eigen::Vector2d, 4>;

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

struct FleetParams
{
	/** Pairs aligned at once (0: one per hardware thread). */
	unsigned threads = 0;
	/** A map placed this surely needs no more pairs: the other pairs are
	 * skipped. Pairs are tried most promising first (feature inliers); a map
	 * not placed tries every pair it has. */
	double settled_confidence = 0.95;
	/** A placed map not yet settled tries this many more pairs, most
	 * promising first, for a surer path. */
	unsigned unsettled_tries = 2;
	/** A placed map whose placement hangs on one pair (no second path of
	 * confident pairs to the reference: nothing checks that pair around a
	 * cycle or refines it jointly) tries this many more pairs, most
	 * promising first, for a second path. A pair of two placed maps is
	 * refined from where the fleet puts them first (placeFleet), so a
	 * second path costs about one refinement and measures the two maps'
	 * own overlap for the joint refinement. 0: a map placed by one pair
	 * keeps it alone (fewer pairs aligned). Each placement says whether a
	 * cycle checked it (FleetPlacement::checked_by_cycle). */
	unsigned second_path_tries = 1;
	/** A cycle whose composed transform moves the walls of a map (RMS,
	 * wallRms) by more than its tolerance (cells of the coarser map) is
	 * contradictory. A pair's tolerance follows its precision:
	 * `cycle_tolerance_per_rmse` × its edge RMSE, at least
	 * `cycle_tolerance_cells` and at most `cycle_tolerance_max_cells`; a
	 * cycle's adds its pairs' `cycle_tolerance_per_rmse` × edge RMSE in
	 * quadrature (their errors add up around it), within the same bounds.
	 * Tight for precise pairs on
	 * purpose: two pairs of precise maps 4 cells apart means one is off, and
	 * the joint refinement would land between them. Right pairs of bent real
	 * maps disagree by 2–35 cells and fit at an RMSE of 1–10 cells. */
	double cycle_tolerance_cells = 3.0;
	double cycle_tolerance_per_rmse = 4.0;
	/** Farther apart, two placements are rivals to the decision, not one.
	 * 0: the decision's `distinct_shift` (placeFleet: its aligner's;
	 * placeFromPairs, which has none: the default). */
	double cycle_tolerance_max_cells = 0;
	/** The tolerance of one pair (see cycle_tolerance_cells). */
	double toleranceOf(const FleetEdge& e) const;
	/** The tolerance of a cycle of `edges` (indices, the closing edge first;
	 * see cycle_tolerance_cells), in cells of the closing edge. Each pair's
	 * RMSE is in its own coarser cells: `coarse_cell` (one per edge, one
	 * length unit: coarseCellInReference) puts them in one unit; empty: all
	 * pairs' cells are taken as one size. */
	double cycleTolerance(
		const std::vector<int>& cycle, const std::vector<FleetEdge>& edges,
		const std::vector<double>& coarse_cell = {}) const;
	/** The largest tolerance: cycle_tolerance_max_cells, or its default. */
	double maxToleranceCells() const;
	/** These parameters with cycle_tolerance_max_cells 0 set to the
	 * decision's distinct_shift (what placeFleet places with). */
	FleetParams resolvedFor(const DecisionParams& decision) const;
	/** The tree's placements refined at once from every confident pair kept
	 * (JointPlacement.h): a map reached through a chain is then placed by
	 * every pair that sees it, not by one path. */
	bool joint_refinement = true;

	/** Reads `section` of an MRPT ini file (keys: fleetParamFields(); absent
	 * keys keep their values). Throws std::invalid_argument naming the
	 * section and the key whose value cannot work. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& section);
	/** Writes every key with its meaning. */
	void saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& section) const;
	/** Why these values cannot work ("" when they can). */
	std::string invalidReason() const;
};

/** One fleet parameter: its ini key (section [fleet]; the ROS parameter of
 * the same name), its member, its valid range (0 also valid where it turns
 * the setting to its default) and what it sets. Loading, saving,
 * validation, the ROS nodes and docs/parameters.md read this one list. */
struct FleetParamField
{
	const char* key;
	std::variant<double FleetParams::*, unsigned FleetParams::*, bool FleetParams::*> member;
	double lo, hi;
	bool zero_is_default;
	const char* description;
};
const std::vector<FleetParamField>& fleetParamFields();
/** The fleet parameter table (docs/parameters.md): key, default, valid range, description. */
std::string fleetParamsMarkdown();

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

/** The cells of the coarser map of the pair `e`, in `e.to`'s metres. */
double coarseCellInTo(const std::vector<GridInFrame>& maps, const FleetEdge& e);
/** The cells of the coarser map of the pair `e` in the reference's metres,
 * `e.to` placed by `placements`: what the pair's RMSE and tolerance count. */
double coarseCellInReference(
	const std::vector<GridInFrame>& maps, const std::vector<FleetPlacement>& placements, const FleetEdge& e);

/** RMS distance (metres of the target frame) between where two transforms
 * put the four corners of `map`'s grid: how far apart two placements of a
 * map are. */
double cornerRms(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b);

/** The WallSpread of a map (see WallSpread). */
WallSpread wallSpread(const GridInFrame& map);
/** RMS distance between where two transforms put a map's walls (its WallSpread). */
double wallRms(const WallSpread& spread, const Similarity2D& a, const Similarity2D& b);

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
