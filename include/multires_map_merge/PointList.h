#pragma once
// What the method registers and judges: points in a map's cell coordinates
// (x = column, y = row; EdgePoints.h makes them from a class image).

#include <Eigen/Core>

#include <vector>

namespace multires_map_merge
{
using PointList = std::vector<Eigen::Vector2d>;
}  // namespace multires_map_merge
