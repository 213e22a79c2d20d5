#pragma once
// Reading and writing grid maps by file extension. Every failure throws
// MapIOError with a message that names the file and the problem.

#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <stdexcept>
#include <string>

namespace multires_map_merge
{
struct MapIOError : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

/** Loads .gridmap / .gridmap.gz (a serialized COccupancyGridMap2D),
 * map_server .yaml (+ its image), or .simplemap / .simplemap.gz (rendered at
 * `simplemap_resolution` metres). Rejects empty maps and non-finite metadata. */
mrpt::maps::COccupancyGridMap2D loadGridMap(
	const std::string& path, double simplemap_resolution = 0.05);

/** Saves .gridmap.gz / .gridmap, or map_server .yaml plus a .pgm beside it
 * (occupied 0, free 254, unknown 205; origin = the grid's lower-left corner).
 * `frame` (rigid) places the grid's metric frame in the file's frame; only a
 * .yaml origin [x, y, yaw] can hold a non-identity one exactly. */
void saveGridMap(
	const mrpt::maps::COccupancyGridMap2D& grid, const std::string& path, const Similarity2D& frame = {});

bool hasSuffix(const std::string& s, const std::string& suffix);

}  // namespace multires_map_merge
