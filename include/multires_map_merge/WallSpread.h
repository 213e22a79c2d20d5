#pragma once
// How far apart two placements of one map put what it saw: the RMS distance
// over its wall cells, computed exactly from four points (WallSpread). The
// fleet's cycle check and joint refinement, and the benchmarks, measure a
// placement so.
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/PointList.h>
#include <multires_map_merge/Similarity2D.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>

namespace multires_map_merge
{
/** Four points of a map's frame with the mean and the spread (covariance)
 * of its wall cells (occupied; its known cells if it has almost none): the
 * centroid ± √(2λ) along each principal axis. A similarity moves every
 * point affinely, so the RMS of two placements' difference at these four is
 * exactly its RMS over every wall cell: how far apart two placements put
 * what the map saw, as the benchmark measures a placement (the corners of
 * the box around it would count a turn about √3 times over, and a grid's
 * padding of unknown space more). */
using WallSpread = std::array<Eigen::Vector2d, 4>;

/** Four points with the mean and the spread of `cells` (cell coordinates,
 * at least one), in the map's frame (`to_frame`: cells → frame). */
WallSpread spreadOf(const PointList& cells, const Similarity2D& to_frame);
/** The WallSpread of a map's walls, from its class image (GridImage.h) or
 * the part of it whose (0, 0) is the grid's cell `corner` (a prepared map's,
 * PreparedMap::grid_corner): its occupied cells; with fewer than three, its
 * known cells; none known, the whole image. */
WallSpread wallSpread(const GridInFrame& map, const cv::Mat& classes, cv::Point corner = {0, 0});
/** The same from the map's grid. */
WallSpread wallSpread(const GridInFrame& map);

/** RMS distance between where two transforms put a map's walls (its WallSpread). */
double wallRms(const WallSpread& spread, const Similarity2D& a, const Similarity2D& b);
/** RMS distance (metres of the target frame) between where two transforms
 * put the four corners of `map`'s grid: how far apart two placements of a
 * map's grid are (its padding of unknown space counted too). */
double cornerRms(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b);

}  // namespace multires_map_merge
