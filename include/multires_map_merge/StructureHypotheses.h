#pragma once
// Hypotheses without features, for the maps where SIFT finds none that is
// right: independent maps of the same building whose corners and clutter
// differ (a Tango mesh slice against a lidar map, two sessions months apart).
// What survives is the building's structure: its dominant wall directions
// and where its walls are. Rotations come from the wall-direction histograms
// (walls are mostly at right angles), translations from the FFT
// cross-correlation of the two wall images, over a ladder of scales.
// Used only when no feature hypothesis is confident (it costs more).

#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>

#include <opencv2/core.hpp>

#include <map>
#include <mutex>
#include <optional>
#include <vector>

namespace multires_map_merge
{
struct StructureParams
{
	int working_size = 256;  //!< the reference is searched at most this many cells across
	/** Scales tried without metadata: 2^(k/steps_per_octave) within [min, max]. */
	double min_scale = 0.25, max_scale = 4.0;
	int steps_per_octave = 4;
	int peaks_per_pose = 2;  //!< correlation peaks kept per rotation and scale
	int max_hypotheses = 8;
};

/** A map's walls as the structure search reads them, each made when first
 * asked and kept: its dominant wall direction and its wall images at the
 * sizes asked for (a fleet's reference meets the same sizes in every pair).
 * Safe to share between threads; the images returned are not to be written. */
class MapWalls
{
   public:
	explicit MapWalls(cv::Mat classes) : classes_(std::move(classes)), occupied_(classes_ == kOccupied) {}
	const cv::Mat& classes() const { return classes_; }
	/** dominantWallDirection of the classes. */
	double dominantDirection() const;
	/** The walls at `f` (≤ 1) times the map's size as 0/1 floats, a cell a
	 * wall where any wall cell lies under it (as resampleClasses keeps
	 * walls), blurred by a cell. */
	cv::Mat at(double f) const;

   private:
	cv::Mat classes_;
	cv::Mat occupied_;  // every size's walls start from it
	mutable std::once_flag direction_once_;
	mutable double direction_ = 0;
	mutable std::mutex mutex_;
	mutable std::map<double, cv::Mat> walls_;  // by factor
};

/** Similarity hypotheses other → ref (full-resolution cell coordinates),
 * best correlation first. With `expected_scale` only that scale is tried
 * (TsICP refines it). */
std::vector<Hypothesis> structureHypotheses(
	const MapWalls& ref, const MapWalls& other, const StructureParams& p = {},
	std::optional<double> expected_scale = std::nullopt);
/** The same on two class images (their walls made for this call alone). */
std::vector<Hypothesis> structureHypotheses(
	const cv::Mat& ref_classes, const cv::Mat& other_classes, const StructureParams& p = {},
	std::optional<double> expected_scale = std::nullopt);

/** The dominant wall direction of a class image, in radians in [0, π/2):
 * walls at right angles share it. */
double dominantWallDirection(const cv::Mat& classes);

}  // namespace multires_map_merge
