#pragma once
// The ground-truth pair maker: renders two overlapping parts of one real,
// SLAM-corrected run into two grids at any two resolutions, the second in a
// known rotated/shifted frame. Both parts share the run's corrected world
// frame, so the true transform between the maps is exact. Used by tests, the
// demo and the benchmarks.

#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/ScanLog.h>
#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/poses/CPose2D.h>

#include <string>
#include <vector>

namespace multires_map_merge
{
struct PairSpec
{
	double ref_resolution = 0.05;  //!< metres per cell
	double other_resolution = 0.05;
	/** Pose of the other map's frame in the reference map's frame. */
	mrpt::poses::CPose2D other_frame;
	/** The reference renders scans [0, ref_end·N), the other [other_begin·N, N). */
	double ref_end = 0.6;
	double other_begin = 0.4;
	float max_range = 15.0f;  //!< metres of each beam inserted
	/** MRPT's per-pass free update (0 = MRPT's default, the same weight as a
	 * hit). Lower values (e.g. 0.55) keep fine walls solid, as hit-counting
	 * SLAM mappers do; the default leaves 2 cm walls dotted, the harder case. */
	float free_update_certainty = 0.0f;
};

struct GroundTruthPair
{
	mrpt::maps::COccupancyGridMap2D ref, other;
	/** x_ref = T(x_other) in metres, each map read with its stated metadata. */
	Similarity2D other_to_ref;

	/** The same transform between the two maps' cell coordinates. */
	Similarity2D otherCellsToRefCells() const;
};

/** The same map as a SLAM system would save it, with its origin off the cell
 * lattice: rendered in `frame` ⊕ (dx, dy) and held with origin (dx, dy), so
 * the result is the map of `frame` whose cell corners sit at (dx, dy) plus
 * whole cells. Saved as map_server files, it is what users feed the aligner. */
GridInFrame renderGridOffLattice(
	const ScanSequence& scans, size_t begin, size_t end, double resolution,
	const mrpt::poses::CPose2D& frame, double dx, double dy, float max_range = 15.0f);

GroundTruthPair makeGroundTruthPair(const ScanSequence& scans, const PairSpec& spec);

/** A copy of `grid` whose cells are unchanged but whose stated cell size is
 * `stated_resolution` (origin kept): a map with wrong metadata. */
mrpt::maps::COccupancyGridMap2D withStatedResolution(
	const mrpt::maps::COccupancyGridMap2D& grid, double stated_resolution);

/** Error of an estimated transform against the truth, as the RMS distance
 * between where each point lands under the two (same units as the points). */
double pointRmse(
	const Similarity2D& estimate, const Similarity2D& truth,
	const std::vector<Eigen::Vector2d>& points);

/** The centres of `map`'s occupied cells in its map frame: the points a
 * placement error is measured on. */
std::vector<Eigen::Vector2d> occupiedPointsInMapFrame(const GridInFrame& map);

/** Makes unknown every cell of `map` within `margin_m` of what `seen` knows
 * (`map_to_seen`: map's frame → seen's map frame): a robot that explored
 * only beyond another one, for fleets where a robot overlaps only a
 * non-reference robot. */
void forgetSeenBy(GridInFrame& map, const Similarity2D& map_to_seen, const GridInFrame& seen, double margin_m);

}  // namespace multires_map_merge
