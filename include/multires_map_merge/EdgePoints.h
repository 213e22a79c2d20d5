#pragma once
// Edge points: occupied cells that border free space, the structure both maps
// share whatever their resolution. TsICP registers these.

#include <multires_map_merge/PointList.h>

#include <opencv2/core.hpp>

namespace multires_map_merge
{
/** Cell coordinates (x = column, y = row; cell centre at integer coordinates)
 * of the occupied cells of a class image (see GridImage.h) with a free cell
 * among their 8 neighbours. */
PointList edgePoints(const cv::Mat& classes);

/** Every occupied cell, same coordinates. A wall's edge is a staircase whose
 * steps depend on the resolution and on how the wall lies on the lattice; the
 * wall's occupied cells, taken whole, sit where the wall is: the aligner
 * finishes on these (TConfigParams::icp_finish_on_occupied). */
PointList occupiedPoints(const cv::Mat& classes);

/** The set cells of a CV_8U mask, same coordinates. */
PointList cellsOf(const cv::Mat& mask);

}  // namespace multires_map_merge
