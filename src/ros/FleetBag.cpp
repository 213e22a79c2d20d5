#include <multires_map_merge/ros/FleetBag.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <map_msgs/OccupancyGridUpdate.h>
#include <boost/make_shared.hpp>
#include <rosbag/bag.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace multires_map_merge::ros1
{
namespace
{
/** `part` pasted into a map of `whole`'s extent (same frame and lattice). */
nav_msgs::OccupancyGrid onExtent(const nav_msgs::OccupancyGrid& whole, const nav_msgs::OccupancyGrid& part)
{
	nav_msgs::OccupancyGrid out = whole;
	std::fill(out.data.begin(), out.data.end(), int8_t(-1));
	const double res = whole.info.resolution;
	const int ox = int(std::lround((part.info.origin.position.x - whole.info.origin.position.x) / res));
	const int oy = int(std::lround((part.info.origin.position.y - whole.info.origin.position.y) / res));
	for (uint32_t y = 0; y < part.info.height; ++y)
		for (uint32_t x = 0; x < part.info.width; ++x)
		{
			const int wx = ox + int(x), wy = oy + int(y);
			if (wx >= 0 && wy >= 0 && wx < int(whole.info.width) && wy < int(whole.info.height))
				out.data[size_t(wy) * whole.info.width + wx] = part.data[size_t(y) * part.info.width + x];
		}
	return out;
}
}  // namespace

void writeFleetBag(const std::string& bag_path, const std::vector<FleetBagRobot>& robots, int steps, double period_s)
{
	if (steps < 1 || !(period_s > 0)) throw std::invalid_argument("writeFleetBag: steps >= 1 and period > 0");
	rosbag::Bag bag;
	try
	{
		bag.open(bag_path, rosbag::bagmode::Write);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error("'" + bag_path + "': cannot write the bag (" + e.what() + ")");
	}
	// Maps latched, as SLAM nodes publish them: `rosbag play --keep-alive`
	// then serves the last one to a late subscriber (the merger discovers
	// robots every few seconds).
	// A connection header replaces rosbag's own: it must name the type too.
	auto latched = boost::make_shared<ros::M_string>();
	(*latched)["type"] = ros::message_traits::datatype<nav_msgs::OccupancyGrid>();
	(*latched)["md5sum"] = ros::message_traits::md5sum<nav_msgs::OccupancyGrid>();
	(*latched)["message_definition"] = ros::message_traits::definition<nav_msgs::OccupancyGrid>();
	(*latched)["callerid"] = "/fleet_bag";
	(*latched)["latching"] = "1";
	std::map<std::string, ScanSequence> logs;
	const ros::Time t0(1000, 0);
	for (const auto& r : robots)
	{
		if (!logs.count(r.log)) logs.emplace(r.log, loadScans(r.log));
		const ScanSequence& s = logs.at(r.log);
		const size_t n = s.size(), b = size_t(r.begin * n), e = size_t(r.end * n);
		// Off the lattice, the same offset at every step: one lattice per robot.
		const double dx = 0.37 * r.resolution, dy = 0.61 * r.resolution;
		std_msgs::Header h;
		h.frame_id = r.name.substr(r.name.find_first_not_of('/')) + "/map";
		const nav_msgs::OccupancyGrid whole =
			msgFromGrid(renderGridOffLattice(s, b, e, r.resolution, r.frame, dx, dy), h);
		nav_msgs::OccupancyGrid previous;
		for (int k = std::max(0, r.join_step); k < steps; ++k)
		{
			const double share = double(k - r.join_step + 1) / double(steps - r.join_step);
			h.stamp = t0 + ros::Duration(k * period_s);
			nav_msgs::OccupancyGrid now = onExtent(
				whole, msgFromGrid(renderGridOffLattice(s, b, b + size_t(share * double(e - b)), r.resolution, r.frame, dx, dy), h));
			now.header = h;
			now.info.map_load_time = h.stamp;
			if (k == r.join_step || k % 2 == 0)
				bag.write(r.name + "/map", h.stamp, now, latched);
			else
			{
				// The bounding box of what changed.
				int x0 = int(now.info.width), y0 = int(now.info.height), x1 = -1, y1 = -1;
				for (int y = 0; y < int(now.info.height); ++y)
					for (int x = 0; x < int(now.info.width); ++x)
						if (now.data[size_t(y) * now.info.width + x] != previous.data[size_t(y) * now.info.width + x])
							x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
				if (x1 >= 0)
				{
					map_msgs::OccupancyGridUpdate u;
					u.header = h;
					u.x = x0, u.y = y0, u.width = uint32_t(x1 - x0 + 1), u.height = uint32_t(y1 - y0 + 1);
					for (int y = y0; y <= y1; ++y)
						u.data.insert(u.data.end(), now.data.begin() + size_t(y) * now.info.width + x0,
									  now.data.begin() + size_t(y) * now.info.width + x1 + 1);
					bag.write(r.name + "/map_updates", h.stamp, u);
				}
			}
			previous = std::move(now);
		}
	}
	bag.close();
}

}  // namespace multires_map_merge::ros1
