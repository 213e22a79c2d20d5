// merge_maps_node: serves merge_maps (multires_map_merge/MergeMaps, two maps)
// and merge_fleet (multires_map_merge/MergeFleet, N maps), and publishes the
// last merged map, latched, on merged_map. All the work is in
// MergeMapsService; this file is the ROS plumbing.
#include <multires_map_merge/ros/AlignerParamsFromRos.h>
#include <multires_map_merge/ros/MergeMapsService.h>

#include <ros/ros.h>

#include <mutex>

using namespace multires_map_merge;

int main(int argc, char** argv)
{
	ros::init(argc, argv, "merge_maps");
	ros::NodeHandle nh, pnh("~");

	std::unique_ptr<ros1::MergeMapsService> service;
	const char *threads_key = "concurrent_requests", *max_cells_key = "max_merged_cells";  // the node's own
	int threads = 2, max_merged_cells = 1 << 26;
	try
	{
		pnh.param(threads_key, threads, threads);
		pnh.param(max_cells_key, max_merged_cells, max_merged_cells);
		if (threads < 1) throw std::invalid_argument(std::string("~") + threads_key + " must be >= 1");
		if (max_merged_cells < 1) throw std::invalid_argument(std::string("~") + max_cells_key + " must be >= 1");
		service = std::make_unique<ros1::MergeMapsService>(ros1::alignerParamsFromRos(pnh, {threads_key, max_cells_key}));
		service->max_merged_cells = static_cast<size_t>(max_merged_cells);
		service->fleet_params = ros1::fleetParamsFromRos(pnh);
	}
	catch (const std::exception& e)
	{
		ROS_FATAL_STREAM("merge_maps: bad configuration: " << e.what());
		return 1;
	}

	ros::Publisher merged_pub = nh.advertise<nav_msgs::OccupancyGrid>("merged_map", 1, /*latch=*/true);
	std::mutex publish_mutex;  // keeps "last merged" the last one served
	auto serve = [&](MergeMaps::Request& req, MergeMaps::Response& res) {
		service->merge(req, res);
		if (res.success)
		{
			res.merged.header.stamp = res.merged.info.map_load_time = ros::Time::now();
			std::lock_guard<std::mutex> lock(publish_mutex);
			merged_pub.publish(res.merged);
		}
		ROS_INFO_STREAM(
			"merge_maps: " << res.message << " (confidence " << res.confidence << ", " << res.runtime << " s)");
		return true;  // a refused merge is an answer, not a transport failure
	};
	ros::ServiceServer server =
		nh.advertiseService<MergeMaps::Request, MergeMaps::Response>("merge_maps", serve);
	auto serve_fleet = [&](MergeFleet::Request& req, MergeFleet::Response& res) {
		service->mergeFleet(req, res);
		if (!res.merged.data.empty())
		{
			res.merged.header.stamp = res.merged.info.map_load_time = ros::Time::now();
			std::lock_guard<std::mutex> lock(publish_mutex);
			merged_pub.publish(res.merged);
		}
		ROS_INFO_STREAM("merge_fleet: " << res.message << " (" << res.runtime << " s)");
		for (size_t i = 0; i < res.messages.size(); ++i)
			if (!res.placed[i]) ROS_WARN_STREAM("merge_fleet: maps[" << i << "] " << res.messages[i]);
		return true;
	};
	ros::ServiceServer fleet_server =
		nh.advertiseService<MergeFleet::Request, MergeFleet::Response>("merge_fleet", serve_fleet);
	ROS_INFO_STREAM("merge_maps: serving " << server.getService() << " and " << fleet_server.getService()
										   << ", publishing " << merged_pub.getTopic());

	ros::AsyncSpinner spinner(threads);
	spinner.start();
	ros::waitForShutdown();
	return 0;
}
