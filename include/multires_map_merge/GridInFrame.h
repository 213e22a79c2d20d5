#pragma once
// A grid and the exact pose of its frame. MRPT grids keep their lower-left
// corner on a multiple of the cell size, so a map whose origin is anywhere
// else (every map_server file, every nav_msgs/OccupancyGrid) is held as a grid
// in its *origin frame* — corner at (0, 0), axes along the grid — plus the
// rigid pose of that frame in the frame the map is named in. Nothing is
// rounded, and rotated origins are exact.

#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

namespace multires_map_merge
{
/** What a map's free space says. A robot's map saw its free space; a floor
 * plan drew it: furniture it does not draw and walls a robot never saw are
 * not evidence against an alignment (MapAgreement.h, occupancyField). */
enum class MapKind
{
	Sensed,
	FloorPlan
};

struct GridInFrame
{
	mrpt::maps::COccupancyGridMap2D grid;  //!< metres in its own (origin) frame
	/** Rigid (scale 1): the grid's metric frame → the map's frame (a
	 * map_server `origin`, a message's `info.origin`). Identity for .gridmap
	 * files, whose frame is the grid's own. */
	Similarity2D origin;
	/** A map_server file says `floor_plan: true` for a drawn plan. */
	MapKind kind = MapKind::Sensed;

	/** Cell coordinates (cell centres at integers) → the map's frame. */
	Similarity2D cellToMapFrame() const { return origin.compose(cellToMetric(grid)); }
	/** The lower-left corner of cell (0, 0) in the map's frame. */
	Eigen::Vector2d cornerInMapFrame() const { return origin.apply({grid.getXMin(), grid.getYMin()}); }
	bool originIsIdentity() const { return origin.yaw == 0 && origin.t.isZero() && origin.scale == 1; }
};

/** Cells added on each side of a grid (x left and right, y below and above). */
struct CellMargins
{
	int left = 0, below = 0, right = 0, above = 0;
};

/** The map with `m` more unknown cells around it, its map frame unchanged:
 * how a map file holds padding around what the robot saw (gmapping saves
 * its whole default grid). The new grid's corner is at its frame's (0, 0),
 * as a map_server file's; the origin takes the shift, exactly. */
GridInFrame widened(const GridInFrame& map, const CellMargins& m);

/** Re-expresses a transform between two grids' metric frames as one between
 * their maps' frames: ref.origin ∘ between_grids ∘ other.origin⁻¹. */
Similarity2D betweenMapFrames(
	const GridInFrame& ref, const Similarity2D& between_grids, const GridInFrame& other);
/** The inverse: between the maps' frames → between the grids' frames. */
Similarity2D betweenGrids(
	const GridInFrame& ref, const Similarity2D& between_map_frames, const GridInFrame& other);

}  // namespace multires_map_merge
