// Rosbag-driven offline merging: the test records real map pairs on two
// topics with the rosbag C++ API, reads them back with rosbag::View and merges
// every pair through the service's code path; then the CLI's --bag.
#include <multires_map_merge/ros/BagMaps.h>
#include <multires_map_merge/ros/MergeMapsService.h>

#include <gtest/gtest.h>
#include <rosbag/bag.h>

#include <filesystem>

#include "cli_run.h"
#include "ros_test_maps.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;
namespace fs = std::filesystem;

namespace
{
const char* kRef = "/robot1/map";
const char* kOther = "/robot2/map";

/** Two real pairs, recorded as robots would publish them: each robot's map
 * on its own topic, at its own resolution, in its own frame. */
const std::vector<MsgPair>& recordedPairs()
{
	static const std::vector<MsgPair> pairs = {
		msgPair(malagaSpec(0.05, 0.08, 30), rigid(0, 0, 0), rigid(-7, 2, 0)),
		msgPair(malagaSpec(0.10, 0.04, 200), rigid(5, 5, 0.5), rigid(1, -3, 0)),
	};
	return pairs;
}

std::string recordBag()
{
	const std::string dir = ::testing::TempDir() + "/bags";
	fs::create_directories(dir);
	const std::string path = dir + "/two_robots.bag";
	rosbag::Bag bag(path, rosbag::bagmode::Write);
	double t = 1;
	for (const MsgPair& p : recordedPairs())
	{
		bag.write(kRef, ros::Time(t), p.ref);
		bag.write(kOther, ros::Time(t + 0.5), p.other);
		t += 1;
	}
	bag.close();
	return path;
}

const std::string& bagPath()
{
	static const std::string path = recordBag();
	return path;
}
}  // namespace

TEST(RosbagMerge, EveryRecordedPairMergesToTheTruth)
{
	const auto refs = ros1::occupancyGridsInBag(bagPath(), kRef);
	const auto others = ros1::occupancyGridsInBag(bagPath(), kOther);
	ASSERT_EQ(refs.size(), recordedPairs().size());
	ASSERT_EQ(others.size(), recordedPairs().size());
	const ros1::MergeMapsService service;
	for (size_t i = 0; i < refs.size(); ++i)
	{
		SCOPED_TRACE("pair " + std::to_string(i));
		MergeMaps::Request req;
		req.reference = refs[i];
		req.other = others[i];
		MergeMaps::Response res;
		service.merge(req, res);
		expectTransformMatchesTruth(res, recordedPairs()[i]);
		expectMergedGridIsRight(res, recordedPairs()[i], recordedPairs()[i].grids.ref.getResolution());
	}
}

TEST(RosbagMerge, MissingBagOrTopicIsNamed)
{
	try
	{
		ros1::occupancyGridsInBag(::testing::TempDir() + "/no_such.bag", kRef);
		ADD_FAILURE() << "no exception";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("no_such.bag"), std::string::npos) << e.what();
	}
	try
	{
		ros1::occupancyGridsInBag(bagPath(), "/robot3/map");
		ADD_FAILURE() << "no exception";
	}
	catch (const std::runtime_error& e)
	{
		// Says what is there instead.
		EXPECT_NE(std::string(e.what()).find("/robot1/map [nav_msgs/OccupancyGrid]"), std::string::npos)
			<< e.what();
	}
}

// fleet-bag renders for seconds before it writes: an --out it cannot write
// is refused first, naming it.
TEST(RosbagMerge, FleetBagRefusesAnUnwritableOutputBeforeRendering)
{
	const std::string out = ::testing::TempDir() + "/no_such_folder/session.bag";
	FILE* p = popen((std::string(MMM_FLEET_BAG) + " --out " + out + " 2>&1").c_str(), "r");
	std::string text;
	char buf[512];
	while (p && fgets(buf, sizeof buf, p)) text += buf;
	const int status = p ? pclose(p) : -1;
	EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << text;
	EXPECT_NE(text.find("--out '" + out + "': no folder"), std::string::npos) << text;
	EXPECT_EQ(text.find("wrote"), std::string::npos) << text;
}

TEST(RosbagMerge, CliMergesTheLastMapsOnTwoTopics)
{
	const std::string dir = ::testing::TempDir() + "/bags";
	const CliRun r = runCli(
		"--bag " + bagPath() + " --topics " + kRef + " " + kOther + " --json " + dir + "/bag.json --out " +
		dir + "/bag_merged.yaml");
	ASSERT_EQ(r.exit_code, 0) << r.output;
	// The last pair, in the messages' frames.
	const MsgPair& last = recordedPairs().back();
	const std::string j = slurp(dir + "/bag.json");
	const Similarity2D got(
		jsonNumber(j, "scale"), jsonNumber(j, "yaw"), {jsonNumber(j, "x"), jsonNumber(j, "y")});
	EXPECT_NEAR(got.scale, last.truth.scale, 0.002);
	EXPECT_NEAR(wrapToPi(got.yaw - last.truth.yaw), 0, 0.2 * M_PI / 180);
	EXPECT_NEAR((got.t - last.truth.t).norm(), 0, 0.1);
	// The merged map keeps the reference's rotated origin: only .yaml can say so.
	const std::string yaml = slurp(dir + "/bag_merged.yaml");
	EXPECT_NE(yaml.find(", 0.5]"), std::string::npos) << yaml;
	EXPECT_TRUE(fs::exists(dir + "/bag_merged.pgm"));
	const CliRun gridmap = runCli(
		"--bag " + bagPath() + " --topics " + kRef + " " + kOther + " --out " + dir + "/m.gridmap.gz");
	EXPECT_EQ(gridmap.exit_code, 2) << gridmap.output;
	EXPECT_NE(gridmap.output.find("save as .yaml"), std::string::npos) << gridmap.output;

	for (const std::string& bad :
		 {"--bag " + dir + "/no_such.bag --topics /a /b", "--bag " + bagPath() + " --topics " + kRef,
		  "--bag " + bagPath() + " --topics " + kRef + " /robot3/map",
		  "--bag " + bagPath() + " --topics /a /b extra.gridmap"})
	{
		const CliRun b = runCli(bad);
		EXPECT_EQ(b.exit_code, 2) << bad << "\n" << b.output;
	}
}
