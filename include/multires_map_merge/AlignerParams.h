#pragma once
// The aligner's parameters (CScalingGridMapAligner::TConfigParams), each
// stage's own kept together in the order of the method, and their one list
// (key, member, range, meaning) that loading, saving, validation, the ROS keys
// and docs/parameters.md read (src/AlignerParams.cpp).

#include <multires_map_merge/Decision.h>
#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/Finish.h>
#include <multires_map_merge/LatticeShift.h>
#include <multires_map_merge/TsICP.h>

#include <mrpt/config/CLoadableOptions.h>

#include <string>
#include <variant>
#include <vector>

namespace multires_map_merge
{
struct AlignerParams : public mrpt::config::CLoadableOptions
{
	// --- Preparation (PreparedMap.h)
	/** Each map prepared as its known part: the box of its occupied and
	 * free cells plus kKnownMargin cells of unknown (PreparedMap::
	 * grid_corner), its feature levels sized by the box's longer side and
	 * framed in unknown (FeatureParams). How much unknown a file holds
	 * around what a robot saw then changes nothing, neither the result nor
	 * the time: a gmapping grid is 4000 cells across whatever it mapped.
	 * Results stay in the grids' cells. The decision is calibrated on its
	 * candidates too; off by default because on files saved with little
	 * padding the whole grid's search merges a few more pairs
	 * (docs/method.md, step 0; docs/limits.md). */
	bool crop_to_known = false;

	// --- Features and RANSAC (initial hypotheses)
	int pyramid_levels = 4;  //!< per map; each level halves the cell count per axis
	/** Pyramid levels larger than this are not searched for features
	 * (FeatureParams::max_level_cells): bounds the time and memory of SIFT. */
	double feature_max_level_cells = 1 << 18;
	double sift_contrast_threshold = 0.04;
	double sift_edge_threshold = 10;
	double ratio_test = 0.8;
	double ransac_threshold = 3.0;  //!< cells of the reference pyramid level
	int ransac_iterations = 4000;
	int ransac_min_inliers = 5;
	int hypotheses_per_level_pair = 2;
	int max_hypotheses = 8;  //!< refined by TsICP, most inliers first
	/** Also try hypotheses from the maps' structure
	 * (StructureHypotheses.h), unless a feature hypothesis is merged
	 * whatever comes: they are right ones for independent maps and the
	 * rivals the decision weighs. */
	bool structure_search = true;
	/** Refine every hypothesis (up to max_hypotheses) and always search
	 * the structure, even once the maps are found to coincide or a
	 * candidate is confident, and refine the screened rivals of every
	 * pair's best: what calibration data is made with. */
	bool exhaustive_search = false;
	/** Before a pair is merged on its walls agreeing (not on coinciding
	 * cells: exact_confidence), the other map is aligned once more to
	 * the reference mirrored (its x axis flipped, kept with the prepared
	 * reference; feature hypotheses only): its candidates are rivals. A
	 * map against its own mirror image, or a flipped map, fits at least
	 * as well mirrored and is refused (TReturnInfo::mirror_score). */
	bool mirror_check = true;
	/** A pair refused with OTHER aligned onto REF is aligned once more the
	 * other way round (REF onto OTHER) and merged if that is confident,
	 * its transforms inverted (TReturnInfo::roles_swapped): the search is
	 * not symmetric in the maps (OTHER's features are matched into REF,
	 * the structure search moves OTHER). Off by default: the calibration
	 * has sensor pairs in both orders but a coarser map only as OTHER,
	 * and as REF it merged E5_11 ← E5_05 recorded 3.3× coarser 912 px
	 * off (docs/decision.md). Not with a start (tracking) nor
	 * exhaustive_search (calibration data makes each order a pair of its
	 * own). */
	bool both_orders = false;
	// --- TsICP
	double xi_min = 0.35;
	double lambda = 2.0;
	int icp_max_iterations = 100;
	double icp_relative_tolerance = 1e-7;
	int icp_coarse_points = 10000;  //!< TsICPParams::coarse_points
	/** Cheap verification before the expensive one: each hypothesis is
	 * first refined by TsICP on about this many points of the fixed map
	 * and judged on as many per map; unless the maps could be the same
	 * cells there (edge RMSE < 1.5 coarse cells), one whose decision score
	 * is more than `screen_margin` below lowestMergeableScore() is dropped
	 * (Candidate::screened) instead of refined on every point. 0: off. */
	int screen_points = 1500;
	double screen_margin = 0.15;
	/** Every candidate refined on every point is refit this many times
	 * to the best shifts of its moved walls' tiles (bendBalanced in
	 * MapAgreement.h: both maps, one vote per tile) before it is judged,
	 * and the refit kept if its decision score is higher. Independent
	 * SLAM maps bend: TsICP's trimmed fit follows the part that agrees
	 * best and is off by cells over the rest. Chance fits gain from it
	 * too: the decision is calibrated on refit candidates (negatives of
	 * both map orders). Not where the maps may be the same cells. 0: off. */
	int bend_refit_iterations = 3;
	/** The decided transform is refined once more by TsICP on every
	 * occupied cell of both maps (EdgePoints.h, occupiedPoints): edges
	 * are staircases that differ between resolutions and rotations. The
	 * decision is made before, on the edges; this moves the transform by
	 * a fraction of a cell (more than finish_max_shift: not taken).
	 * Skipped where the decided edges are 1.5 coarse cells apart or more
	 * (RMSE): walls that differ by that much gain nothing from it. */
	bool icp_finish_on_occupied = true;
	double finish_max_shift = 1.5;  //!< cells of the coarser map
	/** The finish's last step (LatticeShift.h): the sub-cell shift that
	 * makes the finer map's occupied cells, drawn on the coarser map's
	 * lattice, cover the coarser map's: the best whole-cell slip within
	 * one cell, then steps of this many coarse cells over ± half a cell
	 * around it (0: off). */
	double finish_lattice_step = 0.05;
	/** Where the decided edges are 1.5 coarse cells apart or more (maps
	 * that bend: no finish on occupied cells), the decided transform is
	 * refit by TsICP with this overlap preference λ instead of `lambda`.
	 * The search's λ trims to the part of the overlap that fits best,
	 * which on bent maps is one region: the pose is off over the rest.
	 * A larger λ keeps more of the overlap, so the pose balances the
	 * bends over all of it (the annotation of independent maps is a
	 * fit over the whole overlap). Tuned on Halmstad E5/HIH, both map
	 * orders (docs/method.md, step 6). 0: off. */
	double finish_bent_lambda = 4.0;
	// --- Evidence (MapAgreement.h)
	/** Walls within this many cells of the finer map, plus the coarser
	 * map's quantisation, agree: independent SLAM maps bend and thicken
	 * walls by a few cells (toleranceInTarget, MapAgreement.h). */
	double verify_tolerance = 3.0;
	/** The far perturbations that measure chance: shifts of this many
	 * coarse cells along each axis, turns of ± verify_turn_deg. */
	double verify_shift = 12.0;
	double verify_turn_deg = 8.0;
	/** --- Decision (Decision.h; docs/decision.md): calibrated by
	 * decision-fit on Halmstad E5/HIH, cross-site,
	 * CARMEN, mirror and live-fleet data. Ini keys decision_*,
	 * distinct_shift and min_confidence (decisionParamFields()). */
	DecisionParams decision;
	/** Trust the stated resolutions as a prior on the scale. */
	bool use_resolution_metadata = false;
	double metadata_scale_tolerance = 0.15;  //!< relative, with use_resolution_metadata
	// --- Limits
	/** Larger maps are refused before any work, so peak memory stays
	 * bounded (docs/limits.md states the bound per cell). */
	double max_map_cells = 32e6;

	void loadFromConfigFile(
		const mrpt::config::CConfigFileBase& source, const std::string& section) override;
	void saveToConfigFile(
		mrpt::config::CConfigFileBase& target, const std::string& section) const override;

	/** Why these values cannot work ("" when they can): out-of-range or
	 * non-finite values. loadFromConfigFile throws std::invalid_argument
	 * with it; alignScaled reports it as not merged. */
	std::string invalidReason() const;

	FeatureParams featureParams() const;
	TsICPParams icpParams() const;
	LatticeShiftParams latticeParams() const;
	FinishParams finishParams() const;
};

/** One aligner parameter: its ini key (section [aligner]; the ROS parameter of
 * the same name), its member, its valid range (0 also valid where it turns the
 * step off) and what it sets. Loading, saving, validation, the ROS nodes' keys
 * and docs/parameters.md (gridmap-merge --parameters) all read this one list; the
 * decision's parameters are decisionParamFields(). */
struct AlignerParamField
{
	using Params = AlignerParams;
	const char* key;
	std::variant<int Params::*, double Params::*, bool Params::*> member;
	double lo, hi;
	bool zero_turns_off;
	const char* description;
};
const std::vector<AlignerParamField>& alignerParamFields();

/** Every ini key, the aligner's and then the decision's, in the saved order. */
std::vector<std::string> alignerParamKeys();

/** The aligner parameter table (docs/parameters.md): key, default, valid range, description. */
std::string alignerParamsMarkdown();

}  // namespace multires_map_merge
