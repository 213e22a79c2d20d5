// The map_merge node on a real master: a recorded session of four robots
// (FleetBag: three in fr079 at 5 / 3 / 8 cm, the third joining late, one in
// intel) replayed from a bag, full maps on latched topics as SLAM nodes
// publish them, map updates in between. The merged map, TF world → each
// robot's map frame and the status are checked against the truth; then
// garbage on the robots' topics must not take the node down.
#include <multires_map_merge/FleetStatus.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/ros/FleetBag.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <gtest/gtest.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <opencv2/core.hpp>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_ros/transform_listener.h>

#include <filesystem>
#include <map>
#include <mutex>

#include "test_data.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

namespace
{
const double kDeg = M_PI / 180;

std::vector<ros1::FleetBagRobot> session()
{
	const std::string fr079 = std::string(MMM_SHARED_DATA) + "/carmen_corrected/freiburg-079-corrected.log.gz";
	const std::string intel = std::string(MMM_SHARED_DATA) + "/carmen_corrected/intel-corrected.log.gz";
	return {
		{"/robot1", fr079, 0.00, 0.45, 0.05, {}, 0},
		{"/robot2", fr079, 0.30, 0.75, 0.03, {2.0, -1.0, 40 * kDeg}, 0},
		{"/robot3", fr079, 0.55, 0.95, 0.08, {-1.5, 3.0, -120 * kDeg}, 2},
		{"/robot4", intel, 0.00, 0.60, 0.05, {}, 0},
	};
}

struct Watch
{
	std::mutex m;
	std::optional<FleetStatus> status;
	std::optional<nav_msgs::OccupancyGrid> merged;
	std::map<std::string, nav_msgs::OccupancyGrid> last_map;  // per robot, as played
};

template <class Pred>
bool spinUntil(Pred done, double seconds)
{
	const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(seconds);
	while (ros::ok() && ros::WallTime::now() < until)
	{
		if (done()) return true;
		ros::WallDuration(0.1).sleep();
	}
	return done();
}

/** RMS displacement of the robot's occupied cells, TF pose against the truth,
 * in cells of the coarser of its map and robot1's. */
double errorCells(const nav_msgs::OccupancyGrid& msg, const ros1::FleetBagRobot& r, const Similarity2D& est)
{
	const Similarity2D truth(1, r.frame.phi(), {r.frame.x(), r.frame.y()});
	return pointRmse(est, truth, occupiedPointsInMapFrame(ros1::gridFromMsg(msg))) / std::max(0.05, r.resolution);
}
}  // namespace

TEST(MapMergeNode, MergesAFleetFromABagAndSurvivesGarbage)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros::NodeHandle nh;
	const auto robots = session();
	const std::string bag_path =
		(std::filesystem::temp_directory_path() / ("mmm_fleet_" + std::to_string(getpid()) + ".bag")).string();
	ros1::writeFleetBag(bag_path, robots, 4, 1.0);

	Watch w;
	ros::Subscriber status_sub = nh.subscribe<FleetStatus>("/map_merge/status", 5, [&](const FleetStatus::ConstPtr& s) {
		std::lock_guard<std::mutex> l(w.m);
		w.status = *s;
	});
	ros::Subscriber merged_sub = nh.subscribe<nav_msgs::OccupancyGrid>("/map", 1, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
		std::lock_guard<std::mutex> l(w.m);
		w.merged = *m;
	});
	tf2_ros::Buffer tf_buffer;
	tf2_ros::TransformListener tf_listener(tf_buffer);
	ros::AsyncSpinner spinner(2);
	spinner.start();

	// Replay: latched full maps (a late subscriber still gets the last one),
	// updates as they come, one wall second per recorded second.
	std::map<std::string, ros::Publisher> pubs;
	rosbag::Bag bag(bag_path);
	rosbag::View view(bag);
	ros::Time previous;
	std::map<std::string, nav_msgs::OccupancyGrid> played;  // the map each robot has, updates applied
	for (const rosbag::MessageInstance& m : view)
	{
		if (!previous.isZero() && m.getTime() > previous) ros::WallDuration((m.getTime() - previous).toSec()).sleep();
		previous = m.getTime();
		const std::string robot = ros::names::parentNamespace(m.getTopic());
		if (auto grid = m.instantiate<nav_msgs::OccupancyGrid>())
		{
			if (!pubs.count(m.getTopic())) pubs[m.getTopic()] = nh.advertise<nav_msgs::OccupancyGrid>(m.getTopic(), 1, true);
			pubs[m.getTopic()].publish(*grid);
			played[robot] = *grid;
		}
		else if (auto up = m.instantiate<map_msgs::OccupancyGridUpdate>())
		{
			if (!pubs.count(m.getTopic())) pubs[m.getTopic()] = nh.advertise<map_msgs::OccupancyGridUpdate>(m.getTopic(), 10, true);
			pubs[m.getTopic()].publish(*up);
			nav_msgs::OccupancyGrid& g = played[robot];
			for (uint32_t y = 0; y < up->height; ++y)
				std::copy_n(up->data.begin() + size_t(y) * up->width, up->width,
							g.data.begin() + size_t(up->y + y) * g.info.width + up->x);
		}
	}
	bag.close();
	std::filesystem::remove(bag_path);

	// Every robot of the building placed, the other building out.
	auto placedAsExpected = [&]() {
		std::lock_guard<std::mutex> l(w.m);
		if (!w.status || w.status->robots.size() != robots.size()) return false;
		for (size_t i = 0; i < w.status->robots.size(); ++i)
			if (w.status->placed[i] != (w.status->robots[i] != "/robot4")) return false;
		return true;
	};
	const bool settled = spinUntil(placedAsExpected, 300);
	{
		std::lock_guard<std::mutex> l(w.m);
		ASSERT_TRUE(w.status) << "no status from map_merge";
		// (A SCOPED_TRACE in a loop body ends with the body: the status goes
		// into the message instead.)
		std::string statuses;
		for (size_t i = 0; i < w.status->robots.size(); ++i)
			statuses += "\n" + w.status->robots[i] + ": " + w.status->messages[i];
		ASSERT_TRUE(settled) << "robots not placed as expected within 300 s" << statuses;
		for (size_t i = 0; i < w.status->robots.size(); ++i)
			if (w.status->robots[i] == "/robot4")
			{
				EXPECT_NE(w.status->messages[i].find("not placed"), std::string::npos) << w.status->messages[i];
			}
	}
	// TF against the truth. The world is one robot's map frame (whichever
	// the node settled on), so robot 1's frame in it is the truth's origin:
	// each robot is compared through robot1/map -> world -> robotN/map.
	auto poseInWorld = [&](const std::string& frame) {
		geometry_msgs::TransformStamped t;
		EXPECT_TRUE(spinUntil([&]() { return tf_buffer.canTransform("world", frame, ros::Time(0)); }, 30)) << frame;
		t = tf_buffer.lookupTransform("world", frame, ros::Time(0));
		const double yaw = 2 * std::atan2(t.transform.rotation.z, t.transform.rotation.w);
		return Similarity2D(1, yaw, {t.transform.translation.x, t.transform.translation.y});
	};
	const Similarity2D robot1_in_world = poseInWorld("robot1/map");
	for (size_t i = 1; i < 3; ++i)
	{
		const std::string frame = robots[i].name.substr(1) + "/map";
		const Similarity2D in_robot1 = robot1_in_world.inverse().compose(poseInWorld(frame));
		EXPECT_LE(errorCells(played[robots[i].name], robots[i], in_robot1), 2.0) << frame;
	}
	// The merged map (the next one: the last may predate the placements): in
	// the world frame, larger than robot 1's alone.
	{
		std::lock_guard<std::mutex> l(w.m);
		w.merged.reset();
	}
	ASSERT_TRUE(spinUntil([&]() { std::lock_guard<std::mutex> l(w.m); return w.merged.has_value(); }, 30));
	{
		std::lock_guard<std::mutex> l(w.m);
		EXPECT_EQ(w.merged->header.frame_id, "world");
		const GridInFrame merged = ros1::gridFromMsg(*w.merged), first = ros1::gridFromMsg(played["/robot1"]);
		EXPECT_GT(cv::countNonZero(toClassImage(merged.grid) != kUnknown), 1.3 * cv::countNonZero(toClassImage(first.grid) != kUnknown));
	}

	// Garbage: wrong sizes, NaN resolution, values out of range, updates
	// outside the map. The node stays up and keeps every robot placed.
	nav_msgs::OccupancyGrid bad = played["/robot1"];
	bad.data.resize(3);
	pubs["/robot1/map"].publish(bad);
	bad = played["/robot2"];
	bad.info.resolution = std::nanf("");
	pubs["/robot2/map"].publish(bad);
	map_msgs::OccupancyGridUpdate up;
	up.x = 100000, up.width = 1, up.height = 1, up.data = {50};
	if (!pubs.count("/robot1/map_updates"))
		pubs["/robot1/map_updates"] = nh.advertise<map_msgs::OccupancyGridUpdate>("/robot1/map_updates", 10, true);
	pubs["/robot1/map_updates"].publish(up);
	up.x = 0, up.data = {127};
	pubs["/robot1/map_updates"].publish(up);
	ros::WallDuration(3.0).sleep();
	{
		std::lock_guard<std::mutex> l(w.m);
		w.status.reset();
	}
	ASSERT_TRUE(spinUntil([&]() { std::lock_guard<std::mutex> l(w.m); return w.status.has_value(); }, 30))
		<< "map_merge stopped publishing after garbage";
	EXPECT_TRUE(placedAsExpected());
}

int main(int argc, char** argv)
{
	testing::InitGoogleTest(&argc, argv);
	ros::init(argc, argv, "test_map_merge_node");
	return RUN_ALL_TESTS();
}
