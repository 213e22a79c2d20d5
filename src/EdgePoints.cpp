#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>

#include <opencv2/imgproc.hpp>

namespace multires_map_merge
{
PointList cellsOf(const cv::Mat& mask)
{
	std::vector<cv::Point> cells;
	cv::findNonZero(mask, cells);
	PointList pts;
	pts.reserve(cells.size());
	for (const auto& c : cells) pts.emplace_back(c.x, c.y);
	return pts;
}

PointList edgePoints(const cv::Mat& classes)
{
	CV_Assert(classes.type() == CV_8UC1);
	cv::Mat free_near, edges;
	cv::dilate(classes == kFree, free_near, cv::Mat::ones(3, 3, CV_8U));
	cv::bitwise_and(classes == kOccupied, free_near, edges);
	return cellsOf(edges);
}

PointList occupiedPoints(const cv::Mat& classes)
{
	CV_Assert(classes.type() == CV_8UC1);
	return cellsOf(classes == kOccupied);
}

}  // namespace multires_map_merge
