#pragma once
// The fleet's parameters (FleetMerge.h), their one list of ini keys, and the
// tolerances they give a pair and a cycle.
#include <multires_map_merge/Decision.h>
#include <multires_map_merge/FleetEdge.h>

#include <string>
#include <variant>
#include <vector>

namespace mrpt::config
{
class CConfigFileBase;
}

namespace multires_map_merge
{
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

}  // namespace multires_map_merge
