#pragma once
// A grid with more unknown cells around it, in the same metric frame: how a
// map file holds padding around what the robot saw.

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <algorithm>

namespace multires_map_merge::test
{
/** The grid with `left` and `below` more unknown cells on those sides and
 * `right_above` on the others; cell (left, below) is the grid's (0, 0). */
inline mrpt::maps::COccupancyGridMap2D padded(
	const mrpt::maps::COccupancyGridMap2D& g, int left, int below, int right_above)
{
	const double r = g.getResolution();
	mrpt::maps::COccupancyGridMap2D out(
		float(g.getXMin() - left * r), float(g.getXMax() + right_above * r), float(g.getYMin() - below * r),
		float(g.getYMax() + right_above * r), float(r));
	for (unsigned cy = 0; cy < g.getSizeY(); ++cy)
		std::copy(g.getRow(cy), g.getRow(cy) + g.getSizeX(), out.getRow(int(cy) + below) + left);
	return out;
}
}  // namespace multires_map_merge::test
