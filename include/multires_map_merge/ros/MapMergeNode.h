#pragma once
// The map_merge node (m-explore's interface, README "Replacing m-explore's
// map_merge"): its parameters, read once from one list, and the plumbing
// around LiveFleet — discovery of robots, subscriptions, the three timers on
// their own queues, the merged map (latched), TF world_frame → each robot's
// map frame and the status topic. nodes/map_merge_node.cpp only starts it.
#include <multires_map_merge/FleetStatus.h>
#include <multires_map_merge/ros/LiveFleet.h>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <tf2_ros/transform_broadcaster.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
/** The node's own parameters (m-explore's names and defaults, plus ours). */
struct MapMergeSettings
{
	double merging_rate = 4.0, discovery_rate = 0.05, estimation_rate = 0.5, estimation_confidence = 1.0;
	bool known_init_poses = true, publish_tf = true;
	std::string robot_map_topic = "map", robot_map_updates_topic = "map_updates", robot_namespace = "",
				merged_map_topic = "map", world_frame = "world";
	double output_resolution = 0;
};

/** Every private parameter the node reads: its own, LiveFleet's
 * (estimation_budget, retry_growth) and the aligner's (with ~config_file).
 * Throws std::invalid_argument naming the parameter at fault. */
struct MapMergeConfig
{
	MapMergeSettings node;
	LiveFleetParams fleet;
	static MapMergeConfig fromParams(const ros::NodeHandle& private_nh);
};

class MapMergeNode
{
   public:
	explicit MapMergeNode(const MapMergeConfig& config);
	/** Discovers the robots there are and starts the timers' spinners. */
	void start();

   private:
	void discover();
	void publishMerged();
	void publishPlacements();
	/** One estimation, logging each robot whose state changed. */
	void estimate();

	MapMergeSettings settings_;
	LiveFleet fleet_;
	ros::NodeHandle nh_, pnh_{"~"};
	ros::Publisher merged_pub_, status_pub_;
	tf2_ros::TransformBroadcaster tf_;
	std::vector<ros::Subscriber> subscribers_;
	std::mutex subscribe_mutex_;
	std::map<std::string, std::string> last_messages_;
	// Timers on their own queues: a slow estimation never delays the merged
	// map, a slow fusion (maps changing every second) never delays TF and
	// the status, and discovery and the map callbacks never wait for either.
	ros::CallbackQueue estimation_queue_, merging_queue_;
	ros::NodeHandle estimation_nh_, merging_nh_;
	ros::Timer discovery_timer_, placements_timer_, merging_timer_, estimation_timer_;
	std::unique_ptr<ros::AsyncSpinner> estimation_spinner_, merging_spinner_, spinner_;
};

}  // namespace multires_map_merge::ros1
