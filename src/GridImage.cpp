#include <multires_map_merge/GridImage.h>

#include <opencv2/imgproc.hpp>

namespace multires_map_merge
{
cv::Mat toClassImage(const mrpt::maps::COccupancyGridMap2D& grid)
{
	const int w = static_cast<int>(grid.getSizeX()), h = static_cast<int>(grid.getSizeY());
	cv::Mat img(h, w, CV_8UC1);
	for (int cy = 0; cy < h; ++cy)
	{
		auto* row = img.ptr<uint8_t>(cy);
		for (int cx = 0; cx < w; ++cx) row[cx] = classify(occupancyProbability(grid, cx, cy));
	}
	return img;
}

Similarity2D cellToMetric(const mrpt::maps::COccupancyGridMap2D& grid)
{
	return Similarity2D::cellToMetric(grid.getResolution(), grid.getXMin(), grid.getYMin());
}

cv::Mat resampleMask(const cv::Mat& mask, double factor)
{
	CV_Assert(mask.type() == CV_8UC1 && factor > 0);
	const cv::Size size(std::max(1, cvRound(mask.cols * factor)), std::max(1, cvRound(mask.rows * factor)));
	// INTER_AREA gives each output cell the fraction of set input cells under
	// it; "any" is that fraction being non-zero. In 8 bits one set cell of N
	// rounds to 0 past N = 510: there lone cells drop out (the structure
	// search's far-shrunk views, e.g. a reference shrunk 25× for a large
	// scale). Kept so: fractions in floats there were measured no better
	// (Halmstad sensor pairs +2 / −1, fleets' worst placements farther) and
	// slower (4000² pairs +23 %).
	cv::Mat frac;
	cv::resize(mask, frac, size, 0, 0, factor < 1 ? cv::INTER_AREA : cv::INTER_NEAREST);
	return frac > 0;
}

cv::Mat resampleClasses(const cv::Mat& classes, double factor)
{
	CV_Assert(classes.type() == CV_8UC1 && factor > 0);
	const cv::Mat free = resampleMask(classes == kFree, factor);
	cv::Mat out(free.size(), CV_8UC1, cv::Scalar(kUnknown));
	out.setTo(kFree, free);
	out.setTo(kOccupied, resampleMask(classes == kOccupied, factor));
	return out;
}

cv::Mat forDisplay(const cv::Mat& classes)
{
	cv::Mat flipped;
	cv::flip(classes, flipped, 0);
	return flipped;
}

}  // namespace multires_map_merge
