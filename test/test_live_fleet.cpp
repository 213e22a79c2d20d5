// The live fleet merge (LiveFleet, what the map_merge node runs) without a
// master: robots' growing maps as nav_msgs/OccupancyGrid at 5 / 3 / 8 cm in
// their own frames, one of another building, a robot joining late, map
// updates, garbage messages, and a wrong map that must not move a placed robot.
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/ros/LiveFleet.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "test_data.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

namespace
{
struct RobotSpec
{
	std::string name, log;
	double begin, end, res;
	mrpt::poses::CPose2D frame;  //!< its map frame in the run's (= the world robot's map frame)
};

const ScanSequence& scans(const std::string& log)
{
	static std::map<std::string, ScanSequence> cache;
	auto it = cache.find(log);
	if (it == cache.end()) it = cache.emplace(log, loadScans(std::string(MMM_SHARED_DATA) + "/carmen_corrected/" + log)).first;
	return it->second;
}

/** The robot's map after `share` of its part of the run, off-lattice origin. */
nav_msgs::OccupancyGrid mapMsg(const RobotSpec& r, double share, uint32_t stamp)
{
	const ScanSequence& s = scans(r.log);
	const size_t n = s.size(), b = size_t(r.begin * n), e = size_t((r.begin + share * (r.end - r.begin)) * n);
	std_msgs::Header h;
	h.frame_id = r.name + "/map";
	h.stamp = ros::Time(stamp, 0);
	return ros1::msgFromGrid(renderGridOffLattice(s, b, e, r.res, r.frame, 0.37 * r.res, 0.61 * r.res), h);
}

const std::vector<RobotSpec>& robots()
{
	static const std::vector<RobotSpec> r = {
		{"/robot1", "freiburg-079-corrected.log.gz", 0.00, 0.45, 0.05, {}},
		{"/robot2", "freiburg-079-corrected.log.gz", 0.30, 0.75, 0.03, {2.0, -1.0, 40 * M_PI / 180}},
		{"/robot3", "freiburg-079-corrected.log.gz", 0.55, 0.95, 0.08, {-1.5, 3.0, -120 * M_PI / 180}},
		{"/robot4", "intel-corrected.log.gz", 0.00, 0.60, 0.05, {}},  // another building
	};
	return r;
}

/** RMS error of a placement over the robot's occupied cells, in cells of the
 * coarser of its map and the world robot's. */
double errorCells(const nav_msgs::OccupancyGrid& msg, const RobotSpec& r, const Similarity2D& in_world)
{
	const Similarity2D truth(1, r.frame.phi(), {r.frame.x(), r.frame.y()});
	return pointRmse(in_world, truth, occupiedPointsInMapFrame(ros1::gridFromMsg(msg))) / std::max(0.05, r.res);
}

ros1::LiveFleet::RobotStatus statusOf(const ros1::LiveFleet& f, const std::string& name)
{
	for (const auto& s : f.status())
		if (s.name == name) return s;
	throw std::runtime_error("no robot " + name);
}
}  // namespace

TEST(LiveFleet, GrowingMapsLateJoinerOtherBuildingAndNoFlicker)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleet fleet({});
	const auto& R = robots();
	for (size_t i : {0, 1, 3}) fleet.addRobot(R[i].name);

	// 1. Half of each robot's run.
	std::vector<nav_msgs::OccupancyGrid> half;
	for (const auto& r : R) half.push_back(mapMsg(r, 0.5, 1));
	for (size_t i : {0, 1, 3}) ASSERT_EQ(fleet.onMap(R[i].name, half[i]), "");
	EXPECT_EQ(fleet.worldRobot(), "/robot1");
	fleet.estimate();
	EXPECT_TRUE(statusOf(fleet, "/robot1").placed);
	auto s2 = statusOf(fleet, "/robot2");
	ASSERT_TRUE(s2.placed) << s2.message;
	EXPECT_LE(errorCells(half[1], R[1], s2.in_world), 2.0);
	EXPECT_EQ(s2.frame_id, "/robot2/map");
	const auto s4 = statusOf(fleet, "/robot4");
	EXPECT_FALSE(s4.placed);
	EXPECT_NE(s4.message.find("not placed"), std::string::npos) << s4.message;

	// 2. The maps grow, a robot joins late.
	fleet.addRobot(R[2].name);
	std::vector<nav_msgs::OccupancyGrid> full;
	for (const auto& r : R) full.push_back(mapMsg(r, 1.0, 2));
	for (size_t i = 0; i < R.size(); ++i) ASSERT_EQ(fleet.onMap(R[i].name, full[i]), "") << R[i].name;
	fleet.estimate();
	for (size_t i : {1, 2})
	{
		const auto s = statusOf(fleet, R[i].name);
		ASSERT_TRUE(s.placed) << R[i].name << ": " << s.message;
		EXPECT_LE(errorCells(full[i], R[i], s.in_world), 2.0) << R[i].name;
		EXPECT_NEAR(s.in_world.scale, 1.0, 0.01);
		EXPECT_FALSE(s.stated_resolution_off) << R[i].name << " scale " << s.in_world.scale;  // stated exactly
	}
	EXPECT_FALSE(statusOf(fleet, "/robot4").placed);
	const auto merged = fleet.merged("world");
	ASSERT_TRUE(merged);
	EXPECT_EQ(merged->header.frame_id, "world");
	EXPECT_NEAR(merged->info.resolution, 0.05, 1e-6);
	const GridInFrame world = ros1::gridFromMsg(*merged), ref = ros1::gridFromMsg(full[0]);
	EXPECT_GT(cv::countNonZero(toClassImage(world.grid) != kUnknown), 1.3 * cv::countNonZero(toClassImage(ref.grid) != kUnknown));

	// 3. Robot 2 now sends another building's map: its estimate fails, and
	// its placement stays where it was (no flicker).
	const Similarity2D before = statusOf(fleet, "/robot2").in_world;
	nav_msgs::OccupancyGrid wrong = full[3];
	wrong.header = full[1].header;
	wrong.header.stamp = ros::Time(3, 0);
	ASSERT_EQ(fleet.onMap("/robot2", wrong), "");
	fleet.estimate();
	const auto kept = statusOf(fleet, "/robot2");
	EXPECT_TRUE(kept.placed);
	EXPECT_EQ(kept.in_world.t, before.t);
	EXPECT_EQ(kept.in_world.yaw, before.yaw);
	EXPECT_NE(kept.message.find("kept"), std::string::npos) << kept.message;
}

TEST(LiveFleet, GarbageMessagesAreIgnoredWithAReason)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleet fleet({});
	const auto& R = robots();
	fleet.addRobot(R[0].name);
	nav_msgs::OccupancyGrid good = mapMsg(R[0], 0.3, 5);
	map_msgs::OccupancyGridUpdate up;
	up.width = 2, up.height = 2, up.data = {100, 100, 100, 100};
	EXPECT_NE(fleet.onUpdate(R[0].name, up).find("no full map"), std::string::npos);
	nav_msgs::OccupancyGrid bad = good;
	bad.data.resize(7);
	EXPECT_NE(fleet.onMap(R[0].name, bad).find("ignored"), std::string::npos);
	bad = good;
	bad.info.resolution = std::nanf("");
	EXPECT_NE(fleet.onMap(R[0].name, bad).find("resolution"), std::string::npos);
	EXPECT_NE(fleet.onMap("/nobody", good).find("unknown robot"), std::string::npos);
	ASSERT_EQ(fleet.onMap(R[0].name, good), "");
	nav_msgs::OccupancyGrid older = good;
	older.header.stamp = ros::Time(4, 0);
	EXPECT_NE(fleet.onMap(R[0].name, older).find("older"), std::string::npos);

	// Updates: wrong sizes, values, places are refused; a good one is applied,
	// clipped at the map's edge.
	map_msgs::OccupancyGridUpdate u = up;
	u.data.pop_back();
	EXPECT_NE(fleet.onUpdate(R[0].name, u).find("width x height"), std::string::npos);
	u = up, u.data[0] = 101;
	EXPECT_NE(fleet.onUpdate(R[0].name, u).find("-1..100"), std::string::npos);
	u = up, u.x = -1;
	EXPECT_NE(fleet.onUpdate(R[0].name, u).find("negative"), std::string::npos);
	u = up, u.x = int(good.info.width);
	EXPECT_NE(fleet.onUpdate(R[0].name, u).find("outside"), std::string::npos);
	fleet.estimate();
	const auto before = fleet.merged("world");
	ASSERT_TRUE(before);
	const GridInFrame g = ros1::gridFromMsg(good);
	EXPECT_GT(ros1::gridFromMsg(*before).grid.getCell(g.grid.getSizeX() - 1, 0), 0.1f);  // not occupied yet
	u = up, u.x = int(good.info.width) - 1, u.y = 0;
	EXPECT_EQ(fleet.onUpdate(R[0].name, u), "");
	const auto merged = fleet.merged("world");  // no estimation between: the update alone must show
	ASSERT_TRUE(merged);  // the good map, with the update, survives
	const GridInFrame m = ros1::gridFromMsg(*merged);
	EXPECT_EQ(m.grid.getSizeX(), g.grid.getSizeX());
	EXPECT_LT(m.grid.getCell(g.grid.getSizeX() - 1, 0), 0.1f);  // the updated corner cell: occupied (MRPT: 0)
}

TEST(LiveFleet, KnownInitialPosesPlaceWithoutEstimating)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleetParams p;
	p.known_init_poses = true;
	ros1::LiveFleet fleet(p);
	const auto& R = robots();
	fleet.addRobot(R[0].name, Similarity2D(1, 0.5, {10, 20}));
	fleet.addRobot(R[1].name);  // no pose: stays out, said why
	ASSERT_EQ(fleet.onMap(R[0].name, mapMsg(R[0], 0.3, 1)), "");
	ASSERT_EQ(fleet.onMap(R[1].name, mapMsg(R[1], 0.3, 1)), "");
	fleet.estimate();
	EXPECT_TRUE(statusOf(fleet, "/robot1").placed);
	EXPECT_FALSE(statusOf(fleet, "/robot2").placed);
	EXPECT_NE(statusOf(fleet, "/robot2").message.find("init_pose"), std::string::npos);
	const auto merged = fleet.merged("world");
	ASSERT_TRUE(merged);
	// The merged map is robot 1's map at its initial pose in the world.
	const Similarity2D origin = ros1::originOf(*merged);
	EXPECT_NEAR(origin.yaw, 0.5, 1e-6);
}

TEST(LiveFleet, AFirstRobotThatOverlapsNoOneDoesNotHoldTheWorld)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleet fleet({});
	const auto& R = robots();
	for (size_t i : {3, 0, 1}) fleet.addRobot(R[i].name);
	for (size_t i : {3, 0, 1}) ASSERT_EQ(fleet.onMap(R[i].name, mapMsg(R[i], 0.5, 1)), "");  // another building first
	EXPECT_EQ(fleet.worldRobot(), "/robot4");
	fleet.estimate();
	EXPECT_EQ(fleet.worldRobot(), "/robot1");  // the largest group's first robot
	EXPECT_FALSE(statusOf(fleet, "/robot4").placed) << statusOf(fleet, "/robot4").message;
	const auto s2 = statusOf(fleet, "/robot2");
	ASSERT_TRUE(s2.placed) << s2.message;
	EXPECT_LE(errorCells(mapMsg(R[1], 0.5, 1), R[1], s2.in_world), 2.0);
	// Committed now: the world stays, whatever comes.
	fleet.estimate();
	EXPECT_EQ(fleet.worldRobot(), "/robot1");
}

TEST(LiveFleet, AStatedResolutionThatIsOffIsSaid)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleet fleet({});
	const auto& R = robots();
	for (size_t i : {0, 1}) fleet.addRobot(R[i].name);
	ASSERT_EQ(fleet.onMap(R[0].name, mapMsg(R[0], 0.5, 1)), "");
	nav_msgs::OccupancyGrid misstated = mapMsg(R[1], 0.5, 1);
	misstated.info.resolution = 0.05f;  // 3 cm cells said to be 5 cm
	ASSERT_EQ(fleet.onMap(R[1].name, misstated), "");
	fleet.estimate();
	const auto s2 = statusOf(fleet, "/robot2");
	ASSERT_TRUE(s2.placed) << s2.message;
	EXPECT_NEAR(s2.in_world.scale, 0.6, 0.01);
	EXPECT_TRUE(s2.stated_resolution_off);
	EXPECT_FALSE(statusOf(fleet, "/robot1").stated_resolution_off);
}

TEST(LiveFleet, AnEstimationAlignsOnlyWhatChanged)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleetParams p;
	p.retry_growth = 10;  // a refused pair waits for its maps to grow elevenfold (or retry_estimations)
	ros1::LiveFleet fleet(p);
	const auto& R = robots();
	for (size_t i : {0, 1, 3}) fleet.addRobot(R[i].name);
	for (size_t i : {0, 1, 3}) ASSERT_EQ(fleet.onMap(R[i].name, mapMsg(R[i], 0.5, 1)), "");
	fleet.estimate();
	auto st = fleet.lastEstimation();
	EXPECT_EQ(st.maps_prepared, 3u);
	EXPECT_EQ(st.pairs_aligned, 3u);  // robot 4 is placed by nothing: all its pairs are tried
	const auto placed = statusOf(fleet, "/robot2");
	ASSERT_TRUE(placed.placed) << placed.message;

	// Nothing changed: nothing is prepared or aligned again, nothing moves.
	fleet.estimate();
	st = fleet.lastEstimation();
	EXPECT_EQ(st.maps_prepared, 0u);
	EXPECT_EQ(st.pairs_aligned, 0u);
	EXPECT_EQ(st.pairs_reused, 3u);
	EXPECT_EQ(statusOf(fleet, "/robot2").in_world.t, placed.in_world.t);
	EXPECT_FALSE(statusOf(fleet, "/robot4").placed);

	// Robot 2's map grows: it is prepared again and tracked from its placement;
	// its refused pair with robot 4 waits (it did not grow enough), robot 1's
	// with robot 4 is unchanged.
	const auto grown = mapMsg(R[1], 0.6, 2);
	ASSERT_EQ(fleet.onMap(R[1].name, grown), "");
	fleet.estimate();
	st = fleet.lastEstimation();
	EXPECT_EQ(st.maps_prepared, 1u);
	EXPECT_EQ(st.pairs_aligned, 1u);
	EXPECT_EQ(st.pairs_reused, 2u);
	const auto tracked = statusOf(fleet, "/robot2");
	ASSERT_TRUE(tracked.placed) << tracked.message;
	EXPECT_LE(errorCells(grown, R[1], tracked.in_world), 2.0);
	EXPECT_NE(tracked.message.find("refined"), std::string::npos) << tracked.message;
}

TEST(LiveFleet, ABudgetDefersPairsButEveryPairIsAlignedInTurn)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleetParams p;
	p.estimation_budget_s = 1e-6;  // past at once: one alignment per estimation
	ros1::LiveFleet fleet(p);
	const auto& R = robots();
	for (size_t i : {0, 1, 2}) fleet.addRobot(R[i].name);
	for (size_t i : {0, 1, 2}) ASSERT_EQ(fleet.onMap(R[i].name, mapMsg(R[i], 0.5, 1)), "");
	size_t aligned = 0, deferred = 0;
	for (int k = 0; k < 3; ++k)
	{
		fleet.estimate();
		const auto st = fleet.lastEstimation();
		EXPECT_GE(st.pairs_aligned, 1u);  // always progress
		aligned += st.pairs_aligned, deferred += st.pairs_deferred;
		if (st.pairs_deferred == 0) break;  // every pair known: the next estimation has nothing to do
	}
	EXPECT_GT(deferred, 0u);
	EXPECT_GE(aligned, 2u);  // both robots' pairs in turn, none starved
	fleet.estimate();  // all known now: nothing left to align
	const auto st = fleet.lastEstimation();
	EXPECT_EQ(st.pairs_aligned, 0u);
	EXPECT_EQ(st.pairs_deferred, 0u);
	EXPECT_EQ(st.pairs_reused + st.pairs_skipped, 3u);  // skipped: between maps placed surely
	for (size_t i : {1, 2})
	{
		const auto s = statusOf(fleet, R[i].name);
		ASSERT_TRUE(s.placed) << R[i].name << ": " << s.message;
		EXPECT_LE(errorCells(mapMsg(R[i], 0.5, 1), R[i], s.in_world), 2.0) << R[i].name;
	}
}

// Under a budget that is always past, with every map growing between
// estimations (each placed pair is realigned every time, first in line), the
// pairs of later rounds still get their turn: every robot ends up placed.
TEST(LiveFleet, ABudgetStarvesNoPairWhileTheMapsGrow)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleetParams p;
	p.estimation_budget_s = 1e-6;
	ros1::LiveFleet fleet(p);
	const auto& R = robots();
	for (size_t i : {0, 1, 2}) fleet.addRobot(R[i].name);
	std::vector<nav_msgs::OccupancyGrid> last(3);
	for (int k = 0; k < 5; ++k)
	{
		for (size_t i : {0, 1, 2})
			ASSERT_EQ(fleet.onMap(R[i].name, last[i] = mapMsg(R[i], 0.6 + 0.1 * k, uint32_t(k + 1))), "");
		fleet.estimate();
	}
	for (size_t i : {1, 2})
	{
		const auto s = statusOf(fleet, R[i].name);
		ASSERT_TRUE(s.placed) << R[i].name << ": " << s.message;
		EXPECT_LE(errorCells(last[i], R[i], s.in_world), 2.0) << R[i].name;
	}
}

// SLAM nodes republish unchanged maps: that must not cost an estimation.
TEST(LiveFleet, AMapSentAgainUnchangedIsNotAlignedAgain)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	ros1::LiveFleet fleet({});
	const auto& R = robots();
	for (size_t i : {0, 1}) fleet.addRobot(R[i].name);
	std::vector<nav_msgs::OccupancyGrid> maps;
	for (size_t i : {0, 1}) maps.push_back(mapMsg(R[i], 0.5, 1));
	for (size_t i : {0, 1}) ASSERT_EQ(fleet.onMap(R[i].name, maps[i]), "");
	fleet.estimate();
	ASSERT_TRUE(statusOf(fleet, "/robot2").placed);
	for (auto& m : maps) m.header.stamp = ros::Time(2, 0);
	for (size_t i : {0, 1}) ASSERT_EQ(fleet.onMap(R[i].name, maps[i]), "");
	fleet.estimate();
	EXPECT_EQ(fleet.lastEstimation().maps_prepared, 0u);
	EXPECT_EQ(fleet.lastEstimation().pairs_aligned, 0u);
	// One changed cell is a change.
	maps[1].data[maps[1].data.size() / 2] = 100;
	ASSERT_EQ(fleet.onMap(R[1].name, maps[1]), "");
	fleet.estimate();
	EXPECT_EQ(fleet.lastEstimation().maps_prepared, 1u);
	EXPECT_EQ(fleet.lastEstimation().pairs_aligned, 1u);
}
