#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/WallSpread.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace multires_map_merge
{
WallSpread spreadOf(const PointList& cells, const Similarity2D& to_frame)
{
	Eigen::Vector2d mean = Eigen::Vector2d::Zero();
	for (const auto& p : cells) mean += p;
	mean /= double(cells.size());
	Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
	for (const auto& p : cells) cov += (p - mean) * (p - mean).transpose();
	cov /= double(cells.size());
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
	WallSpread out;
	for (int axis = 0; axis < 2; ++axis)
	{
		const Eigen::Vector2d half = std::sqrt(2 * std::max(0.0, eig.eigenvalues()[axis])) * eig.eigenvectors().col(axis);
		out[2 * axis] = to_frame(mean + half);
		out[2 * axis + 1] = to_frame(mean - half);
	}
	return out;
}

WallSpread wallSpread(const GridInFrame& map, const cv::Mat& classes, cv::Point corner)
{
	// Its walls; a map with almost none: what it saw; nothing: the whole grid.
	PointList cells_seen = occupiedPoints(classes);
	if (cells_seen.size() < 3) cells_seen = cellsOf(classes != kUnknown);
	if (cells_seen.size() < 3) cells_seen = cellsOf(cv::Mat::ones(classes.size(), CV_8U));
	for (auto& c : cells_seen) c += Eigen::Vector2d(corner.x, corner.y);  // into the grid's cells
	return spreadOf(cells_seen, map.cellToMapFrame());
}

WallSpread wallSpread(const GridInFrame& map) { return wallSpread(map, toClassImage(map.grid)); }

double wallRms(const WallSpread& spread, const Similarity2D& a, const Similarity2D& b)
{
	double se = 0;
	for (const auto& p : spread) se += (a(p) - b(p)).squaredNorm();
	return std::sqrt(se / spread.size());
}

double cornerRms(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b)
{
	const Similarity2D cells = map.cellToMapFrame();
	const double w = map.grid.getSizeX() - 1, h = map.grid.getSizeY() - 1;
	double se = 0;
	for (const Eigen::Vector2d& c : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)})
		se += (a(cells(c)) - b(cells(c))).squaredNorm();
	return std::sqrt(se / 4);
}

}  // namespace multires_map_merge
