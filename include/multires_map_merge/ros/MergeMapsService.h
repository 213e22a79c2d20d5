#pragma once
// The merge_maps service, without the ROS plumbing: a request of two
// nav_msgs/OccupancyGrid in, a response out. The node, the rosbag path of the
// CLI and the tests all call this one function, so a map merged from a bag is
// merged exactly as the service would merge it.

#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/MergeFleet.h>
#include <multires_map_merge/MergeMaps.h>

#include <optional>

namespace multires_map_merge::ros1
{
class MergeMapsService
{
   public:
	/** Throws std::invalid_argument when `params` cannot work. */
	explicit MergeMapsService(const CScalingGridMapAligner::TConfigParams& params = {});

	/** What a caller beyond the service may want as well. */
	struct Details
	{
		CScalingGridMapAligner::TReturnInfo info;
		std::optional<FusedMap> fused;  //!< when merged
	};

	/** Aligns `other` onto `reference` and fuses them. Never throws: a bad
	 * request, a map that cannot be aligned and an alignment below
	 * min_confidence all give success = false and a message saying why.
	 * The transform (other's frame_id → reference's frame_id, through both
	 * info.origin poses) is filled when the maps were aligned, even if the
	 * merged map was then refused (too large); otherwise scale = 0.
	 * use_resolution_metadata is on if the request or the parameters ask. */
	void merge(const MergeMaps::Request& req, MergeMaps::Response& res, Details* details = nullptr) const;

	/** roscpp's service callback signature. Always true: a refused merge is
	 * an answer (success = false), not a transport failure. */
	bool operator()(MergeMaps::Request& req, MergeMaps::Response& res) const
	{
		merge(req, res);
		return true;
	}

	/** merge_fleet: N maps into maps[reference]'s frame (FleetMerge.h). Never
	 * throws; success only when every map was placed, and the merged map then
	 * holds all of them (else it holds those placed, if any besides the
	 * reference, and `messages` says why the others were not). */
	void mergeFleet(const MergeFleet::Request& req, MergeFleet::Response& res) const;

	const CScalingGridMapAligner::TConfigParams& params() const { return params_; }

	/** The largest merged map returned, in cells (int8 each); above it the
	 * request is refused with a message suggesting a coarser output. */
	size_t max_merged_cells = size_t(1) << 26;
	/** How merge_fleet places its maps (FleetMerge.h). */
	FleetParams fleet_params;

   private:
	CScalingGridMapAligner::TConfigParams params_;
};

}  // namespace multires_map_merge::ros1
