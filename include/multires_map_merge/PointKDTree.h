#pragma once
// Nearest-neighbour queries on a fixed 2-D point list (nanoflann, as shipped
// with MRPT). Built once per point set; TsICP queries it every iteration.

#include <multires_map_merge/TsICP.h>

#include <memory>

namespace multires_map_merge
{
class PointKDTree
{
   public:
	explicit PointKDTree(const PointList& points);
	~PointKDTree();
	PointKDTree(const PointKDTree&) = delete;
	PointKDTree& operator=(const PointKDTree&) = delete;

	/** Index of the nearest point and its squared distance. */
	std::pair<size_t, double> nearest(const Eigen::Vector2d& q) const;

   private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

}  // namespace multires_map_merge
