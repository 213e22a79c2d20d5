#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapAgreement.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace multires_map_merge
{
namespace
{
// Free cells that stay free within `radius` cells: a wall seen one coarse
// cell off is quantisation, not disagreement.
cv::Mat clearlyFree(const cv::Mat& classes, int radius)
{
	cv::Mat out;
	cv::erode(
		classes == kFree, out,
		cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
	return out;
}
}  // namespace

Agreement mapAgreement(
	const cv::Mat& ref, const cv::Mat& other, const Similarity2D& other_to_ref, double margin)
{
	CV_Assert(ref.type() == CV_8UC1 && other.type() == CV_8UC1);
	Agreement a;
	if (ref.empty() || other.empty() || !other_to_ref.isFinite() || !(other_to_ref.scale > 0))
		return a;
	// `margin` coarse cells, in each map's own cells.
	const int r_ref = std::max(1, cvRound(margin * std::max(1.0, other_to_ref.scale)));
	const int r_other = std::max(1, cvRound(margin * std::max(1.0, 1.0 / other_to_ref.scale)));

	const Eigen::Matrix<double, 2, 3> m = other_to_ref.matrix().topRows<2>();
	cv::Mat m_cv(2, 3, CV_64F);
	for (int r = 0; r < 2; ++r)
		for (int c = 0; c < 3; ++c) m_cv.at<double>(r, c) = m(r, c);
	auto warp = [&](const cv::Mat& mask) {
		cv::Mat out;
		cv::warpAffine(mask, out, m_cv, ref.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
		return out;
	};
	const cv::Mat other_occ = warp(other == kOccupied);
	const cv::Mat other_known = warp(other != kUnknown);
	const cv::Mat other_free = warp(clearlyFree(other, r_other));
	const cv::Mat ref_occ = ref == kOccupied, ref_known = ref != kUnknown;
	const cv::Mat ref_free = clearlyFree(ref, r_ref);

	a.occupied_overlap = cv::countNonZero(ref_occ & other_known) + cv::countNonZero(other_occ & ref_known);
	a.conflicts = cv::countNonZero(ref_occ & other_free) + cv::countNonZero(other_occ & ref_free);
	a.consistency = a.occupied_overlap == 0
		? 0.0
		: 1.0 - static_cast<double>(a.conflicts) / static_cast<double>(a.occupied_overlap);
	return a;
}

OccupancyField occupancyField(const cv::Mat& classes)
{
	OccupancyField f;
	cv::distanceTransform(classes != kOccupied, f.dist_to_occupied, cv::DIST_L2, cv::DIST_MASK_PRECISE);
	cv::distanceTransform(classes == kFree, f.dist_to_not_free, cv::DIST_L2, cv::DIST_MASK_PRECISE);
	f.known = classes != kUnknown;
	return f;
}

cv::Mat knownWithin(const cv::Mat& known, double cells)
{
	const int r = std::max(1, int(std::ceil(cells)));
	cv::Mat near;
	cv::dilate(known, near, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1)));
	return near;
}

Support tolerantSupport(
	const PointList& points, const Similarity2D& t, const OccupancyField& target, double tolerance)
{
	Support s;
	const int w = target.known.cols, h = target.known.rows;
	const Eigen::Matrix2d a = t.linear();
	for (const auto& p : points)
	{
		const Eigen::Vector2d q = a * p + t.t;
		const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
		if (x < 0 || y < 0 || x >= w || y >= h) continue;
		// Near a wall counts even where the target has not seen the exact
		// cell (walls border unknown space); elsewhere only seen space judges.
		const float d = target.dist_to_occupied.at<float>(y, x);
		if (d <= tolerance)
			++s.judged, ++s.supported;
		else if (target.known.at<uint8_t>(y, x))
		{
			++s.judged;
			s.conflicts += target.dist_to_not_free.at<float>(y, x) > tolerance;
		}
	}
	return s;
}

namespace
{
PointList thinned(const PointList& pts, size_t most)
{
	if (pts.size() <= most) return pts;
	PointList out;
	const double step = double(pts.size()) / most;
	for (double i = 0; i < pts.size(); i += step) out.push_back(pts[static_cast<size_t>(i)]);
	return out;
}
}  // namespace

TwoWaySupport twoWaySupport(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tol_coarse, size_t most)
{
	TwoWaySupport s;
	if (!other_to_ref.isFinite() || !(other_to_ref.scale > 0)) return s;
	// One coarse cell, in each map's own cells.
	const double coarse_in_ref = std::max(1.0, other_to_ref.scale);
	const double coarse_in_other = std::max(1.0, 1.0 / other_to_ref.scale);
	s.other_in_ref = tolerantSupport(thinned(other_points, most), other_to_ref, ref_field, tol_coarse * coarse_in_ref);
	s.ref_in_other =
		tolerantSupport(thinned(ref_points, most), other_to_ref.inverse(), other_field, tol_coarse * coarse_in_other);
	return s;
}

Chance chanceSupport(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tol_coarse, double shift_coarse,
	double turn_deg, size_t most)
{
	if (other_points.empty() || !other_to_ref.isFinite()) return {};
	Eigen::Vector2d centre(0, 0);
	for (const auto& p : other_points) centre += p;
	centre = other_to_ref(centre / double(other_points.size()));
	const double shift = shift_coarse * std::max(1.0, other_to_ref.scale);
	std::vector<Similarity2D> moves;
	const Eigen::Vector2d shifts[] = {{shift, 0}, {-shift, 0}, {0, shift}, {0, -shift}};
	for (const Eigen::Vector2d& d : shifts)
		moves.emplace_back(1, 0, d);
	for (const double deg : {turn_deg, -turn_deg})
	{
		Similarity2D turn(1, deg * M_PI / 180, {0, 0});
		turn.t = centre - turn.apply(centre);
		moves.push_back(turn);
	}
	Chance best;
	for (const auto& m : moves)
	{
		const TwoWaySupport s =
			twoWaySupport(ref_points, ref_field, other_points, other_field, m.compose(other_to_ref), tol_coarse, most);
		best.support = std::max(best.support, s.score());
		best.consistency = std::max(best.consistency, s.consistency());
	}
	return best;
}

}  // namespace multires_map_merge
