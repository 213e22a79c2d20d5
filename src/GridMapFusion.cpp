#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridMapFusion.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

float fuseCell(float a, float b)
{
	const CellClass ca = classify(a), cb = classify(b);
	if (ca == kOccupied || cb == kOccupied)
		return std::max(ca == kOccupied ? a : 0.f, cb == kOccupied ? b : 0.f);
	if (ca == kFree || cb == kFree) return std::min(ca == kFree ? a : 1.f, cb == kFree ? b : 1.f);
	return 0.5f;
}

namespace
{
// Occupancy probability of the cell containing metric point p, or 0.5 outside.
float occupancyAt(const COccupancyGridMap2D& g, const Eigen::Vector2d& p)
{
	const int cx = static_cast<int>(std::floor((p.x() - g.getXMin()) / g.getResolution()));
	const int cy = static_cast<int>(std::floor((p.y() - g.getYMin()) / g.getResolution()));
	if (cx < 0 || cy < 0 || cx >= static_cast<int>(g.getSizeX()) || cy >= static_cast<int>(g.getSizeY()))
		return 0.5f;
	return occupancyProbability(g, cx, cy);
}

// Sub-samples per output cell axis so that every input cell is hit.
int samplesPerAxis(double out_res, double in_cell_in_out_frame)
{
	return std::clamp(static_cast<int>(std::ceil(out_res / in_cell_in_out_frame)), 1, 16);
}
}  // namespace

FusedMap fuseGridMaps(
	const COccupancyGridMap2D& ref, const COccupancyGridMap2D& other, const Similarity2D& other_to_ref,
	double res, size_t max_cells)
{
	if (!std::isfinite(res) || !(res > 0))
		throw std::invalid_argument("output resolution must be a positive number of metres");
	if (!other_to_ref.isFinite() || !(other_to_ref.scale > 0))
		throw std::invalid_argument("fusion needs a finite transform with positive scale");

	// Union of ref's extent and other's transformed corners.
	double x0 = ref.getXMin(), x1 = ref.getXMax(), y0 = ref.getYMin(), y1 = ref.getYMax();
	for (double x : {other.getXMin(), other.getXMax()})
		for (double y : {other.getYMin(), other.getYMax()})
		{
			const Eigen::Vector2d c = other_to_ref(Eigen::Vector2d(x, y));
			x0 = std::min(x0, c.x()), x1 = std::max(x1, c.x());
			y0 = std::min(y0, c.y()), y1 = std::max(y1, c.y());
		}
	const double w = std::ceil((x1 - x0) / res), h = std::ceil((y1 - y0) / res);
	if (w * h > static_cast<double>(max_cells))
		throw MergedMapTooLarge(
			"merged map would have " + std::to_string(static_cast<long long>(w * h)) +
			" cells, more than the limit of " + std::to_string(max_cells));

	FusedMap fused;
	COccupancyGridMap2D& out = fused.merged.grid;
	out.setSize(
		static_cast<float>(x0), static_cast<float>(x0 + w * res), static_cast<float>(y0),
		static_cast<float>(y0 + h * res), static_cast<float>(res), 0.5f);
	const Similarity2D ref_to_other = other_to_ref.inverse();
	const int k_ref = samplesPerAxis(res, ref.getResolution());
	const int k_other = samplesPerAxis(res, other.getResolution() * other_to_ref.scale);
	const double ox = out.getXMin(), oy = out.getYMin();
	const int W = static_cast<int>(out.getSizeX()), H = static_cast<int>(out.getSizeY());
	fused.ref_classes.create(H, W, CV_8UC1);
	fused.other_classes.create(H, W, CV_8UC1);

	// Each input is first reduced over its sub-samples with the same rule,
	// then the two are combined.
	auto reduce = [&](int cx, int cy, int k, auto&& sample) {
		float p = 0.5f;
		for (int i = 0; i < k; ++i)
			for (int j = 0; j < k; ++j)
				p = fuseCell(p, sample(Eigen::Vector2d(ox + (cx + (i + 0.5) / k) * res, oy + (cy + (j + 0.5) / k) * res)));
		return p;
	};
#pragma omp parallel for schedule(dynamic, 16)
	for (int cy = 0; cy < H; ++cy)
		for (int cx = 0; cx < W; ++cx)
		{
			const float a = reduce(cx, cy, k_ref, [&](const Eigen::Vector2d& p) { return occupancyAt(ref, p); });
			const float b = reduce(
				cx, cy, k_other, [&](const Eigen::Vector2d& p) { return occupancyAt(other, ref_to_other(p)); });
			out.setCell(cx, cy, 1.0f - fuseCell(a, b));  // MRPT stores P(free)
			fused.ref_classes.at<uint8_t>(cy, cx) = classify(a);
			fused.other_classes.at<uint8_t>(cy, cx) = classify(b);
		}
	return fused;
}

FusedMap fuseGridMaps(
	const GridInFrame& ref, const GridInFrame& other, const Similarity2D& other_to_ref, double res,
	size_t max_cells)
{
	FusedMap fused = fuseGridMaps(ref.grid, other.grid, betweenGrids(ref, other_to_ref, other), res, max_cells);
	fused.merged.origin = ref.origin;
	return fused;
}

}  // namespace multires_map_merge
