#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapAgreement.h>

#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <vector>

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

// Wall normals from the structure tensor of the occupied cells, smoothed over
// a couple of cells (a wall drawn two cells thick has one direction), at each
// occupied cell (kNoDirection elsewhere). Gradients in 16 bits and the tensor
// summed at occupied cells only: a 4000² map must not pay several float
// images for it.
cv::Mat wallNormals(const cv::Mat& occupied)
{
	cv::Mat gx, gy;
	cv::Sobel(occupied / 255, gx, CV_16S, 1, 0, 3);
	cv::Sobel(occupied / 255, gy, CV_16S, 0, 1, 3);
	constexpr int kRadius = 6;
	constexpr double kSigma = 2.0;
	float weight[2 * kRadius + 1][2 * kRadius + 1];
	for (int dy = -kRadius; dy <= kRadius; ++dy)
		for (int dx = -kRadius; dx <= kRadius; ++dx)
			weight[dy + kRadius][dx + kRadius] = float(std::exp(-(dx * dx + dy * dy) / (2 * kSigma * kSigma)));
	cv::Mat out(occupied.size(), CV_8U, cv::Scalar(kNoDirection));
	for (int y = 0; y < occupied.rows; ++y)
		for (int x = 0; x < occupied.cols; ++x)
		{
			if (!occupied.at<uint8_t>(y, x)) continue;
			float a = 0, b = 0, c = 0;
			for (int v = std::max(0, y - kRadius); v <= std::min(occupied.rows - 1, y + kRadius); ++v)
			{
				const int16_t *rx = gx.ptr<int16_t>(v), *ry = gy.ptr<int16_t>(v);
				const float* wr = weight[v - y + kRadius];
				for (int u = std::max(0, x - kRadius); u <= std::min(occupied.cols - 1, x + kRadius); ++u)
				{
					if (rx[u] == 0 && ry[u] == 0) continue;
					const float w = wr[u - x + kRadius], fx = rx[u], fy = ry[u];
					a += w * fx * fx, b += w * fy * fy, c += w * fx * fy;
				}
			}
			const float trace = a + b, aniso = std::sqrt((a - b) * (a - b) + 4 * c * c);
			if (trace > 0 && aniso > 0.5f * trace)  // a line, not a corner or a speck
			{
				double deg = 0.5 * std::atan2(2.0 * c, double(a - b)) * 180.0 / M_PI;
				if (deg < 0) deg += 180;
				out.at<uint8_t>(y, x) = static_cast<uint8_t>(std::min(179.0, std::floor(deg)));
			}
		}
	return out;
}

// Walls whose normals differ by at most this run the same way.
constexpr double kSameDirectionDeg = 20.0;

// How a point landing on target cell (x, y) is judged: near a wall counts
// even where the target has not seen the exact cell (walls border unknown
// space); elsewhere only seen space judges, and a point there farther than
// the tolerance from any wall or unknown cell is a wall where the target
// clearly sees none.
enum class Landing
{
	Unjudged,
	Supported,
	Agreeing,
	Conflicting
};
Landing landing(const OccupancyField& target, int x, int y, double tolerance)
{
	const int w = target.known.cols, h = target.known.rows;
	if (x >= 0 && y >= 0 && x < w && y < h)
	{
		if (target.dist_to_occupied.at<float>(y, x) <= tolerance) return Landing::Supported;
		if (!target.known.at<uint8_t>(y, x)) return Landing::Unjudged;
		return target.dist_to_not_free.at<float>(y, x) > tolerance ? Landing::Conflicting : Landing::Agreeing;
	}
	if (!target.empty_beyond || w == 0 || h == 0) return Landing::Unjudged;
	// Beyond a plan's image: judged from the image's nearest cell c, d away.
	// A wall is at most d + its distance from c; the building, inside the
	// image (a convex box), at least hypot(d, its distance from c).
	const int cx = std::clamp(x, 0, w - 1), cy = std::clamp(y, 0, h - 1);
	const double d = std::hypot(double(x - cx), double(y - cy));
	if (target.dist_to_occupied.at<float>(cy, cx) + d <= tolerance) return Landing::Supported;
	return std::hypot(d, double(target.dist_to_not_free.at<float>(cy, cx))) > tolerance ? Landing::Conflicting
																						: Landing::Agreeing;
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

double toleranceInTarget(double tolerance, double source_to_target_scale)
{
	const double ratio = std::max(source_to_target_scale, 1.0 / source_to_target_scale);
	const double in_finer_cells = tolerance + (ratio - 1.0);
	return source_to_target_scale >= 1.0 ? in_finer_cells : in_finer_cells * source_to_target_scale;
}

OccupancyField occupancyField(const cv::Mat& classes, MapKind kind)
{
	OccupancyField f;
	cv::distanceTransform(classes != kOccupied, f.dist_to_occupied, cv::DIST_L2, cv::DIST_MASK_PRECISE);
	if (kind == MapKind::Sensed)
	{
		cv::distanceTransform(classes == kFree, f.dist_to_not_free, cv::DIST_L2, cv::DIST_MASK_PRECISE);
		f.known = classes != kUnknown;
	}
	else
	{
		// What a plan leaves out of its building (grey, transparent) is drawn
		// as empty: a wall there, beyond the tolerance from the building,
		// conflicts (its distance to what is not free is to the building).
		// Its white only vouches near walls.
		const cv::Mat outside = classes == kUnknown;
		cv::distanceTransform(outside, f.dist_to_not_free, cv::DIST_L2, cv::DIST_MASK_PRECISE);
		f.known = (f.dist_to_occupied <= kPlanVouchesCells) | outside;
		f.empty_beyond = true;
	}
	const cv::Mat occupied = classes == kOccupied;
	f.wall_normal_deg = wallNormals(occupied);
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
	const PointList& points, const OccupancyField& source, const Similarity2D& t, const OccupancyField& target,
	double tolerance, bool judge_directions)
{
	Support s;
	const int w = target.known.cols, h = target.known.rows;
	const Eigen::Matrix2d a = t.linear();
	const double turn_deg = t.yaw * 180.0 / M_PI;
	const bool directions = judge_directions && !source.wall_normal_deg.empty() && !target.wall_normal_deg.empty();
	const int reach = static_cast<int>(std::floor(tolerance));
	const double reach2 = tolerance * tolerance;
	for (const auto& p : points)
	{
		const Eigen::Vector2d q = a * p + t.t;
		const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
		const Landing l = landing(target, x, y, tolerance);
		if (l == Landing::Supported)
		{
			++s.judged, ++s.supported;
			if (!directions) continue;
			const int px = static_cast<int>(std::lround(p.x())), py = static_cast<int>(std::lround(p.y()));
			if (px < 0 || py < 0 || px >= source.wall_normal_deg.cols || py >= source.wall_normal_deg.rows)
				continue;
			const uint8_t ds = source.wall_normal_deg.at<uint8_t>(py, px);
			if (ds == kNoDirection) continue;
			// Near a wall running the same way, not merely near a wall (a
			// wall crossing it, at a junction or by a wrong transform).
			// Judged only near a wall that has a direction: walls drawn as
			// speckle or clutter (no line to follow) say nothing either way.
			const double moved = double(ds) + turn_deg;
			bool near_directed = false, near_same = false;
			for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach) && !near_same; ++v)
			{
				const uint8_t* row = target.wall_normal_deg.ptr<uint8_t>(v);
				for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
				{
					if (row[u] == kNoDirection || double((u - x) * (u - x) + (v - y) * (v - y)) > reach2) continue;
					near_directed = true;
					if (std::abs(std::remainder(double(row[u]) - moved, 180.0)) <= kSameDirectionDeg)
					{
						near_same = true;
						break;
					}
				}
			}
			if (!near_directed) continue;
			++s.directed;
			s.directed_supported += near_same;
		}
		else if (l != Landing::Unjudged)
		{
			++s.judged;
			s.conflicts += l == Landing::Conflicting;
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
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance, size_t most,
	bool judge_directions)
{
	TwoWaySupport s;
	if (!other_to_ref.isFinite() || !(other_to_ref.scale > 0)) return s;
	s.other_in_ref = tolerantSupport(
		thinned(other_points, most), other_field, other_to_ref, ref_field,
		toleranceInTarget(tolerance, other_to_ref.scale), judge_directions);
	s.ref_in_other = tolerantSupport(
		thinned(ref_points, most), ref_field, other_to_ref.inverse(), other_field,
		toleranceInTarget(tolerance, 1.0 / other_to_ref.scale), judge_directions);
	return s;
}

namespace
{
/** Per shift (offsets[ky] rows, offsets[kx] columns; index ky × n + kx):
 * the sum of `worth` where the points land shifted, and whether any lands
 * on a judged cell. */
struct ShiftScores
{
	std::vector<long> value;
	std::vector<uint8_t> judged;
};
ShiftScores scoreShifts(
	const std::vector<ptrdiff_t>& unshifted, const std::vector<int8_t>& worth, const std::vector<uint8_t>& judged_at,
	int window_w, const std::vector<int>& offsets)
{
	const size_t n = offsets.size();
	ShiftScores s{std::vector<long>(n * n, 0), std::vector<uint8_t>(n * n, 0)};
	// Offsets a cell apart (the usual case): a point's shifts along a row
	// read adjacent window cells, a loop the compiler vectorises. The sums
	// are of integers: any order gives the same.
	bool adjacent = true;
	for (size_t k = 1; k < n; ++k) adjacent &= offsets[k] == offsets[k - 1] + 1;
	std::vector<int> row_value(n);
	std::vector<uint8_t> row_judged(n);
	for (size_t ky = 0; ky < n; ++ky)
	{
		std::fill(row_value.begin(), row_value.end(), 0);
		std::fill(row_judged.begin(), row_judged.end(), 0);
		const ptrdiff_t row_offset = ptrdiff_t(offsets[ky]) * window_w;
		for (const ptrdiff_t i : unshifted)
		{
			const int8_t* w = &worth[size_t(i + row_offset + offsets[0])];
			const uint8_t* j = &judged_at[size_t(i + row_offset + offsets[0])];
			if (adjacent)
				for (size_t kx = 0; kx < n; ++kx) row_value[kx] += w[kx], row_judged[kx] |= j[kx];
			else
				for (size_t kx = 0; kx < n; ++kx)
				{
					const int dx = offsets[kx] - offsets[0];
					row_value[kx] += w[dx], row_judged[kx] |= j[dx];
				}
		}
		std::copy(row_value.begin(), row_value.end(), s.value.begin() + ky * n);
		std::copy(row_judged.begin(), row_judged.end(), s.judged.begin() + ky * n);
	}
	return s;
}
}  // namespace

/** Cells: beyond this, a point is not binned in a tile. */
constexpr double kFarthestBinned = 1e8;

ShiftField shiftField(
	const PointList& points, const OccupancyField& source, const Similarity2D& t, const OccupancyField& target,
	double tolerance, double tile, double reach, double step)
{
	ShiftField f;
	const int w = target.known.cols, h = target.known.rows;
	const Eigen::Matrix2d a = t.linear();
	// Each tile's points: rounded where they land in the target, and as
	// they are in the source (the bent pass moves them again).
	struct Tile
	{
		std::vector<cv::Point> landed;
		PointList sources;
	};
	std::map<std::pair<int, int>, Tile> tiles;
	for (const auto& p : points)
	{
		const Eigen::Vector2d q = a * p + t.t;
		// Beyond a plan's image points are judged too, unless so far (a wild
		// transform) that their tile's index would not fit in an int.
		const bool near_image = q.x() > -reach && q.y() > -reach && q.x() < w + reach && q.y() < h + reach;
		const bool binnable = std::abs(q.x()) < kFarthestBinned && std::abs(q.y()) < kFarthestBinned;
		if (!near_image && !(target.empty_beyond && binnable)) continue;
		Tile& tile_of_q = tiles[{int(std::floor(q.x() / tile)), int(std::floor(q.y() / tile))}];
		tile_of_q.landed.emplace_back(int(std::lround(q.x())), int(std::lround(q.y())));
		tile_of_q.sources.push_back(p);
	}
	// Fewer points than this fit some shift by chance: the tile says nothing.
	constexpr size_t kMinTilePoints = 12;
	const int steps = std::max(0, int(std::floor(reach / step)));
	std::vector<int> shift_offsets;  // along either axis, in target cells
	for (int i = -steps; i <= steps; ++i) shift_offsets.push_back(int(std::lround(i * step)));
	std::map<std::pair<int, int>, cv::Point> best_shift;
	for (const auto& [key, tile_points] : tiles)
	{
		const std::vector<cv::Point>& pts = tile_points.landed;
		if (pts.size() < kMinTilePoints) continue;
		// How a point lands anywhere in the tile's window (its points' box
		// grown by the reach), judged once: every shift reads it.
		const int r = int(std::lround(steps * step));
		int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(), y1 = x1;
		for (const auto& p : pts)
			x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
		x0 -= r, y0 -= r, x1 += r, y1 += r;
		// Per window cell what a point landing there is worth (+1 supported,
		// -1 conflicting) and whether it is judged at all; per point its
		// index unshifted: every shift adds one offset to all of them.
		const int window_w = x1 - x0 + 1;
		const size_t window_cells = size_t(window_w) * size_t(y1 - y0 + 1);
		std::vector<int8_t> worth(window_cells, 0);
		std::vector<uint8_t> judged_at(window_cells, 0);
		// Off a robot map's grid nothing is judged (the zeros above); off a
		// plan's image its outside is.
		const bool whole_window = target.empty_beyond;
		const int judged_x0 = whole_window ? x0 : std::max(x0, 0), judged_x1 = whole_window ? x1 : std::min(x1, w - 1);
		const int judged_y0 = whole_window ? y0 : std::max(y0, 0), judged_y1 = whole_window ? y1 : std::min(y1, h - 1);
		for (int y = judged_y0; y <= judged_y1; ++y)
			for (int x = judged_x0; x <= judged_x1; ++x)
			{
				const Landing l = landing(target, x, y, tolerance);
				const size_t i = size_t(y - y0) * window_w + size_t(x - x0);
				worth[i] = l == Landing::Supported ? 1 : l == Landing::Conflicting ? -1 : 0;
				judged_at[i] = l != Landing::Unjudged;
			}
		std::vector<ptrdiff_t> unshifted(pts.size());
		for (size_t k = 0; k < pts.size(); ++k)
			unshifted[k] = ptrdiff_t(pts[k].y - y0) * window_w + ptrdiff_t(pts[k].x - x0);
		const ShiftScores scores = scoreShifts(unshifted, worth, judged_at, window_w, shift_offsets);
		long best_value = std::numeric_limits<long>::min();
		int best_norm = 0;
		bool judged = false;
		cv::Point best(0, 0);
		for (size_t ky = 0; ky < shift_offsets.size(); ++ky)
			for (size_t kx = 0; kx < shift_offsets.size(); ++kx)
			{
				const cv::Point d(shift_offsets[kx], shift_offsets[ky]);
				const size_t k = ky * shift_offsets.size() + kx;
				const long value = scores.value[k];
				const int norm = d.x * d.x + d.y * d.y;
				if (scores.judged[k] && (value > best_value || (value == best_value && norm < best_norm)))
					best_value = value, best_norm = norm, best = d, judged = true;
			}
		if (!judged) continue;
		best_shift[key] = best;
		Eigen::Vector2d centroid(0, 0);
		for (const auto& p : tile_points.sources) centroid += p;
		centroid /= double(tile_points.sources.size());
		f.fitted.emplace_back(centroid, t.apply(centroid) + Eigen::Vector2d(best.x, best.y));
	}
	// Each tile judged again, shifted as its neighbours fit best (their
	// component-wise median; none fitted: unshifted). A smooth bend is
	// predicted by the neighbours and judged as if straightened; shifts that
	// go each their own way (a wrong transform) predict nothing. Leaving the
	// tile's own shift out keeps a tile from fitting itself onto any walls
	// within reach, which chance does as well as the truth.
	for (const auto& [key, tile_points] : tiles)
	{
		std::vector<int> xs, ys;
		for (int dy = -1; dy <= 1; ++dy)
			for (int dx = -1; dx <= 1; ++dx)
			{
				const auto it = best_shift.find({key.first + dx, key.second + dy});
				if ((dx || dy) && it != best_shift.end()) xs.push_back(it->second.x), ys.push_back(it->second.y);
			}
		Similarity2D shifted = t;
		if (!xs.empty())
		{
			std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
			std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
			shifted.t += Eigen::Vector2d(xs[xs.size() / 2], ys[ys.size() / 2]);
		}
		const Support s = tolerantSupport(tile_points.sources, source, shifted, target, tolerance, false);
		f.bent.judged += s.judged, f.bent.supported += s.supported, f.bent.conflicts += s.conflicts;
	}
	for (const auto& [key, d] : best_shift)
		for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}})
		{
			const auto it = best_shift.find({key.first + dx, key.second + dy});
			if (it == best_shift.end()) continue;
			++f.neighbour_pairs;
			f.coherent_pairs += std::hypot(double(it->second.x - d.x), double(it->second.y - d.y)) <= tolerance;
		}
	return f;
}

TwoWayShiftField twoWayShiftField(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance, size_t most)
{
	TwoWayShiftField f;
	if (!other_to_ref.isFinite() || !(other_to_ref.scale > 0)) return f;
	// Tile, reach and step in coarse cells, in each map's own cells.
	for (const auto& [points, source, field, t, out] :
		 {std::tuple{&other_points, &other_field, &ref_field, other_to_ref, &f.other_in_ref},
		  std::tuple{&ref_points, &ref_field, &other_field, other_to_ref.inverse(), &f.ref_in_other}})
	{
		const double coarse = std::max(1.0, t.scale);  // target cells per coarse cell
		*out = shiftField(
			thinned(*points, most), *source, t, *field, toleranceInTarget(tolerance, t.scale), kShiftTileCoarseCells * coarse,
			kShiftReachCoarseCells * coarse, coarse);
	}
	return f;
}

Similarity2D bendBalanced(const TwoWayShiftField& f, const Similarity2D& other_to_ref)
{
	const size_t n = f.other_in_ref.fitted.size() + f.ref_in_other.fitted.size();
	if (n < 3) return other_to_ref;
	Eigen::Matrix2Xd other_cells(2, n), ref_cells(2, n);
	size_t i = 0;
	for (const auto& [other_centroid, in_ref] : f.other_in_ref.fitted)
		other_cells.col(i) = other_centroid, ref_cells.col(i++) = in_ref;
	for (const auto& [ref_centroid, in_other] : f.ref_in_other.fitted)
		other_cells.col(i) = in_other, ref_cells.col(i++) = ref_centroid;
	return Similarity2D::fromMatrix(Eigen::Matrix3d(Eigen::umeyama(other_cells, ref_cells, true)));
}

Chance chanceSupport(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance, double shift_coarse,
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
			twoWaySupport(ref_points, ref_field, other_points, other_field, m.compose(other_to_ref), tolerance, most, false);
		best.support = std::max(best.support, s.score());
		best.consistency = std::max(best.consistency, s.consistency());
	}
	return best;
}

}  // namespace multires_map_merge
