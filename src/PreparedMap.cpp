#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/PreparedMap.h>
#include <multires_map_merge/StructureHypotheses.h>

#include <mrpt/system/CTicTac.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <future>

namespace multires_map_merge
{
namespace
{
/** The map's edge points, the k-d tree on them (none below 3 points) and
 * their centroid. */
void setEdges(PreparedMap& p, PointList edges)
{
	p.edges = std::move(edges);
	p.edge_tree = p.edges.size() >= 3 ? std::make_shared<const PointKDTree>(p.edges) : nullptr;
	Eigen::Vector2d sum(0, 0);
	for (const auto& e : p.edges) sum += e;
	p.wall_centroid = p.edges.empty() ? sum : Eigen::Vector2d(sum / double(p.edges.size()));
}

/** Share of `points` that `t` moves onto the target's known space. */
double shareOnKnown(const PointList& points, const Similarity2D& t, const OccupancyField& target)
{
	if (points.empty()) return 0;
	size_t on = 0;
	const Eigen::Matrix2d a = t.linear();
	for (const auto& p : points) on += onMask(target.known, a * p + t.t);
	return double(on) / points.size();
}
}  // namespace

void describeMap(PreparedMap& p)
{
	mrpt::system::CTicTac stage;
	p.features = extractPyramidFeatures(p.classes, p.feature_params);
	p.stage_seconds["features"] += stage.Tac();

	// Edge points, and what the verification judges them against.
	stage.Tic();
	setEdges(p, edgePoints(p.classes));
	p.field = occupancyField(p.classes, p.kind);
	p.stage_seconds["edges"] += stage.Tac();
}

cv::Mat knownPart(const cv::Mat& classes, int margin, cv::Point& corner)
{
	const cv::Rect known = cv::boundingRect(classes != kUnknown);
	corner = {0, 0};
	if (known.empty()) return classes;
	const cv::Rect box(known.x - margin, known.y - margin, known.width + 2 * margin, known.height + 2 * margin);
	const cv::Rect inside = box & cv::Rect(0, 0, classes.cols, classes.rows);
	cv::Mat part(box.size(), CV_8UC1, cv::Scalar(kUnknown));
	classes(inside).copyTo(part(inside - box.tl()));
	corner = box.tl();
	return part;
}

// Shifts only (written out, not composed: uncropped maps keep their
// transforms bit for bit, angles unwrapped).
Similarity2D gridCells(const PreparedMap& ref, const Similarity2D& prepared_cells, const PreparedMap& other)
{
	Similarity2D out = prepared_cells;
	out.t += ref.toGridCells().t - out.linear() * other.toGridCells().t;
	return out;
}

Similarity2D preparedCells(const PreparedMap& ref, const Similarity2D& grid_cells, const PreparedMap& other)
{
	Similarity2D out = grid_cells;
	out.t += out.linear() * other.toGridCells().t - ref.toGridCells().t;
	return out;
}

PreparedMapPtr PreparedMap::mirrored() const
{
	return mirror_cache.get([this] { return mirroredMap(*this); });
}

const MapWalls& PreparedMap::walls() const
{
	return *walls_cache.get([this] { return std::make_shared<const MapWalls>(classes); });
}

PreparedMapPtr mirroredMap(const PreparedMap& map)
{
	auto p = std::make_shared<PreparedMap>();
	p->resolution = map.resolution;
	p->kind = map.kind;
	p->feature_params = map.feature_params;
	p->grid_corner = map.grid_corner;  // neither a frame: only cells are compared
	p->cell_to_metric = map.cell_to_metric;
	cv::flip(map.classes, p->classes, 1);
	// SIFT is not mirror-symmetric: the features anew, on another thread
	// (one map here, not two at once). The edges and the field are the map's
	// own mirrored: the same as computed on the flipped map (the exact
	// distance transform is symmetric; the points in the scan order
	// edgePoints gives), without computing them.
	auto features = std::async(
		std::launch::async, [&]() { return extractPyramidFeatures(p->classes, p->feature_params); });
	const double last_x = map.classes.cols - 1;
	PointList edges;
	edges.reserve(map.edges.size());
	for (const auto& e : map.edges) edges.emplace_back(last_x - e.x(), e.y());
	std::sort(edges.begin(), edges.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
		return std::pair(a.y(), a.x()) < std::pair(b.y(), b.x());
	});
	setEdges(*p, std::move(edges));
	cv::flip(map.field.dist_to_occupied, p->field.dist_to_occupied, 1);
	cv::flip(map.field.dist_to_not_free, p->field.dist_to_not_free, 1);
	cv::flip(map.field.known, p->field.known, 1);
	p->field.empty_beyond = map.field.empty_beyond;
	p->features = features.get();
	return p;
}

TsICPResult refineFromTheInside(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& start, const TsICPParams& ip,
	size_t fixed_points)
{
	const double ref_inside = shareOnKnown(ref.edges, start.inverse(), other.field);
	const double other_inside = shareOnKnown(other.edges, start, ref.field);
	// Sampled only when asked: the fixed set is otherwise used in place, not copied.
	auto run = [&](const PointList& fixed, const PointKDTree& moving, const Similarity2D& from) {
		return fixed_points > 0 && fixed.size() > fixed_points ? runTsICP(strided(fixed, fixed_points), moving, from, ip)
															   : runTsICP(fixed, moving, from, ip);
	};
	if (other_inside <= ref_inside) return run(ref.edges, *other.edge_tree, start);
	TsICPResult r = run(other.edges, *ref.edge_tree, start.inverse());
	const double s2 = 1.0 / (r.transform.scale * r.transform.scale);  // other cells² → ref cells²
	r.transform = r.transform.inverse();
	r.trimmed_mse *= s2;
	r.objective *= s2;
	for (auto& o : r.objective_history) o *= s2;
	return r;
}

}  // namespace multires_map_merge
