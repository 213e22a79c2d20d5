// The merge_maps service handler and the OccupancyGrid conversion, without a
// ROS master: real maps, rotated origins, every kind of bad request.
#include <multires_map_merge/ros/MergeMapsService.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <gtest/gtest.h>

#include <functional>
#include <limits>

#include "ros_test_maps.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

TEST(OccupancyGridConversion, RoundTripKeepsCellsAndOrigin)
{
	const auto grid = renderGrid(malagaScans(), 0, 30, 0.07);
	std_msgs::Header h;
	h.frame_id = "map";
	const Similarity2D origin = rigid(12.5, -3.25, 2.5);
	const auto msg = ros1::msgFromGrid({grid, origin}, h);
	EXPECT_EQ(msg.header.frame_id, "map");
	ASSERT_EQ(msg.info.width, grid.getSizeX());
	ASSERT_EQ(msg.info.height, grid.getSizeY());
	const GridInFrame back = ros1::gridFromMsg(msg);
	ASSERT_EQ(back.grid.getSizeX(), grid.getSizeX());
	ASSERT_EQ(back.grid.getSizeY(), grid.getSizeY());
	EXPECT_NEAR(back.grid.getResolution(), 0.07, 1e-6);
	size_t differ = 0;
	for (unsigned y = 0; y < grid.getSizeY(); ++y)
		for (unsigned x = 0; x < grid.getSizeX(); ++x)
			differ += (std::abs(back.grid.getCell(x, y) - grid.getCell(x, y)) > 0.02f);
	EXPECT_EQ(differ, 0u);
	// The grid's corner lands where it was: origin ∘ (x_min, y_min).
	const Eigen::Vector2d corner = back.origin({0, 0});
	const Eigen::Vector2d expected = origin({grid.getXMin(), grid.getYMin()});
	EXPECT_NEAR((corner - expected).norm(), 0, 1e-9);
	EXPECT_NEAR(wrapToPi(back.origin.yaw - 2.5), 0, 1e-9);
}

TEST(OccupancyGridConversion, DefaultQuaternionIsIdentityAndNoiseIsTolerated)
{
	nav_msgs::OccupancyGrid msg;
	msg.info.width = msg.info.height = 4;
	msg.info.resolution = 0.1f;
	msg.data.assign(16, -1);
	msg.info.origin.position.x = 2;  // orientation left all zero, as in a fresh message
	EXPECT_EQ(ros1::gridFromMsg(msg).origin.yaw, 0);
	msg.info.origin.orientation.w = 2;  // not normalised: still a rotation of 0
	msg.info.origin.orientation.z = 1e-9;
	EXPECT_NEAR(ros1::gridFromMsg(msg).origin.yaw, 0, 1e-8);
}

TEST(MergeMapsService, RotatedOriginsGiveTheTruthBetweenFrames)
{
	const MsgPair& p = rotatedOriginsPair();
	ros1::MergeMapsService service;
	MergeMaps::Response res;
	ros1::MergeMapsService::Details details;
	service.merge(validRequest(p), res, &details);
	expectTransformMatchesTruth(res, p);
	expectMergedGridIsRight(res, p, 0.05);
	EXPECT_EQ(res.message, "merged");
	EXPECT_TRUE(details.info.success);
	ASSERT_TRUE(details.fused.has_value());
	EXPECT_EQ(details.fused->merged.grid.getSizeX(), res.merged.info.width);
}

TEST(MergeMapsService, OutputResolutionAndSizeLimit)
{
	const MsgPair& p = rotatedOriginsPair();
	ros1::MergeMapsService service;
	MergeMaps::Request req = validRequest(p);
	req.output_resolution = 0.1;
	MergeMaps::Response res;
	service.merge(req, res);
	expectTransformMatchesTruth(res, p);
	expectMergedGridIsRight(res, p, 0.1);

	// Too large an output is refused with advice, but the alignment is kept.
	req.output_resolution = 0.001;
	service.merge(req, res);
	EXPECT_FALSE(res.success);
	EXPECT_NE(res.message.find("coarser output_resolution"), std::string::npos) << res.message;
	EXPECT_TRUE(res.merged.data.empty());
	EXPECT_NEAR(res.scale, 1.0, 0.002);
}

TEST(MergeMapsService, BadRequestsAreRefusedWithAReasonAndTheNextCallWorks)
{
	const MsgPair& p = rotatedOriginsPair();
	const ros1::MergeMapsService service;
	for (const BadRequest& c : badRequests())
	{
		SCOPED_TRACE(c.what);
		MergeMaps::Request req = validRequest(p);
		c.spoil(req);
		MergeMaps::Response res;
		service.merge(req, res);
		EXPECT_FALSE(res.success);
		EXPECT_TRUE(saysAnyOf(res.message, c.says)) << res.message;
		EXPECT_TRUE(res.merged.data.empty());
		EXPECT_EQ(res.scale, 0);
	}
	MergeMaps::Response res;
	service.merge(validRequest(p), res);
	expectTransformMatchesTruth(res, p);
}

TEST(MergeMapsService, ParametersAreCheckedAndUsed)
{
	CScalingGridMapAligner::TConfigParams bad;
	bad.xi_min = 2;
	EXPECT_THROW(ros1::MergeMapsService{bad}, std::invalid_argument);
	bad = {};
	bad.lambda = std::numeric_limits<double>::quiet_NaN();
	EXPECT_THROW(ros1::MergeMapsService{bad}, std::invalid_argument);

	// A trusted resolution prior that the maps contradict leaves nothing to merge:
	// the stated 8 cm are replaced by a lie of 4 cm.
	MergeMaps::Request req = validRequest(rotatedOriginsPair());
	req.other.info.resolution = 0.04f;
	MergeMaps::Response res;
	ros1::MergeMapsService().merge(req, res);
	ASSERT_TRUE(res.success) << res.message;  // metadata not trusted: the 8 cm are recovered
	EXPECT_NEAR(res.implied_resolution_other, 0.08, 0.08 * 0.002);
	req.use_resolution_metadata = true;
	ros1::MergeMapsService().merge(req, res);
	EXPECT_FALSE(res.success);
	CScalingGridMapAligner::TConfigParams trusting;
	trusting.use_resolution_metadata = true;
	req.use_resolution_metadata = false;
	ros1::MergeMapsService(trusting).merge(req, res);
	EXPECT_FALSE(res.success) << "the node-wide parameter must apply too";
}
