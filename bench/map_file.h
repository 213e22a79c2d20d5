#pragma once
// map_server files as the benchmark and the tests write them from images
// (the yaml's text is MapIO's mapServerYaml), and part of an image saved
// where it lies in the whole.
#include <opencv2/core.hpp>

#include <string>

namespace multires_bench
{
/** Writes the yaml `yaml` for `image` (as the yaml names it: relative to
 * the yaml, or absolute) at `resolution`, the image's bottom-left corner at
 * (`corner_x`, `corner_y`) m, unturned, with map_server's default
 * thresholds; a floor plan says so. Throws std::runtime_error naming the
 * file if it cannot be written. */
void writeMapServerYaml(
	const std::string& yaml, const std::string& image, double resolution, double corner_x = 0, double corner_y = 0,
	bool floor_plan = false);

/** The part `rect` (rows top first, as stored) of a map_server image whose
 * corner is at the frame's origin, saved as `<stem>.pgm` and `<stem>.yaml`
 * where it lies in that frame: its corner moves to the part's bottom-left
 * cell. Returns the yaml. */
std::string writeImagePart(
	const cv::Mat& image, const cv::Rect& rect, double resolution, const std::string& stem, bool floor_plan = false);

}  // namespace multires_bench
