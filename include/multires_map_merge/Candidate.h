#pragma once
// A refined hypothesis of one pair as the search judged it
// (CScalingGridMapAligner::TCandidate): what the decision, the report and the
// calibration data read of it.

#include <multires_map_merge/Decision.h>
#include <multires_map_merge/Similarity2D.h>

#include <Eigen/Core>

#include <limits>

namespace multires_map_merge
{
/** One refined hypothesis of a pair and how it was judged. */
struct Candidate
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

}  // namespace multires_map_merge
