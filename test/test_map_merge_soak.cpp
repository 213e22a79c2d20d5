// Soak of the live map_merge node: four robots of Debian's malaga run (5 / 3 /
// 8 / 6 cm, own frames) send a map update every second and a full map every
// ten, for three minutes, while the node estimates, merges and publishes.
// The node's resident memory (VmRSS, read through its pid from the master)
// swings by tens of MB within an estimation or a fusion, so windows are
// compared, not samples: the highest RSS of the last minute may exceed the
// highest of the second by no more than kGrowthBoundMb, and no sample may
// exceed kPeakBoundMb. A leak of one map copy per update (~1 MB/s) or per
// estimation breaks either.
#include <multires_map_merge/FleetStatus.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <gtest/gtest.h>
#include <map_msgs/OccupancyGridUpdate.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <atomic>
#include <fstream>

#include "test_data.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

namespace
{
constexpr double kSeconds = 180, kBaselineFrom = 60, kEndFrom = 120;
constexpr double kGrowthBoundMb = 64, kPeakBoundMb = 1536;

/** The node's pid, by the master's lookupNode and the node's getPid. */
int pidOf(const std::string& node)
{
	XmlRpc::XmlRpcValue args, result, payload;
	args[0] = ros::this_node::getName();
	args[1] = node;
	if (!ros::master::execute("lookupNode", args, result, payload, true)) return -1;
	const std::string uri = payload;
	std::string host;
	uint32_t port = 0;
	if (!ros::network::splitURI(uri, host, port)) return -1;
	XmlRpc::XmlRpcClient client(host.c_str(), int(port), "/");
	XmlRpc::XmlRpcValue pid_args, pid_result;
	pid_args[0] = ros::this_node::getName();
	if (!client.execute("getPid", pid_args, pid_result) || pid_result.getType() != XmlRpc::XmlRpcValue::TypeArray) return -1;
	return int(pid_result[2]);
}

double rssMb(int pid)
{
	std::ifstream f("/proc/" + std::to_string(pid) + "/status");
	for (std::string line; std::getline(f, line);)
		if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024;
	return -1;
}
}  // namespace

TEST(MapMergeSoak, ResidentMemoryStaysSteady)
{
	ros::NodeHandle nh;
	const ScanSequence scans = loadScans(mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	const size_t n = scans.size();
	struct Robot
	{
		std::string name;
		double begin, end, res;
		mrpt::poses::CPose2D frame;
	};
	const std::vector<Robot> robots = {
		{"/robot1", 0.0, 0.6, 0.05, {}},
		{"/robot2", 0.3, 0.9, 0.03, {2, -1, 0.7}},
		{"/robot3", 0.4, 1.0, 0.08, {-1.5, 3, -2.1}},
		{"/robot4", 0.1, 0.7, 0.06, {4, 1, 3.0}},
	};
	std::vector<nav_msgs::OccupancyGrid> maps;
	std::vector<ros::Publisher> map_pubs, update_pubs;
	for (const auto& r : robots)
	{
		std_msgs::Header h;
		h.frame_id = r.name.substr(1) + "/map";
		maps.push_back(ros1::msgFromGrid(
			renderGridOffLattice(scans, size_t(r.begin * n), size_t(r.end * n), r.res, r.frame, 0.3 * r.res, 0.6 * r.res), h));
		map_pubs.push_back(nh.advertise<nav_msgs::OccupancyGrid>(r.name + "/map", 1, true));
		update_pubs.push_back(nh.advertise<map_msgs::OccupancyGridUpdate>(r.name + "/map_updates", 10));
	}
	std::atomic<int> statuses{0}, merged_maps{0};
	std::atomic<bool> all_placed{false};
	ros::Subscriber sub = nh.subscribe<FleetStatus>("/map_merge/status", 5, [&](const FleetStatus::ConstPtr& s) {
		++statuses;
		all_placed = s->placed.size() == robots.size() && std::all_of(s->placed.begin(), s->placed.end(), [](uint8_t p) { return p; });
	});
	ros::Subscriber merged_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
		"/map", 1, [&](const nav_msgs::OccupancyGrid::ConstPtr&) { ++merged_maps; });
	ros::AsyncSpinner spinner(1);
	spinner.start();

	int pid = -1;
	for (int i = 0; i < 100 && pid < 0; ++i, ros::WallDuration(0.2).sleep()) pid = pidOf("/map_merge");
	ASSERT_GT(pid, 0) << "cannot find map_merge's pid";

	double baseline = 0, end_rss = 0, peak = 0;
	const ros::WallTime start = ros::WallTime::now();
	for (int tick = 0; (ros::WallTime::now() - start).toSec() < kSeconds; ++tick)
	{
		for (size_t i = 0; i < robots.size(); ++i)
		{
			nav_msgs::OccupancyGrid& m = maps[i];
			m.header.stamp = ros::Time::now();
			if (tick % 10 == 0)
				map_pubs[i].publish(m);
			else
			{
				// A 20x20 region that changes every second (a door opening, a person).
				map_msgs::OccupancyGridUpdate u;
				u.header = m.header;
				u.x = int((tick * 37) % std::max(1u, m.info.width - 20)), u.y = int((tick * 53) % std::max(1u, m.info.height - 20));
				u.width = u.height = 20;
				u.data.assign(400, int8_t(tick % 2 ? 0 : -1));
				for (uint32_t y = 0; y < 20; ++y)
					std::copy_n(u.data.begin() + y * 20, 20, m.data.begin() + size_t(u.y + y) * m.info.width + u.x);
				update_pubs[i].publish(u);
			}
		}
		const double rss = rssMb(pid);
		ASSERT_GT(rss, 0) << "map_merge died at " << tick << " s";
		peak = std::max(peak, rss);
		const double t = (ros::WallTime::now() - start).toSec();
		if (t >= kEndFrom)
			end_rss = std::max(end_rss, rss);
		else if (t >= kBaselineFrom)
			baseline = std::max(baseline, rss);
		ros::WallDuration(1.0).sleep();
	}
	RecordProperty("baseline_rss_mb", std::to_string(baseline));
	RecordProperty("end_rss_mb", std::to_string(end_rss));
	std::cout << "map_merge RSS: highest " << baseline << " MB in " << kBaselineFrom << "-" << kEndFrom << " s, "
			  << end_rss << " MB after, peak " << peak << " MB" << std::endl;
	// TF and status at merging_rate (2 Hz) whatever the fusion costs; the
	// merged map as often as fusing four changing maps allows.
	EXPECT_GT(statuses.load(), int(1.5 * kSeconds)) << "placements published too rarely";
	EXPECT_GT(merged_maps.load(), int(kSeconds / 10)) << "merged map published too rarely";
	std::cout << statuses.load() << " status messages, " << merged_maps.load() << " merged maps in " << kSeconds << " s" << std::endl;
	EXPECT_TRUE(all_placed.load());
	EXPECT_LE(end_rss - baseline, kGrowthBoundMb);
	EXPECT_LE(peak, kPeakBoundMb);
}

int main(int argc, char** argv)
{
	testing::InitGoogleTest(&argc, argv);
	ros::init(argc, argv, "test_map_merge_soak");
	return RUN_ALL_TESTS();
}
