#pragma once
// What the CLI (and other front ends) report of a merge: the JSON result and
// the overlay picture a person judges at a glance.

#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace multires_map_merge
{
/** The JSON result: {"success", "transform": {"x","y","yaw","scale"},
 * "scale_cells", "implied_resolution_other", "overlap", "objective",
 * "inliers", "confidence", "runtime_s", "stages": {...}, "error"}. */
std::string toJson(const CScalingGridMapAligner::TReturnInfo& r, double runtime_s);

/** Colour overlay (BGR, +y up) of the two inputs sampled on the merged grid:
 * occupied in both = black, only in the reference = blue, only in the other
 * = red, free = white, unknown = grey. */
cv::Mat overlayImage(const cv::Mat& ref_classes, const cv::Mat& other_classes);

/** The JSON of an N-map merge: {"success" (every map placed), "reference",
 * "maps": [{"file", "success", "transform": {"x","y","yaw","scale"} (the pose
 * of that map's frame in the reference's), "confidence", "placed_through",
 * "error"}, ...] one per non-reference map in input order, "pairs_aligned",
 * "pairs_skipped", "pairs": [every aligned pair], "runtime_s", "error"}. */
std::string fleetJson(
	const FleetResult& r, const std::vector<std::string>& names, size_t reference, double runtime_s,
	const std::string& error = "");

/** Overlay of N maps sampled on the merged grid (empty = not placed): walls
 * of one map in its own colour (the reference's first), walls two or more
 * agree on black, free white, unknown grey; +y up. */
cv::Mat fleetOverlayImage(const std::vector<cv::Mat>& classes);

}  // namespace multires_map_merge
