#pragma once
// Independent ROS maps of one place (../shared/data/ros_maps, SOURCES.md
// 2b): map_saver files of a house, a care site and a small test area, each
// mapped two or three times on different days. No annotation: the truth of
// a pair is the rigid transform a brute-force search over every turn and
// shift finds (most of one map's walls on the other's), an independent
// method. Every ordered pair of a place is a positive; every pair of maps of
// different places a negative.

#include "context.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace multires_bench
{
struct RosPlace
{
	std::string name;  //!< short: troyes, heerlen, tb3
	std::string dir;  //!< under ros_maps/
	std::vector<std::string> maps;  //!< yaml stems
};
extern const std::vector<RosPlace> kRosPlaces;

/** A right merge lays the other map within this of the brute-force truth
 * (mean over its occupied cells): half a metre at their 5 cm. */
constexpr double kRosRightCells = 10.0;

struct RosMapsRun
{
	std::string place, ref, other;  //!< place of REF; maps as place/stem
	bool positive = false;  //!< same place
	bool merged = false, right = false;
	double displacement_cells = NAN;  //!< reported transform against the truth (positives)
	double confidence = 0, seconds = 0;
	std::string message;
};

/** The rigid transform between two class images' cells (other → ref) that
 * lays the most occupied cells of `other` on those of `ref`: every turn
 * (1°) and shift on 4× coarser images, then the best few refined at full
 * resolution (0.1°, 1 cell). */
Similarity2D bruteForceRigid(const cv::Mat& ref_classes, const cv::Mat& other_classes);

/** Every ordered pair (positives judged against the brute-force truth,
 * negatives across places), as map_server files; every candidate to
 * ctx.candidates (site "ros", calibration data). */
std::vector<RosMapsRun> runRosMaps(const BenchContext& ctx);

void writeRosMapsSection(std::ostream& md, const std::vector<RosMapsRun>& runs);

}  // namespace multires_bench
