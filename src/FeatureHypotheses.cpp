#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <algorithm>
#include <cmath>

namespace multires_map_merge
{
std::vector<LevelFeatures> extractPyramidFeatures(const cv::Mat& classes, const FeatureParams& p)
{
	auto sift = cv::SIFT::create(0, 3, p.sift_contrast_threshold, p.sift_edge_threshold);
	std::vector<LevelFeatures> levels;
	for (int l = 0; l < p.pyramid_levels; ++l)
	{
		const double f = std::ldexp(1.0, -l);
		if (std::min(classes.cols, classes.rows) * f < p.min_level_size && l > 0) break;
		cv::Mat img = l == 0 ? classes.clone() : resampleClasses(classes, f);
		if (p.unknown_as_free) img.setTo(kFree, img == kUnknown);
		LevelFeatures lf;
		lf.scale = f;
		std::vector<cv::KeyPoint> kps;
		sift->detectAndCompute(img, cv::noArray(), kps, lf.descriptors);
		for (const auto& k : kps)  // level pixel centre → full-resolution cell
			lf.points.emplace_back(
				static_cast<float>((k.pt.x + 0.5) / f - 0.5), static_cast<float>((k.pt.y + 0.5) / f - 0.5));
		levels.push_back(std::move(lf));
	}
	return levels;
}

std::optional<Similarity2D> ransacSimilarity(
	const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to, double threshold,
	int iterations, double confidence, int min_inliers, std::vector<uchar>& inlier_mask)
{
	inlier_mask.assign(from.size(), 0);
	if (from.size() < 2 || from.size() != to.size()) return std::nullopt;
	cv::Mat m = cv::estimateAffinePartial2D(
		from, to, inlier_mask, cv::RANSAC, threshold, static_cast<size_t>(iterations), confidence, 10);
	if (m.empty() || cv::countNonZero(inlier_mask) < min_inliers) return std::nullopt;
	Eigen::Matrix<double, 2, 3> e;
	for (int r = 0; r < 2; ++r)
		for (int c = 0; c < 3; ++c) e(r, c) = m.at<double>(r, c);
	auto s = Similarity2D::fromMatrix(e);
	if (!s.isFinite() || !(s.scale > 0)) return std::nullopt;
	return s;
}

namespace
{
// Two hypotheses are one if they put the other map's points in the same
// place to within a few reference cells.
bool sameHypothesis(const Similarity2D& a, const Similarity2D& b)
{
	return std::abs(std::log(a.scale / b.scale)) < 0.03 && std::abs(wrapToPi(a.yaw - b.yaw)) < 0.05 &&
		(a.t - b.t).norm() < 5.0;
}
}  // namespace

std::vector<Hypothesis> featureHypotheses(
	const std::vector<LevelFeatures>& ref, const std::vector<LevelFeatures>& other,
	const FeatureParams& p, std::optional<double> expected_scale, double scale_tolerance)
{
	cv::BFMatcher matcher(cv::NORM_L2);
	std::vector<Hypothesis> found;
	for (size_t i = 0; i < ref.size(); ++i)
		for (size_t j = 0; j < other.size(); ++j)
		{
			if (ref[i].descriptors.rows < 2 || other[j].descriptors.rows < 2) continue;
			std::vector<std::vector<cv::DMatch>> knn;
			matcher.knnMatch(other[j].descriptors, ref[i].descriptors, knn, 2);
			std::vector<cv::Point2f> from, to;
			for (const auto& m : knn)
				if (m.size() == 2 && m[0].distance < p.ratio_test * m[1].distance)
				{
					from.push_back(other[j].points[m[0].queryIdx]);
					to.push_back(ref[i].points[m[0].trainIdx]);
				}
			const double thr = p.ransac_threshold / ref[i].scale;
			for (int k = 0; k < p.hypotheses_per_level_pair; ++k)
			{
				std::vector<uchar> mask;
				auto s = ransacSimilarity(
					from, to, thr, p.ransac_iterations, p.ransac_confidence, p.min_inliers, mask);
				if (!s) break;
				found.push_back({*s, cv::countNonZero(mask), static_cast<int>(from.size()),
								 static_cast<int>(i), static_cast<int>(j)});
				// Re-run on the matches this model did not explain: a second
				// building wing, or a symmetric twin, gets its own chance.
				std::vector<cv::Point2f> f2, t2;
				for (size_t q = 0; q < mask.size(); ++q)
					if (!mask[q]) f2.push_back(from[q]), t2.push_back(to[q]);
				from.swap(f2);
				to.swap(t2);
			}
		}
	if (expected_scale)
		found.erase(
			std::remove_if(found.begin(), found.end(), [&](const Hypothesis& h) {
				return std::abs(std::log(h.other_to_ref.scale / *expected_scale)) >
					std::log1p(scale_tolerance);
			}),
			found.end());
	std::stable_sort(found.begin(), found.end(), [](const Hypothesis& a, const Hypothesis& b) {
		return a.inliers > b.inliers;
	});
	std::vector<Hypothesis> unique;
	for (const auto& h : found)
		if (std::none_of(unique.begin(), unique.end(), [&](const Hypothesis& u) {
				return sameHypothesis(u.other_to_ref, h.other_to_ref);
			}))
			unique.push_back(h);
	return unique;
}

}  // namespace multires_map_merge
