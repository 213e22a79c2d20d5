#include <multires_map_merge/GridInFrame.h>

#include <algorithm>

namespace multires_map_merge
{
Similarity2D betweenMapFrames(const GridInFrame& ref, const Similarity2D& between_grids, const GridInFrame& other)
{
	return ref.origin.compose(between_grids).compose(other.origin.inverse());
}

GridInFrame widened(const GridInFrame& map, const CellMargins& m)
{
	const auto& g = map.grid;
	const int w = int(g.getSizeX()), h = int(g.getSizeY());
	const double r = g.getResolution();
	GridInFrame out;
	out.kind = map.kind;
	out.grid.setSize(0, float((w + m.left + m.right) * r), 0, float((h + m.below + m.above) * r), float(r), 0.5f);
	for (int cy = 0; cy < h; ++cy) std::copy(g.getRow(cy), g.getRow(cy) + w, out.grid.getRow(cy + m.below) + m.left);
	// Cell (left, below) of the new grid is cell (0, 0) of the map's.
	out.origin = map.origin.compose(Similarity2D(1, 0, {g.getXMin() - m.left * r, g.getYMin() - m.below * r}));
	return out;
}

Similarity2D betweenGrids(const GridInFrame& ref, const Similarity2D& between_map_frames, const GridInFrame& other)
{
	return ref.origin.inverse().compose(between_map_frames).compose(other.origin);
}

}  // namespace multires_map_merge
