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

#include <multires_map_merge/AlignerParams.h>
#include <multires_map_merge/Candidate.h>
#include <multires_map_merge/Decision.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/PreparedMap.h>
#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/slam/CMetricMapsAlignmentAlgorithm.h>

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
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

	/** The parameters (AlignerParams.h). */
	using TConfigParams = AlignerParams;
	TConfigParams options;

	/** One refined hypothesis and how it was judged (Candidate.h). */
	using TCandidate = Candidate;

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
	/** The search, decision and finish of one pair (a given start first),
	 * reported in the grids' cells. */
	TReturnInfo align(
		const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric) const;
	/** The same in the prepared maps' cells (PreparedMap::grid_corner). */
	TReturnInfo alignInPreparedCells(
		const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric) const;
	/** mirror_check: the other map aligned to the reference mirrored
	 * (feature hypotheses only); its candidates join `search` as rivals. Returns their best
	 * score (NaN with none judged in full). */
	double mirrorPass(const TPreparedMap& ref, const TPreparedMap& other, pair_search::SearchState& search) const;
};

}  // namespace multires_map_merge
