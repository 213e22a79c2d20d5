#pragma once
// The comparison system: MRPT's own grid-map aligner (Blanco et al.;
// mrpt::slam::CGridMapAligner), as a user of Debian's libmrpt would run it.

#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <string>

namespace multires_bench
{
struct AnchorResult
{
	bool aligned = false;  //!< returned a pose (right or wrong)
	std::string why;  //!< when not: MRPT's refusal or error
	multires_map_merge::Similarity2D metric;  //!< other's frame in ref's (scale 1)
	double seconds = 0;
};

/** CGridMapAligner on a CMultiMetricMap of each grid plus a points map of its
 * occupied cells (with bare grids it segfaults), featsPerSquareMeter = 0.1
 * (its default 0.015 finds nothing on real maps), everything else default.
 * Never throws: MRPT's exceptions (it refuses different resolutions) come
 * back in `why`. */
AnchorResult alignWithMrpt(
	const mrpt::maps::COccupancyGridMap2D& ref, const mrpt::maps::COccupancyGridMap2D& other);

}  // namespace multires_bench
