#pragma once
// The aligner facade: two occupancy grids in, the similarity between them
// out, in the order of the method:
//   1. grids → class images; SIFT over a resolution pyramid; 2-point RANSAC
//      → similarity hypotheses (FeatureHypotheses.h)
//   2. edge points of both maps (EdgePoints.h)
//   3. each hypothesis refined by trimmed scaling ICP (TsICP.h)
//   4. the best refinement judged against both maps' cells (MapAgreement.h);
//      below min_confidence it is reported as not merged.
// Resolution metadata is not needed: everything runs in cell coordinates and
// the scale between the maps' cells is estimated.

#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/LatticeShift.h>
#include <multires_map_merge/MapAgreement.h>
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

namespace multires_map_merge
{
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
		 * candidate is confident: what calibration data is made with. */
		bool exhaustive_search = false;
		/** Before a pair is merged on its walls agreeing (not on coinciding
		 * cells: exact_confidence), the other map is aligned once more
		 * mirrored (its x axis flipped; feature hypotheses only): its
		 * candidates are rivals. A map against its own mirror image, or a
		 * flipped map, fits at least as well mirrored and is refused
		 * (TReturnInfo::mirror_score). */
		bool mirror_check = true;
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
		 * lattice, cover the coarser map's, searched in steps of this many
		 * coarse cells over ± half a cell (0: off). */
		double finish_lattice_step = 0.05;
		/** Where the decided edges are 1.5 coarse cells apart or more (maps
		 * that bend: no finish on occupied cells), the decided transform is
		 * refit by TsICP with this overlap preference λ instead of `lambda`.
		 * The search's λ trims to the part of the overlap that fits best,
		 * which on bent maps is one region: the pose is off over the rest.
		 * A larger λ keeps more of the overlap, so the pose balances the
		 * bends over all of it (the annotation of independent maps is a
		 * fit over the whole overlap). Tuned on Halmstad E5/HIH, both map
		 * orders (README). 0: off. */
		double finish_bent_lambda = 4.0;
		// --- Decision (README "How the decision works"; calibrated by
		// scripts/calibrate_decision.py on Halmstad E5/HIH and CARMEN negatives)
		/** Walls within this many cells of the coarser map agree: independent
		 * SLAM maps bend and thicken walls by a few cells. */
		double verify_tolerance = 3.0;
		/** The far perturbations that measure chance: shifts of this many
		 * coarse cells along each axis, turns of ± verify_turn_deg. */
		double verify_shift = 12.0;
		double verify_turn_deg = 8.0;
		// Calibrated (scripts/calibrate_decision.py, bench/results/calibration.txt)
		// on E5/HIH pairs, cross-site, CARMEN, mirror and live-fleet data (growing
		// partial maps of two buildings: without them a fit placed intel's robot
		// in fr079), made by this code with these defaults: no wrong calibration
		// candidate passes, with a margin (README, "How the decision works").
		double decision_chance_weight = 1.0;
		/** Evidence discount: the score loses √(decision_evidence / n) for n
		 * judged wall points (a small overlap proves little). */
		double decision_evidence = 400;
		/** The score gains this times min(m, decision_feature_cap) /
		 * decision_feature_cap for the m feature matches (FeatureHypotheses.h,
		 * agreeingMatches) that the transform takes onto each other: local
		 * appearance (corners, door frames, clutter) agreeing where the walls
		 * do, evidence the walls alone do not give between look-alike
		 * buildings. 0: walls only. */
		double decision_feature_weight = 0.2;
		double decision_feature_cap = 10;
		/** The best candidate merges on its walls only if they agree more
		 * than chance by at least this (bent consistency − chance): two
		 * buildings whose walls agree about as well anywhere (a small map
		 * against a large one of another building) prove nothing, however
		 * few rivals they have. 0: no gate beyond B ≥ C. */
		double decision_min_lead = 0.04;
		/** The best candidate merges on its walls only if at least this
		 * share of its wall points lying near a directed wall of the other
		 * map lie near one running the same way (within 20°;
		 * TwoWaySupport::wallAlignment): a wrong alignment lays walls across
		 * walls, which the tolerant consistency counts as agreement. */
		double decision_min_wall_alignment = 0.7;
		/** The best candidate merges on its walls only if at least this
		 * share of adjacent tiles of its moved walls fit best after about the
		 * same small shift (TwoWayShiftField::coherence): independent maps
		 * bend smoothly, while a wrong alignment that lays walls near walls
		 * fits each region by a shift of its own. 0: no gate. */
		double decision_min_shift_coherence = 0.25;
		/** The pair's decision value: the best-scoring candidate's score plus
		 * this times its lead over the best distinct rival (distinct_shift):
		 * the right alignment of one building stands out, a chance fit of
		 * two buildings has rivals nearly as good. */
		double decision_runner_up_weight = 1.0;
		/** A rival scoring below this counts as this: with no rival, the lead
		 * is measured from it. */
		double decision_runner_up_floor = 0.25;
		/** Candidates whose other-map wall centroids lie more than this many
		 * coarse cells apart (or turned by over verify_turn_deg, or scaled by
		 * over 10 %) are rivals, not one answer. Independent maps bend by
		 * several cells, so a building's right placement refines to optima a
		 * bend apart (20-35 cells on Halmstad), which must not rival each
		 * other; calibrated, at most 2 m at 5 cm cells, the displacement the
		 * benchmark still calls right. */
		double distinct_shift = 40.0;
		/** The decision value at which confidence is 0.5; ±0.1 · (1 +
		 * decision_runner_up_weight) around it spans 0..1. */
		double decision_threshold = 0.664;
		/** Below this the result is "not merged". */
		double min_confidence = 0.5;
		/** Trust the stated resolutions as a prior on the scale. */
		bool use_resolution_metadata = false;
		double metadata_scale_tolerance = 0.15;  //!< relative, with use_resolution_metadata
		// --- Limits
		/** Larger maps are refused before any work, so peak memory stays
		 * bounded (README "Limits" states the bound per cell). */
		double max_map_cells = 32e6;

		void loadFromConfigFile(
			const mrpt::config::CConfigFileBase& source, const std::string& section) override;
		void saveToConfigFile(
			mrpt::config::CConfigFileBase& target, const std::string& section) const override;

		/** Why these values cannot work ("" when they can): out-of-range or
		 * non-finite values. loadFromConfigFile throws std::invalid_argument
		 * with it; alignScaled reports it as not merged. */
		std::string invalidReason() const;

		/** The lowest candidate score whose decision value can reach
		 * decision_threshold (with no rival above the floor). */
		double lowestMergeableScore() const;
		/** The least score a further candidate needs to matter once the
		 * best so far scores `best_score`: to merge, to beat it, or as a
		 * rival to lower its confidence (below confidence 1). */
		double relevantScore(double best_score) const;
		/** Decision value per unit of confidence: 0.2 (1 + runner-up weight). */
		double valuePerConfidence() const;
		/** Walls agreeing this well (bent consistency) against chance
		 * may merge on them: they lead chance by decision_min_lead. */
		bool leadsChance(double bent_consistency, double chance_consistency) const;
		/** Walls near each other run alike in at least
		 * decision_min_wall_alignment of the cases. */
		bool wallsRunAlike(double wall_alignment) const;
		/** Regions of the walls fit after shifts alike in at least
		 * decision_min_shift_coherence of adjacent tiles. */
		bool shiftsCohere(double shift_coherence) const;

		FeatureParams featureParams() const;
		TsICPParams icpParams() const;
		LatticeShiftParams latticeParams() const;
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
		/** Tolerant consistency of both maps' wall points (MapAgreement.h,
		 * twoWaySupport) and the best of it under far perturbations of the
		 * same transform: what chance gives in these two maps. */
		double tolerant_consistency = 0, chance_consistency = 0;
		double support = 0;  //!< share of wall points near a wall of the other map
		double chance_support = 0;  //!< the best support under the same far perturbations
		/** Of the wall points near a wall of the other map, the share near
		 * one running the same way (TwoWaySupport::wallAlignment). */
		double wall_alignment = 0;
		/** Of adjacent tiles of the moved walls, the share whose best small
		 * shifts agree (TwoWayShiftField::coherence). */
		double shift_coherence = 0;
		/** Feature matches this transform takes onto each other
		 * (decision_feature_weight). */
		size_t feature_agreement = 0;
		/** The tolerant consistency with each tile of the moved walls shifted
		 * as its neighbours fit best (TwoWayShiftField::bentConsistency): as
		 * if a smooth bend were taken out. */
		double bent_consistency = 0;
		size_t judged_points = 0;  //!< wall points on seen space, weaker direction
		/** bent_consistency + chance_weight · (it − chance) − √(evidence / judged) */
		double score = 0;
		/** From the cells alone (the maps coincide cell for cell); 0 when they cannot. */
		double exact_confidence = 0;
		/** Where the other map's wall centroid lands in the reference (cells):
		 * tells rival candidates apart. */
		Eigen::Vector2d other_centre{0, 0};
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
		/** Found for the mirrored other map (mirror_check): a rival of
		 * every candidate, never chosen. */
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
		/** Tolerant consistency of the chosen candidate (TCandidate), and
		 * the best of it under far perturbations (chance). */
		double consistency = 0, chance_consistency = 0;
		double wall_alignment = 0;  //!< TCandidate::wall_alignment of the chosen candidate
		double shift_coherence = 0;  //!< TCandidate::shift_coherence of the chosen candidate
		double bent_consistency = 0;  //!< TCandidate::bent_consistency of the chosen candidate
		size_t feature_agreement = 0;  //!< TCandidate::feature_agreement of the chosen candidate
		/** The chosen candidate's score, and where it is the pair's best-
		 * scoring one, its best distinct rival's score and the decision value
		 * (TCandidate; NaN otherwise). */
		double score = std::numeric_limits<double>::quiet_NaN();
		double runner_up_score = std::numeric_limits<double>::quiet_NaN();
		double decision_value = std::numeric_limits<double>::quiet_NaN();
		/** The best score of the mirrored other map (mirror_check; NaN where
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

	/** One map as the aligner sees it: its class image, feature pyramid,
	 * edge points and occupancy field. Preparing is most of an alignment's
	 * time, and a map in a fleet takes part in several pairs: prepare it
	 * once, align it in each. Valid with the options it was prepared with
	 * (alignScaled refuses maps prepared with other feature options). */
	struct TPreparedMap
	{
		/** Why this map cannot be aligned, after "reference map " or "other
		 * map " ("" when it can): no structure, too small or too large. */
		std::string problem;
		double resolution = 0;  //!< as stated
		Similarity2D cell_to_metric;  //!< the grid's cells → its metric frame
		cv::Mat classes;  //!< GridImage.h
		FeatureParams feature_params;  //!< those the features were extracted with
		std::vector<LevelFeatures> features;
		PointList edges;
		/** On `edges`, built once: every hypothesis's TsICP moves one map's
		 * edges, either map's (null with fewer than 3 edge points). */
		std::shared_ptr<const PointKDTree> edge_tree;
		OccupancyField field;
		std::map<std::string, double> stage_seconds;  //!< features, edges
	};
	using PreparedMapPtr = std::shared_ptr<const TPreparedMap>;

	/** Rivals, not one answer found twice: the candidates put the other map
	 * elsewhere (its wall centroid more than distinct_shift coarse cells
	 * apart, turned by more than verify_turn_deg, or scaled by over 10 %). */
	bool areRivals(const TCandidate& a, const TCandidate& b) const;
	/** The candidate's walls may decide a merge: they lead chance
	 * (leadsChance), run alike (wallsRunAlike) and shift alike region by
	 * region (shiftsCohere). */
	bool mayMergeOnWalls(const TCandidate& c) const;

	/** Prepares one map with these options. Never throws on bad content:
	 * the map's `problem` says what is wrong. */
	PreparedMapPtr prepare(const mrpt::maps::COccupancyGridMap2D& grid) const;

	/** The finish on occupied cells (icp_finish_on_occupied) of a transform
	 * between prepared maps' cells, on its own: what align() applies to the
	 * decided transform (when it moves no wall by more than
	 * finish_max_shift), exposed so the benchmark can start it from the truth. */
	Similarity2D finishOnOccupied(const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& cells) const;
	/** The refit over the whole overlap (finish_bent_lambda) of a transform
	 * between prepared maps' cells whose edges are `rmse_coarse_cells`
	 * apart (TCandidate::rmse_coarse_cells): what align() reports for the
	 * decided candidate. `cells` itself when off, below 1.5 coarse cells
	 * (finishOnOccupied's), or when the refit would place the other map
	 * elsewhere (a rival, areRivals). Exposed so the benchmark judges every
	 * candidate as it would be reported. */
	Similarity2D finishBent(
		const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& cells, double rmse_coarse_cells) const;

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
	 * any origin; `cells` is unchanged. */
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
	/** Features, edge points and occupancy field of a map's `classes`. */
	void describe(TPreparedMap& map) const;
	/** The map's edge points and the k-d tree on them (none below 3 points). */
	static void setEdges(TPreparedMap& map, PointList edges);
	/** The map with its x axis flipped, described (mirror_check). */
	PreparedMapPtr mirrored(const TPreparedMap& map) const;
	/** With `mirror_pass_relevant`: the search of mirror_check on the
	 * mirrored other map (no structure, no finish, no check of its own);
	 * hypotheses scoring below that score (less screen_margin) are screened. */
	TReturnInfo align(
		const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric,
		std::optional<double> mirror_pass_relevant = std::nullopt) const;
};

}  // namespace multires_map_merge
