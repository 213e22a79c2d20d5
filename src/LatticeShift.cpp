#include <multires_map_merge/LatticeShift.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace multires_map_merge
{
namespace
{
/** Counts, for one shift, the coarse cells the shifted fine points round to
 * that are not among the seen occupied ones but are known, plus the seen
 * occupied ones no point rounds to. `stamp` marks cells already counted for
 * this `id` (no clearing between shifts). */
size_t mismatch(
	const PointList& fine, const Eigen::Vector2d& shift, const cv::Mat& seen, const cv::Mat& near_known,
	size_t seen_count, cv::Mat& stamp, int id)
{
	size_t hits = 0, extra = 0;
	for (const auto& p : fine)
	{
		const int x = int(std::floor(p.x() + shift.x() + 0.5)), y = int(std::floor(p.y() + shift.y() + 0.5));
		if (x < 0 || y < 0 || x >= stamp.cols || y >= stamp.rows) continue;
		int& st = stamp.at<int>(y, x);
		if (st == id) continue;
		st = id;
		if (seen.at<uint8_t>(y, x)) ++hits;
		else if (near_known.at<uint8_t>(y, x)) ++extra;
	}
	return seen_count - hits + extra;
}

/** The whole-cell shift in [-1, 1]² that leaves the least mismatch, (0, 0)
 * unless another leaves strictly less. Maps that coincide cell for cell fit
 * exactly on part of their points a cell off too: where walls are two cells
 * thick, one face lands on the other and the fit's error there is zero, so
 * a trimmed fit settles on half the points (ψ = 0) as readily as on all of
 * them. The cells the shifted points fill tell the two apart. */
Eigen::Vector2d wholeCellSlip(
	const PointList& fine, const cv::Mat& seen, const cv::Mat& near_known, size_t seen_count)
{
	cv::Mat stamp = cv::Mat::zeros(near_known.size(), CV_32S);
	Eigen::Vector2d best(0, 0);
	size_t least = mismatch(fine, best, seen, near_known, seen_count, stamp, 1);
	int id = 1;
	for (int dy = -1; dy <= 1; ++dy)
		for (int dx = -1; dx <= 1; ++dx)
		{
			if (dx == 0 && dy == 0) continue;
			const Eigen::Vector2d shift(dx, dy);
			if (const size_t cost = mismatch(fine, shift, seen, near_known, seen_count, stamp, ++id); cost < least)
				least = cost, best = shift;
		}
	return best;
}
}  // namespace

Eigen::Vector2d latticeShift(
	const PointList& fine_in_coarse, const PointList& coarse_seen, const cv::Mat& coarse_near_known,
	const LatticeShiftParams& p)
{
	CV_Assert(coarse_near_known.type() == CV_8UC1);
	if (fine_in_coarse.empty() || coarse_seen.empty() || !(p.step > 0) || !(p.range > 0)) return {0, 0};
	// The seen cells are a subset of the occupied ones (points, not a mask).
	cv::Mat seen = cv::Mat::zeros(coarse_near_known.size(), CV_8U);
	for (const auto& c : coarse_seen) seen.at<uint8_t>(int(c.y()), int(c.x())) = 1;

	// Two passes: the whole range at four steps, then around its answer.
	// Steps bounded below: the work grows with (range / step)².
	const double finest = std::max(p.step, p.range / 100);
	Eigen::Vector2d centre = wholeCellSlip(fine_in_coarse, seen, coarse_near_known, coarse_seen.size());
	double half = p.range, step = std::max(finest, p.range / 10);
	for (int pass = 0; pass < 2; ++pass)
	{
		int n = int(std::round(half / step));
		// A shift of exactly half a cell is where the points round either
		// way: which way depends on their last bit (and the machine), and a
		// plateau ending there one-sidedly moves its centre (identical maps
		// came out a fortieth of a cell off). The whole range's pass stops a
		// step short of it; the next pass still reaches past it.
		if (pass == 0 && n > 1) --n;
		const int side = 2 * n + 1;
		std::vector<size_t> cost(size_t(side) * side);
		cv::parallel_for_(cv::Range(0, side * side), [&](const cv::Range& r) {
			cv::Mat stamp = cv::Mat::zeros(coarse_near_known.size(), CV_32S);
			for (int k = r.start; k < r.end; ++k)
			{
				const Eigen::Vector2d shift = centre + step * Eigen::Vector2d(k % side - n, k / side - n);
				cost[size_t(k)] = mismatch(fine_in_coarse, shift, seen, coarse_near_known, coarse_seen.size(), stamp, k + 1);
			}
		});
		const size_t least = *std::min_element(cost.begin(), cost.end());
		Eigen::Vector2d sum(0, 0);
		double count = 0;
		for (int k = 0; k < side * side; ++k)
			if (double(cost[size_t(k)]) <= double(least) * (1 + p.plateau))
				sum += centre + step * Eigen::Vector2d(k % side - n, k / side - n), count += 1;
		centre = sum / count;
		half = 2 * step;
		step = finest;
	}
	return centre;
}

}  // namespace multires_map_merge
