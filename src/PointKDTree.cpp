#include <multires_map_merge/PointKDTree.h>

#include <nanoflann.hpp>
#include <utility>

namespace multires_map_merge
{
namespace
{
struct PointListAdaptor
{
	const PointList& pts;
	size_t kdtree_get_point_count() const { return pts.size(); }
	double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][dim]; }
	template <class BBox>
	bool kdtree_get_bbox(BBox&) const
	{
		return false;
	}
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<
	nanoflann::L2_Simple_Adaptor<double, PointListAdaptor>, PointListAdaptor, 2, uint32_t>;
}  // namespace

struct PointKDTree::Impl
{
	explicit Impl(PointList p)
		: points(std::move(p)), adaptor{points}, tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16))
	{
		tree.buildIndex();
	}
	PointList points;  // before the adaptor and tree, which refer to it
	PointListAdaptor adaptor;
	Tree tree;
};

PointKDTree::PointKDTree(PointList points) : impl_(std::make_unique<Impl>(std::move(points)))
{
}
PointKDTree::~PointKDTree() = default;

std::pair<size_t, double> PointKDTree::nearest(const Eigen::Vector2d& q) const
{
	uint32_t idx = 0;  // nanoflann 1.4 indexes with uint32_t
	double d2 = 0;
	impl_->tree.knnSearch(q.data(), 1, &idx, &d2);
	return {static_cast<size_t>(idx), d2};
}

std::pair<size_t, double> PointKDTree::nearest(const Eigen::Vector2d& q, size_t near) const
{
	if (near >= impl_->points.size()) return nearest(q);
	// Widened a little: nanoflann's own sum of squares may round the other way.
	const double bound = (q - impl_->points[near]).squaredNorm() * (1 + 1e-9) + 1e-12;
	uint32_t idx = 0;
	double d2 = 0;
	nanoflann::KNNResultSet<double, uint32_t> result(1);
	result.init(&idx, &d2);
	d2 = bound;  // the result set's worst distance: nothing farther is searched
	impl_->tree.findNeighbors(result, q.data(), nanoflann::SearchParams());
	if (result.size() == 0) return nearest(q);  // not reached with a finite q
	return {static_cast<size_t>(idx), d2};
}

const PointList& PointKDTree::points() const
{
	return impl_->points;
}

}  // namespace multires_map_merge
