#include <multires_map_merge/ros/BagMaps.h>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <set>
#include <stdexcept>

namespace multires_map_merge::ros1
{
std::vector<nav_msgs::OccupancyGrid> occupancyGridsInBag(const std::string& bag_path, const std::string& topic)
{
	rosbag::Bag bag;
	try
	{
		bag.open(bag_path, rosbag::bagmode::Read);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error("'" + bag_path + "': cannot read the bag (" + e.what() + ")");
	}
	std::vector<nav_msgs::OccupancyGrid> grids;
	try
	{
		for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic)))
			if (const auto grid = m.instantiate<nav_msgs::OccupancyGrid>()) grids.push_back(*grid);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error("'" + bag_path + "': cannot read topic " + topic + " (" + e.what() + ")");
	}
	if (grids.empty())
	{
		std::set<std::string> topics;
		for (const rosbag::ConnectionInfo* c : rosbag::View(bag).getConnections())
			topics.insert(c->topic + " [" + c->datatype + "]");
		std::string held;
		for (const auto& t : topics) held += (held.empty() ? "" : ", ") + t;
		throw std::runtime_error(
			"'" + bag_path + "': no nav_msgs/OccupancyGrid on topic " + topic +
			" (the bag holds: " + (held.empty() ? "nothing" : held) + ")");
	}
	return grids;
}

}  // namespace multires_map_merge::ros1
