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

/** The same maps recorded finer: each 5 cm cell split into cells this many
 * times smaller (2 cm), stated at 0.02 m. A lab mapped at 2 cm is in cells
 * what a 2.5x larger place is at 5 cm; the walls keep their thickness in
 * metres (2-3 cells), which a 2 cm lidar map would draw thinner. */
constexpr double kRosFinerFactor = 2.5;
/** What the benchmark runs: the files, and the files kRosFinerFactor× finer. */
inline const std::vector<double> kRosFactors = {1.0, kRosFinerFactor};

/** "files", or "×2.5 finer": a row's cells in the report. */
std::string rosCellsLabel(double factor);

struct RosMapsRun
{
	std::string place, ref, other;  //!< place of REF; maps as place/stem
	double factor = 1;  //!< cells this many times finer than the files' (kRosFinerFactor)
	bool positive = false;  //!< same place
	bool merged = false, right = false;
	double displacement_cells = NAN;  //!< reported transform against the truth (positives), cells of the files
	double confidence = 0, seconds = 0;
	std::string message;
};

/** The rigid transform between two class images' cells (other → ref) that
 * lays the most occupied cells of `other` on those of `ref`: every turn
 * (1°) and shift on 4× coarser images, then the best few refined at full
 * resolution (0.1°, 1 cell). */
Similarity2D bruteForceRigid(const cv::Mat& ref_classes, const cv::Mat& other_classes);

/** Every ordered pair (positives judged against the brute-force truth,
 * negatives across places), as map_server files, at each of `factors` (1:
 * the files; else every map resampled that many times finer, written to
 * map_server files and read back); the candidates at factor 1 to
 * ctx.candidates (site "ros", calibration data). */
std::vector<RosMapsRun> runRosMaps(const BenchContext& ctx, const std::vector<double>& factors = {1.0});

void writeRosMapsSection(std::ostream& md, const std::vector<RosMapsRun>& runs);

}  // namespace multires_bench
