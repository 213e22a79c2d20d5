// map_merge: the live multi-robot merging node, a replacement for m-explore's
// multirobot_map_merge/map_merge with the same parameters and topics (README:
// "Replacing m-explore's map_merge"), robots at any resolution. The node is
// ros1::MapMergeNode, the work ros1::LiveFleet; this file starts them.
#include <multires_map_merge/ros/MapMergeNode.h>

#include <malloc.h>

#include <memory>

using namespace multires_map_merge;

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
	ros::NodeHandle pnh("~");  // alive to the end: the last handle gone shuts the node down
	std::unique_ptr<ros1::MapMergeNode> node;
	try
	{
		node = std::make_unique<ros1::MapMergeNode>(ros1::MapMergeConfig::fromParams(pnh));
	}
	catch (const std::exception& e)
	{
		ROS_FATAL_STREAM("map_merge: bad configuration: " << e.what());
		return 1;
	}
	node->start();
	ros::waitForShutdown();
	return 0;
}
