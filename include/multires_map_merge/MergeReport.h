#pragma once
// What the CLI (and other front ends) report of a merge: the JSON result and
// the overlay picture a person judges at a glance.

#include <multires_map_merge/CScalingGridMapAligner.h>

#include <opencv2/core.hpp>
#include <string>

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

}  // namespace multires_map_merge
