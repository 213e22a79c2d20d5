// TsICP on real edge points (Debian's malaga simplemap).
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/TsICP.h>

#include <gtest/gtest.h>

#include <algorithm>

#include "test_data.h"

using namespace multires_map_merge;

namespace
{
const ScanSequence& malaga()
{
	static const ScanSequence s = loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	return s;
}
PointList edgesOf(const mrpt::maps::COccupancyGridMap2D& g) { return edgePoints(toClassImage(g)); }
}  // namespace

TEST(ChooseOverlap, PicksTheInlierFraction)
{
	// 60 pairs at ~0.1 cell, 40 far away: ψ must keep exactly the 60.
	std::vector<double> d;
	for (int i = 0; i < 60; ++i) d.push_back(0.01 + 1e-4 * i);
	for (int i = 0; i < 40; ++i) d.push_back(25.0 + i);
	const Trimming t = chooseOverlap(d, TsICPParams{});
	EXPECT_EQ(t.count, 60u);
	EXPECT_NEAR(t.overlap, 0.6, 1e-12);
}

TEST(ChooseOverlap, NeverBelowXiMin)
{
	std::vector<double> d(100, 100.0);
	d[0] = 0;  // one perfect pair must not win a 1 % overlap
	TsICPParams p;
	const Trimming t = chooseOverlap(d, p);
	EXPECT_GE(t.overlap, p.xi_min);
}

TEST(TsICP, ObjectiveNeverIncreasesOnARealMultiResolutionPair)
{
	PairSpec spec;
	spec.ref_resolution = 0.05;
	spec.other_resolution = 0.08;
	spec.other_frame = mrpt::poses::CPose2D(2.0, -1.0, 0.6);
	const auto pair = makeGroundTruthPair(malaga(), spec);
	const Similarity2D truth = pair.otherCellsToRefCells();
	// Start 4° and 4 % off, 6 cells away: the paper's basin.
	const Similarity2D start(truth.scale * 1.04, truth.yaw + 4 * M_PI / 180, truth.t + Eigen::Vector2d(6, -4));
	const TsICPResult r = runTsICP(edgesOf(pair.ref), edgesOf(pair.other), start);
	ASSERT_GE(r.objective_history.size(), 3u);
	for (size_t k = 1; k < r.objective_history.size(); ++k)
		EXPECT_LE(r.objective_history[k], r.objective_history[k - 1]) << "iteration " << k;
	EXPECT_LT(r.objective, 0.5 * r.objective_history.front());
	EXPECT_NEAR(r.transform.scale / truth.scale, 1.0, 0.002);
	EXPECT_NEAR(wrapToPi(r.transform.yaw - truth.yaw), 0.0, 0.2 * M_PI / 180);
}

// A constructed partial overlap: the other map holds the left 60 % of the
// reference's edge points, seen through a known similarity.
struct PartialOverlap
{
	PointList ref, other;
	Similarity2D truth;  // other → ref
	double overlap;  // fraction of ref points the other map covers
};

static PartialOverlap makePartialOverlap()
{
	PartialOverlap c;
	c.ref = edgesOf(renderGrid(malaga(), 0, malaga().size(), 0.05));
	std::vector<double> xs;
	for (const auto& p : c.ref) xs.push_back(p.x());
	std::nth_element(xs.begin(), xs.begin() + xs.size() * 6 / 10, xs.end());
	const double cut = xs[xs.size() * 6 / 10];
	c.truth = Similarity2D(1.0 / 1.6, 0.4, {120, -35});
	const Similarity2D to_other = c.truth.inverse();
	size_t kept = 0;
	for (const auto& p : c.ref)
		if (p.x() < cut) c.other.push_back(to_other(p)), ++kept;
	c.overlap = static_cast<double>(kept) / c.ref.size();
	return c;
}

TEST(TsICP, PsiPicksTheTrueOverlap)
{
	const PartialOverlap c = makePartialOverlap();
	const Similarity2D start(c.truth.scale * 0.98, c.truth.yaw - 0.03, c.truth.t + Eigen::Vector2d(3, 3));
	const TsICPResult r = runTsICP(c.ref, c.other, start);
	// Reference points just past the cut lie a cell or two from the last
	// covered ones, so ξ may include a thin band beyond the true overlap.
	EXPECT_GE(r.overlap, c.overlap - 0.01);
	EXPECT_LE(r.overlap, c.overlap + 0.05);
	EXPECT_NEAR(r.transform.scale / c.truth.scale, 1.0, 1e-4);
	EXPECT_NEAR(wrapToPi(r.transform.yaw - c.truth.yaw), 0.0, 1e-4);
}

TEST(TsICP, ScaleDoesNotCollapseFromAnUnderestimate)
{
	// Forward (data → model) correspondences reward shrinking the data onto
	// a dense patch; backward ones make every reference point pay for it.
	const PartialOverlap c = makePartialOverlap();
	const Similarity2D start(c.truth.scale * 0.9, c.truth.yaw + 0.05, c.truth.t);
	const TsICPResult r = runTsICP(c.ref, c.other, start);
	EXPECT_NEAR(r.transform.scale / c.truth.scale, 1.0, 1e-3);
	EXPECT_TRUE(r.converged);
}

TEST(TsICP, RejectsDegenerateInput)
{
	const PointList two = {{0, 0}, {1, 1}}, many = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
	EXPECT_THROW(runTsICP(two, many, {}), std::invalid_argument);
	EXPECT_THROW(runTsICP(many, many, Similarity2D(0.0, 0, {0, 0})), std::invalid_argument);
	EXPECT_THROW(runTsICP(many, many, Similarity2D(NAN, 0, {0, 0})), std::invalid_argument);
}

TEST(ChooseOverlap, TiesGoToTheLargerOverlap)
{
	// Identical maps: every distance is zero, so the overlap is all of it.
	const Trimming t = chooseOverlap(std::vector<double>(50, 0.0), TsICPParams{});
	EXPECT_EQ(t.count, 50u);
	EXPECT_DOUBLE_EQ(t.objective, 0.0);
}

TEST(PointKDTree, AHintBoundsTheSearchAndChangesNoAnswerTiesIncluded)
{
	// TsICP bounds each reference point's search by its partner of the
	// iteration before; the answer must be the unbounded search's, also
	// where a query lies exactly between lattice points (ties).
	PairSpec spec;
	spec.ref_resolution = 0.05;
	spec.other_resolution = 0.08;
	const auto pair = makeGroundTruthPair(malaga(), spec);
	const PointList points = edgesOf(pair.other);
	ASSERT_GT(points.size(), 1000u);
	const PointKDTree tree(points);
	size_t ties = 0;
	for (size_t k = 0; k < points.size(); k += 7)
	{
		// Half a cell off (equidistant from two neighbours when both are
		// walls), and a few cells off; hints near and far.
		for (const Eigen::Vector2d& d : {Eigen::Vector2d(0.5, 0), Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(3.3, -2.1)})
		{
			const Eigen::Vector2d q = points[k] + d;
			const auto plain = tree.nearest(q);
			ties += std::count_if(points.begin(), points.end(), [&](const Eigen::Vector2d& p) {
				return (q - p).squaredNorm() == plain.second;
			}) > 1;
			for (const size_t hint : {k, plain.first, (k * 7919) % points.size()})
			{
				const auto hinted = tree.nearest(q, hint);
				ASSERT_EQ(hinted.first, plain.first) << "point " << k << " hint " << hint;
				ASSERT_EQ(hinted.second, plain.second);
			}
		}
	}
	EXPECT_GT(ties, 100u) << "the tie case must be exercised";
}
