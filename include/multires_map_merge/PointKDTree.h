#pragma once
// Nearest-neighbour queries on a fixed 2-D point list (nanoflann, as shipped
// with MRPT). Built once per point set and kept with it (a prepared map holds
// one for its edge points, which every hypothesis's TsICP queries).

#include <multires_map_merge/PointList.h>

#include <memory>

namespace multires_map_merge
{
class PointKDTree
{
   public:
	/** Keeps its own copy of the points, so that it can be shared and
	 * outlive the list it was built from. */
	explicit PointKDTree(PointList points);
	~PointKDTree();
	PointKDTree(const PointKDTree&) = delete;
	PointKDTree& operator=(const PointKDTree&) = delete;

	/** Index of the nearest point and its squared distance. */
	std::pair<size_t, double> nearest(const Eigen::Vector2d& q) const;
	/** The same, told that the point `near` lies close to `q` (its distance
	 * bounds the search, which then skips most of the tree). The answer is
	 * the same, ties included: only subtrees farther than that bound, which
	 * hold no nearest point, are left out. */
	std::pair<size_t, double> nearest(const Eigen::Vector2d& q, size_t near) const;
	const PointList& points() const;

   private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

}  // namespace multires_map_merge
