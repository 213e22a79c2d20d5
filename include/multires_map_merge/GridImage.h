#pragma once
// Grid ↔ image conversion, in one place. Everything in this package works on
// "class images": CV_8UC1 with row = cy and column = cx of the grid (no flip),
// so image pixel coordinates *are* cell coordinates and a similarity found
// between two class images is a similarity between the two grids' cells.
// Only images meant for people (PNG output) are flipped so that +y points up.

#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <opencv2/core.hpp>

#include <cmath>

namespace multires_map_merge
{
/** The three cell classes, as grey levels (dark = occupied, as maps are drawn). */
enum CellClass : uint8_t
{
	kOccupied = 0,
	kUnknown = 127,
	kFree = 255
};

/** Occupancy probability bounds: a cell is occupied above kOccupiedAbove,
 * free below kFreeBelow, unknown in between. */
constexpr float kOccupiedAbove = 0.505f;
constexpr float kFreeBelow = 0.495f;

/** The class of an occupancy probability (inline: the fusion asks it for
 * every sample of every map). */
inline CellClass classify(float occupancy_probability)
{
	if (occupancy_probability > kOccupiedAbove) return kOccupied;
	if (occupancy_probability < kFreeBelow) return kFree;
	return kUnknown;
}

/** Occupancy probability of a cell (MRPT stores the probability of *free*). */
inline float occupancyProbability(const mrpt::maps::COccupancyGridMap2D& g, int cx, int cy)
{
	return 1.0f - g.getCell(cx, cy);
}

/** Class image of a grid (row = cy, no flip). */
cv::Mat toClassImage(const mrpt::maps::COccupancyGridMap2D& grid);

/** Cell coordinates → metric coordinates of this grid, from its stated metadata. */
Similarity2D cellToMetric(const mrpt::maps::COccupancyGridMap2D& grid);

/** Resamples a mask (0 / non-zero) by `factor` (< 1 shrinks): an output
 * cell is set (255) if any input cell under it is, or where it covers more
 * than 510 input cells, if at least one in 510 of them is (a lone cell
 * drops out). */
cv::Mat resampleMask(const cv::Mat& mask, double factor);

/** Resamples a class image by `factor` (< 1 shrinks) the way a coarser grid
 * would have recorded the same world: a coarse cell is occupied if any fine
 * cell under it is, else free if any is, else unknown. A thin wall stays a
 * wall, which plain area averaging would wash out. */
cv::Mat resampleClasses(const cv::Mat& classes, double factor);

/** A class image as people expect to see a map: +y up. */
cv::Mat forDisplay(const cv::Mat& classes);

/** Whether `cell` (cell coordinates) rounds to a set cell of the CV_8U `mask`. */
inline bool onMask(const cv::Mat& mask, const Eigen::Vector2d& cell)
{
	const int x = static_cast<int>(std::lround(cell.x())), y = static_cast<int>(std::lround(cell.y()));
	return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x);
}

}  // namespace multires_map_merge
