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

namespace
{
/** Malaga (Debian's mrpt-common) as three robots' messages: each a share of
 * the run at its own resolution, in its own frame, with a rotated origin. */
struct FleetMsgs
{
	MergeFleet::Request req;
	std::vector<Similarity2D> truth;  //!< map i's frame → the reference's
	std::vector<double> res;
};

const FleetMsgs& malagaFleet()
{
	static const FleetMsgs f = [] {
		FleetMsgs out;
		const ScanSequence& s = malagaScans();
		const size_t n = s.size();
		struct Robot
		{
			double begin, end, res;
			mrpt::poses::CPose2D frame;
			Similarity2D origin;
		};
		const std::vector<Robot> robots = {
			{0.0, 0.6, 0.05, {}, rigid(3, -1, 0.3)},
			{0.4, 1.0, 0.08, {1.5, -2.5, 120 * M_PI / 180}, rigid(-20, 40, -1.0)},
			{0.2, 0.8, 0.03, {-4, 2, -60 * M_PI / 180}, rigid(7, 7, 2.0)},
		};
		for (size_t i = 0; i < robots.size(); ++i)
		{
			const Robot& r = robots[i];
			std_msgs::Header h;
			h.frame_id = "robot" + std::to_string(i + 1) + "/map";
			const auto grid = renderGrid(s, size_t(r.begin * n), size_t(r.end * n), r.res, r.frame);
			out.req.maps.push_back(ros1::msgFromGrid({grid, r.origin}, h));
			// map frame → grid frame (origin⁻¹) → the run in r.frame → ref grid → ref frame
			out.truth.push_back(robots[0].origin.compose(Similarity2D(1, r.frame.phi(), {r.frame.x(), r.frame.y()}))
									.compose(r.origin.inverse()));
			out.res.push_back(r.res);
		}
		return out;
	}();
	return f;
}
}  // namespace

TEST(MergeFleetService, PlacesEveryMapInTheReferenceFrame)
{
	const FleetMsgs& f = malagaFleet();
	MergeFleet::Response res;
	ros1::MergeMapsService().mergeFleet(f.req, res);
	ASSERT_TRUE(res.success) << res.message;
	ASSERT_EQ(res.placed.size(), 3u);
	ASSERT_EQ(res.transforms.size(), 3u);
	for (size_t i = 1; i < 3; ++i)
	{
		ASSERT_TRUE(res.placed[i]) << res.messages[i];
		const Similarity2D got(res.scales[i], res.transforms[i].theta, {res.transforms[i].x, res.transforms[i].y});
		const GridInFrame map = ros1::gridFromMsg(f.req.maps[i]);
		PointList pts = edgePoints(toClassImage(map.grid));
		for (auto& q : pts) q = map.cellToMapFrame()(q);
		EXPECT_LT(pointRmse(got, f.truth[i], pts) / std::max(f.res[0], f.res[i]), 1.0) << "maps[" << i << "]";
		EXPECT_NEAR(res.scales[i], 1.0, 0.005);
		EXPECT_GE(res.confidences[i], 0.5);
	}
	EXPECT_EQ(res.merged.header.frame_id, "robot1/map");
	EXPECT_NEAR(res.merged.info.resolution, 0.05, 1e-6);
	EXPECT_EQ(res.pairs_aligned + res.pairs_skipped, 3u);
	EXPECT_GT(res.runtime, 0);
}

TEST(MergeFleetService, BadRequestsNameTheMapAndTheField)
{
	const FleetMsgs& f = malagaFleet();
	ros1::MergeMapsService service;
	MergeFleet::Response res;
	MergeFleet::Request bad = f.req;
	bad.maps[2].data.resize(10);
	service.mergeFleet(bad, res);
	EXPECT_FALSE(res.success);
	EXPECT_NE(res.message.find("maps[2]"), std::string::npos) << res.message;
	// Several bad maps: each named in the one answer.
	bad.maps[0].info.resolution = -0.05;
	service.mergeFleet(bad, res);
	EXPECT_FALSE(res.success);
	EXPECT_NE(res.message.find("2 maps are not usable grids"), std::string::npos) << res.message;
	EXPECT_NE(res.message.find("maps[0]"), std::string::npos) << res.message;
	EXPECT_NE(res.message.find("maps[2]"), std::string::npos) << res.message;
	bad = f.req;
	bad.reference = 3;
	service.mergeFleet(bad, res);
	EXPECT_FALSE(res.success);
	EXPECT_NE(res.message.find("reference"), std::string::npos) << res.message;
	bad.maps.resize(1);
	bad.reference = 0;
	service.mergeFleet(bad, res);
	EXPECT_FALSE(res.success);
	EXPECT_NE(res.message.find("at least two"), std::string::npos) << res.message;
	bad = f.req;
	bad.output_resolution = -1;
	service.mergeFleet(bad, res);
	EXPECT_NE(res.message.find("output_resolution"), std::string::npos) << res.message;
}
