// Unit tests of the stages before TsICP: class images, edges, RANSAC,
// feature hypotheses, map agreement.
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapAgreement.h>
#include <multires_map_merge/StructureHypotheses.h>

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

TEST(FeatureHypotheses, LargeLevelsAreSkippedAndThePyramidGoesDeeper)
{
	const cv::Mat fine = realClasses(0.02);
	FeatureParams p;
	p.pyramid_levels = 3;
	p.min_level_size = 16;
	p.max_level_cells = double(fine.total()) / 4;  // level 0 is too large, level 1 just fits
	const auto levels = extractPyramidFeatures(fine, p);
	ASSERT_EQ(levels.size(), 3u);
	EXPECT_DOUBLE_EQ(levels[0].scale, 0.5);
	EXPECT_DOUBLE_EQ(levels[2].scale, 0.125);
	for (const auto& l : levels) EXPECT_GT(l.descriptors.rows, 10);
	// Keypoints are still in full-resolution cells: all inside the map.
	for (const auto& q : levels[0].points)
		EXPECT_TRUE(q.x > -1 && q.y > -1 && q.x < fine.cols && q.y < fine.rows) << q;
}

namespace
{
// A real pair at 5 and 10 cm, the second turned and shifted.
GroundTruthPair malaga5and10()
{
	const ScanSequence s = loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	PairSpec spec;
	spec.ref_resolution = 0.05;
	spec.other_resolution = 0.1;
	spec.other_frame = mrpt::poses::CPose2D(3, 1, 1.0);
	return makeGroundTruthPair(s, spec);
}
}  // namespace

TEST(MapAgreement, HighAtTruthLowWhenShifted)
{
	const auto pair = malaga5and10();
	const cv::Mat a = toClassImage(pair.ref), b = toClassImage(pair.other);
	const Similarity2D truth = pair.otherCellsToRefCells();
	const Agreement good = mapAgreement(a, b, truth);
	const Agreement bad = mapAgreement(a, b, Similarity2D(1, 0, {30, 0}).compose(truth));
	EXPECT_GT(good.consistency, 0.95);
	EXPECT_LT(bad.consistency, 0.8);
	EXPECT_GT(good.occupied_overlap, 1000u);
}

namespace
{
// The malaga pair's wall points and fields, judged under the truth moved by
// `move` (reference cells).
struct MalagaSupport
{
	GroundTruthPair pair = malaga5and10();
	cv::Mat a = toClassImage(pair.ref), b = toClassImage(pair.other);
	PointList ea = edgePoints(a), eb = edgePoints(b);
	OccupancyField fa = occupancyField(a), fb = occupancyField(b);
	Similarity2D truth = pair.otherCellsToRefCells();
	TwoWaySupport at(const Similarity2D& move = Similarity2D()) const
	{
		return twoWaySupport(ea, fa, eb, fb, move.compose(truth), 3.0);
	}
};
}  // namespace

TEST(MapAgreement, TolerantConsistencyIsAPeakAboveChance)
{
	// At the truth the walls agree and beat the same transform moved far
	// away; moved far away they do not.
	const MalagaSupport m;
	const TwoWaySupport at_truth = m.at();
	const Chance chance = chanceSupport(m.ea, m.fa, m.eb, m.fb, m.truth, 3.0, 12.0, 8.0);
	EXPECT_GT(at_truth.consistency(), 0.9);
	EXPECT_GT(at_truth.consistency(), chance.consistency + 0.1);
	EXPECT_GT(at_truth.judged(), 500u);
	// Bent walls (a 2-cell shift of the coarser map) still agree.
	EXPECT_GT(m.at(Similarity2D(1, 0, {4, 0})).consistency(), 0.8);
	EXPECT_LT(m.at(Similarity2D(1, 0, {60, 0})).consistency(), at_truth.consistency() - 0.15);
}

TEST(FeatureHypotheses, MatchesAgreeUnderTheTruthNotElsewhere)
{
	// The decision's feature evidence (agreeingMatches): SIFT matches of the
	// real 5 cm / 10 cm pair that the truth takes onto each other (22 here);
	// turned by 45° about the map's centre or slid 30 coarse cells, none.
	const MalagaSupport m;
	FeatureParams p;
	const auto matches = featureMatches(extractPyramidFeatures(m.a, p), extractPyramidFeatures(m.b, p), p);
	const size_t at_truth = agreeingMatches(matches, m.truth);
	EXPECT_GT(at_truth, 15u);
	const Eigen::Vector2d centre(m.a.cols / 2.0, m.a.rows / 2.0);
	Similarity2D turn(1, M_PI / 4, {0, 0});
	turn.t = centre - turn.apply(centre);
	EXPECT_LE(agreeingMatches(matches, turn.compose(m.truth)), 2u);
	EXPECT_LE(agreeingMatches(matches, Similarity2D(1, 0, {60, 0}).compose(m.truth)), 2u);
	// A transform at a scale no level pair matches (10x) takes none.
	EXPECT_EQ(agreeingMatches(matches, Similarity2D(10, 0, {0, 0})), 0u);
}

TEST(MapAgreement, WallNormalsOfEachWallCell)
{
	// A horizontal wall (normal along y, 90°) and a vertical one (normal
	// along x, 0°) meeting it in a T: each wall cell has its normal, the
	// junction none, free space none.
	cv::Mat classes(60, 60, CV_8U, cv::Scalar(kFree));
	classes.row(10).setTo(kOccupied);
	classes(cv::Rect(45, 10, 1, 50)).setTo(kOccupied);
	const OccupancyField f = occupancyField(classes);
	EXPECT_NEAR(f.wall_normal_deg.at<uint8_t>(10, 20), 90, 1);
	const int vertical = f.wall_normal_deg.at<uint8_t>(40, 45);
	EXPECT_TRUE(vertical <= 1 || vertical >= 179) << vertical;
	EXPECT_EQ(f.wall_normal_deg.at<uint8_t>(10, 45), kNoDirection) << "a T junction runs no one way";
	EXPECT_EQ(f.wall_normal_deg.at<uint8_t>(30, 20), kNoDirection) << "free space has no wall";
}

TEST(MapAgreement, AFloorPlanJudgesNearItsWallsAndItsOutsideNotItsRooms)
{
	// A plan: one room (walls on the rectangle 20..79), white inside, the
	// outside left unknown as map_server reads a plan's grey.
	cv::Mat plan(100, 100, CV_8U, cv::Scalar(kUnknown));
	plan(cv::Rect(20, 20, 60, 60)).setTo(kOccupied);
	plan(cv::Rect(21, 21, 58, 58)).setTo(kFree);
	const OccupancyField f = occupancyField(plan, MapKind::FloorPlan);
	auto judge = [&](double x, double y) {
		return tolerantSupport({Eigen::Vector2d(x, y)}, f, Similarity2D(), f, 3.0, false);
	};
	const Support on_wall = judge(20, 50), beside = judge(18, 50), furniture = judge(50, 50), outside = judge(10, 50);
	EXPECT_EQ(on_wall.supported, 1u);
	EXPECT_EQ(beside.supported, 1u) << "within the tolerance of its wall: a wall drawn thicker";
	EXPECT_EQ(furniture.judged, 0u) << "the plan's white far from its walls is drawn, not seen";
	EXPECT_EQ(outside.judged, 1u);
	EXPECT_EQ(outside.conflicts, 1u) << "a wall where the plan has no building conflicts";
	// A plan draws its whole building: beyond its image is outside too.
	const Support beyond = judge(-30, 50), far_beyond = judge(500, -400);
	EXPECT_EQ(beyond.judged, 1u);
	EXPECT_EQ(beyond.conflicts, 1u) << "a wall beyond the plan's image, where it has no building";
	EXPECT_EQ(far_beyond.conflicts, 1u);
	const OccupancyField robot = occupancyField(plan);
	EXPECT_EQ(tolerantSupport({Eigen::Vector2d(-30, 50)}, robot, Similarity2D(), robot, 3.0, false).judged, 0u)
		<< "a robot's map has seen nothing beyond its grid";
	// Its tiles' shifts (the bent consistency) judge beyond it too; a wild
	// transform's points, too far to bin, are dropped, not a crash.
	PointList wall;
	for (int y = 30; y < 70; ++y) wall.emplace_back(10, y);
	const ShiftField bent = shiftField(wall, f, Similarity2D(), f, 3.0, 20, 4, 1);
	EXPECT_EQ(bent.bent.judged, wall.size());
	EXPECT_EQ(bent.bent.conflicts, wall.size());
	const ShiftField wild = shiftField(wall, f, Similarity2D(1, 0, {1e15, -1e15}), f, 3.0, 20, 4, 1);
	EXPECT_EQ(wild.bent.judged, 0u);
}

TEST(MapAgreement, APlanCroppedToItsBuildingJudgesAsAWiderOne)
{
	// The same plan twice: with 20 cells of outside around its building,
	// and cropped to the building's walls. Points on, beside and beyond its
	// walls are judged alike in both (the cropped one shifted by 20).
	cv::Mat wide(100, 100, CV_8U, cv::Scalar(kUnknown));
	wide(cv::Rect(20, 20, 60, 60)).setTo(kOccupied);
	wide(cv::Rect(21, 21, 58, 58)).setTo(kFree);
	const cv::Mat tight = wide(cv::Rect(20, 20, 60, 60)).clone();
	const OccupancyField fw = occupancyField(wide, MapKind::FloorPlan), ft = occupancyField(tight, MapKind::FloorPlan);
	for (const Eigen::Vector2d& p : {Eigen::Vector2d(20, 50), Eigen::Vector2d(18, 50), Eigen::Vector2d(16, 50),
									Eigen::Vector2d(10, 50), Eigen::Vector2d(5, 5), Eigen::Vector2d(95, 60),
									Eigen::Vector2d(82, 82)})
	{
		const Support sw = tolerantSupport({p}, fw, Similarity2D(), fw, 3.0, false);
		const Support st = tolerantSupport({p}, ft, Similarity2D(1, 0, {-20, -20}), ft, 3.0, false);
		EXPECT_EQ(sw.judged, st.judged) << p.transpose();
		EXPECT_EQ(sw.supported, st.supported) << p.transpose();
		EXPECT_EQ(sw.conflicts, st.conflicts) << p.transpose();
	}
}

TEST(MapAgreement, WallsRunAlikeAtTruthNotWhenTurned)
{
	// At the truth (and with walls bent by two cells) the walls lying near
	// the other map's walls lie near walls running the same way; turned by
	// 45° about the map's centre, the walls that still lie near walls cross
	// them.
	const MalagaSupport m;
	const TwoWaySupport at_truth = m.at();
	EXPECT_GT(at_truth.wallAlignment(), 0.8);
	EXPECT_GT(at_truth.other_in_ref.directed, 300u);
	EXPECT_GT(m.at(Similarity2D(1, 0, {4, 0})).wallAlignment(), 0.8);
	const Eigen::Vector2d centre(m.a.cols / 2.0, m.a.rows / 2.0);
	Similarity2D turn(1, M_PI / 4, {0, 0});
	turn.t = centre - turn.apply(centre);
	const TwoWaySupport turned = m.at(turn);
	EXPECT_LT(turned.wallAlignment(), 0.5);
	EXPECT_GT(turned.other_in_ref.directed + turned.ref_in_other.directed, 50u) << "turned walls still lie near walls";
}

namespace
{
/** The malaga pair with the other map bent smoothly, as SLAM bends walls:
 * each cell moved by a sine wave of up to `amplitude` cells across the map;
 * judged (verify_tolerance 3: 4 cells of the finer map, 2 of its own) under
 * the truth or wrong transforms. */
struct BentMalaga : MalagaSupport
{
	PointList bent_edges;
	OccupancyField bent_field;
	explicit BentMalaga(double amplitude)
	{
		cv::Mat map_x(b.size(), CV_32F), map_y(b.size(), CV_32F);
		for (int y = 0; y < b.rows; ++y)
			for (int x = 0; x < b.cols; ++x)
			{
				map_x.at<float>(y, x) = float(x + amplitude * std::sin(2 * M_PI * y / b.rows));
				map_y.at<float>(y, x) = float(y + amplitude * std::sin(2 * M_PI * x / b.cols));
			}
		cv::Mat bent;
		cv::remap(b, bent, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(kUnknown));
		bent_edges = edgePoints(bent);
		bent_field = occupancyField(bent);
	}
	TwoWayShiftField shifts(const Similarity2D& t) const
	{
		return twoWayShiftField(ea, fa, bent_edges, bent_field, t, 3.0);
	}
	double rigidConsistency(const Similarity2D& t) const
	{
		return twoWaySupport(ea, fa, bent_edges, bent_field, t, 3.0).consistency();
	}
	/** Turned by 45° about the map's centre: walls still lie near walls
	 * here and there. */
	Similarity2D turned() const
	{
		const Eigen::Vector2d centre(a.cols / 2.0, a.rows / 2.0);
		Similarity2D turn(1, M_PI / 4, {0, 0});
		turn.t = centre - turn.apply(centre);
		return turn.compose(truth);
	}
	/** Slid 30 coarse cells: along corridors, some regions still fit. */
	Similarity2D slid() const { return Similarity2D(1, 0, {60, 0}).compose(truth); }
};
}  // namespace

TEST(MapAgreement, RegionsShiftAlikeUnderTheTruthNotWhenTurned)
{
	// Bent by up to 4 cells: under the truth its regions fit best after
	// shifts that vary smoothly; turned or slid, each region by a shift of
	// its own.
	const BentMalaga m(4.0);
	const TwoWayShiftField at_truth = m.shifts(m.truth);
	EXPECT_GT(at_truth.coherence(), 0.6);
	EXPECT_GT(at_truth.other_in_ref.neighbour_pairs + at_truth.ref_in_other.neighbour_pairs, 20u);
	EXPECT_GT(m.rigidConsistency(m.truth), m.rigidConsistency(m.turned()) + 0.2)
		<< "bent, yet the walls lie nearer each other than turned";
	EXPECT_LT(m.shifts(m.turned()).coherence(), 0.3);
	EXPECT_LT(m.shifts(m.slid()).coherence(), at_truth.coherence() - 0.3);
}

TEST(MapAgreement, TakingOutASmoothBendRestoresTheWallsUnderTheTruthOnly)
{
	// Bent by up to 7 cells, beyond the tolerance (2): under the truth many
	// walls miss the other map's, yet each region's neighbours predict the
	// shift that puts it back (the bent consistency). A wrong transform's
	// regions fit by shifts of their own, which predict nothing.
	const BentMalaga m(7.0);
	const double truth_rigid = m.rigidConsistency(m.truth), truth_unbent = m.shifts(m.truth).bentConsistency();
	EXPECT_LT(truth_rigid, 0.65) << "the bend moves many walls beyond the tolerance";
	EXPECT_GT(truth_unbent, 0.85);
	EXPECT_GT(truth_unbent, truth_rigid + 0.25);
	const double turned = m.shifts(m.turned()).bentConsistency();
	EXPECT_LT(turned, m.rigidConsistency(m.turned()) + 0.05) << "turned: nothing to take out";
	EXPECT_LT(turned, truth_unbent - 0.4);
	EXPECT_LT(m.shifts(m.slid()).bentConsistency(), truth_unbent - 0.35);
}

TEST(MapAgreement, TheBendBalancedRefitBringsAnOffTransformBackToTheTruth)
{
	// Bent by up to 4 cells and placed 3 % too large and 5 cells off: each
	// region's best shift points back to where the truth puts it, and the
	// similarity fitted to those shifts (a vote per region) is nearer the
	// truth over the whole map; refit again, nearer still, to about the
	// bend's own spread.
	const BentMalaga m(4.0);
	const Eigen::Vector2d centre(m.a.cols / 2.0, m.a.rows / 2.0);
	Similarity2D off(1.03, 0, {0, 0});
	off.t = centre - off.apply(centre) + Eigen::Vector2d(5, -4);
	const Similarity2D start = off.compose(m.truth);
	auto meanOffTruth = [&](const Similarity2D& t) {
		double sum = 0;
		for (const auto& p : m.bent_edges) sum += (t.apply(p) - m.truth.apply(p)).norm();
		return sum / double(m.bent_edges.size());
	};
	Similarity2D refit = start;
	std::vector<double> off_truth{meanOffTruth(start)};
	for (int i = 0; i < 3; ++i)
	{
		refit = bendBalanced(m.shifts(refit), refit);
		off_truth.push_back(meanOffTruth(refit));
	}
	const std::string history = ::testing::PrintToString(off_truth);
	EXPECT_GT(off_truth[0], 8.0);
	EXPECT_LT(off_truth[1], 0.5 * off_truth[0]) << history;
	// The bend itself moves the walls by up to 4 coarse cells: no similarity
	// is nearer the truth than about a coarse cell everywhere.
	EXPECT_LT(off_truth[3], 1.5 * m.truth.scale) << "within a coarse cell and a half of the truth: " << history;
	EXPECT_NEAR(refit.scale, m.truth.scale, 0.01 * m.truth.scale);
}

TEST(StructureHypotheses, FindATurnedRescaledRealMapWithoutFeatures)
{
	// The same real map at 5 and 8 cm (rendered from the scans), the coarse
	// one turned by 117° and moved: the wall directions give the turn, the
	// wall correlation the translation, the scale ladder the scale.
	const cv::Mat fine = realClasses(0.05), coarse0 = realClasses(0.08);
	const Similarity2D turn(1.0, 117 * M_PI / 180, {700, 200});
	const cv::Mat coarse = warpClasses(coarse0, turn, cv::Size(900, 900));
	EXPECT_NEAR(
		std::abs(wrapToPi(4 * (dominantWallDirection(coarse) - dominantWallDirection(fine) - turn.yaw))) / 4, 0,
		3 * M_PI / 180);
	const auto hyps = structureHypotheses(fine, coarse);
	ASSERT_FALSE(hyps.empty());
	bool found = false;
	for (const auto& h : hyps)
		found |= std::abs(std::log(h.other_to_ref.scale / 1.6)) < 0.12 &&
			std::abs(wrapToPi(h.other_to_ref.yaw + turn.yaw)) < 4 * M_PI / 180;
	EXPECT_TRUE(found) << "no hypothesis near scale 1.6, yaw -117°";
}

TEST(StructureHypotheses, PlaceAMapMovedWithinUnexploredMargin)
{
	// A map moved deep into a larger canvas of unknown cells (unexplored
	// margin) comes back to the right cells of the whole map, to a few cells
	// (one working pixel of a map this size is about four cells).
	const cv::Mat ref = realClasses(0.05);
	const Similarity2D moved(1.0, 0.0, {310, 170});
	const cv::Mat other = warpClasses(ref, moved, cv::Size(ref.cols + 400, ref.rows + 300));
	const auto hyps = structureHypotheses(ref, other);
	ASSERT_FALSE(hyps.empty());
	const Similarity2D truth = moved.inverse();  // other's cells → ref's
	const Similarity2D& best = hyps.front().other_to_ref;
	EXPECT_NEAR(best.scale, 1.0, 0.03);
	EXPECT_NEAR(wrapToPi(best.yaw), 0.0, 2 * M_PI / 180);
	for (const Eigen::Vector2d& corner : {Eigen::Vector2d(310, 170), Eigen::Vector2d(310 + ref.cols, 170 + ref.rows)})
		EXPECT_LT((best(corner) - truth(corner)).norm(), 12.0) << "corner " << corner.transpose();
}
