#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridMapFusion.h>

#include <algorithm>
#include <array>
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
// Occupancy probabilities of a grid's cells, read through a table over its
// 8-bit cells: the values of occupancyProbability() without a call into
// MRPT's log-odds table for each of the fusion's samples.
class OccupancyReader
{
   public:
	explicit OccupancyReader(const COccupancyGridMap2D& g)
		: grid_(&g), w_(static_cast<int>(g.getSizeX())), h_(static_cast<int>(g.getSizeY()))
	{
		static_assert(sizeof(COccupancyGridMap2D::cellType) == 1, "the table covers 8-bit cells");
		for (int v = 0; v < 256; ++v)
			probability_[v] = 1.0f - COccupancyGridMap2D::l2p(static_cast<COccupancyGridMap2D::cellType>(v));
	}
	// The cell containing point p (in cell units, cell (0, 0) spanning
	// [0, 1)²), or 0.5 outside.
	float at(const Eigen::Vector2d& p) const
	{
		const int cx = static_cast<int>(std::floor(p.x())), cy = static_cast<int>(std::floor(p.y()));
		if (cx < 0 || cy < 0 || cx >= w_ || cy >= h_) return 0.5f;
		return probability_[static_cast<uint8_t>(grid_->getRow(cy)[cx])];
	}
	/** The bounding box of the cells that are occupied or free (empty when
	 * none): every other cell reads as unknown. */
	cv::Rect knownBox() const
	{
		int x0 = w_, y0 = h_, x1 = -1, y1 = -1;
		for (int cy = 0; cy < h_; ++cy)
		{
			const auto* row = grid_->getRow(cy);
			int first = 0, last = w_ - 1;
			while (first < w_ && classify(probability_[static_cast<uint8_t>(row[first])]) == kUnknown) ++first;
			if (first == w_) continue;
			while (classify(probability_[static_cast<uint8_t>(row[last])]) == kUnknown) --last;
			x0 = std::min(x0, first), x1 = std::max(x1, last), y0 = std::min(y0, cy), y1 = cy;
		}
		return x1 < 0 ? cv::Rect() : cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
	}

   private:
	const COccupancyGridMap2D* grid_;
	int w_, h_;
	std::array<float, 256> probability_;
};

// The output columns [first, last) of row `row` where any sub-sample can land
// in an input grid (or a box of it: `shift` then taken to the box's corner)
// of in_w × in_h cells, `from_out` taking output cell coordinates to the
// input's (a few columns of slack each side). Elsewhere every sample falls
// outside, which leaves the cell as the other maps say (fuseCell(p, 0.5) = p
// for every p the rule makes).
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

/** The metric box of the union of the inputs' extents in the output frame. */
struct Box
{
	double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
	void add(const COccupancyGridMap2D& g, const Similarity2D& to_out)
	{
		for (double x : {g.getXMin(), g.getXMax()})
			for (double y : {g.getYMin(), g.getYMax()})
			{
				const Eigen::Vector2d c = to_out(Eigen::Vector2d(x, y));
				x0 = std::min(x0, c.x()), x1 = std::max(x1, c.x());
				y0 = std::min(y0, c.y()), y1 = std::max(y1, c.y());
			}
	}
};

/** One input as the output's cells see it: output cell coordinates → its
 * cell units (one affine map, no sine, cosine or division per sample), the
 * output cells it can touch and its sub-samples per output cell. */
class InputSampler
{
   public:
	InputSampler(const Placed& m, const COccupancyGridMap2D& out, double res) : read_(*m.grid)
	{
		const double in_res = m.grid->getResolution();
		const Eigen::Vector2d out_corner(out.getXMin(), out.getYMin());
		const Similarity2D from_out = m.to_out.inverse();
		linear_ = from_out.linear() * (res / in_res);
		shift_ = (from_out.linear() * out_corner + from_out.t - Eigen::Vector2d(m.grid->getXMin(), m.grid->getYMin())) / in_res;
		Box b;
		b.add(*m.grid, m.to_out);
		const int W = static_cast<int>(out.getSizeX()), H = static_cast<int>(out.getSizeY());
		const int cx0 = std::max(0, int(std::floor((b.x0 - out_corner.x()) / res)) - 1);
		const int cy0 = std::max(0, int(std::floor((b.y0 - out_corner.y()) / res)) - 1);
		const int cx1 = std::min(W, int(std::ceil((b.x1 - out_corner.x()) / res)) + 1);
		const int cy1 = std::min(H, int(std::ceil((b.y1 - out_corner.y()) / res)) + 1);
		touched_ = cv::Rect(cx0, cy0, std::max(0, cx1 - cx0), std::max(0, cy1 - cy0));
		k_ = samplesPerAxis(res, in_res * m.to_out.scale);
		// Beyond its known cells an input leaves the output as the others
		// make it (fuseCell(p, unknown) = p): only they are read. A robot's
		// map is mostly unexplored margin.
		known_ = read_.knownBox();
		out_w_ = W;
	}

	/** The output columns [first, last) of row `cy` this input can change. */
	std::pair<int, int> columns(int cy) const
	{
		if (cy < touched_.y || cy >= touched_.y + touched_.height || known_.empty()) return {0, 0};
		const auto [first, last] = columnsOverGrid(
			linear_, shift_ - Eigen::Vector2d(known_.x, known_.y), cy, known_.width, known_.height, out_w_);
		return {std::max(first, touched_.x), std::min(last, touched_.x + touched_.width)};
	}

	/** The input over output cell (cx, cy): its sub-samples reduced with the cell rule. */
	float at(int cx, int cy) const
	{
		float p = 0.5f;
		for (int i = 0; i < k_; ++i)
			for (int j = 0; j < k_; ++j)
			{
				const Eigen::Vector2d c(cx + (i + 0.5) / k_, cy + (j + 0.5) / k_);
				p = fuseCell(p, read_.at(linear_ * c + shift_));
			}
		return p;
	}

   private:
	OccupancyReader read_;
	Eigen::Matrix2d linear_;
	Eigen::Vector2d shift_;
	cv::Rect touched_;
	cv::Rect known_;  //!< the input's known cells (OccupancyReader::knownBox)
	int k_ = 1, out_w_ = 0;
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

	Box box;
	for (const auto& m : in) box.add(*m.grid, m.to_out);
	const double w = std::ceil((box.x1 - box.x0) / res), h = std::ceil((box.y1 - box.y0) / res);
	if (w * h > static_cast<double>(max_cells))
		throw MergedMapTooLarge(
			"merged map would have " + std::to_string(static_cast<long long>(w * h)) +
			" cells, more than the limit of " + std::to_string(max_cells));

	Fused fused;
	COccupancyGridMap2D& out = fused.grid;
	out.setSize(
		static_cast<float>(box.x0), static_cast<float>(box.x0 + w * res), static_cast<float>(box.y0),
		static_cast<float>(box.y0 + h * res), static_cast<float>(res), 0.5f);
	const int W = static_cast<int>(out.getSizeX()), H = static_cast<int>(out.getSizeY());
	std::vector<InputSampler> samplers;
	for (const auto& m : in)
	{
		samplers.emplace_back(m, out, res);
		fused.classes.emplace_back(H, W, CV_8UC1, cv::Scalar(kUnknown));
	}

	// The output is fused in bands of rows, one input at a time over a band:
	// an input turned against the output is read across its rows, and the
	// band uses the cache lines of its columns again before another input's
	// evict them. Each cell still combines the inputs in their order (each
	// input first reduced over its sub-samples), so the order of the passes
	// does not change the result.
	constexpr int kBandRows = 32;
	const int bands = (H + kBandRows - 1) / kBandRows;
#pragma omp parallel for schedule(dynamic, 1)
	for (int band = 0; band < bands; ++band)
	{
		const int row0 = band * kBandRows, rows = std::min(kBandRows, H - row0);
		std::vector<float> p(static_cast<size_t>(rows) * W, 0.5f);
		for (size_t m = 0; m < in.size(); ++m)
			for (int cy = row0; cy < row0 + rows; ++cy)
			{
				const auto [first, last] = samplers[m].columns(cy);
				float* p_row = &p[static_cast<size_t>(cy - row0) * W];
				uint8_t* class_row = fused.classes[m].ptr<uint8_t>(cy);
				for (int cx = first; cx < last; ++cx)
				{
					const float pm = samplers[m].at(cx, cy);
					class_row[cx] = classify(pm);
					p_row[cx] = fuseCell(p_row[cx], pm);
				}
			}
		for (int cy = row0; cy < row0 + rows; ++cy)
			for (int cx = 0; cx < W; ++cx)
				out.setCell(cx, cy, 1.0f - p[static_cast<size_t>(cy - row0) * W + cx]);  // MRPT stores P(free)
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
