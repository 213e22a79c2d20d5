#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/LatticeShift.h>
#include <multires_map_merge/MapAgreement.h>
#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/StructureHypotheses.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/system/CTicTac.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

#include <cmath>
#include <future>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

CScalingGridMapAligner::CScalingGridMapAligner()
{
	setLoggerName("CScalingGridMapAligner");
}

void CScalingGridMapAligner::TConfigParams::loadFromConfigFile(
	const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	MRPT_LOAD_CONFIG_VAR(pyramid_levels, int, c, s);
	MRPT_LOAD_CONFIG_VAR(feature_max_level_cells, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sift_contrast_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(sift_edge_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(ratio_test, double, c, s);
	MRPT_LOAD_CONFIG_VAR(ransac_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(ransac_iterations, int, c, s);
	MRPT_LOAD_CONFIG_VAR(ransac_min_inliers, int, c, s);
	MRPT_LOAD_CONFIG_VAR(hypotheses_per_level_pair, int, c, s);
	MRPT_LOAD_CONFIG_VAR(max_hypotheses, int, c, s);
	MRPT_LOAD_CONFIG_VAR(structure_search, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(exhaustive_search, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(mirror_check, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(xi_min, double, c, s);
	MRPT_LOAD_CONFIG_VAR(lambda, double, c, s);
	MRPT_LOAD_CONFIG_VAR(icp_max_iterations, int, c, s);
	MRPT_LOAD_CONFIG_VAR(icp_relative_tolerance, double, c, s);
	MRPT_LOAD_CONFIG_VAR(icp_coarse_points, int, c, s);
	MRPT_LOAD_CONFIG_VAR(screen_points, int, c, s);
	MRPT_LOAD_CONFIG_VAR(screen_margin, double, c, s);
	MRPT_LOAD_CONFIG_VAR(bend_refit_iterations, int, c, s);
	MRPT_LOAD_CONFIG_VAR(icp_finish_on_occupied, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(finish_max_shift, double, c, s);
	MRPT_LOAD_CONFIG_VAR(finish_lattice_step, double, c, s);
	MRPT_LOAD_CONFIG_VAR(finish_bent_lambda, double, c, s);
	MRPT_LOAD_CONFIG_VAR(verify_tolerance, double, c, s);
	MRPT_LOAD_CONFIG_VAR(verify_shift, double, c, s);
	MRPT_LOAD_CONFIG_VAR(verify_turn_deg, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_chance_weight, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_evidence, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_feature_weight, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_feature_cap, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_min_lead, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_min_wall_alignment, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_min_shift_coherence, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_runner_up_weight, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_runner_up_floor, double, c, s);
	MRPT_LOAD_CONFIG_VAR(distinct_shift, double, c, s);
	MRPT_LOAD_CONFIG_VAR(decision_threshold, double, c, s);
	MRPT_LOAD_CONFIG_VAR(min_confidence, double, c, s);
	MRPT_LOAD_CONFIG_VAR(use_resolution_metadata, bool, c, s);
	MRPT_LOAD_CONFIG_VAR(metadata_scale_tolerance, double, c, s);
	MRPT_LOAD_CONFIG_VAR(max_map_cells, double, c, s);
	if (const std::string why = invalidReason(); !why.empty())
		throw std::invalid_argument("[" + s + "] " + why);
}

std::string CScalingGridMapAligner::TConfigParams::invalidReason() const
{
	std::ostringstream why;
	auto in = [&](const char* name, double v, double lo, double hi) {
		if (!(v >= lo && v <= hi) && why.tellp() == 0)
			why << name << " = " << v << " is outside [" << lo << ", " << hi << "]";
	};
	in("pyramid_levels", pyramid_levels, 1, 8);
	in("feature_max_level_cells", feature_max_level_cells, 4096, 1e10);
	in("sift_contrast_threshold", sift_contrast_threshold, 0, 1);
	in("sift_edge_threshold", sift_edge_threshold, 1, 1e3);
	in("ratio_test", ratio_test, 0.1, 1);
	in("ransac_threshold", ransac_threshold, 0.1, 100);
	in("ransac_iterations", ransac_iterations, 1, 1e6);
	in("ransac_min_inliers", ransac_min_inliers, 2, 1e9);
	in("hypotheses_per_level_pair", hypotheses_per_level_pair, 1, 100);
	in("max_hypotheses", max_hypotheses, 1, 1000);
	in("xi_min", xi_min, 0.05, 1);
	in("lambda", lambda, 0, 100);
	in("icp_max_iterations", icp_max_iterations, 1, 1e5);
	in("icp_relative_tolerance", icp_relative_tolerance, 0, 1);
	in("icp_coarse_points", icp_coarse_points, 0, 1e9);
	if (screen_points != 0)  // 0 turns it off; a screen needs enough points to judge
		in("screen_points", screen_points, 100, 1e9);
	in("screen_margin", screen_margin, 0, 10);
	in("bend_refit_iterations", bend_refit_iterations, 0, 100);
	in("finish_max_shift", finish_max_shift, 0, 100);
	if (finish_lattice_step != 0)  // 0 turns it off; finer steps only cost time
		in("finish_lattice_step", finish_lattice_step, 0.01, 0.5);
	in("finish_bent_lambda", finish_bent_lambda, 0, 100);
	in("verify_tolerance", verify_tolerance, 0.5, 50);
	in("verify_shift", verify_shift, 1, 1000);
	in("verify_turn_deg", verify_turn_deg, 1, 90);
	in("decision_chance_weight", decision_chance_weight, 0, 10);
	in("decision_evidence", decision_evidence, 0, 1e6);
	in("decision_feature_weight", decision_feature_weight, 0, 10);
	in("decision_feature_cap", decision_feature_cap, 1, 1e6);
	in("decision_min_lead", decision_min_lead, -1, 1);
	in("decision_min_wall_alignment", decision_min_wall_alignment, 0, 1);
	in("decision_min_shift_coherence", decision_min_shift_coherence, 0, 1);
	in("decision_runner_up_weight", decision_runner_up_weight, 0, 100);
	in("decision_runner_up_floor", decision_runner_up_floor, -10, 10);
	in("distinct_shift", distinct_shift, 1, 1e4);
	in("decision_threshold", decision_threshold, 0, 10);
	in("min_confidence", min_confidence, 0, 1);
	in("metadata_scale_tolerance", metadata_scale_tolerance, 0, 10);
	in("max_map_cells", max_map_cells, 64, 1e10);
	return why.str();
}

void CScalingGridMapAligner::TConfigParams::saveToConfigFile(
	mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	MRPT_SAVE_CONFIG_VAR_COMMENT(pyramid_levels, "Pyramid levels per map (each halves the size)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(feature_max_level_cells, "Larger pyramid levels are not searched for features");
	MRPT_SAVE_CONFIG_VAR_COMMENT(sift_contrast_threshold, "SIFT contrast threshold");
	MRPT_SAVE_CONFIG_VAR_COMMENT(sift_edge_threshold, "SIFT edge threshold");
	MRPT_SAVE_CONFIG_VAR_COMMENT(ratio_test, "Lowe's ratio test for feature matches");
	MRPT_SAVE_CONFIG_VAR_COMMENT(ransac_threshold, "RANSAC inlier threshold [cells of the reference level]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(ransac_iterations, "RANSAC iterations per level pair");
	MRPT_SAVE_CONFIG_VAR_COMMENT(ransac_min_inliers, "Fewest RANSAC inliers for a hypothesis");
	MRPT_SAVE_CONFIG_VAR_COMMENT(hypotheses_per_level_pair, "RANSAC re-runs per level pair");
	MRPT_SAVE_CONFIG_VAR_COMMENT(max_hypotheses, "Hypotheses refined by TsICP");
	MRPT_SAVE_CONFIG_VAR_COMMENT(structure_search, "Also try structure hypotheses (unless a feature one is merged whatever comes)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(exhaustive_search, "Refine every hypothesis and always search the structure (calibration data)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(mirror_check, "Before merging on the walls (not on coinciding cells), the other map's mirror image is aligned too: its candidates are rivals");
	MRPT_SAVE_CONFIG_VAR_COMMENT(xi_min, "Smallest overlap TsICP may choose");
	MRPT_SAVE_CONFIG_VAR_COMMENT(lambda, "Overlap preference: psi = e/xi^(1+lambda)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(icp_max_iterations, "TsICP iteration limit");
	MRPT_SAVE_CONFIG_VAR_COMMENT(icp_relative_tolerance, "TsICP stops below this relative gain");
	MRPT_SAVE_CONFIG_VAR_COMMENT(icp_coarse_points, "TsICP converges on about this many points first (0: all)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(screen_points, "Each hypothesis is first refined and judged on about this many points (0: off)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(screen_margin, "Dropped there when its score is this far below the lowest score that can merge");
	MRPT_SAVE_CONFIG_VAR_COMMENT(bend_refit_iterations, "Refits of the transform to its wall tiles' best shifts (0: off)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(icp_finish_on_occupied, "Finish the decided transform by TsICP on all occupied cells");
	MRPT_SAVE_CONFIG_VAR_COMMENT(finish_max_shift, "A finish moving any point further is not taken [coarse cells]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(finish_lattice_step, "Step of the finish's sub-cell shift on the coarser lattice (0: off) [coarse cells]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(finish_bent_lambda, "Maps that bend: the decided transform is refit with this overlap preference (0: off)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(verify_tolerance, "Walls this close agree [cells of the coarser map]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(verify_shift, "Chance: the transform shifted by this much [coarse cells]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(verify_turn_deg, "Chance: the transform turned by this much [deg]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_chance_weight, "Score = B + w (B - chance T) - sqrt(evidence / judged) + feature term");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_evidence, "Evidence discount of small overlaps [wall points]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_feature_weight, "Score gained at decision_feature_cap agreeing feature matches");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_feature_cap, "Agreeing feature matches beyond this gain no more");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_min_lead, "Merged on its walls only if they agree more than chance by this");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_min_wall_alignment, "Merged on its walls only if this share of near walls run alike");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_min_shift_coherence, "Merged on its walls only if this share of adjacent regions fit after alike shifts");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_runner_up_weight, "Decision value = best score + w (it - best distinct rival's score)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_runner_up_floor, "A rival scoring below this counts as this");
	MRPT_SAVE_CONFIG_VAR_COMMENT(distinct_shift, "Candidates this far apart are rivals [coarse cells]");
	MRPT_SAVE_CONFIG_VAR_COMMENT(decision_threshold, "Decision value at confidence 0.5 (calibrated)");
	MRPT_SAVE_CONFIG_VAR_COMMENT(min_confidence, "Below this the maps are reported as not merged");
	MRPT_SAVE_CONFIG_VAR_COMMENT(use_resolution_metadata, "Use the stated resolutions as a scale prior");
	MRPT_SAVE_CONFIG_VAR_COMMENT(metadata_scale_tolerance, "Relative scale tolerance of that prior");
	MRPT_SAVE_CONFIG_VAR_COMMENT(max_map_cells, "Larger maps are refused (bounds peak memory)");
}

namespace
{
/** Whether two placements of the other map (its transform into the
 * reference's cells and where its wall centroid lands) are within `cells`
 * coarse cells at the centroid, `turn_deg` and `log_scale` of each other. */
bool samePlacement(
	const Similarity2D& a, const Eigen::Vector2d& a_centre, const Similarity2D& b, const Eigen::Vector2d& b_centre,
	double cells, double turn_deg, double log_scale)
{
	const double coarse = std::max({1.0, a.scale, b.scale});
	return (a_centre - b_centre).norm() <= cells * coarse &&
		std::abs(std::remainder(a.yaw - b.yaw, 2 * M_PI)) <= turn_deg * M_PI / 180 &&
		std::abs(std::log(a.scale / b.scale)) <= log_scale;
}
}  // namespace

bool CScalingGridMapAligner::areRivals(const TCandidate& a, const TCandidate& b) const
{
	return !samePlacement(
		a.cells, a.other_centre, b.cells, b.other_centre, options.distinct_shift, options.verify_turn_deg,
		std::log(1.1));
}

bool CScalingGridMapAligner::TConfigParams::leadsChance(double bent_consistency, double chance_consistency) const
{
	return bent_consistency - chance_consistency >= decision_min_lead;
}

bool CScalingGridMapAligner::TConfigParams::wallsRunAlike(double wall_alignment) const
{
	return wall_alignment >= decision_min_wall_alignment;
}

bool CScalingGridMapAligner::TConfigParams::shiftsCohere(double shift_coherence) const
{
	return shift_coherence >= decision_min_shift_coherence;
}

bool CScalingGridMapAligner::mayMergeOnWalls(const TCandidate& c) const
{
	return options.leadsChance(c.bent_consistency, c.chance_consistency) &&
		options.wallsRunAlike(c.wall_alignment) && options.shiftsCohere(c.shift_coherence);
}

double CScalingGridMapAligner::TConfigParams::lowestMergeableScore() const
{
	// value = s + k (s − rival) with rival ≥ floor, so value ≥ threshold needs
	// (1 + k) s − k floor ≥ threshold.
	return (decision_threshold + decision_runner_up_weight * decision_runner_up_floor) /
		(1 + decision_runner_up_weight);
}

double CScalingGridMapAligner::TConfigParams::relevantScore(double best_score) const
{
	// A rival r lowers the confidence of value s + k (s − r) while that is
	// below the value of confidence 1: r > s − (V₁ − s)/k. A better s raises
	// both bounds, so the least relevant score only rises.
	const double k = decision_runner_up_weight;
	if (!(k > 0) || !std::isfinite(best_score)) return lowestMergeableScore();
	const double value_for_certainty = decision_threshold + 0.5 * valuePerConfidence();
	return std::max(lowestMergeableScore(), std::min(best_score, best_score - (value_for_certainty - best_score) / k));
}

double CScalingGridMapAligner::TConfigParams::valuePerConfidence() const
{
	// Confidence 0.5 at the threshold, rising by 1 over 0.2 (1 + k) of value.
	return 0.2 * (1 + decision_runner_up_weight);
}

FeatureParams CScalingGridMapAligner::TConfigParams::featureParams() const
{
	FeatureParams p;
	p.pyramid_levels = pyramid_levels;
	p.max_level_cells = feature_max_level_cells;
	p.sift_contrast_threshold = sift_contrast_threshold;
	p.sift_edge_threshold = sift_edge_threshold;
	p.ratio_test = ratio_test;
	p.ransac_threshold = ransac_threshold;
	p.ransac_iterations = ransac_iterations;
	p.min_inliers = ransac_min_inliers;
	p.hypotheses_per_level_pair = hypotheses_per_level_pair;
	return p;
}

LatticeShiftParams CScalingGridMapAligner::TConfigParams::latticeParams() const
{
	LatticeShiftParams p;
	p.step = finish_lattice_step;
	return p;
}

TsICPParams CScalingGridMapAligner::TConfigParams::icpParams() const
{
	TsICPParams p;
	p.xi_min = xi_min;
	p.lambda = lambda;
	p.max_iterations = icp_max_iterations;
	p.relative_tolerance = icp_relative_tolerance;
	p.coarse_points = icp_coarse_points;
	return p;
}

namespace
{
std::string checkGrid(const COccupancyGridMap2D& g)
{
	std::ostringstream why;
	const double res = g.getResolution();
	if (!std::isfinite(res) || !(res > 0))
		why << "has an invalid resolution (" << res << ")";
	else if (!std::isfinite(g.getXMin()) || !std::isfinite(g.getYMin()))
		why << "has a non-finite origin";
	else if (g.getSizeX() < 8 || g.getSizeY() < 8)
		why << "is too small (" << g.getSizeX() << "x" << g.getSizeY()
			<< " cells; at least 8x8 needed)";
	return why.str();
}

// Confidence that two maps coincide cell for cell (two parts of one SLAM
// run: walls within a cell), from the strict cell agreement, discounted when
// the overlap TsICP settled on is pinned at ξmin (the sign of a wrong start)
// or when the fitted edges sit far apart. A pinned ξ whose pairs fit to a
// fraction of a cell is no such sign: maps whose edges coincide exactly on
// part of the overlap make ψ = 0 there, and any larger ξ loses to it.
// At this edge RMSE (coarse cells) or more the maps are not the same cells:
// exactConfidence is 0 whatever the cells say.
constexpr double kExactMaxRmse = 1.5;
// At this cell consistency or less, neither. The screen's tolerant
// consistency (walls 3 coarse cells apart do not conflict) is the same
// count with a wider margin: on the calibration pairs it never fell more
// than 0.03 below the cell consistency; 0.05 less leaves room for its sample.
constexpr double kExactMinConsistency = 0.7;
constexpr double kExactMinScreenConsistency = kExactMinConsistency - 0.05;
// A sample refinement this close to a candidate that coincides cell for cell
// (centre in coarse cells, turn, log scale) is the same placement: within
// the spread of TsICP's optima from different starts on one pair of maps.
constexpr double kSamePlacementCells = 1.5;
constexpr double kSamePlacementTurnDeg = 0.5;
constexpr double kSamePlacementScale = 0.01;

double exactConfidence(double consistency, double overlap, double xi_min, double rmse_coarse)
{
	const double exact = std::clamp((0.5 - rmse_coarse) / 0.2, 0.0, 1.0);
	const double pinned = std::max(exact, std::clamp((overlap - xi_min) / 0.02, 0.0, 1.0));
	const double tight = std::clamp(kExactMaxRmse - rmse_coarse, 0.0, 1.0);
	const double agree = std::clamp((consistency - kExactMinConsistency) / 0.25, 0.0, 1.0);
	return agree * std::min(pinned, tight);
}

// Fewer wall points than this on the other map's seen space (in the weaker
// direction) is too little overlap to judge.
constexpr size_t kMinJudgedPoints = 40;
}  // namespace

namespace
{
/** Whether `q` (target cells) rounds to a set cell of `mask`. */
bool onMask(const cv::Mat& mask, const Eigen::Vector2d& q)
{
	const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
	return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x);
}

/** Share of `points` that `t` moves onto the target's known space. */
double shareOnKnown(const PointList& points, const Similarity2D& t, const OccupancyField& target)
{
	if (points.empty()) return 0;
	size_t on = 0;
	const Eigen::Matrix2d a = t.linear();
	for (const auto& p : points) on += onMask(target.known, a * p + t.t);
	return double(on) / points.size();
}

/** How far `to` moves `points` from where `from` puts them (reference
 * cells), over those that `from` puts on the reference's known space. */
double largestShift(const PointList& points, const Similarity2D& from, const Similarity2D& to, const OccupancyField& ref)
{
	double shift = 0;
	const Eigen::Matrix2d a = from.linear(), b = to.linear();
	for (const auto& p : points)
	{
		const Eigen::Vector2d q = a * p + from.t;
		if (onMask(ref.known, q)) shift = std::max(shift, (b * p + to.t - q).norm());
	}
	return shift;
}

/** The points that `t` puts on `near_known` (a target's knownWithin). The
 * margin keeps whole walls: the space behind a wall is unknown, and a wall
 * band cut where the other map's knowledge ends would pull the fit to one
 * side. */
PointList nearKnown(const PointList& points, const Similarity2D& t, const cv::Mat& near_known)
{
	PointList inside;
	const Eigen::Matrix2d a = t.linear();
	for (const auto& p : points)
		if (onMask(near_known, a * p + t.t)) inside.push_back(p);
	return inside;
}

/** TsICP on the occupied cells both maps see (their overlap under `cells`),
 * from `cells`, the coarser map's cells as the fixed set: each coarse cell
 * centre lies inside the band the finer map draws a wall with and finds its
 * partner there, while a fine point finds a coarse centre up to half a coarse
 * cell off, to one side or the other. The coarse centres keep the coarse
 * map's rounding, which `lattice` then takes out (LatticeShift.h). Returns
 * `cells` when the overlap is too thin to refine on. */
Similarity2D finishOnOccupiedCells(
	const CScalingGridMapAligner::TPreparedMap& ref, const CScalingGridMapAligner::TPreparedMap& other,
	const Similarity2D& cells, const TsICPParams& ip, const LatticeShiftParams& lattice)
{
	// Two cells of the coarser map, in each target's cells.
	const double coarse_in_ref = std::max(1.0, cells.scale), coarse_in_other = coarse_in_ref / cells.scale;
	const cv::Mat ref_near_known = knownWithin(ref.field.known, 2 * coarse_in_ref);
	const cv::Mat other_near_known = knownWithin(other.field.known, 2 * coarse_in_other);
	// From the classes here rather than kept prepared: only merged pairs pay.
	const PointList ref_seen = nearKnown(occupiedPoints(ref.classes), cells.inverse(), other_near_known);
	const PointList other_seen = nearKnown(occupiedPoints(other.classes), cells, ref_near_known);
	if (ref_seen.size() < 10 || other_seen.size() < 10) return cells;
	const bool other_coarser = cells.scale > 1;
	const PointList& coarse_seen = other_coarser ? other_seen : ref_seen;
	const PointList& fine_seen = other_coarser ? ref_seen : other_seen;
	const TsICPResult r = runTsICP(coarse_seen, fine_seen, other_coarser ? cells.inverse() : cells, ip);
	Similarity2D fine_to_coarse = r.transform;
	if (lattice.step > 0 && fine_to_coarse.isFinite())
	{
		PointList fine_in_coarse(fine_seen.size());
		const Eigen::Matrix2d a = fine_to_coarse.linear();
		for (size_t i = 0; i < fine_seen.size(); ++i) fine_in_coarse[i] = a * fine_seen[i] + fine_to_coarse.t;
		// Two cells of the coarse map: what latticeShift counts extras on.
		const cv::Mat& coarse_near_known = other_coarser ? other_near_known : ref_near_known;
		const Eigen::Vector2d shift = latticeShift(fine_in_coarse, coarse_seen, coarse_near_known, lattice);
		fine_to_coarse = Similarity2D(1, 0, shift).compose(fine_to_coarse);
	}
	const Similarity2D t = other_coarser ? fine_to_coarse.inverse() : fine_to_coarse;
	return t.isFinite() && t.scale > 0 ? t : cells;
}

/** TsICP trims to the share ξ ≥ ξmin of its fixed set's points that find a
 * partner, so the fixed set should be the map that lies more inside the
 * other (a small map inside a large one): judged at the start transform.
 * The result is always other → ref, in reference cells. */
TsICPResult refineFromTheInside(
	const CScalingGridMapAligner::TPreparedMap& ref, const CScalingGridMapAligner::TPreparedMap& other,
	const Similarity2D& start, const TsICPParams& ip, size_t fixed_points = 0)
{
	const double ref_inside = shareOnKnown(ref.edges, start.inverse(), other.field);
	const double other_inside = shareOnKnown(other.edges, start, ref.field);
	// Sampled only when asked: the fixed set is otherwise used in place, not copied.
	auto run = [&](const PointList& fixed, const PointKDTree& moving, const Similarity2D& from) {
		return fixed_points > 0 && fixed.size() > fixed_points ? runTsICP(strided(fixed, fixed_points), moving, from, ip)
															   : runTsICP(fixed, moving, from, ip);
	};
	if (other_inside <= ref_inside) return run(ref.edges, *other.edge_tree, start);
	TsICPResult r = run(other.edges, *ref.edge_tree, start.inverse());
	const double s2 = 1.0 / (r.transform.scale * r.transform.scale);  // other cells² → ref cells²
	r.transform = r.transform.inverse();
	r.trimmed_mse *= s2;
	r.objective *= s2;
	for (auto& o : r.objective_history) o *= s2;
	return r;
}
}  // namespace

CScalingGridMapAligner::PreparedMapPtr CScalingGridMapAligner::prepare(const COccupancyGridMap2D& grid) const
{
	auto p = std::make_shared<TPreparedMap>();
	p->resolution = grid.getResolution();
	p->feature_params = options.featureParams();
	if (!options.invalidReason().empty()) return p;  // alignScaled says why; nothing here is safe to run
	if (std::string why = checkGrid(grid); !why.empty())
	{
		p->problem = std::move(why);
		return p;
	}
	if (double(grid.getSizeX()) * grid.getSizeY() > options.max_map_cells)
	{
		std::ostringstream why;
		why << "is too large (" << grid.getSizeX() << "x" << grid.getSizeY() << " cells > max_map_cells = "
			<< options.max_map_cells << "); resample it coarser or raise max_map_cells (memory grows with it)";
		p->problem = why.str();
		return p;
	}
	p->cell_to_metric = cellToMetric(grid);

	// 1. The map as an image; features over a resolution pyramid (describe).
	mrpt::system::CTicTac stage;
	p->classes = toClassImage(grid);
	p->stage_seconds["features"] = stage.Tac();
	// Said plainly here rather than as "no feature matches" later.
	const int occupied = cv::countNonZero(p->classes == kOccupied), free = cv::countNonZero(p->classes == kFree);
	if (occupied + free == 0) p->problem = "is all unknown: nothing to align";
	else if (occupied == 0) p->problem = "has no occupied cells: nothing to align";
	else if (free == 0) p->problem = "has no free cells: no walls to align";
	if (!p->problem.empty()) return p;
	describe(*p);
	return p;
}

void CScalingGridMapAligner::setEdges(TPreparedMap& p, PointList edges)
{
	p.edges = std::move(edges);
	p.edge_tree = p.edges.size() >= 3 ? std::make_shared<const PointKDTree>(p.edges) : nullptr;
}

void CScalingGridMapAligner::describe(TPreparedMap& p) const
{
	mrpt::system::CTicTac stage;
	p.features = extractPyramidFeatures(p.classes, p.feature_params);
	p.stage_seconds["features"] += stage.Tac();

	// 2. Edge points, and what the verification judges them against.
	stage.Tic();
	setEdges(p, edgePoints(p.classes));
	p.field = occupancyField(p.classes);
	p.stage_seconds["edges"] += stage.Tac();
}

CScalingGridMapAligner::PreparedMapPtr CScalingGridMapAligner::mirrored(const TPreparedMap& map) const
{
	auto p = std::make_shared<TPreparedMap>();
	p->resolution = map.resolution;
	p->feature_params = map.feature_params;
	p->cell_to_metric = map.cell_to_metric;  // not a frame: only cells are compared
	cv::flip(map.classes, p->classes, 1);
	// SIFT is not mirror-symmetric: the features anew, on another thread
	// (one map here, not two at once). The edges and the field are the map's
	// own mirrored: the same as computed on the flipped map (the exact
	// distance transform is symmetric; the points in the scan order
	// edgePoints gives), without computing them.
	auto features = std::async(
		std::launch::async, [&]() { return extractPyramidFeatures(p->classes, p->feature_params); });
	const double last_x = map.classes.cols - 1;
	PointList edges;
	edges.reserve(map.edges.size());
	for (const auto& e : map.edges) edges.emplace_back(last_x - e.x(), e.y());
	std::sort(edges.begin(), edges.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
		return std::pair(a.y(), a.x()) < std::pair(b.y(), b.x());
	});
	setEdges(*p, std::move(edges));
	cv::flip(map.field.dist_to_occupied, p->field.dist_to_occupied, 1);
	cv::flip(map.field.dist_to_not_free, p->field.dist_to_not_free, 1);
	cv::flip(map.field.known, p->field.known, 1);
	p->features = features.get();
	return p;
}

Similarity2D CScalingGridMapAligner::finishOnOccupied(
	const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& cells) const
{
	return finishOnOccupiedCells(ref, other, cells, options.icpParams(), options.latticeParams());
}

Similarity2D CScalingGridMapAligner::finishBent(
	const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& cells, double rmse_coarse_cells) const
{
	// Maps whose edges may coincide are the exact finish's (finishOnOccupied).
	if (options.finish_bent_lambda <= 0 || !(rmse_coarse_cells >= kExactMaxRmse) || other.edges.empty() ||
		!ref.edge_tree || !other.edge_tree)
		return cells;
	TsICPParams wide = options.icpParams();
	wide.lambda = options.finish_bent_lambda;
	const Similarity2D refit = refineFromTheInside(ref, other, cells, wide).transform;
	Eigen::Vector2d other_centroid(0, 0);
	for (const auto& p : other.edges) other_centroid += p;
	other_centroid /= double(other.edges.size());
	// The decision judged `cells`: the refit moves it within its bends, never
	// to a rival placement.
	if (refit.isFinite() && refit.scale > 0 &&
		samePlacement(
			refit, refit.apply(other_centroid), cells, cells.apply(other_centroid), options.distinct_shift,
			options.verify_turn_deg, std::log(1.1)))
		return refit;
	MRPT_LOG_DEBUG_STREAM("refit over the whole overlap not taken: it places the other map elsewhere");
	return cells;
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const COccupancyGridMap2D& ref, const COccupancyGridMap2D& other) const
{
	mrpt::system::CTicTac total;
	// The two maps are independent: prepared at once (prepare logs nothing;
	// OpenCV runs a parallel_for_ that finds its pool busy on the caller's
	// thread). Most of that time is serial: distance field, edges, k-d tree.
	auto other_prepared = std::async(std::launch::async, [&]() { return prepare(other); });
	const PreparedMapPtr ref_map = prepare(ref), other_map = other_prepared.get();
	TReturnInfo info = alignScaled(*ref_map, *other_map);
	for (const auto* p : {ref_map.get(), other_map.get()})
		for (const auto& [name, seconds] : p->stage_seconds) info.stage_seconds[name] += seconds;
	info.executionTime = total.Tac();
	return info;
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const TPreparedMap& ref, const TPreparedMap& other) const
{
	return align(ref, other, std::nullopt);
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& start_metric) const
{
	return align(ref, other, start_metric);
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::align(
	const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric,
	std::optional<double> mirror_pass_relevant) const
{
	const bool mirror_pass = mirror_pass_relevant.has_value();
	mrpt::system::CTicTac total, stage;
	TReturnInfo info;
	auto fail = [&](const std::string& why) {
		info.success = false;
		info.message = why;
		info.executionTime = total.Tac();
		MRPT_LOG_INFO_STREAM("not merged: " << why);
		return info;
	};
	if (const std::string why = options.invalidReason(); !why.empty())
		return fail("invalid parameters: " + why);
	for (const auto& [p, which] : {std::pair{&ref, "reference"}, std::pair{&other, "other"}})
		if (!p->problem.empty()) return fail(std::string(which) + " map " + p->problem);
	const FeatureParams fp = options.featureParams();
	if (!sameExtraction(fp, ref.feature_params) || !sameExtraction(fp, other.feature_params))
		return fail("the maps were prepared with other feature options than this aligner's");

	std::optional<double> expected_scale;
	if (options.use_resolution_metadata) expected_scale = other.resolution / ref.resolution;

	// 2. Edge points (prepared).
	const PointList &ref_edges = ref.edges, &other_edges = other.edges;
	const OccupancyField &ref_field = ref.field, &other_field = other.field;
	const cv::Mat &ref_img = ref.classes, &other_img = other.classes;
	info.ref_edge_points = ref_edges.size();
	info.other_edge_points = other_edges.size();
	if (ref_edges.size() < 10 || other_edges.size() < 10)
		return fail("too few occupied cells bordering free space to register the maps");

	// Feature matches of every pyramid level pair: RANSAC's input, and
	// evidence of each candidate (decision_feature_weight).
	stage.Tic();
	const std::vector<LevelMatches> matches = featureMatches(ref.features, other.features, fp);
	info.stage_seconds["matches"] = stage.Tac();

	// 3. TsICP from each hypothesis; 4. judge each on the cells. The best
	// confidence wins; ψ breaks ties between equally trusted refinements.
	const TsICPParams ip = options.icpParams();
	double icp_s = 0, verify_s = 0;
	bool have = false;
	// One hypothesis refined and judged: no shared state, so a few run at once.
	struct Refined
	{
		bool valid = false;
		TsICPResult r;
		TCandidate cand;
		double icp_s = 0, verify_s = 0;
	};
	// The decision's score of a transform, judged on at most `most` points
	// per map; with fewer than the decision judges, the evidence discount is
	// taken for the count the decision would judge.
	// The wall alignment is judged in the full judgement only (`in_full`):
	// a screen never decides.
	struct Judgement
	{
		TwoWaySupport sup;
		Chance chance;
		TwoWayShiftField bends;
		size_t feature_agreement = 0;
		double score = 0;
	};
	auto decisionScore = [&](const Similarity2D& t, size_t most, bool in_full) {
		Judgement j;
		j.sup = twoWaySupport(ref_edges, ref_field, other_edges, other_field, t, options.verify_tolerance, most, in_full);
		j.chance = chanceSupport(
			ref_edges, ref_field, other_edges, other_field, t, options.verify_tolerance, options.verify_shift,
			options.verify_turn_deg, most);
		j.bends = twoWayShiftField(ref_edges, ref_field, other_edges, other_field, t, options.verify_tolerance, most);
		auto full = [&](size_t judged, size_t n) {
			return double(judged) * double(std::min(n, kJudgedPoints)) / double(std::max<size_t>(1, std::min(n, most)));
		};
		const double judged = std::min(
			full(j.sup.other_in_ref.judged, other_edges.size()), full(j.sup.ref_in_other.judged, ref_edges.size()));
		// Judged as if a smooth bend were taken out (TwoWayShiftField): two
		// SLAM runs of one building differ by one.
		const double bc = j.bends.bentConsistency();
		j.feature_agreement = agreeingMatches(matches, t);
		j.score = bc + options.decision_chance_weight * (bc - j.chance.consistency) -
			std::sqrt(options.decision_evidence / std::max(1.0, judged)) +
			options.decision_feature_weight * std::min(double(j.feature_agreement), options.decision_feature_cap) /
				options.decision_feature_cap;
		return j;
	};
	// The transform refit to where its regions fit best (bend_refit_iterations),
	// from its judgement's shift field (the first refit's: not computed again).
	auto bendRefit = [&](const Judgement& judged_at, Similarity2D t) {
		for (int i = 0; i < options.bend_refit_iterations && t.isFinite() && t.scale > 0; ++i)
			t = bendBalanced(
				i == 0 ? judged_at.bends
					   : twoWayShiftField(ref_edges, ref_field, other_edges, other_field, t, options.verify_tolerance),
				t);
		return t;
	};
	Eigen::Vector2d other_centroid(0, 0);
	for (const auto& p : other_edges) other_centroid += p;
	other_centroid /= double(other_edges.size());
	auto candidate = [&other_centroid](const Hypothesis& h, const TsICPResult& r, double rmse_coarse, double cell_consistency,
						const Judgement& j) {
		const TwoWaySupport& sup = j.sup;
		TCandidate c;
		c.initial_cells = h.other_to_ref;
		c.cells = r.transform;
		c.overlap = r.overlap;
		c.rmse_coarse_cells = rmse_coarse;
		c.consistency = cell_consistency;
		c.tolerant_consistency = sup.consistency();
		c.chance_consistency = j.chance.consistency;
		c.support = sup.score();
		c.chance_support = j.chance.support;
		c.wall_alignment = sup.wallAlignment();
		c.bent_consistency = j.bends.bentConsistency();
		c.shift_coherence = j.bends.coherence();
		c.feature_agreement = j.feature_agreement;
		c.judged_points = sup.judged();
		c.score = j.score;
		c.other_centre = r.transform.apply(other_centroid);
		return c;
	};
	// With use_resolution_metadata, a refinement that leaves the stated scale is no candidate.
	auto scaleAsStated = [&](const Similarity2D& t) {
		return !expected_scale ||
			std::abs(std::log(t.scale / *expected_scale)) <= std::log1p(options.metadata_scale_tolerance);
	};
	// The screen's bar (stopsAtScreen): below it a hypothesis can neither merge
	// nor, as a rival, lower the best candidate's confidence; raised by
	// refineAll as better candidates are found.
	const double least_relevant = mirror_pass && !options.exhaustive_search
		? std::max(options.lowestMergeableScore(), *mirror_pass_relevant)
		: options.lowestMergeableScore();
	double screen_bar = least_relevant - options.screen_margin;
	// Candidates whose maps coincide cell for cell, found in earlier batches
	// (refineAll): a hypothesis whose sample refinement lands on one of them
	// is not refined again. Same-log maps give many hypotheses that all
	// converge there; refining each on every point was most of the time on
	// large maps. Read-only while a batch runs.
	std::vector<TCandidate> exact_found;
	auto onExactFound = [&](const Similarity2D& t) {
		const Eigen::Vector2d centre = t.apply(other_centroid);
		return std::any_of(exact_found.begin(), exact_found.end(), [&](const TCandidate& c) {
			return samePlacement(
				t, centre, c.cells, c.other_centre, kSamePlacementCells, kSamePlacementTurnDeg, kSamePlacementScale);
		});
	};
	// The cheap verification of a hypothesis (screen_points): TsICP on a
	// sample of the fixed set, judged on samples. It needs nothing of the
	// other hypotheses, so screens run ahead of the refinements they gate.
	struct Screen
	{
		bool ran = false;  //!< screen_points > 0
		bool valid = false;  //!< a finite transform at the scale allowed
		TsICPResult quick;
		Judgement judged;
		double rmse_coarse = 0;
		bool may_be_exact = false;
		double icp_s = 0, verify_s = 0;
	};
	auto screenOne = [&](const Hypothesis& h) {
		Screen s;
		if (options.screen_points <= 0) return s;
		s.ran = true;
		mrpt::system::CTicTac clock;
		s.quick = refineFromTheInside(ref, other, h.other_to_ref, ip, size_t(options.screen_points));
		s.icp_s = clock.Tac();
		if (!s.quick.transform.isFinite() || !(s.quick.transform.scale > 0) || !scaleAsStated(s.quick.transform))
			return s;
		clock.Tic();
		s.judged = decisionScore(s.quick.transform, size_t(options.screen_points), false);
		s.verify_s = clock.Tac();
		s.rmse_coarse = std::sqrt(s.quick.trimmed_mse) / std::max(1.0, s.quick.transform.scale);
		MRPT_LOG_DEBUG_STREAM(
			"screen " << h.other_to_ref << " -> " << s.quick.transform << " rmse " << s.rmse_coarse
					  << " tolerant consistency " << s.judged.sup.consistency() << " bent "
					  << s.judged.bends.bentConsistency() << " chance " << s.judged.chance.consistency << " score "
					  << s.judged.score);
		// Only where neither way to be sure (below) is near: the maps are
		// not the same cells, and their walls agree too little.
		s.may_be_exact = s.rmse_coarse < kExactMaxRmse && s.judged.sup.consistency() > kExactMinScreenConsistency;
		s.valid = true;
		return s;
	};
	// A screened hypothesis goes no further when it cannot come near a merge
	// (below the screen's bar: it is not refined on every point nor judged in
	// full) or it landed on a candidate found to coincide cell for cell.
	auto convergedOnExact = [&](const Screen& s) {
		return s.valid && !options.exhaustive_search && onExactFound(s.quick.transform);
	};
	auto stopsAtScreen = [&](const Screen& s) {
		return s.ran && (!s.valid || (!s.may_be_exact && s.judged.score < screen_bar) || convergedOnExact(s));
	};
	// What a hypothesis that stops at its screen leaves: its screen's
	// candidate (none without a valid screen).
	auto screenedOnly = [&](const Hypothesis& h, const Screen& s) {
		Refined out;
		out.icp_s = s.icp_s, out.verify_s = s.verify_s;
		if (!s.valid) return out;
		out.cand = candidate(h, s.quick, s.rmse_coarse, std::numeric_limits<double>::quiet_NaN(), s.judged);
		out.cand.screened = true;
		out.cand.converged_on_exact = convergedOnExact(s);
		out.r = s.quick;
		out.valid = true;
		return out;
	};
	auto refineInFull = [&](const Hypothesis& h, const Screen& s) {
		Refined out;
		out.icp_s = s.icp_s, out.verify_s = s.verify_s;
		// Independent maps: refined on every point from the sample's result
		// (fewer iterations; the same optimum to within a cell). Where the
		// maps may coincide cell for cell, from the hypothesis, as without the
		// screen: converged from a sample, TsICP stops a few hundredths of a
		// cell short of exact.
		const Similarity2D full_start = s.ran && !s.may_be_exact ? s.quick.transform : h.other_to_ref;
		mrpt::system::CTicTac clock;
		TsICPResult r = refineFromTheInside(ref, other, full_start, ip);
		out.icp_s += clock.Tac();
		if (!r.transform.isFinite() || !(r.transform.scale > 0) || !scaleAsStated(r.transform)) return out;

		// 4. Judge on the cells, against chance (MapAgreement.h).
		clock.Tic();
		const double coarse = std::max(1.0, r.transform.scale);  // coarser cell, in ref cells
		const double rmse_coarse = std::sqrt(r.trimmed_mse) / coarse;
		// The strict cell check warps whole maps: spared where it cannot count
		// (most hypotheses between independent maps).
		const bool may_be_exact = rmse_coarse < kExactMaxRmse;
		const double cell_consistency = may_be_exact ? mapAgreement(ref_img, other_img, r.transform).consistency
													 : std::numeric_limits<double>::quiet_NaN();
		Judgement judgement = decisionScore(r.transform, kJudgedPoints, true);
		// Refit to where its regions fit best (bend_refit_iterations).
		if (options.bend_refit_iterations > 0 && !may_be_exact)
		{
			const Similarity2D balanced = bendRefit(judgement, r.transform);
			if (balanced.isFinite() && balanced.scale > 0 && scaleAsStated(balanced))
				if (Judgement j = decisionScore(balanced, kJudgedPoints, true); j.score > judgement.score)
					judgement = std::move(j), r.transform = balanced;
		}
		out.verify_s += clock.Tac();
		TCandidate& cand = out.cand;
		cand = candidate(h, r, rmse_coarse, cell_consistency, judgement);
		// The first way to be sure (the maps coincide cell for cell) is this
		// candidate's alone; the second is the pair's (decide, below). Both
		// need walls enough to judge: a map squeezed into a few cells (TsICP
		// let the scale collapse to 0.02 on two disjoint parts) agrees with
		// anything there.
		cand.exact_confidence = may_be_exact && cand.judged_points >= kMinJudgedPoints
			? exactConfidence(cell_consistency, r.overlap, ip.xi_min, rmse_coarse)
			: 0.0;
		cand.confidence = cand.exact_confidence;
		out.r = r;
		out.valid = true;
		return out;
	};
	// Every judged candidate with what the report needs of its hypothesis.
	struct Judged
	{
		Hypothesis h;
		TsICPResult r;
	};
	std::vector<Judged> judged;
	auto confidenceOfValue = [&](double value) {
		return std::clamp(0.5 + (value - options.decision_threshold) / options.valuePerConfidence(), 0.0, 1.0);
	};
	// Merged whatever the other hypotheses give: the maps coincide cell for
	// cell, or the candidate's score alone (above the floor) reaches the
	// confidence (a rival scores at most as much, so the decision value is at
	// least the score; one scoring more would itself be merged). Searching on
	// is then only time: independent maps never get there (calibration data).
	auto mergedWhateverComes = [&](const TCandidate& c, double exact_needed) {
		return c.exact_confidence >= exact_needed ||
			(!c.screened && c.judged_points >= kMinJudgedPoints && c.score >= options.decision_runner_up_floor &&
			 mayMergeOnWalls(c) &&
			 confidenceOfValue(c.score) >= std::max(0.5, options.min_confidence));
	};
	// Two ways to be sure: the maps coincide cell for cell (a candidate's
	// exact_confidence), or (independent maps) the best-scoring candidate's
	// walls agree well above chance and better than any distinct rival's
	// (its decision value). The chosen candidate's numbers go to `info`.
	auto decide = [&]() {
		auto& cands = info.candidates;
		size_t best = cands.size();
		for (size_t i = 0; i < cands.size(); ++i)
			if (!cands[i].screened && !cands[i].mirrored && cands[i].judged_points >= kMinJudgedPoints &&
				(best == cands.size() || cands[i].score > cands[best].score))
				best = i;
		for (size_t i = 0; i < cands.size(); ++i)
		{
			TCandidate& c = cands[i];
			c.confidence = c.exact_confidence;
			if (i != best) continue;
			// Screened candidates are no rivals: they scored below the lowest
			// mergeable score less screen_margin, about the floor, on a sample.
			c.runner_up_score = options.decision_runner_up_floor;
			for (const auto& o : cands)
				if (&o != &c && !o.screened && (o.mirrored || areRivals(c, o)))
					c.runner_up_score = std::max(c.runner_up_score, o.score);
			c.decision_value =
				c.score + options.decision_runner_up_weight * (c.score - c.runner_up_score);
			if (mayMergeOnWalls(c)) c.confidence = std::max(c.confidence, confidenceOfValue(c.decision_value));
		}
		// At equal confidence (none at all, typically) the candidate decided
		// on is reported: a refusal then says why that one was not enough.
		std::optional<size_t> chosen;
		auto before = [&](size_t i, size_t j) {
			if (cands[i].confidence != cands[j].confidence) return cands[i].confidence > cands[j].confidence;
			if ((i == best) != (j == best)) return i == best;
			return judged[i].r.objective < judged[j].r.objective;
		};
		for (size_t i = 0; i < cands.size(); ++i)
			if (!cands[i].mirrored && (!chosen || before(i, *chosen))) chosen = i;
		if (!chosen) return;
		have = true;
		const TCandidate& cand = cands[*chosen];
		const Hypothesis& h = judged[*chosen].h;
		const TsICPResult& r = judged[*chosen].r;
		info.cells = r.transform;
		info.initial_cells = h.other_to_ref;
		info.overlap = r.overlap;
		info.objective = r.objective;
		info.trimmed_rmse_coarse_cells = cand.rmse_coarse_cells;
		info.consistency = cand.tolerant_consistency;
		info.chance_consistency = cand.chance_consistency;
		info.wall_alignment = cand.wall_alignment;
		info.shift_coherence = cand.shift_coherence;
		info.feature_agreement = cand.feature_agreement;
		info.bent_consistency = cand.bent_consistency;
		info.score = cand.score;
		info.runner_up_score = cand.runner_up_score;
		info.decision_value = cand.decision_value;
		info.confidence = cand.confidence;
		info.ransac_inliers = h.inliers;
		info.ransac_matches = h.matches;
		info.icp_iterations = r.iterations;
		info.objective_history = r.objective_history;
	};
	// A hypothesis whose sample score is screen_margin below the relevant
	// score of the best candidate so far (relevantScore) changes neither the
	// decision nor the confidence, beyond the sample's noise: screened.
	auto bestScore = [&]() {
		double best = -std::numeric_limits<double>::infinity();
		for (const auto& c : info.candidates)
			if (!c.screened && !c.mirrored && c.judged_points >= kMinJudgedPoints) best = std::max(best, c.score);
		return best;
	};
	// relevantScore is at least lowestMergeableScore; the mirror pass's own
	// bar (least_relevant) may be higher.
	auto screenBar = [&]() {
		return std::max(least_relevant, options.relevantScore(bestScore())) - options.screen_margin;
	};
	// Refined a few at a time (one per thread), judged in order: the result
	// is the sequential one, at most a round's tail computed in vain when a
	// candidate is merged whatever comes (the maps coincide cell for cell
	// with confidence 0.95, so no other hypothesis can do meaningfully
	// better, or its score alone reaches the threshold). A round takes the
	// hypotheses in order until one per thread needs refining on every point,
	// their screens run ahead, one per thread at a time: the threads refine
	// together instead of one waiting while the other screens.
	auto refineAll = [&](const std::vector<Hypothesis>& list) {
		const size_t n = std::min<size_t>(list.size(), size_t(std::max(0, options.max_hypotheses)));
		const size_t threads = size_t(std::clamp(cv::getNumThreads(), 1, 4));
		std::vector<Screen> screens(n);
		size_t screened_up_to = 0;
		bool stop = false;
		for (size_t first = 0; first < n && !stop;)
		{
			if (!options.exhaustive_search) screen_bar = screenBar();
			std::vector<Refined> done;
			std::vector<size_t> in_full;  // hypotheses of this round refined on every point
			size_t end = first;
			while (end < n && in_full.size() < threads)
			{
				if (end == screened_up_to)
				{
					const size_t upto = std::min(n, screened_up_to + threads);
					cv::parallel_for_(cv::Range(int(screened_up_to), int(upto)), [&](const cv::Range& range) {
						for (int j = range.start; j < range.end; ++j) screens[j] = screenOne(list[j]);
					});
					screened_up_to = upto;
				}
				if (stopsAtScreen(screens[end]))
					done.push_back(screenedOnly(list[end], screens[end]));
				else
					done.emplace_back(), in_full.push_back(end);
				++end;
			}
			cv::parallel_for_(cv::Range(0, int(in_full.size())), [&](const cv::Range& range) {
				for (int k = range.start; k < range.end; ++k)
					done[in_full[k] - first] = refineInFull(list[in_full[k]], screens[in_full[k]]);
			});
			for (size_t j = first; j < end; ++j)
			{
				const Hypothesis& h = list[j];
				const Refined& one = done[j - first];
				++info.hypotheses_refined;
				icp_s += one.icp_s, verify_s += one.verify_s;
				if (!one.valid) continue;
				const TCandidate& cand = one.cand;
				info.candidates.push_back(cand);
				judged.push_back({h, one.r});
				MRPT_LOG_DEBUG_STREAM(
					"hypothesis " << h.other_to_ref << " inliers " << h.inliers << " -> " << one.r.transform << " xi "
								  << one.r.overlap << " rmse " << cand.rmse_coarse_cells << " tolerant consistency "
								  << cand.tolerant_consistency << " bent " << cand.bent_consistency << " chance "
								  << cand.chance_consistency << " score "
								  << cand.score
								  << (cand.converged_on_exact ? " (on an exact candidate)" : cand.screened ? " (screened)" : "")
								  << " exact conf "
								  << cand.exact_confidence);
				if (mergedWhateverComes(cand, 0.95) && !options.exhaustive_search) stop = true;
				if (!cand.screened && cand.exact_confidence >= options.min_confidence) exact_found.push_back(cand);
			}
			first = end;
		}
		decide();
	};
	// A given start first (tracking): confident, it needs no search.
	if (start_metric)
	{
		Hypothesis h;
		h.other_to_ref = ref.cell_to_metric.inverse().compose(*start_metric).compose(other.cell_to_metric);
		info.hypotheses = 1;
		refineAll({h});
	}
	// 1. RANSAC on the features of every pair of pyramid levels.
	info.tracked = have && info.confidence >= options.min_confidence && !options.exhaustive_search;
	if (!info.tracked)
	{
		stage.Tic();
		const auto hyps =
			featureHypotheses(matches, fp, expected_scale, options.metadata_scale_tolerance);
		info.stage_seconds["ransac"] = stage.Tac();
		info.hypotheses += hyps.size();
		refineAll(hyps);
	}
	// The building's structure gives more hypotheses (StructureHypotheses.h):
	// right ones for independent maps whose corners differ, and rivals the
	// decision must see (it was calibrated with them). Spared only where a
	// candidate is merged whatever comes, or a given start was confident.
	const bool sure = std::any_of(info.candidates.begin(), info.candidates.end(), [&](const TCandidate& c) {
		return mergedWhateverComes(c, options.min_confidence);
	});
	if (options.structure_search && !info.tracked && !mirror_pass && (!sure || options.exhaustive_search))
	{
		stage.Tic();
		const auto more = structureHypotheses(ref_img, other_img, {}, expected_scale);
		info.stage_seconds["structure"] = stage.Tac();
		info.hypotheses += more.size();
		refineAll(more);
	}
	info.stage_seconds["icp"] = icp_s;
	info.stage_seconds["verify"] = verify_s;
	if (mirror_pass) return info;  // its candidates are all the caller needs

	// The mirror check (mirror_check): a merge that does not rest on
	// coinciding cells rests on walls agreeing, which a mirror image can
	// reach on a building's symmetries; the mirrored map's candidates become
	// rivals. (In calibration data, every pair is checked.)
	const bool rests_on_walls = have && info.confidence >= options.min_confidence &&
		std::none_of(info.candidates.begin(), info.candidates.end(),
					 [&](const TCandidate& c) { return c.exact_confidence >= options.min_confidence; });
	if (options.mirror_check && !info.tracked && (rests_on_walls || (have && options.exhaustive_search)))
	{
		stage.Tic();
		const PreparedMapPtr flipped = mirrored(other);
		// Below this a mirrored candidate cannot lower the confidence.
		const TReturnInfo m = align(ref, *flipped, std::nullopt, options.relevantScore(bestScore()));
		for (TCandidate c : m.candidates)
		{
			c.mirrored = true;
			if (!c.screened && c.judged_points >= kMinJudgedPoints)
				info.mirror_score = std::isnan(info.mirror_score) ? c.score : std::max(info.mirror_score, c.score);
			info.candidates.push_back(c);
			Judged j;
			j.h.other_to_ref = c.initial_cells;
			j.r.transform = c.cells;
			judged.push_back(j);
		}
		info.hypotheses += m.hypotheses;
		info.hypotheses_refined += m.hypotheses_refined;
		decide();
		info.stage_seconds["mirror"] = stage.Tac();
	}
	if (!have)
		return fail(info.hypotheses ? "no hypothesis survived refinement"
									: "no consistent feature matches or structure between the maps (do they overlap?)");

	// The decided transform finished on the occupied cells (icp_finish_on_occupied):
	// a fraction of a cell where the maps' walls coincide that closely. Not
	// where their edges are 1.5 coarse cells apart or more (independent maps:
	// on Halmstad E5/HIH it moved OTHER by 0.04 px on average, for 0.5 s).
	if (options.icp_finish_on_occupied && info.confidence >= options.min_confidence &&
		info.trimmed_rmse_coarse_cells < kExactMaxRmse)
	{
		stage.Tic();
		const Similarity2D finished = finishOnOccupiedCells(ref, other, info.cells, ip, options.latticeParams());
		const double shift = largestShift(other_edges, info.cells, finished, ref_field);
		const double coarse = std::max(1.0, info.cells.scale);
		if (shift <= options.finish_max_shift * coarse)
			info.cells = finished;
		else
			MRPT_LOG_DEBUG_STREAM("finish on occupied cells not taken: it moves a wall by " << shift / coarse << " coarse cells");
		info.stage_seconds["finish"] = stage.Tac();
	}
	// Maps that bend (the exact finish did not apply): the pose balanced over
	// the whole overlap (finishBent).
	else if (!mirror_pass && options.finish_bent_lambda > 0 && info.trimmed_rmse_coarse_cells >= kExactMaxRmse)
	{
		stage.Tic();
		info.cells = finishBent(ref, other, info.cells, info.trimmed_rmse_coarse_cells);
		info.stage_seconds["finish"] = stage.Tac();
	}
	info.metric = ref.cell_to_metric.compose(info.cells).compose(other.cell_to_metric.inverse());
	info.implied_resolution_other = info.cells.scale * ref.resolution;
	info.executionTime = total.Tac();
	if (info.confidence < options.min_confidence)
	{
		std::ostringstream why;
		why << "alignment not confident enough (confidence " << info.confidence << " < "
			<< options.min_confidence << "; tolerant consistency " << info.consistency << ", " << info.bent_consistency
			<< " with its bends taken out, against " << info.chance_consistency << " by chance";
		if (std::isfinite(info.decision_value))
			why << ", score " << info.score << " against " << info.runner_up_score << " for the best rival (decision value "
				<< info.decision_value << ", " << options.decision_threshold << " needed)";
		if (std::isfinite(info.decision_value) && !options.leadsChance(info.bent_consistency, info.chance_consistency))
			why << ", walls agreeing no more than chance (less than decision_min_lead = " << options.decision_min_lead
				<< " above it)";
		if (std::isfinite(info.decision_value) && !options.wallsRunAlike(info.wall_alignment))
			why << ", walls near the other map's running alike in only " << info.wall_alignment
				<< " of the cases (decision_min_wall_alignment = " << options.decision_min_wall_alignment << ")";
		if (std::isfinite(info.decision_value) && !options.shiftsCohere(info.shift_coherence))
			why << ", its regions fitting best after shifts alike in only " << info.shift_coherence
				<< " of adjacent ones (decision_min_shift_coherence = " << options.decision_min_shift_coherence << ")";
		why << ", overlap " << info.overlap << ", edge RMSE " << info.trimmed_rmse_coarse_cells << " cells)";
		if (info.mirror_score > info.score)
			why << "; the other map fits better mirrored (score " << info.mirror_score
				<< "): is one of the maps flipped (y axis up vs down)?";
		return fail(why.str());
	}
	info.success = true;
	info.message = "merged";
	return info;
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const GridInFrame& ref, const GridInFrame& other) const
{
	TReturnInfo info = alignScaled(ref.grid, other.grid);
	info.metric = betweenMapFrames(ref, info.metric, other);
	return info;
}

mrpt::poses::CPosePDF::Ptr CScalingGridMapAligner::AlignPDF(
	const mrpt::maps::CMetricMap* m1, const mrpt::maps::CMetricMap* m2,
	const mrpt::poses::CPosePDFGaussian&,
	mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult> outInfo)
{
	const auto* ref = dynamic_cast<const COccupancyGridMap2D*>(m1);
	const auto* other = dynamic_cast<const COccupancyGridMap2D*>(m2);
	ASSERTMSG_(ref && other, "CScalingGridMapAligner aligns two COccupancyGridMap2D");
	const TReturnInfo info = alignScaled(*ref, *other);
	if (outInfo)
	{
		if (auto* full = dynamic_cast<TReturnInfo*>(&outInfo->get()))
			*full = info;
		else
			outInfo->get().executionTime = info.executionTime;
	}
	if (!info.success) return nullptr;
	const double sigma_xy = info.trimmed_rmse_coarse_cells *
		std::max(ref->getResolution(), other->getResolution());
	mrpt::math::CMatrixDouble33 cov;
	cov.setZero();
	cov(0, 0) = cov(1, 1) = sigma_xy * sigma_xy;
	cov(2, 2) = mrpt::square(0.1 * M_PI / 180.0);
	return std::make_shared<mrpt::poses::CPosePDFGaussian>(
		mrpt::poses::CPose2D(info.metric.t.x(), info.metric.t.y(), info.metric.yaw), cov);
}

mrpt::poses::CPose3DPDF::Ptr CScalingGridMapAligner::Align3DPDF(
	const mrpt::maps::CMetricMap*, const mrpt::maps::CMetricMap*,
	const mrpt::poses::CPose3DPDFGaussian&, mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult>)
{
	THROW_EXCEPTION("CScalingGridMapAligner aligns 2-D grid maps only; use AlignPDF()");
}

}  // namespace multires_map_merge
