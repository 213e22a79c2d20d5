#include <multires_map_merge/GridInFrame.h>

namespace multires_map_merge
{
Similarity2D betweenMapFrames(const GridInFrame& ref, const Similarity2D& between_grids, const GridInFrame& other)
{
	return ref.origin.compose(between_grids).compose(other.origin.inverse());
}

Similarity2D betweenGrids(const GridInFrame& ref, const Similarity2D& between_map_frames, const GridInFrame& other)
{
	return ref.origin.inverse().compose(between_map_frames).compose(other.origin);
}

}  // namespace multires_map_merge
