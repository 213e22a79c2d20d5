#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

namespace multires_map_merge
{
bool sameExtraction(const FeatureParams& a, const FeatureParams& b)
{
	return a.pyramid_levels == b.pyramid_levels && a.min_level_size == b.min_level_size &&
		a.max_level_cells == b.max_level_cells && a.levels_by_longer_side == b.levels_by_longer_side &&
		a.level_frame == b.level_frame && a.sift_contrast_threshold == b.sift_contrast_threshold &&
		a.sift_edge_threshold == b.sift_edge_threshold && a.unknown_as_free == b.unknown_as_free;
}

std::vector<LevelFeatures> extractPyramidFeatures(const cv::Mat& classes, const FeatureParams& p)
{
	auto sift = cv::SIFT::create(0, 3, p.sift_contrast_threshold, p.sift_edge_threshold);
	std::vector<LevelFeatures> levels;
	// What max_level_cells bounds (the cell count, or the longer side
	// squared) and what min_level_size bounds (the shorter side, or the longer).
	const double cells = p.levels_by_longer_side ? std::pow(std::max(classes.cols, classes.rows), 2.0)
												 : double(classes.cols) * classes.rows;
	const double side = p.levels_by_longer_side ? std::max(classes.cols, classes.rows)
												: std::min(classes.cols, classes.rows);
	const int frame = p.level_frame;
	for (int l = 0; int(levels.size()) < p.pyramid_levels; ++l)
	{
		const double f = std::ldexp(1.0, -l);
		if (cells * f * f > p.max_level_cells) continue;
		if (side * f < p.min_level_size && !levels.empty()) break;
		cv::Mat img = l == 0 ? classes.clone() : resampleClasses(classes, f);
		if (frame > 0) cv::copyMakeBorder(img, img, frame, frame, frame, frame, cv::BORDER_CONSTANT, kUnknown);
		if (p.unknown_as_free) img.setTo(kFree, img == kUnknown);
		LevelFeatures lf;
		lf.scale = f;
		std::vector<cv::KeyPoint> kps;
		sift->detectAndCompute(img, cv::noArray(), kps, lf.descriptors);
		for (const auto& k : kps)  // level pixel centre → full-resolution cell
			lf.points.emplace_back(
				static_cast<float>((k.pt.x - frame + 0.5) / f - 0.5),
				static_cast<float>((k.pt.y - frame + 0.5) / f - 0.5));
		levels.push_back(std::move(lf));
	}
	return levels;
}

std::optional<Similarity2D> ransacSimilarity(
	const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to, double threshold,
	int iterations, double confidence, int min_inliers, std::vector<uchar>& inlier_mask, double min_scale,
	double max_scale)
{
	inlier_mask.assign(from.size(), 0);
	const size_t n = from.size();
	if (n < 2 || n != to.size()) return std::nullopt;
	const double thr2 = threshold * threshold;
	auto countInliers = [&](const Similarity2D& m, std::vector<uchar>* mask) {
		const Eigen::Matrix2d a = m.linear();
		int count = 0;
		for (size_t k = 0; k < n; ++k)
		{
			const Eigen::Vector2d q = a * Eigen::Vector2d(from[k].x, from[k].y) + m.t;
			const bool in = (q - Eigen::Vector2d(to[k].x, to[k].y)).squaredNorm() <= thr2;
			count += in;
			if (mask) (*mask)[k] = in;
		}
		return count;
	};
	std::mt19937 rng(12345);  // the same maps give the same hypotheses
	std::uniform_int_distribution<size_t> pick(0, n - 1);
	std::optional<Similarity2D> best;
	int best_count = 0;
	long needed = iterations;
	for (long it = 0; it < needed; ++it)
	{
		const size_t a = pick(rng), b = pick(rng);
		if (a == b) continue;
		const Eigen::Vector2d df(from[b].x - from[a].x, from[b].y - from[a].y);
		const Eigen::Vector2d dt(to[b].x - to[a].x, to[b].y - to[a].y);
		if (df.norm() < 1e-6 || dt.norm() < 1e-6) continue;
		const double scale = dt.norm() / df.norm();
		if (scale < min_scale || scale > max_scale) continue;
		Similarity2D m(scale, std::atan2(dt.y(), dt.x()) - std::atan2(df.y(), df.x()), {0, 0});
		m.t = Eigen::Vector2d(to[a].x, to[a].y) - m.linear() * Eigen::Vector2d(from[a].x, from[a].y);
		const int count = countInliers(m, nullptr);
		if (count <= best_count) continue;
		best_count = count, best = m;
		// Adaptive stop: enough draws to see an all-inlier pair with `confidence`.
		const double w = double(count) / n;
		const double miss = 1 - w * w;
		if (miss <= 0)
			needed = it + 1;
		else
			needed = std::min<long>(iterations, static_cast<long>(std::ceil(std::log(1 - confidence) / std::log(miss))));
	}
	if (!best || best_count < std::max(2, min_inliers)) return std::nullopt;
	// Re-fit on the inliers (least squares), keep it if it explains as much.
	std::vector<uchar> mask(n, 0);
	countInliers(*best, &mask);
	Eigen::Matrix2Xd src(2, best_count), dst(2, best_count);
	for (size_t k = 0, c = 0; k < n; ++k)
		if (mask[k])
		{
			src.col(c) = Eigen::Vector2d(from[k].x, from[k].y);
			dst.col(c) = Eigen::Vector2d(to[k].x, to[k].y);
			++c;
		}
	const Similarity2D refit = Similarity2D::fromMatrix(Eigen::Matrix3d(Eigen::umeyama(src, dst, true)));
	std::vector<uchar> refit_mask(n, 0);
	if (refit.isFinite() && refit.scale >= min_scale && refit.scale <= max_scale &&
		countInliers(refit, &refit_mask) >= best_count)
		best = refit, mask.swap(refit_mask);
	inlier_mask = mask;
	if (cv::countNonZero(inlier_mask) < min_inliers) return std::nullopt;
	return best;
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

std::vector<LevelMatches> featureMatches(
	const std::vector<LevelFeatures>& ref, const std::vector<LevelFeatures>& other, const FeatureParams& p)
{
	cv::BFMatcher matcher(cv::NORM_L2);
	std::vector<LevelMatches> all;
	for (size_t i = 0; i < ref.size(); ++i)
		for (size_t j = 0; j < other.size(); ++j)
		{
			LevelMatches lm;
			lm.level_scale = other[j].scale / ref[i].scale;
			lm.tolerance = p.ransac_threshold / ref[i].scale;
			lm.ref_level = static_cast<int>(i), lm.other_level = static_cast<int>(j);
			if (ref[i].descriptors.rows >= 2 && other[j].descriptors.rows >= 2)
			{
				std::vector<std::vector<cv::DMatch>> knn;
				matcher.knnMatch(other[j].descriptors, ref[i].descriptors, knn, 2);
				for (const auto& m : knn)
					if (m.size() == 2 && m[0].distance < p.ratio_test * m[1].distance)
					{
						lm.from.push_back(other[j].points[m[0].queryIdx]);
						lm.to.push_back(ref[i].points[m[0].trainIdx]);
					}
			}
			all.push_back(std::move(lm));
		}
	return all;
}

size_t agreeingMatches(const std::vector<LevelMatches>& matches, const Similarity2D& other_to_ref)
{
	size_t n = 0;
	for (const auto& lm : matches)
	{
		if (std::abs(std::log(other_to_ref.scale / lm.level_scale)) > 0.5 * std::log(2.0)) continue;
		for (size_t k = 0; k < lm.from.size(); ++k)
			if ((other_to_ref.apply(Eigen::Vector2d(lm.from[k].x, lm.from[k].y)) -
				 Eigen::Vector2d(lm.to[k].x, lm.to[k].y))
					.norm() <= lm.tolerance)
				++n;
	}
	return n;
}

std::vector<Hypothesis> featureHypotheses(
	const std::vector<LevelFeatures>& ref, const std::vector<LevelFeatures>& other,
	const FeatureParams& p, std::optional<double> expected_scale, double scale_tolerance)
{
	return featureHypotheses(featureMatches(ref, other, p), p, expected_scale, scale_tolerance);
}

std::vector<Hypothesis> featureHypotheses(
	const std::vector<LevelMatches>& matches, const FeatureParams& p, std::optional<double> expected_scale,
	double scale_tolerance)
{
	std::vector<Hypothesis> found;
	for (const LevelMatches& lm : matches)
	{
		std::vector<cv::Point2f> from = lm.from, to = lm.to;  // re-run on what each model leaves
		// Levels of equal cell size match best: this pair looks for a
		// scale near other level / ref level, within a factor of 2 (the
		// neighbouring level pairs cover the rest).
		for (int k = 0; k < p.hypotheses_per_level_pair; ++k)
		{
			std::vector<uchar> mask;
			auto s = ransacSimilarity(
				from, to, lm.tolerance, p.ransac_iterations, p.ransac_confidence, p.min_inliers, mask,
				lm.level_scale / 2, lm.level_scale * 2);
			if (!s) break;
			found.push_back({*s, cv::countNonZero(mask), static_cast<int>(from.size()), lm.ref_level, lm.other_level});
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
