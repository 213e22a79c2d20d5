#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>

#include <mrpt/poses/CPose3D.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

GridInFrame renderGridOffLattice(
	const ScanSequence& scans, size_t begin, size_t end, double resolution, const mrpt::poses::CPose2D& frame,
	double dx, double dy, float max_range)
{
	// A point p of the shifted frame is p + (dx, dy) in `frame`.
	return {renderGrid(scans, begin, end, resolution, frame + mrpt::poses::CPose2D(dx, dy, 0), max_range),
			Similarity2D(1, 0, {dx, dy})};
}

GroundTruthPair makeGroundTruthPair(const ScanSequence& scans, const PairSpec& spec)
{
	const size_t n = scans.size();
	const auto at = [n](double f) {
		return static_cast<size_t>(std::lround(std::clamp(f, 0.0, 1.0) * static_cast<double>(n)));
	};
	GroundTruthPair p;
	p.ref = renderGrid(scans, 0, at(spec.ref_end), spec.ref_resolution, {}, spec.max_range,
		spec.free_update_certainty);
	p.other = renderGrid(
		scans, at(spec.other_begin), n, spec.other_resolution, spec.other_frame, spec.max_range,
		spec.free_update_certainty);
	p.other_to_ref = Similarity2D(
		1.0, spec.other_frame.phi(), Eigen::Vector2d(spec.other_frame.x(), spec.other_frame.y()));
	return p;
}

Similarity2D GroundTruthPair::otherCellsToRefCells() const
{
	return cellToMetric(ref).inverse().compose(other_to_ref).compose(cellToMetric(other));
}

COccupancyGridMap2D withStatedResolution(const COccupancyGridMap2D& grid, double res)
{
	const int w = static_cast<int>(grid.getSizeX()), h = static_cast<int>(grid.getSizeY());
	COccupancyGridMap2D out;
	out.setSize(
		grid.getXMin(), grid.getXMin() + static_cast<float>(w * res), grid.getYMin(),
		grid.getYMin() + static_cast<float>(h * res), static_cast<float>(res));
	const int w2 = std::min<int>(w, out.getSizeX()), h2 = std::min<int>(h, out.getSizeY());
	for (int cy = 0; cy < h2; ++cy)
		for (int cx = 0; cx < w2; ++cx) out.setCell(cx, cy, grid.getCell(cx, cy));
	return out;
}

std::vector<Eigen::Vector2d> occupiedPointsInMapFrame(const GridInFrame& map)
{
	std::vector<cv::Point> cells;
	cv::findNonZero(toClassImage(map.grid) == kOccupied, cells);
	const Similarity2D to_frame = map.cellToMapFrame();
	std::vector<Eigen::Vector2d> pts;
	pts.reserve(cells.size());
	for (const auto& c : cells) pts.push_back(to_frame(Eigen::Vector2d(c.x, c.y)));
	return pts;
}

double pointRmse(
	const Similarity2D& estimate, const Similarity2D& truth,
	const std::vector<Eigen::Vector2d>& points)
{
	if (points.empty()) return 0;
	double sum = 0;
	for (const auto& p : points) sum += (estimate(p) - truth(p)).squaredNorm();
	return std::sqrt(sum / static_cast<double>(points.size()));
}

void forgetSeenBy(GridInFrame& map, const Similarity2D& map_to_seen, const GridInFrame& seen, double margin_m)
{
	cv::Mat known = toClassImage(seen.grid) != kUnknown;
	const int margin = static_cast<int>(std::ceil(margin_m / seen.grid.getResolution()));
	cv::dilate(known, known, cv::Mat::ones(2 * margin + 1, 2 * margin + 1, CV_8UC1));
	const Similarity2D to_seen_cells = seen.cellToMapFrame().inverse().compose(map_to_seen).compose(map.cellToMapFrame());
	for (int y = 0; y < int(map.grid.getSizeY()); ++y)
		for (int x = 0; x < int(map.grid.getSizeX()); ++x)
		{
			const Eigen::Vector2d q = to_seen_cells(Eigen::Vector2d(x, y));
			const int qx = int(std::lround(q.x())), qy = int(std::lround(q.y()));
			if (qx >= 0 && qy >= 0 && qx < known.cols && qy < known.rows && known.at<uint8_t>(qy, qx))
				map.grid.setCell(x, y, 0.5f);
		}
}

}  // namespace multires_map_merge
