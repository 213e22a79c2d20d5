#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapAgreement.h>

#include <opencv2/imgproc.hpp>

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
	const cv::Mat& ref, const cv::Mat& other, const Similarity2D& other_to_ref)
{
	CV_Assert(ref.type() == CV_8UC1 && other.type() == CV_8UC1);
	Agreement a;
	if (ref.empty() || other.empty() || !other_to_ref.isFinite() || !(other_to_ref.scale > 0))
		return a;
	// One coarse cell, in each map's own cells.
	const int r_ref = std::max(1, cvRound(other_to_ref.scale));
	const int r_other = std::max(1, cvRound(1.0 / other_to_ref.scale));

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

}  // namespace multires_map_merge
