#pragma once
// The aligner facade: two occupancy grids in, the similarity between them
// out, in the order of the method:
//   1. grids → class images; SIFT over a resolution pyramid; 2-point RANSAC
//      → similarity hypotheses (FeatureHypotheses.h)
//   2. edge points of both maps (EdgePoints.h)
//   3. each hypothesis refined by trimmed scaling ICP (TsICP.h)
//   4. each refinement judged against both maps' cells (MapAgreement.h),
//      and the pair decided on that evidence (Decision.h); below
//      min_confidence it is reported as not merged
//   5. the decided transform finished (Finish.h).
// Resolution metadata is not needed: everything runs in cell coordinates and
// the scale between the maps' cells is estimated.

#include <multires_map_merge/Decision.h>
#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/Finish.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/LatticeShift.h>
#include <multires_map_merge/MapAgreement.h>
#include <multires_map_merge/PreparedMap.h>
#include <multires_map_merge/Similarity2D.h>
#include <multires_map_merge/TsICP.h>

#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/slam/CMetricMapsAlignmentAlgorithm.h>

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace multires_map_merge
{
namespace pair_search
{
struct SearchState;  // src/PairSearch.h
}

class CScalingGridMapAligner : public mrpt::slam::CMetricMapsAlignmentAlgorithm
{
   public:
	CScalingGridMapAligner();

	struct TConfigParams : public mrpt::config::CLoadableOptions
	{
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
		 * (TCandidate::screened) instead of refined on every point. 0: off. */
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
	} options;

	/** One refined hypothesis and how it was judged. */
	struct TCandidate
	{
		/** RANSAC start, and TsICP's result after the bend-balanced refit
		 * where that scored higher (bend_refit_iterations); cell coordinates. */
		Similarity2D initial_cells, cells;
		double overlap = 0, rmse_coarse_cells = 0;
		/** Strict cell consistency (MapAgreement); NaN where the edge RMSE
		 * (≥ 1.5 coarse cells) already says the maps are not the same cells. */
		double consistency = 0;
		/** What the decision reads (Decision.h), measured on every point
		 * (on a sample for a screened candidate). */
		Evidence evidence;
		/** DecisionParams::score of the evidence. */
		double score = 0;
		double objective = 0;  //!< TsICP's ψ, squared reference cells
		/** Where the other map's wall centroid lands in the reference (cells):
		 * tells rival candidates apart. */
		Eigen::Vector2d other_centre{0, 0};
		/** Where the candidate puts the other map (rivals are told apart by it). */
		Placement placement() const { return {cells, other_centre}; }
		/** For the pair's best-scoring candidate only: the best distinct
		 * rival's score (at least decision_runner_up_floor) and the decision
		 * value score + runner_up_weight · (score − runner_up_score). */
		double runner_up_score = std::numeric_limits<double>::quiet_NaN();
		double decision_value = std::numeric_limits<double>::quiet_NaN();
		/** max(exact_confidence, from decision_value for the best-scoring candidate) */
		double confidence = 0;
		/** Dropped by the cheap verification (screen_points): the numbers are
		 * those of the sample, not refined further. */
		bool screened = false;
		/** Not refined either: its sample result fell on a candidate already
		 * found to coincide cell for cell (exact_confidence ≥ min_confidence),
		 * where refining it again would find that candidate again. Also
		 * `screened` (no rival, never chosen). */
		bool converged_on_exact = false;
		/** Found with one map mirrored (mirror_check): a rival of every
		 * candidate, never chosen. Its `cells` take the other map's cells to
		 * the mirrored reference's (with TReturnInfo::roles_swapped: the
		 * mirrored other map's cells to the reference's). */
		bool mirrored = false;
	};

	struct TReturnInfo : public mrpt::slam::TMetricMapAlignmentResult
	{
		/** Every refined hypothesis, in the order refined. */
		std::vector<TCandidate> candidates;
		bool success = false;  //!< merged with confidence ≥ min_confidence
		/** A given start was confident: no global search ran (alignScaled with
		 * a start). */
		bool tracked = false;
		/** Merged by REF aligned onto OTHER (both_orders): every number is
		 * that alignment's, its transforms and candidates inverted into this
		 * pair's order. */
		bool roles_swapped = false;
		std::string message;  //!< why not, when not
		/** x_ref = metric(x_other), metres, each map read with its stated metadata. */
		Similarity2D metric;
		/** The same between cell coordinates; cells.scale = reference cells per
		 * cell of other (other's cell size in reference cells). */
		Similarity2D cells;
		/** The feature (RANSAC) estimate TsICP started from, cell coordinates. */
		Similarity2D initial_cells;
		/** Other's real cell size implied by the reference's stated one. */
		double implied_resolution_other = 0;
		double overlap = 0;  //!< TsICP's ξ
		double objective = 0;  //!< TsICP's ψ, squared reference cells
		double trimmed_rmse_coarse_cells = 0;  //!< √e(ξ) in cells of the coarser map
		Evidence evidence;  //!< of the chosen candidate
		/** The chosen candidate's score, and where it is the pair's best-
		 * scoring one, its best distinct rival's score and the decision value
		 * (TCandidate; NaN otherwise). */
		double score = std::numeric_limits<double>::quiet_NaN();
		double runner_up_score = std::numeric_limits<double>::quiet_NaN();
		double decision_value = std::numeric_limits<double>::quiet_NaN();
		/** The best score with one map mirrored (mirror_check; NaN where
		 * the check did not run). Above `score`: a map flipped in y? */
		double mirror_score = std::numeric_limits<double>::quiet_NaN();
		double confidence = 0;  //!< in [0,1]
		int ransac_inliers = 0;
		int ransac_matches = 0;
		int icp_iterations = 0;
		size_t hypotheses = 0, hypotheses_refined = 0;
		size_t ref_edge_points = 0, other_edge_points = 0;
		std::vector<double> objective_history;
		/** features, ransac, edges, icp, verify, structure, finish. icp and
		 * verify add up the hypotheses, which run a few at once: together
		 * they can exceed the wall time. */
		std::map<std::string, double> stage_seconds;
	};

	/** One map as the aligner sees it (PreparedMap.h). Valid with the
	 * options it was prepared with (alignScaled refuses maps prepared with
	 * other feature options). */
	using TPreparedMap = PreparedMap;
	using PreparedMapPtr = multires_map_merge::PreparedMapPtr;

	/** Prepares one map with these options. Never throws on bad content:
	 * the map's `problem` says what is wrong. A floor plan (MapKind) is
	 * judged only near its walls. */
	PreparedMapPtr prepare(const mrpt::maps::COccupancyGridMap2D& grid, MapKind kind = MapKind::Sensed) const;

	/** The full similarity between two grids. Never throws on bad map
	 * content: the reason is in TReturnInfo::message with success = false. */
	TReturnInfo alignScaled(
		const mrpt::maps::COccupancyGridMap2D& ref,
		const mrpt::maps::COccupancyGridMap2D& other) const;

	/** The same for prepared maps (TReturnInfo::stage_seconds then holds the
	 * pair's stages only; executionTime excludes the preparation). */
	TReturnInfo alignScaled(const TPreparedMap& ref, const TPreparedMap& other) const;

	/** The same, refining `start_metric` (other's grid metric frame → ref's,
	 * e.g. the pair's last result before the maps grew) first: when that is
	 * confident, the global search (features, structure) is skipped. How a
	 * live fleet tracks a pair cheaply; an unconfident start costs one
	 * refinement more than alignScaled. */
	TReturnInfo alignScaled(
		const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& start_metric) const;

	/** The same for maps held in their exact frames (map_server files, ROS
	 * messages; MapIO, OccupancyGridConversion): TReturnInfo::metric is then
	 * between the *maps'* frames (x_ref_map = metric(x_other_map)), exact for
	 * any origin; `cells` is unchanged. Either may be a floor plan
	 * (GridInFrame::kind). */
	TReturnInfo alignScaled(const GridInFrame& ref, const GridInFrame& other) const;

	/** MRPT interface. m1 = reference, m2 = other, both COccupancyGridMap2D.
	 * The initial estimate is not needed (the search is global) and ignored.
	 * Returns the metric SE(2) pose of m2's frame in m1's frame (the scale is
	 * in the TReturnInfo, if one is passed), or nullptr when not merged. */
	mrpt::poses::CPosePDF::Ptr AlignPDF(
		const mrpt::maps::CMetricMap* m1, const mrpt::maps::CMetricMap* m2,
		const mrpt::poses::CPosePDFGaussian& initialEstimationPDF,
		mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult> outInfo = std::nullopt) override;

	/** Not supported: grid maps are 2-D. Throws. */
	mrpt::poses::CPose3DPDF::Ptr Align3DPDF(
		const mrpt::maps::CMetricMap* m1, const mrpt::maps::CMetricMap* m2,
		const mrpt::poses::CPose3DPDFGaussian& initialEstimationPDF,
		mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult> outInfo = std::nullopt) override;

   private:
	TReturnInfo alignGrids(
		const mrpt::maps::COccupancyGridMap2D& ref, MapKind ref_kind, const mrpt::maps::COccupancyGridMap2D& other,
		MapKind other_kind) const;
	/** The search, decision and finish of one pair (a given start first). */
	TReturnInfo align(
		const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric) const;
	/** mirror_check: the other map aligned to the reference mirrored
	 * (feature hypotheses only); its candidates join `search` as rivals. Returns their best
	 * score (NaN with none judged in full). */
	double mirrorPass(const TPreparedMap& ref, const TPreparedMap& other, pair_search::SearchState& search) const;
};

/** One aligner parameter: its ini key (section [aligner]; the ROS parameter of
 * the same name), its member, its valid range (0 also valid where it turns the
 * step off) and what it sets. Loading, saving, validation, the ROS nodes' keys
 * and docs/parameters.md (gridmap-merge --parameters) all read this one list; the
 * decision's parameters are decisionParamFields(). */
struct AlignerParamField
{
	using Params = CScalingGridMapAligner::TConfigParams;
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
