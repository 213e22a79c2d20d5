#pragma once
// Reading and writing grid maps by file extension. Every failure throws
// MapIOError with a message that names the file and the problem.

#include <multires_map_merge/GridInFrame.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace multires_map_merge
{
struct MapIOError : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

/** Loads, by extension:
 * - map_server `.yaml` (+ its image), read as ROS 1 map_server reads it:
 *   `mode` trinary | scale | raw, `negate`, `occupied_thresh`, `free_thresh`,
 *   image path relative to the yaml, colour images averaged over their
 *   channels. The grid is in its origin frame and `origin` holds the file's
 *   `origin: [x, y, yaw]` exactly (any position, any yaw).
 * - `.gridmap` / `.gridmap.gz` (a serialized COccupancyGridMap2D): the grid as
 *   stored, identity origin.
 * - `.simplemap` / `.simplemap.gz`: rendered at `simplemap_resolution` metres.
 * Rejects empty maps, non-finite metadata and files it cannot read. */
GridInFrame loadGridMap(const std::string& path, double simplemap_resolution = 0.05);

/** loadGridMap of each path, the files read in parallel. A file that cannot
 * be read throws its MapIOError; several, one MapIOError naming each (in
 * the paths' order). A failure that is not a file's (std::bad_alloc) is
 * rethrown as it is, before any file's. */
std::vector<GridInFrame> loadGridMaps(const std::vector<std::string>& paths, double simplemap_resolution = 0.05);

/** Saves .gridmap.gz / .gridmap, or map_server .yaml plus a .pgm beside it
 * (occupied 0, free 254, unknown 205; trinary; origin = the corner of cell
 * (0, 0) in the map's frame, with its yaw). A .yaml holds the origin exactly.
 * A .gridmap cannot hold a rotated origin (MapIOError) and snaps the corner to
 * a multiple of the cell size: the return value then says by how much the
 * written map is shifted ("" when the file holds the map exactly). A floor
 * plan's .yaml says `floor_plan: true`, so it reloads as a plan. */
std::string saveGridMap(const GridInFrame& map, const std::string& path);
/** A grid whose own metric frame is the map's frame. */
std::string saveGridMap(const mrpt::maps::COccupancyGridMap2D& grid, const std::string& path);

/** The text of a map_server yaml for `image` (named as the yaml names it:
 * relative to the yaml, or absolute): `resolution` m per cell, the image's
 * bottom-left corner at `corner` in the map's frame, turned by `yaw`;
 * trinary, map_server's default thresholds; a floor plan adds
 * `floor_plan: true` (map_server ignores it). The image's name is quoted
 * (it may hold '#' or ": "); numbers are written in the shortest form that
 * reads back exactly (a resolution that is a float's, as that float). */
std::string mapServerYaml(
	const std::string& image, double resolution, const Eigen::Vector2d& corner, double yaw, MapKind kind);

bool hasSuffix(const std::string& s, const std::string& suffix);

/** Several maps' problems in one message, each named as found:
 * "N maps <what>: first; second; ...". */
std::string everyMapsProblem(const std::vector<std::string>& problems, const std::string& what);

/** Why a file cannot be written at `path` ("" when it can): no folder to
 * write into, a folder or other non-file in the way, or no permission.
 * Nothing is created or truncated; programs ask before any work, so that
 * an output that cannot be written is not found at the end. */
std::string whyNotWritable(const std::string& path);

}  // namespace multires_map_merge
