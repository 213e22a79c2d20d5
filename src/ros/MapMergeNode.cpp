#include <multires_map_merge/ros/AlignerParamsFromRos.h>
#include <multires_map_merge/ros/MapMergeNode.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <geometry_msgs/TransformStamped.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <variant>

namespace multires_map_merge::ros1
{
namespace
{
using S = MapMergeSettings;

/** The node's own keys, each read into its member: the one list. */
struct SettingKey
{
	const char* key;
	std::variant<double S::*, bool S::*, std::string S::*> member;
};
const std::vector<SettingKey>& settingKeys()
{
	static const std::vector<SettingKey> keys{
		{"merging_rate", &S::merging_rate},
		{"discovery_rate", &S::discovery_rate},
		{"estimation_rate", &S::estimation_rate},
		{"estimation_confidence", &S::estimation_confidence},
		{"known_init_poses", &S::known_init_poses},
		{"robot_map_topic", &S::robot_map_topic},
		{"robot_map_updates_topic", &S::robot_map_updates_topic},
		{"robot_namespace", &S::robot_namespace},
		{"merged_map_topic", &S::merged_map_topic},
		{"world_frame", &S::world_frame},
		{"publish_tf", &S::publish_tf},
		{"output_resolution", &S::output_resolution},
	};
	return keys;
}
// LiveFleet's keys, read after the aligner's (their defaults follow estimation_rate).
constexpr const char* kBudgetKey = "estimation_budget";
constexpr const char* kRetryGrowthKey = "retry_growth";

void checkRate(const char* name, double v, bool zero_ok)
{
	if (!std::isfinite(v) || v < 0 || (!zero_ok && v == 0))
		throw std::invalid_argument(std::string("~") + name + " must be a rate in Hz > 0");
}

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
}  // namespace

MapMergeConfig MapMergeConfig::fromParams(const ros::NodeHandle& pnh)
{
	MapMergeConfig c;
	S& s = c.node;
	std::vector<std::string> node_keys{kBudgetKey, kRetryGrowthKey};
	for (const auto& k : settingKeys())
	{
		std::visit([&](auto member) { pnh.param(k.key, s.*member, s.*member); }, k.member);
		node_keys.emplace_back(k.key);
	}
	checkRate("merging_rate", s.merging_rate, false);
	checkRate("discovery_rate", s.discovery_rate, false);
	checkRate("estimation_rate", s.estimation_rate, true);  // 0: as m-explore, no estimation
	if (!(s.estimation_confidence >= 0 && s.estimation_confidence <= 2))
		throw std::invalid_argument("~estimation_confidence must be in [0, 2] (1.0 = our calibrated 0.5)");

	LiveFleetParams& f = c.fleet;
	f.aligner = alignerParamsFromRos(pnh, node_keys);
	f.placement = fleetParamsFromRos(pnh);
	// m-explore's threshold, default 1.0, maps onto our confidence at half:
	// 1.0 → 0.5, the calibrated default; min_confidence wins if set.
	if (!pnh.hasParam("min_confidence")) f.aligner.decision.min_confidence = 0.5 * s.estimation_confidence;
	f.output_resolution = s.output_resolution;
	f.known_init_poses = s.known_init_poses;
	f.estimation_budget_s = defaultEstimationBudget(s.estimation_rate);
	pnh.param(kBudgetKey, f.estimation_budget_s, f.estimation_budget_s);
	pnh.param(kRetryGrowthKey, f.retry_growth, f.retry_growth);
	return c;
}

MapMergeNode::MapMergeNode(const MapMergeConfig& config)
	: settings_(config.node), fleet_(config.fleet)  // LiveFleet throws on a negative budget or growth
{
	const S& s = settings_;
	merged_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>(s.merged_map_topic, 1, /*latch=*/true);
	status_pub_ = pnh_.advertise<FleetStatus>("status", 1, /*latch=*/true);
	estimation_nh_.setCallbackQueue(&estimation_queue_);
	merging_nh_.setCallbackQueue(&merging_queue_);
	discovery_timer_ = nh_.createTimer(ros::Duration(1.0 / s.discovery_rate), [this](const ros::TimerEvent&) { discover(); });
	placements_timer_ =
		nh_.createTimer(ros::Duration(1.0 / s.merging_rate), [this](const ros::TimerEvent&) { publishPlacements(); });
	merging_timer_ =
		merging_nh_.createTimer(ros::Duration(1.0 / s.merging_rate), [this](const ros::TimerEvent&) { publishMerged(); });
	if (s.known_init_poses)  // no estimation: robots are placed at their poses as they appear
		estimation_timer_ =
			estimation_nh_.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { fleet_.estimate(); });
	else if (s.estimation_rate == 0)
		ROS_WARN("map_merge: estimation_rate 0 without known_init_poses: no placement is estimated, so no robot "
				 "will be merged (as in m-explore); set estimation_rate > 0 or known_init_poses true");
	else
		estimation_timer_ = estimation_nh_.createTimer(
			ros::Duration(1.0 / s.estimation_rate), [this](const ros::TimerEvent&) { estimate(); });
}

void MapMergeNode::start()
{
	discover();
	estimation_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &estimation_queue_);
	merging_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &merging_queue_);
	spinner_ = std::make_unique<ros::AsyncSpinner>(2);
	merging_spinner_->start();
	estimation_spinner_->start();
	spinner_->start();
	ROS_INFO_STREAM("map_merge: merged map on " << merged_pub_.getTopic() << ", status on " << status_pub_.getTopic()
												<< (settings_.known_init_poses ? " (known initial poses)"
																				: " (estimating placements)"));
}

void MapMergeNode::discover()
{
	const S& s = settings_;
	ros::master::V_TopicInfo topics;
	if (!ros::master::getTopics(topics)) return;
	std::lock_guard<std::mutex> lock(subscribe_mutex_);
	for (const auto& t : topics)
	{
		// m-explore's rule: <robot>/<robot_map_topic> of type
		// nav_msgs/OccupancyGrid, containing robot_namespace, not our output.
		const std::string robot = ros::names::parentNamespace(t.name);
		if (t.datatype != "nav_msgs/OccupancyGrid" || ros::names::append(robot, s.robot_map_topic) != t.name ||
			t.name.find(s.robot_namespace) == std::string::npos || t.name == merged_pub_.getTopic() ||
			fleet_.hasRobot(robot))
			continue;
		std::optional<Similarity2D> pose;
		if (s.known_init_poses && !(pose = initPose(robot)))
		{
			ROS_WARN_STREAM_THROTTLE(60, "map_merge: no initial pose for " << robot << " (set " << robot
										  << "/map_merge/init_pose_{x,y,z,yaw}, or known_init_poses false)");
			continue;
		}
		fleet_.addRobot(robot, pose);
		ROS_INFO_STREAM("map_merge: adding robot " << robot);
		subscribers_.push_back(nh_.subscribe<nav_msgs::OccupancyGrid>(
			t.name, 5, [this, robot](const nav_msgs::OccupancyGrid::ConstPtr& m) {
				if (const std::string why = fleet_.onMap(robot, *m); !why.empty())
					ROS_WARN_STREAM_THROTTLE(10, "map_merge: " << robot << ": " << why);
			}));
		subscribers_.push_back(nh_.subscribe<map_msgs::OccupancyGridUpdate>(
			ros::names::append(robot, s.robot_map_updates_topic), 50,
			[this, robot](const map_msgs::OccupancyGridUpdate::ConstPtr& m) {
				if (const std::string why = fleet_.onUpdate(robot, *m); !why.empty())
					ROS_WARN_STREAM_THROTTLE(10, "map_merge: " << robot << ": " << why);
			}));
	}
}

void MapMergeNode::publishMerged()
{
	std::string why;
	if (auto merged = fleet_.merged(settings_.world_frame, &why))
	{
		merged->header.stamp = merged->info.map_load_time = ros::Time::now();
		merged_pub_.publish(*merged);
	}
}

void MapMergeNode::publishPlacements()
{
	const ros::Time now = ros::Time::now();
	FleetStatus st;
	st.header.stamp = now;
	st.header.frame_id = st.world_frame = settings_.world_frame;
	for (const auto& r : fleet_.status())
	{
		st.robots.push_back(r.name);
		st.frames.push_back(r.frame_id);
		st.placed.push_back(r.placed);
		st.transforms.push_back(pose2DOf(r.in_world));
		st.scales.push_back(r.placed ? r.in_world.scale : 0.0);
		st.confidences.push_back(r.confidence);
		st.messages.push_back(r.message);
		if (!r.placed || !settings_.publish_tf) continue;
		geometry_msgs::TransformStamped t;
		t.header.stamp = now;
		t.header.frame_id = settings_.world_frame;
		t.child_frame_id = r.frame_id;
		t.transform.translation.x = r.in_world.t.x();
		t.transform.translation.y = r.in_world.t.y();
		t.transform.rotation.z = std::sin(r.in_world.yaw / 2);
		t.transform.rotation.w = std::cos(r.in_world.yaw / 2);
		tf_.sendTransform(t);
	}
	status_pub_.publish(st);
}

void MapMergeNode::estimate()
{
	fleet_.estimate();
	for (const auto& r : fleet_.status())  // log changes only
	{
		if (last_messages_[r.name] == r.message) continue;
		last_messages_[r.name] = r.message;
		std::ostringstream pose;
		if (r.placed)
			pose << " [" << settings_.world_frame << " -> " << r.frame_id << ": x " << r.in_world.t.x() << " m, y "
				 << r.in_world.t.y() << " m, yaw " << r.in_world.yaw * 180 / M_PI << " deg, scale "
				 << r.in_world.scale << "]"
				 << (r.stated_resolution_off ? " (its stated resolution is off; TF carries the rigid part)" : "");
		ROS_INFO_STREAM("map_merge: " << r.name << ": " << r.message << pose.str());
	}
}

}  // namespace multires_map_merge::ros1
