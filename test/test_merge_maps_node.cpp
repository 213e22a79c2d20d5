// merge_maps_node on a real master (rostest, loopback): the service answers
// with the ground truth, publishes the merged map latched, refuses every bad
// input without dying, and takes its parameters from an ini file and the
// parameter server.
#include <multires_map_merge/ros/AlignerParamsFromRos.h>
#include <multires_map_merge/ros/MapMergeNode.h>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>

#include "ros_test_maps.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

namespace
{
const MsgPair& pair() { return rotatedOriginsPair(); }

MergeMaps::Response call(const std::string& service, MergeMaps::Request req)
{
	// Wait for a node once; a node that never came up (or died) fails every
	// later call at once instead of waiting again.
	static std::map<std::string, bool> up;
	if (!up.count(service)) up[service] = ros::service::waitForService(service, ros::Duration(120));
	EXPECT_TRUE(up[service]) << service << " never came up";
	MergeMaps srv;
	srv.request = std::move(req);
	EXPECT_TRUE(ros::service::call(service, srv)) << service << ": the call itself failed (node down?)";
	return srv.response;
}
}  // namespace

TEST(MergeMapsNode, ServesTheTruthAndLatchesTheMergedMap)
{
	ros::NodeHandle nh;
	const MergeMaps::Response res = call("/merge_maps", validRequest(pair()));
	expectTransformMatchesTruth(res, pair());
	expectMergedGridIsRight(res, pair(), 0.05);

	// Latched: a subscriber that comes after the call still gets it.
	std::atomic<bool> got{false};
	nav_msgs::OccupancyGrid latched;
	ros::Subscriber sub = nh.subscribe<nav_msgs::OccupancyGrid>(
		"/merged_map", 1, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
			latched = *m;
			got = true;
		});
	const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(30);
	while (!got && ros::WallTime::now() < until)
	{
		ros::spinOnce();
		ros::WallDuration(0.05).sleep();
	}
	ASSERT_TRUE(got) << "nothing latched on /merged_map";
	EXPECT_EQ(latched.header.frame_id, pair().ref.header.frame_id);
	EXPECT_EQ(latched.info.width, res.merged.info.width);
	EXPECT_EQ(latched.info.height, res.merged.info.height);
	EXPECT_EQ(latched.data, res.merged.data);
}

TEST(MergeMapsNode, EveryBadInputIsRefusedAndTheNodeKeepsServing)
{
	for (const BadRequest& c : badRequests())
	{
		SCOPED_TRACE(c.what);
		MergeMaps::Request req = validRequest(pair());
		c.spoil(req);
		const MergeMaps::Response res = call("/merge_maps", req);
		EXPECT_FALSE(res.success);
		EXPECT_TRUE(saysAnyOf(res.message, c.says)) << res.message;
	}
	const MergeMaps::Response res = call("/merge_maps", validRequest(pair()));
	expectTransformMatchesTruth(res, pair());
}

TEST(MergeMapsNode, IniFileIsReadAndPrivateParametersOverrideIt)
{
	// The ini asks for 100000 RANSAC inliers: nothing can merge.
	const MergeMaps::Response strict = call("/from_ini/merge_maps", validRequest(pair()));
	EXPECT_FALSE(strict.success);
	EXPECT_TRUE(saysAnyOf(strict.message, "no consistent feature matches")) << strict.message;
	// The same ini with ~ransac_min_inliers: 5 merges.
	const MergeMaps::Response overridden = call("/ini_overridden/merge_maps", validRequest(pair()));
	expectTransformMatchesTruth(overridden, pair());
}

// The fleet's parameters (merge_fleet, map_merge) come the same way: [fleet]
// of ~config_file, then private parameters of the same names; a bad one is
// refused naming it.
TEST(MergeMapsNode, FleetParametersFromTheIniFileAndTheServer)
{
	const std::string ns = "/fleet_params_check";
	const std::string ini = std::filesystem::temp_directory_path() / "mmm_fleet_params.ini";
	std::ofstream(ini) << "[fleet]\nsettled_confidence = 0.8\nunsettled_tries = 5\njoint_refinement = false\n";
	ros::param::set(ns + "/config_file", ini);
	ros::param::set(ns + "/unsettled_tries", 7);
	const FleetParams p = ros1::fleetParamsFromRos(ros::NodeHandle(ns));
	EXPECT_EQ(p.settled_confidence, 0.8);  // the ini's
	EXPECT_FALSE(p.joint_refinement);
	EXPECT_EQ(p.unsettled_tries, 7u);  // the server's, over the ini's 5
	EXPECT_EQ(p.cycle_tolerance_cells, FleetParams().cycle_tolerance_cells);  // the default
	// The live map_merge node places its robots with them.
	const ros1::MapMergeConfig live = ros1::MapMergeConfig::fromParams(ros::NodeHandle(ns));
	EXPECT_EQ(live.fleet.placement.unsettled_tries, 7u);
	EXPECT_FALSE(live.fleet.placement.joint_refinement);
	ros::param::set(ns + "/settled_confidence", 1.5);
	try
	{
		ros1::fleetParamsFromRos(ros::NodeHandle(ns));
		ADD_FAILURE() << "settled_confidence 1.5 was taken";
	}
	catch (const std::invalid_argument& e)
	{
		// Named as the user set it: the node's parameter, not an ini section.
		EXPECT_NE(std::string(e.what()).find("parameter " + ns + "/settled_confidence = 1.5 is outside"), std::string::npos)
			<< e.what();
	}
	ros::param::del(ns);
	std::filesystem::remove(ini);
}

int main(int argc, char** argv)
{
	::testing::InitGoogleTest(&argc, argv);
	ros::init(argc, argv, "test_merge_maps_node");
	ros::NodeHandle nh;  // keeps the node up for the whole run
	return RUN_ALL_TESTS();
}
