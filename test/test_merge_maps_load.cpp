// merge_maps_node under load on loopback: 1000 requests, valid and invalid
// mixed, four clients at once. The node must stay up, answer every request
// correctly, and its resident memory must not grow by more than a stated
// bound once warm (a leak would show here).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <dirent.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "ros_test_maps.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;

namespace
{
constexpr int kRequests = 1000, kClients = 4, kValidEvery = 5;
constexpr double kRssGrowthBoundMb = 64;

/** The node's pid, found by its command line (one node in this rostest). */
int nodePid()
{
	DIR* proc = opendir("/proc");
	int found = -1;
	while (dirent* e = readdir(proc))
	{
		const int pid = std::atoi(e->d_name);
		if (pid <= 0) continue;
		std::ifstream f(std::string("/proc/") + e->d_name + "/cmdline");
		std::string cmd((std::istreambuf_iterator<char>(f)), {});
		if (cmd.find("merge_maps_node") != std::string::npos) found = pid;
	}
	closedir(proc);
	return found;
}

double rssMb(int pid)
{
	std::ifstream f("/proc/" + std::to_string(pid) + "/status");
	std::string line;
	while (std::getline(f, line))
		if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024;
	return -1;
}
}  // namespace

TEST(MergeMapsLoad, ThousandMixedRequestsFourClientsAtOnce)
{
	// Small real maps keep a valid merge well under a second.
	const MsgPair p = msgPair(malagaSpec(0.10, 0.16, 40), rigid(2, 1, 0.2), rigid(-5, 3, 0));
	const std::vector<BadRequest> bad = badRequests();  // built here, not in the clients
	ASSERT_TRUE(ros::service::waitForService("/merge_maps", ros::Duration(120)));
	const int pid = nodePid();
	ASSERT_GT(pid, 0) << "merge_maps_node not found in /proc";

	std::atomic<int> next{0}, valid_ok{0}, invalid_ok{0}, transport_failures{0};
	double warm_rss = -1;
	std::mutex warm_mutex;
	auto client = [&] {
		ros::NodeHandle nh;
		ros::ServiceClient merge = nh.serviceClient<MergeMaps>("/merge_maps", /*persistent=*/true);
		for (int i; (i = next++) < kRequests;)
		{
			if (i == 100)
			{
				std::lock_guard<std::mutex> lock(warm_mutex);
				warm_rss = rssMb(pid);
			}
			MergeMaps srv;
			srv.request = validRequest(p);
			const bool valid = i % kValidEvery == 0;
			const BadRequest* spoil = valid ? nullptr : &bad[i % bad.size()];
			if (spoil) spoil->spoil(srv.request);
			if (!merge.isValid()) merge = nh.serviceClient<MergeMaps>("/merge_maps", true);
			if (!merge.call(srv))
			{
				++transport_failures;
				continue;
			}
			if (valid)
			{
				SCOPED_TRACE("request " + std::to_string(i));
				expectTransformMatchesTruth(srv.response, p);  // fails the test if off
				valid_ok += srv.response.success;
			}
			else
			{
				EXPECT_FALSE(srv.response.success) << spoil->what;
				EXPECT_TRUE(saysAnyOf(srv.response.message, spoil->says)) << spoil->what << ": " << srv.response.message;
				if (!srv.response.success && saysAnyOf(srv.response.message, spoil->says)) ++invalid_ok;
			}
		}
	};
	std::vector<std::thread> clients;
	for (int c = 0; c < kClients; ++c) clients.emplace_back(client);
	for (auto& t : clients) t.join();

	EXPECT_EQ(transport_failures.load(), 0);
	EXPECT_EQ(valid_ok.load(), kRequests / kValidEvery);
	EXPECT_EQ(invalid_ok.load(), kRequests - kRequests / kValidEvery);
	EXPECT_TRUE(ros::service::exists("/merge_maps", false)) << "the node is gone";
	const double end_rss = rssMb(pid);
	ASSERT_GT(warm_rss, 0);
#if defined(__SANITIZE_ADDRESS__)
	// ASan's allocator keeps freed memory in quarantine (up to 256 MB), so
	// the node's resident memory grows with how much it allocates, not with
	// what it keeps: the bound is checked in the un-instrumented suite
	// (scripts/test.sh runs both); here the requests run for memory errors.
	(void)end_rss;
#else
	EXPECT_LE(end_rss, warm_rss + kRssGrowthBoundMb)
		<< "resident memory grew from " << warm_rss << " MB to " << end_rss << " MB";
#endif
	std::cout << "node RSS: " << warm_rss << " MB after 100 requests, " << end_rss << " MB after " << kRequests
			  << std::endl;
}

int main(int argc, char** argv)
{
	::testing::InitGoogleTest(&argc, argv);
	ros::init(argc, argv, "test_merge_maps_load");
	ros::NodeHandle nh;
	ros::AsyncSpinner spinner(1);
	spinner.start();
	return RUN_ALL_TESTS();
}
