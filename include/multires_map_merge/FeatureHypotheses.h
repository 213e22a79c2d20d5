#pragma once
// Initial similarity hypotheses from image features (method step 1).
//
// SIFT is scale-invariant in principle, but a 2 cm map and a 10 cm map of the
// same wall do not look alike at any one scale: the fine map shows dotted,
// several-cell-thick structure the coarse one never recorded. So both maps are
// resampled into a pyramid the way a coarser grid would have recorded them
// (resampleClasses), and every level of one is matched against every level of
// the other. The level pair whose cell sizes agree yields matches; each level
// pair gives its own 2-point RANSAC hypotheses, all mapped back to full
// resolution cell coordinates.

#include <multires_map_merge/Similarity2D.h>

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace multires_map_merge
{
struct FeatureParams
{
	int pyramid_levels = 4;  //!< levels per map, each half the previous size
	int min_level_size = 64;  //!< cells; smaller levels are skipped
	/** Levels with more cells are skipped (the pyramid then starts lower and
	 * still keeps `pyramid_levels` levels): SIFT doubles its first octave, so
	 * a large map's full-resolution level costs most of the time and memory
	 * of the whole alignment, and the seeds it finds are no better than a
	 * coarser level's (TsICP refines on the full-resolution edges anyway). */
	double max_level_cells = 1 << 18;
	/** Levels sized by the image's longer side instead: at most
	 * √max_level_cells across, smaller ones kept down to min_level_size on
	 * that side. A map cropped to its known part is often long and narrow:
	 * by cell count and shorter side it would lose its finer level or its
	 * coarser ones, which a square grid of padding kept. */
	bool levels_by_longer_side = false;
	/** Pixels of unknown drawn around each level before SIFT, whose
	 * keypoints stay 5 pixels clear of each octave's border and whose blur
	 * reads past it: a map cropped close to its outermost walls keeps the
	 * features there. 0: the level as it is. */
	int level_frame = 0;
	double sift_contrast_threshold = 0.04;
	double sift_edge_threshold = 10;
	double ratio_test = 0.8;  //!< Lowe's ratio for accepting a match
	double ransac_threshold = 3.0;  //!< reprojection error, cells of the reference level
	int ransac_iterations = 4000;
	double ransac_confidence = 0.999;
	int min_inliers = 5;
	int hypotheses_per_level_pair = 2;  //!< RANSAC re-runs on the matches left
	/** Draw unexplored space like free space for SIFT. Off by default: in a
	 * fine map the walls are dotted and the known/unknown boundary carries the
	 * structure, so erasing it loses the 2 cm vs 10 cm matches. */
	bool unknown_as_free = false;
};

struct Hypothesis
{
	Similarity2D other_to_ref;  //!< cell coordinates, full resolution
	int inliers = 0;
	int matches = 0;
	int ref_level = 0, other_level = 0;
};

/** Keypoints and descriptors of one pyramid level. */
struct LevelFeatures
{
	double scale = 1;  //!< level cells per full-resolution cell
	std::vector<cv::Point2f> points;  //!< full-resolution cell coordinates
	cv::Mat descriptors;
};

/** Whether two parameter sets extract the same features (the matching and
 * RANSAC parameters may differ). */
bool sameExtraction(const FeatureParams& a, const FeatureParams& b);

/** SIFT on every pyramid level of a class image. */
std::vector<LevelFeatures> extractPyramidFeatures(const cv::Mat& classes, const FeatureParams& p);

/** The ratio-test matches of one pair of pyramid levels (full-resolution
 * cell coordinates): `from` in the other map, `to` in the reference. */
struct LevelMatches
{
	double level_scale = 1;  //!< the scale other → ref at which these levels' cells are of one size
	double tolerance = 3;  //!< full-resolution reference cells (ransac_threshold at the reference level)
	int ref_level = 0, other_level = 0;
	std::vector<cv::Point2f> from, to;
};
/** Every level of one map matched against every level of the other. */
std::vector<LevelMatches> featureMatches(
	const std::vector<LevelFeatures>& ref, const std::vector<LevelFeatures>& other, const FeatureParams& p);

/** The matches that `other_to_ref` takes to within their tolerance, over
 * the level pairs whose cells are of one size at its scale (within √2):
 * local appearance agreeing under a transform (the decision's evidence
 * beside the walls). */
size_t agreeingMatches(const std::vector<LevelMatches>& matches, const Similarity2D& other_to_ref);

/** Similarity hypotheses other → ref, most RANSAC inliers first, near-
 * duplicates removed. `expected_scale` (from trusted metadata) drops the
 * hypotheses whose scale is more than `scale_tolerance` (relative) away. */
std::vector<Hypothesis> featureHypotheses(
	const std::vector<LevelFeatures>& ref, const std::vector<LevelFeatures>& other,
	const FeatureParams& p, std::optional<double> expected_scale = std::nullopt,
	double scale_tolerance = 0.15);
/** The same from the matches (featureMatches), which the aligner also
 * judges its candidates by. */
std::vector<Hypothesis> featureHypotheses(
	const std::vector<LevelMatches>& matches, const FeatureParams& p,
	std::optional<double> expected_scale = std::nullopt, double scale_tolerance = 0.15);

/** RANSAC over point correspondences for a 4-DOF similarity (2-point
 * minimal sets; the model re-fitted on its inliers with Eigen::umeyama).
 * Only models with a scale in [min_scale, max_scale] are considered:
 * without that bound, a model that shrinks every point onto one spot
 * "explains" all matches of a repetitive map, which is why
 * cv::estimateAffinePartial2D (no such bound) is not used. Deterministic.
 * Returns std::nullopt if no model reaches min_inliers; `inlier_mask` marks
 * the inliers. */
std::optional<Similarity2D> ransacSimilarity(
	const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to, double threshold,
	int iterations, double confidence, int min_inliers, std::vector<uchar>& inlier_mask,
	double min_scale = 1e-3, double max_scale = 1e3);

}  // namespace multires_map_merge
