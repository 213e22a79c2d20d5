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
// Occupancy probability of the cell containing point p (in cell units, cell
// (0, 0) spanning [0, 1)²), or 0.5 outside.
float occupancyAtCell(const COccupancyGridMap2D& g, const Eigen::Vector2d& p)
{
	const int cx = static_cast<int>(std::floor(p.x())), cy = static_cast<int>(std::floor(p.y()));
	if (cx < 0 || cy < 0 || cx >= static_cast<int>(g.getSizeX()) || cy >= static_cast<int>(g.getSizeY()))
		return 0.5f;
	return occupancyProbability(g, cx, cy);
}

// The output columns [first, last) of row `row` where any sub-sample can land
// in an input grid of in_w × in_h cells, `from_out` taking output cell
// coordinates to the input's (a few columns of slack each side). Elsewhere
// every sample falls outside the grid, which leaves the cell as the other
// maps say (fuseCell(p, 0.5) = p for every p the rule makes).
std::pair<int, int> columnsOverGrid(
	const Eigen::Matrix2d& from_out, const Eigen::Vector2d& shift, int row, int in_w, int in_h, int out_w)
{
	double lo = -INFINITY, hi = INFINITY;
	for (int d = 0; d < 2; ++d)
	{
		const double limit = d == 0 ? in_w : in_h, a = from_out(d, 0);
		const double b0 = from_out(d, 1) * row + shift(d), b1 = from_out(d, 1) * (row + 1) + shift(d);
		const double b_min = std::min(b0, b1), b_max = std::max(b0, b1);
		if (std::abs(a) < 1e-12)  // the row runs along this input axis (a cell of slack for rounding)
		{
			if (b_max < -1 || b_min >= limit + 1) return {0, 0};
			continue;
		}
		const double ends[] = {-b_min / a, -b_max / a, (limit - b_min) / a, (limit - b_max) / a};
		lo = std::max(lo, *std::min_element(std::begin(ends), std::end(ends)) - 1);
		hi = std::min(hi, *std::max_element(std::begin(ends), std::end(ends)) + 1);
	}
	if (!(lo < hi)) return {0, 0};
	const int first = static_cast<int>(std::clamp(std::floor(lo) - 1, 0.0, double(out_w)));
	const int last = static_cast<int>(std::clamp(std::ceil(hi) + 1, 0.0, double(out_w)));
	return {first, std::max(first, last)};
}

// Sub-samples per output cell axis so that every input cell is hit. A map
// placed at an estimated scale of 0.999 would need 2 x 2 samples to hit the
// one cell in a thousand that slips between output cells: that 2 % of slack
// costs nothing visible and saves 3/4 of the fusion.
int samplesPerAxis(double out_res, double in_cell_in_out_frame)
{
	return std::clamp(static_cast<int>(std::ceil(0.98 * out_res / in_cell_in_out_frame)), 1, 16);
}
}  // namespace

namespace
{
/** One input of a fusion: a grid and its metric frame → the output's. */
struct Placed
{
	const COccupancyGridMap2D* grid;
	Similarity2D to_out;
};

struct Fused
{
	COccupancyGridMap2D grid;
	std::vector<cv::Mat> classes;  //!< per input
};

/** The cell rule over any number of placed grids, on the union of their
 * extents, in one pass over the output (fusing pairwise into a growing result
 * would resample the result once per map). */
Fused fuseAll(const std::vector<Placed>& in, double res, size_t max_cells)
{
	if (!std::isfinite(res) || !(res > 0))
		throw std::invalid_argument("output resolution must be a positive number of metres");
	for (const auto& m : in)
		if (!m.to_out.isFinite() || !(m.to_out.scale > 0))
			throw std::invalid_argument("fusion needs a finite transform with positive scale");

	double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
	for (const auto& m : in)
		for (double x : {m.grid->getXMin(), m.grid->getXMax()})
			for (double y : {m.grid->getYMin(), m.grid->getYMax()})
			{
				const Eigen::Vector2d c = m.to_out(Eigen::Vector2d(x, y));
				x0 = std::min(x0, c.x()), x1 = std::max(x1, c.x());
				y0 = std::min(y0, c.y()), y1 = std::max(y1, c.y());
			}
	const double w = std::ceil((x1 - x0) / res), h = std::ceil((y1 - y0) / res);
	if (w * h > static_cast<double>(max_cells))
		throw MergedMapTooLarge(
			"merged map would have " + std::to_string(static_cast<long long>(w * h)) +
			" cells, more than the limit of " + std::to_string(max_cells));

	Fused fused;
	COccupancyGridMap2D& out = fused.grid;
	out.setSize(
		static_cast<float>(x0), static_cast<float>(x0 + w * res), static_cast<float>(y0),
		static_cast<float>(y0 + h * res), static_cast<float>(res), 0.5f);
	const double ox = out.getXMin(), oy = out.getYMin();
	const int W = static_cast<int>(out.getSizeX()), H = static_cast<int>(out.getSizeY());
	// Per input: output cell coordinates → its cell units (one affine map, no
	// sine, cosine or division per sample), and the output cells it can touch.
	std::vector<Eigen::Matrix2d> linear;
	std::vector<Eigen::Vector2d> shift;
	std::vector<cv::Rect> touched;
	std::vector<int> k;
	for (const auto& m : in)
	{
		const Similarity2D from_out = m.to_out.inverse();
		const double in_res = m.grid->getResolution();
		linear.push_back(from_out.linear() * (res / in_res));
		shift.push_back((from_out.linear() * Eigen::Vector2d(ox, oy) + from_out.t -
						 Eigen::Vector2d(m.grid->getXMin(), m.grid->getYMin())) / in_res);
		double bx0 = INFINITY, bx1 = -INFINITY, by0 = INFINITY, by1 = -INFINITY;
		for (double x : {m.grid->getXMin(), m.grid->getXMax()})
			for (double y : {m.grid->getYMin(), m.grid->getYMax()})
			{
				const Eigen::Vector2d c = m.to_out(Eigen::Vector2d(x, y));
				bx0 = std::min(bx0, c.x()), bx1 = std::max(bx1, c.x());
				by0 = std::min(by0, c.y()), by1 = std::max(by1, c.y());
			}
		const int cx0 = std::max(0, int(std::floor((bx0 - ox) / res)) - 1), cy0 = std::max(0, int(std::floor((by0 - oy) / res)) - 1);
		const int cx1 = std::min(W, int(std::ceil((bx1 - ox) / res)) + 1), cy1 = std::min(H, int(std::ceil((by1 - oy) / res)) + 1);
		touched.emplace_back(cx0, cy0, std::max(0, cx1 - cx0), std::max(0, cy1 - cy0));
		k.push_back(samplesPerAxis(res, in_res * m.to_out.scale));
		fused.classes.emplace_back(H, W, CV_8UC1, cv::Scalar(kUnknown));
	}

	// Each input is first reduced over its sub-samples with the same rule,
	// then the inputs are combined.
	auto reduce = [&](int cx, int cy, size_t m) {
		float p = 0.5f;
		for (int i = 0; i < k[m]; ++i)
			for (int j = 0; j < k[m]; ++j)
			{
				const Eigen::Vector2d c(cx + (i + 0.5) / k[m], cy + (j + 0.5) / k[m]);
				p = fuseCell(p, occupancyAtCell(*in[m].grid, linear[m] * c + shift[m]));
			}
		return p;
	};
#pragma omp parallel for schedule(dynamic, 16)
	for (int cy = 0; cy < H; ++cy)
	{
		std::vector<std::pair<int, int>> columns(in.size());
		for (size_t m = 0; m < in.size(); ++m)
		{
			if (cy < touched[m].y || cy >= touched[m].y + touched[m].height) continue;
			const auto [first, last] =
				columnsOverGrid(linear[m], shift[m], cy, int(in[m].grid->getSizeX()), int(in[m].grid->getSizeY()), W);
			columns[m] = {std::max(first, touched[m].x), std::min(last, touched[m].x + touched[m].width)};
		}
		for (int cx = 0; cx < W; ++cx)
		{
			float p = 0.5f;
			for (size_t m = 0; m < in.size(); ++m)
			{
				if (cx < columns[m].first || cx >= columns[m].second) continue;
				const float pm = reduce(cx, cy, m);
				fused.classes[m].at<uint8_t>(cy, cx) = classify(pm);
				p = fuseCell(p, pm);
			}
			out.setCell(cx, cy, 1.0f - p);  // MRPT stores P(free)
		}
	}
	return fused;
}
}  // namespace

FusedMap fuseGridMaps(
	const COccupancyGridMap2D& ref, const COccupancyGridMap2D& other, const Similarity2D& other_to_ref,
	double res, size_t max_cells)
{
	Fused f = fuseAll({{&ref, Similarity2D()}, {&other, other_to_ref}}, res, max_cells);
	FusedMap fused;
	fused.merged.grid = std::move(f.grid);
	fused.ref_classes = f.classes[0];
	fused.other_classes = f.classes[1];
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

FusedMaps fuseGridMaps(
	const std::vector<GridInFrame>& maps, size_t reference, const std::vector<std::optional<Similarity2D>>& to_reference,
	double res, size_t max_cells)
{
	if (reference >= maps.size() || to_reference.size() != maps.size() || !to_reference[reference])
		throw std::invalid_argument("fusion needs the reference map and a placement (or none) per map");
	std::vector<Placed> in;
	std::vector<size_t> index;
	for (size_t m = 0; m < maps.size(); ++m)
		if (to_reference[m])
		{
			in.push_back({&maps[m].grid, betweenGrids(maps[reference], *to_reference[m], maps[m])});
			index.push_back(m);
		}
	Fused f = fuseAll(in, res, max_cells);
	FusedMaps fused;
	fused.merged.grid = std::move(f.grid);
	fused.merged.origin = maps[reference].origin;
	fused.classes.resize(maps.size());
	for (size_t i = 0; i < index.size(); ++i) fused.classes[index[i]] = f.classes[i];
	return fused;
}

}  // namespace multires_map_merge
