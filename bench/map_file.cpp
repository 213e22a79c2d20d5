#include "map_file.h"

#include <multires_map_merge/MapIO.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace multires_bench
{
void writeMapServerYaml(
	const std::string& yaml, const std::string& image, double resolution, double corner_x, double corner_y,
	bool floor_plan)
{
	using multires_map_merge::MapKind;
	std::ofstream out(yaml);
	out << multires_map_merge::mapServerYaml(
		image, resolution, {corner_x, corner_y}, 0, floor_plan ? MapKind::FloorPlan : MapKind::Sensed);
	if (!out) throw std::runtime_error("'" + yaml + "': cannot write");
}

std::string writeImagePart(
	const cv::Mat& image, const cv::Rect& rect, double resolution, const std::string& stem, bool floor_plan)
{
	const std::string pgm = stem + ".pgm", yaml = stem + ".yaml";
	if (!cv::imwrite(pgm, image(rect).clone())) throw std::runtime_error("'" + pgm + "': cannot write");
	// Image rows run top down; the frame's y up from the bottom row.
	writeMapServerYaml(
		yaml, std::filesystem::path(pgm).filename().string(), resolution, rect.x * resolution,
		(image.rows - rect.y - rect.height) * resolution, floor_plan);
	return yaml;
}

}  // namespace multires_bench
