#include <multires_map_merge/FleetEdge.h>

#include <algorithm>

namespace multires_map_merge
{
std::string FleetEdge::describe() const
{
	return dropped ? "dropped: contradicts the other alignments around a cycle (" + message + ")" : message;
}

double coarseCellInTo(const std::vector<GridInFrame>& maps, const FleetEdge& e)
{
	return std::max<double>(maps[e.to].grid.getResolution(), maps[e.from].grid.getResolution() * e.from_to_to.scale);
}

double coarseCellInReference(
	const std::vector<GridInFrame>& maps, const std::vector<FleetPlacement>& placements, const FleetEdge& e)
{
	return coarseCellInTo(maps, e) * placements[e.to].in_reference.scale;
}

}  // namespace multires_map_merge
