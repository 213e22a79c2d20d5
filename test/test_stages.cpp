// Unit tests of the stages before TsICP: class images, edges, RANSAC,
// feature hypotheses, map agreement.
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapAgreement.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <random>

#include "test_data.h"

using namespace multires_map_merge;

TEST(GridImage, ClassifiesWithTheStatedThresholds)
{
	EXPECT_EQ(classify(0.9f), kOccupied);
	EXPECT_EQ(classify(0.51f), kOccupied);
	EXPECT_EQ(classify(0.5f), kUnknown);
	EXPECT_EQ(classify(0.49f), kFree);
	mrpt::maps::COccupancyGridMap2D g(0, 1, 0, 1, 0.1f);
	g.setCell(2, 3, 0.1f);  // MRPT stores P(free): 0.1 → occupied
	g.setCell(4, 1, 0.9f);
	const cv::Mat img = toClassImage(g);
	EXPECT_EQ(img.at<uint8_t>(3, 2), kOccupied);  // row = cy: no flip
	EXPECT_EQ(img.at<uint8_t>(1, 4), kFree);
	EXPECT_EQ(img.at<uint8_t>(0, 0), kUnknown);
}

TEST(GridImage, ResamplingKeepsThinWallsAndFreeSpace)
{
	cv::Mat img(8, 8, CV_8UC1, cv::Scalar(kUnknown));
	img(cv::Rect(0, 0, 8, 4)).setTo(kFree);
	img.row(2).setTo(kOccupied);  // a one-cell wall inside free space
	const cv::Mat half = resampleClasses(img, 0.5);
	ASSERT_EQ(half.size(), cv::Size(4, 4));
	for (int c = 0; c < 4; ++c)
	{
		EXPECT_EQ(half.at<uint8_t>(0, c), kFree);
		EXPECT_EQ(half.at<uint8_t>(1, c), kOccupied);  // occupied wins
		EXPECT_EQ(half.at<uint8_t>(3, c), kUnknown);
	}
}

TEST(EdgePoints, OnlyOccupiedCellsTouchingFreeSpace)
{
	cv::Mat img(5, 6, CV_8UC1, cv::Scalar(kUnknown));
	img(cv::Rect(0, 0, 6, 2)).setTo(kFree);
	img.row(2).setTo(kOccupied);  // wall between free (rows 0-1) and unknown
	img.row(3).setTo(kOccupied);  // thick part: not an edge
	const PointList e = edgePoints(img);
	ASSERT_EQ(e.size(), 6u);
	for (const auto& p : e) EXPECT_EQ(p.y(), 2.0);
}

TEST(Ransac, RecoversASimilarityAmongSeventyPercentOutliers)
{
	std::mt19937 rng(7);
	std::uniform_real_distribution<float> u(0, 500);
	std::normal_distribution<float> noise(0, 0.3f);
	const Similarity2D truth(0.2, 2.0, {310, 45});  // 5x scale ratio, 115°
	std::vector<cv::Point2f> from, to;
	for (int i = 0; i < 100; ++i)
	{
		const Eigen::Vector2d p(u(rng), u(rng));
		from.emplace_back(p.x(), p.y());
		if (i < 30)
		{
			const Eigen::Vector2d q = truth(p);
			to.emplace_back(q.x() + noise(rng), q.y() + noise(rng));
		}
		else
			to.emplace_back(u(rng), u(rng));
	}
	std::vector<uchar> mask;
	const auto s = ransacSimilarity(from, to, 2.0, 5000, 0.999, 5, mask);
	ASSERT_TRUE(s.has_value());
	EXPECT_NEAR(s->scale, truth.scale, 0.002);
	EXPECT_NEAR(wrapToPi(s->yaw - truth.yaw), 0, 0.01);
	EXPECT_GE(cv::countNonZero(mask), 28);
	EXPECT_LE(cv::countNonZero(mask), 33);
}

TEST(Ransac, NoModelFromPureNoise)
{
	std::mt19937 rng(3);
	std::uniform_real_distribution<float> u(0, 500);
	std::vector<cv::Point2f> from, to;
	for (int i = 0; i < 60; ++i) from.emplace_back(u(rng), u(rng)), to.emplace_back(u(rng), u(rng));
	std::vector<uchar> mask;
	EXPECT_FALSE(ransacSimilarity(from, to, 1.0, 3000, 0.999, 8, mask).has_value());
}

namespace
{
cv::Mat realClasses(double res)
{
	static const ScanSequence s =
		loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	return toClassImage(renderGrid(s, 0, s.size(), res));
}
cv::Mat warpClasses(const cv::Mat& img, const Similarity2D& t, cv::Size size)
{
	cv::Mat m(2, 3, CV_64F), out;
	const Eigen::Matrix3d e = t.matrix();
	for (int r = 0; r < 2; ++r)
		for (int c = 0; c < 3; ++c) m.at<double>(r, c) = e(r, c);
	cv::warpAffine(img, out, m, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(kUnknown));
	return out;
}
}  // namespace

TEST(FeatureHypotheses, PyramidFindsAFiveTimesScaleOnARealMap)
{
	// The same real map seen at 2 cm and at 10 cm (rendered from the scans,
	// not resampled), the coarse one rotated by 140° in its own frame.
	const cv::Mat fine = realClasses(0.02), coarse0 = realClasses(0.10);
	const Similarity2D rot(1.0, 140 * M_PI / 180, {450, 150});
	const cv::Mat coarse = warpClasses(coarse0, rot, cv::Size(900, 900));
	FeatureParams p;
	const auto hyps = featureHypotheses(extractPyramidFeatures(fine, p), extractPyramidFeatures(coarse, p), p);
	ASSERT_FALSE(hyps.empty());
	// coarse cell → fine cell: undo the rotation, then 5x (cell centres of
	// the two renderings differ by their origins, hence the loose t check).
	const Similarity2D h = hyps.front().other_to_ref;
	EXPECT_NEAR(h.scale, 5.0, 0.1);
	EXPECT_NEAR(wrapToPi(h.yaw + rot.yaw), 0, 2 * M_PI / 180);
	EXPECT_GT(hyps.front().inliers, 10);
}

TEST(MapAgreement, HighAtTruthLowWhenShifted)
{
	const ScanSequence s = loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	PairSpec spec;
	spec.ref_resolution = 0.05;
	spec.other_resolution = 0.1;
	spec.other_frame = mrpt::poses::CPose2D(3, 1, 1.0);
	const auto pair = makeGroundTruthPair(s, spec);
	const cv::Mat a = toClassImage(pair.ref), b = toClassImage(pair.other);
	const Similarity2D truth = pair.otherCellsToRefCells();
	const Agreement good = mapAgreement(a, b, truth);
	const Agreement bad = mapAgreement(a, b, Similarity2D(1, 0, {30, 0}).compose(truth));
	EXPECT_GT(good.consistency, 0.95);
	EXPECT_LT(bad.consistency, 0.8);
	EXPECT_GT(good.occupied_overlap, 1000u);
}
