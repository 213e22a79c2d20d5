#pragma once
// nav_msgs/OccupancyGrid ⇄ COccupancyGridMap2D, through mrpt::ros1bridge, with
// the checks ros1bridge leaves out (it indexes `data` by width×height and
// asserts on out-of-range values) and the one case it refuses: a rotated origin.
//
// Every grid here lives in its *origin frame*: cell (0,0)'s lower-left corner
// at (0,0), axes along the grid. The message's `info.origin` is kept apart as a
// rigid Similarity2D (scale 1) from that frame to the message's frame_id. This
// handles rotated origins exactly and keeps ros1bridge's float coordinates
// small, so its grid size always equals width×height.

#include <multires_map_merge/GridInFrame.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <geometry_msgs/Pose2D.h>
#include <nav_msgs/OccupancyGrid.h>

#include <stdexcept>
#include <string>

namespace multires_map_merge::ros1
{
/** A message that is not a usable occupancy grid; what() says why. */
struct InvalidGridMessage : std::invalid_argument
{
	using std::invalid_argument::invalid_argument;
};

/** Validates and converts to a grid in its origin frame; `origin` is the
 * message's info.origin (into header.frame_id). `what` names the map in error messages ("reference").
 * Accepts: width, height ≥ 1; data.size() = width×height; a finite resolution
 * > 0; a finite origin whose orientation is a rotation about z (any norm; the
 * all-zero quaternion of a default-constructed message counts as identity);
 * cell values -1 (unknown) or 0..100. Throws InvalidGridMessage otherwise. */
GridInFrame gridFromMsg(const nav_msgs::OccupancyGrid& msg, const std::string& what = "map");

/** A grid in its frame (map.origin: rigid, into header.frame_id) as a
 * message: cells through ros1bridge, info.origin = the corner of cell (0, 0)
 * in that frame, with the frame's yaw. */
nav_msgs::OccupancyGrid msgFromGrid(const GridInFrame& map, const std_msgs::Header& header);

/** The pose of info.origin as a rigid Similarity2D; throws InvalidGridMessage
 * when it is not finite or not a rotation about z. */
Similarity2D originOf(const nav_msgs::OccupancyGrid& msg, const std::string& what = "map");

/** The rigid part of a similarity as a Pose2D (x, y, theta = yaw); the
 * scale travels beside it. */
geometry_msgs::Pose2D pose2DOf(const Similarity2D& t);

}  // namespace multires_map_merge::ros1
