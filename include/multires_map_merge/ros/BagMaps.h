#pragma once
// Occupancy grids recorded in a rosbag, for offline merging (the CLI's --bag
// and the rosbag-driven tests).

#include <nav_msgs/OccupancyGrid.h>

#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
/** Every nav_msgs/OccupancyGrid on `topic`, in recorded order, read with
 * rosbag::View. Throws std::runtime_error naming the bag and the topic when
 * the bag cannot be read or holds no grid on that topic (the message then
 * lists the topics it does hold). */
std::vector<nav_msgs::OccupancyGrid> occupancyGridsInBag(const std::string& bag_path, const std::string& topic);

}  // namespace multires_map_merge::ros1
