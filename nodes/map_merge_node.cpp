// map_merge: the live multi-robot merging node, a replacement for m-explore's
// multirobot_map_merge/map_merge with the same parameters and topics (README:
// "Replacing m-explore's map_merge"), robots at any resolution. The work is in
// LiveFleet; this file discovers robots, subscribes, runs the three timers
// and publishes the merged map (latched), TF world_frame → each robot's map
// frame, and a status topic with every robot's placement, scale and reason.
#include <multires_map_merge/FleetStatus.h>
#include <multires_map_merge/ros/AlignerParamsFromRos.h>
#include <multires_map_merge/ros/LiveFleet.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <geometry_msgs/TransformStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <malloc.h>

#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

using namespace multires_map_merge;

namespace
{
struct Settings
{
	double merging_rate = 4.0, discovery_rate = 0.05, estimation_rate = 0.5, estimation_confidence = 1.0;
	bool known_init_poses = true, publish_tf = true;
	std::string robot_map_topic = "map", robot_map_updates_topic = "map_updates", robot_namespace = "",
				merged_map_topic = "map", world_frame = "world";
	double output_resolution = 0;
};

/** Robot `name`'s initial pose, m-explore style: <name>/map_merge/init_pose_{x,y,z,yaw}. */
std::optional<Similarity2D> initPose(const std::string& name)
{
	const std::string ns = ros::names::append(name, "map_merge");
	double x, y, z, yaw;
	if (!ros::param::get(ros::names::append(ns, "init_pose_x"), x) ||
		!ros::param::get(ros::names::append(ns, "init_pose_y"), y) ||
		!ros::param::get(ros::names::append(ns, "init_pose_z"), z) ||
		!ros::param::get(ros::names::append(ns, "init_pose_yaw"), yaw))
		return std::nullopt;
	if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw)) return std::nullopt;
	return Similarity2D(1, yaw, {x, y});
}

void checkRate(const char* name, double v, bool zero_ok)
{
	if (!std::isfinite(v) || v < 0 || (!zero_ok && v == 0))
		throw std::invalid_argument(std::string("~") + name + " must be a rate in Hz > 0");
}
}  // namespace

int main(int argc, char** argv)
{
	// A long-running node that fuses and aligns maps of tens of MB on several
	// threads: glibc's default raises its mmap threshold after the first big
	// free and serves later big blocks from per-thread arenas, which it never
	// returns; resident memory then climbs by hundreds of MB (the soak test
	// saw 0.6 → 1.25 GB in two minutes). Big blocks from mmap go back at free.
	mallopt(M_MMAP_THRESHOLD, 1 << 20);
	mallopt(M_ARENA_MAX, 2);
	ros::init(argc, argv, "map_merge");
	ros::NodeHandle nh, pnh("~");
	Settings s;
	std::unique_ptr<ros1::LiveFleet> fleet;
	try
	{
		pnh.param("merging_rate", s.merging_rate, s.merging_rate);
		pnh.param("discovery_rate", s.discovery_rate, s.discovery_rate);
		pnh.param("estimation_rate", s.estimation_rate, s.estimation_rate);
		pnh.param("estimation_confidence", s.estimation_confidence, s.estimation_confidence);
		pnh.param("known_init_poses", s.known_init_poses, s.known_init_poses);
		pnh.param("robot_map_topic", s.robot_map_topic, s.robot_map_topic);
		pnh.param("robot_map_updates_topic", s.robot_map_updates_topic, s.robot_map_updates_topic);
		pnh.param("robot_namespace", s.robot_namespace, s.robot_namespace);
		pnh.param("merged_map_topic", s.merged_map_topic, s.merged_map_topic);
		pnh.param("world_frame", s.world_frame, s.world_frame);
		pnh.param("publish_tf", s.publish_tf, s.publish_tf);
		pnh.param("output_resolution", s.output_resolution, s.output_resolution);
		checkRate("merging_rate", s.merging_rate, false);
		checkRate("discovery_rate", s.discovery_rate, false);
		checkRate("estimation_rate", s.estimation_rate, true);  // 0: as m-explore, no estimation
		if (!(s.estimation_confidence >= 0 && s.estimation_confidence <= 2))
			throw std::invalid_argument("~estimation_confidence must be in [0, 2] (1.0 = our calibrated 0.5)");

		ros1::LiveFleetParams params;
		params.aligner = ros1::alignerParamsFromRos(
			pnh, {"merging_rate", "discovery_rate", "estimation_rate", "estimation_confidence", "known_init_poses",
				  "robot_map_topic", "robot_map_updates_topic", "robot_namespace", "merged_map_topic", "world_frame",
				  "publish_tf", "output_resolution", "estimation_budget", "retry_growth", "config_file",
				  "config_section"});
		// m-explore's threshold, default 1.0, maps onto our confidence at
		// half: 1.0 → 0.5, the calibrated default; min_confidence wins if set.
		if (!pnh.hasParam("min_confidence")) params.aligner.decision.min_confidence = 0.5 * s.estimation_confidence;
		params.output_resolution = s.output_resolution;
		params.known_init_poses = s.known_init_poses;
		params.estimation_budget_s = ros1::defaultEstimationBudget(s.estimation_rate);
		pnh.param("estimation_budget", params.estimation_budget_s, params.estimation_budget_s);
		pnh.param("retry_growth", params.retry_growth, params.retry_growth);
		fleet = std::make_unique<ros1::LiveFleet>(params);  // throws on a negative budget or growth
	}
	catch (const std::exception& e)
	{
		ROS_FATAL_STREAM("map_merge: bad configuration: " << e.what());
		return 1;
	}

	ros::Publisher merged_pub = nh.advertise<nav_msgs::OccupancyGrid>(s.merged_map_topic, 1, /*latch=*/true);
	ros::Publisher status_pub = pnh.advertise<FleetStatus>("status", 1, /*latch=*/true);
	tf2_ros::TransformBroadcaster tf;
	std::vector<ros::Subscriber> subscribers;
	std::mutex subscribe_mutex;

	auto discover = [&]() {
		ros::master::V_TopicInfo topics;
		if (!ros::master::getTopics(topics)) return;
		std::lock_guard<std::mutex> lock(subscribe_mutex);
		for (const auto& t : topics)
		{
			// m-explore's rule: <robot>/<robot_map_topic> of type
			// nav_msgs/OccupancyGrid, containing robot_namespace, not our output.
			const std::string robot = ros::names::parentNamespace(t.name);
			if (t.datatype != "nav_msgs/OccupancyGrid" || ros::names::append(robot, s.robot_map_topic) != t.name ||
				t.name.find(s.robot_namespace) == std::string::npos || t.name == merged_pub.getTopic() ||
				fleet->hasRobot(robot))
				continue;
			std::optional<Similarity2D> pose;
			if (s.known_init_poses && !(pose = initPose(robot)))
			{
				ROS_WARN_STREAM_THROTTLE(60, "map_merge: no initial pose for " << robot << " (set " << robot
											  << "/map_merge/init_pose_{x,y,z,yaw}, or known_init_poses false)");
				continue;
			}
			fleet->addRobot(robot, pose);
			ROS_INFO_STREAM("map_merge: adding robot " << robot);
			subscribers.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
				t.name, 5, [&, robot](const nav_msgs::OccupancyGrid::ConstPtr& m) {
					if (const std::string why = fleet->onMap(robot, *m); !why.empty())
						ROS_WARN_STREAM_THROTTLE(10, "map_merge: " << robot << ": " << why);
				}));
			subscribers.push_back(nh.subscribe<map_msgs::OccupancyGridUpdate>(
				ros::names::append(robot, s.robot_map_updates_topic), 50,
				[&, robot](const map_msgs::OccupancyGridUpdate::ConstPtr& m) {
					if (const std::string why = fleet->onUpdate(robot, *m); !why.empty())
						ROS_WARN_STREAM_THROTTLE(10, "map_merge: " << robot << ": " << why);
				}));
		}
	};

	auto publishMerged = [&]() {
		std::string why;
		if (auto merged = fleet->merged(s.world_frame, &why))
		{
			merged->header.stamp = merged->info.map_load_time = ros::Time::now();
			merged_pub.publish(*merged);
		}
	};
	auto publishPlacements = [&]() {
		const ros::Time now = ros::Time::now();
		FleetStatus st;
		st.header.stamp = now;
		st.header.frame_id = st.world_frame = s.world_frame;
		for (const auto& r : fleet->status())
		{
			st.robots.push_back(r.name);
			st.frames.push_back(r.frame_id);
			st.placed.push_back(r.placed);
			st.transforms.push_back(ros1::pose2DOf(r.in_world));
			st.scales.push_back(r.placed ? r.in_world.scale : 0.0);
			st.confidences.push_back(r.confidence);
			st.messages.push_back(r.message);
			if (!r.placed || !s.publish_tf) continue;
			geometry_msgs::TransformStamped t;
			t.header.stamp = now;
			t.header.frame_id = s.world_frame;
			t.child_frame_id = r.frame_id;
			t.transform.translation.x = r.in_world.t.x();
			t.transform.translation.y = r.in_world.t.y();
			t.transform.rotation.z = std::sin(r.in_world.yaw / 2);
			t.transform.rotation.w = std::cos(r.in_world.yaw / 2);
			tf.sendTransform(t);
		}
		status_pub.publish(st);
	};

	// Timers on their own queues: a slow estimation never delays the merged
	// map, a slow fusion (maps changing every second) never delays TF and the
	// status, and discovery and the map callbacks never wait for either.
	ros::CallbackQueue estimation_queue, merging_queue;
	ros::NodeHandle estimation_nh, merging_nh;
	estimation_nh.setCallbackQueue(&estimation_queue);
	merging_nh.setCallbackQueue(&merging_queue);
	ros::Timer discovery_timer = nh.createTimer(ros::Duration(1.0 / s.discovery_rate), [&](const ros::TimerEvent&) { discover(); });
	ros::Timer placements_timer =
		nh.createTimer(ros::Duration(1.0 / s.merging_rate), [&](const ros::TimerEvent&) { publishPlacements(); });
	ros::Timer merging_timer =
		merging_nh.createTimer(ros::Duration(1.0 / s.merging_rate), [&](const ros::TimerEvent&) { publishMerged(); });
	std::map<std::string, std::string> last_messages;
	ros::Timer estimation_timer;
	if (s.known_init_poses)  // no estimation: robots are placed at their poses as they appear
		estimation_timer = estimation_nh.createTimer(ros::Duration(1.0), [&](const ros::TimerEvent&) { fleet->estimate(); });
	else if (s.estimation_rate == 0)
		ROS_WARN("map_merge: estimation_rate 0 without known_init_poses: no placement is estimated, so no robot "
				 "will be merged (as in m-explore); set estimation_rate > 0 or known_init_poses true");
	else
		estimation_timer = estimation_nh.createTimer(ros::Duration(1.0 / s.estimation_rate), [&](const ros::TimerEvent&) {
			fleet->estimate();
			for (const auto& r : fleet->status())  // log changes only
				if (last_messages[r.name] != r.message)
				{
					last_messages[r.name] = r.message;
					std::ostringstream pose;
					if (r.placed)
						pose << " [" << s.world_frame << " -> " << r.frame_id << ": x " << r.in_world.t.x() << " m, y "
							 << r.in_world.t.y() << " m, yaw " << r.in_world.yaw * 180 / M_PI << " deg, scale "
							 << r.in_world.scale << "]"
							 << (r.stated_resolution_off ? " (its stated resolution is off; TF carries the rigid part)" : "");
					ROS_INFO_STREAM("map_merge: " << r.name << ": " << r.message << pose.str());
				}
		});
	discover();
	ros::AsyncSpinner estimation_spinner(1, &estimation_queue), merging_spinner(1, &merging_queue);
	merging_spinner.start();
	estimation_spinner.start();
	ros::AsyncSpinner spinner(2);
	spinner.start();
	ROS_INFO_STREAM("map_merge: merged map on " << merged_pub.getTopic() << ", status on " << status_pub.getTopic()
												<< (s.known_init_poses ? " (known initial poses)" : " (estimating placements)"));
	ros::waitForShutdown();
	return 0;
}
