#include "map_file.h"

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
	std::ofstream out(yaml);
	out.precision(10);  // cells × resolution, without a product's last-bit noise
	out << "image: " << image << "\nresolution: " << resolution << "\norigin: [" << corner_x << ", " << corner_y
		<< ", 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
		<< (floor_plan ? "floor_plan: true\n" : "");
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
