#pragma once
// The last step of the finish: a whole-cell slip, then a sub-cell shift. A
// coarse map marks a cell occupied when a wall passes anywhere through it,
// so its walls sit on its lattice, up to half a cell from where they are;
// any fit of distances to coarse cell centres keeps part of that rounding.
// Drawing the finer map's occupied cells on the coarse lattice the same way
// and shifting them until they fill the coarse map's occupied cells, no more
// and no fewer, undoes it. Walls two cells thick let a fit slip a whole cell
// (one face on the other): the whole-cell shifts are compared first.

#include <multires_map_merge/PointList.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace multires_map_merge
{
struct LatticeShiftParams
{
	/** Largest sub-cell shift tried along each axis around the best
	 * whole-cell slip (within one cell), coarse cells: 1 + range in all. */
	double range = 0.5;
	double step = 0.05;  //!< finest shift step, coarse cells
	/** Shifts whose mismatch is within this share of the least are all as
	 * good (a shift moves no point across a cell border for a while): the
	 * answer is their centre. */
	double plateau = 0.02;
};

/** The shift (coarse cells) to add to `fine_in_coarse` (the finer map's
 * occupied cells, already in the coarse map's cell coordinates) that best
 * makes them, rounded to coarse cells, cover `coarse_seen` (the coarse map's
 * occupied cells the finer map sees) and nothing else the coarse map knows.
 * `coarse_near_known` (CV_8U, non-zero where known) is what it knows grown by
 * two cells (knownWithin), so that walls at the edge of what it saw count.
 * Searched coarse to fine, after the best whole-cell shift within one cell
 * (maps that coincide cell for cell can also fit exactly a cell off on half
 * their points, where walls are two cells thick). */
Eigen::Vector2d latticeShift(
	const PointList& fine_in_coarse, const PointList& coarse_seen, const cv::Mat& coarse_near_known,
	const LatticeShiftParams& p = {});

}  // namespace multires_map_merge
