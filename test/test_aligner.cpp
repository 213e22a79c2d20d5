// CScalingGridMapAligner on real data with exact ground truth.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/GroundTruthPair.h>

#include <gtest/gtest.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/poses/CPosePDFGaussian.h>

#include <map>
#include <thread>

#include "test_data.h"

using namespace multires_map_merge;

namespace
{
const ScanSequence& scansOf(const std::string& path)
{
	static std::map<std::string, ScanSequence> cache;
	auto it = cache.find(path);
	if (it == cache.end()) it = cache.emplace(path, loadScans(path)).first;
	return it->second;
}

struct Case
{
	const char* dataset;  // under /usr/share/mrpt/datasets
	double ref_res, other_res, yaw_deg;
	double split;  // ref renders [0, split), other [1 - split, 1)
};

std::ostream& operator<<(std::ostream& o, const Case& c)
{
	return o << c.dataset << " " << c.ref_res << "m vs " << c.other_res << "m, " << c.yaw_deg << " deg";
}

GroundTruthPair makePair(const ScanSequence& scans, const Case& c)
{
	PairSpec spec;
	spec.ref_resolution = c.ref_res;
	spec.other_resolution = c.other_res;
	spec.other_frame = mrpt::poses::CPose2D(1.5, -2.5, c.yaw_deg * M_PI / 180);
	spec.ref_end = c.split;
	spec.other_begin = 1 - c.split;
	return makeGroundTruthPair(scans, spec);
}

/** The accuracy bounds: scale < 0.2 %, yaw < 0.2°, point RMSE < 0.5
 * cell of the coarser map (over the other map's edge points). */
void expectAccurate(const GroundTruthPair& pair, const CScalingGridMapAligner::TReturnInfo& r)
{
	ASSERT_TRUE(r.success) << r.message;
	const Similarity2D truth_cells = pair.otherCellsToRefCells();
	EXPECT_NEAR(r.cells.scale / truth_cells.scale, 1.0, 0.002);
	EXPECT_NEAR(wrapToPi(r.cells.yaw - truth_cells.yaw) * 180 / M_PI, 0.0, 0.2);
	EXPECT_NEAR(r.metric.scale, 1.0, 0.002);  // metadata is true here
	PointList pts = edgePoints(toClassImage(pair.other));
	for (auto& p : pts) p = cellToMetric(pair.other)(p);
	const double coarse = std::max(pair.ref.getResolution(), pair.other.getResolution());
	EXPECT_LT(pointRmse(r.metric, pair.other_to_ref, pts) / coarse, 0.5);
	EXPECT_NEAR(r.implied_resolution_other / pair.other.getResolution(), 1.0, 0.002);
	EXPECT_GE(r.confidence, 0.5);
	EXPECT_GE(r.overlap, 0.35);
}

class RealPairs : public ::testing::TestWithParam<Case>
{
};

TEST_P(RealPairs, AlignsWithinTheBounds)
{
	const Case c = GetParam();
	const auto pair = makePair(scansOf(test::mrptDataset(c.dataset)), c);
	CScalingGridMapAligner aligner;
	expectAccurate(pair, aligner.alignScaled(pair.ref, pair.other));
}

const char* kMalaga = "malaga-cs-fac-building.simplemap.gz";
const char* kLocalization = "localization_demo.simplemap.gz";

INSTANTIATE_TEST_SUITE_P(
	Malaga, RealPairs,
	::testing::Values(
		Case{kMalaga, 0.05, 0.05, 0, 0.6}, Case{kMalaga, 0.05, 0.08, 30, 0.6},
		Case{kMalaga, 0.05, 0.10, 90, 0.6}, Case{kMalaga, 0.10, 0.02, 180, 0.6},
		Case{kMalaga, 0.02, 0.10, 270, 0.6}, Case{kMalaga, 0.03, 0.07, -123, 0.6}));

// The localization_demo halves overlap less; 70 % parts keep the true
// overlap above ξmin = 0.35, which TsICP needs.
INSTANTIATE_TEST_SUITE_P(
	LocalizationDemo, RealPairs,
	::testing::Values(
		Case{kLocalization, 0.05, 0.05, 270, 0.7}, Case{kLocalization, 0.05, 0.08, 90, 0.7},
		Case{kLocalization, 0.10, 0.02, 180, 0.7}, Case{kLocalization, 0.02, 0.10, 45, 0.7}));

TEST(Fr079, TheGroundTruthPairsOfThePaperAlign)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const ScanSequence& scans = scansOf(log);
	ASSERT_GT(scans.size(), 4000u);
	CScalingGridMapAligner aligner;
	for (const Case c : {Case{"fr079", 0.02, 0.10, 90, 0.6}, Case{"fr079", 0.10, 0.02, 180, 0.6},
						 Case{"fr079", 0.04, 0.06, 33, 0.6}})
	{
		SCOPED_TRACE(::testing::PrintToString(c));
		const auto pair = makePair(scans, c);
		expectAccurate(pair, aligner.alignScaled(pair.ref, pair.other));
	}
}

// Same-log maps give many hypotheses that converge on one placement: once a
// candidate there coincides cell for cell, a hypothesis whose sample
// refinement lands on it is not refined again, and the result is the one
// refining every hypothesis gives.
TEST(Search, HypothesesLandingOnAnExactCandidateAreNotRefinedAgain)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const ScanSequence& scans = scansOf(log);
	CScalingGridMapAligner fast, every;
	every.options.exhaustive_search = true;
	// A threshold no score reaches alone: the search does not stop on a
	// score (where a calibration puts it), only on the cells.
	fast.options.decision.threshold = every.options.decision.threshold = 5;
	size_t landed = 0;
	for (const Case c : {Case{"fr079", 0.02, 0.02, 0, 0.6}, Case{"fr079", 0.04, 0.06, 33, 0.6}})
	{
		SCOPED_TRACE(::testing::PrintToString(c));
		const auto pair = makePair(scans, c);
		const auto a = fast.alignScaled(pair.ref, pair.other), b = every.alignScaled(pair.ref, pair.other);
		expectAccurate(pair, a);
		expectAccurate(pair, b);
		for (size_t i = 0; i < a.candidates.size(); ++i)
		{
			const auto& c = a.candidates[i];
			if (!c.converged_on_exact) continue;
			++landed;
			EXPECT_TRUE(c.screened);
			const bool near_exact = std::any_of(a.candidates.begin(), a.candidates.begin() + i, [&](const auto& e) {
				return !e.screened && e.evidence.exact_confidence >= fast.options.decision.min_confidence && !fast.options.decision.areRivals(e.placement(), c.placement());
			});
			EXPECT_TRUE(near_exact) << "candidate " << i << " landed on no exact candidate found before it";
		}
		for (const auto& c : b.candidates) EXPECT_FALSE(c.converged_on_exact);
		// The same placement to a fraction of a coarse cell at the map's corners.
		const double coarse = std::max(pair.ref.getResolution(), pair.other.getResolution());
		const double w = pair.other.getXMax() - pair.other.getXMin(), h = pair.other.getYMax() - pair.other.getYMin();
		for (const auto& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)})
		{
			const Eigen::Vector2d p = corner + Eigen::Vector2d(pair.other.getXMin(), pair.other.getYMin());
			EXPECT_LT((a.metric.apply(p) - b.metric.apply(p)).norm() / coarse, 0.5);
		}
	}
	EXPECT_GT(landed, 0u) << "no hypothesis landed on an exact candidate: the test checks nothing";
}

// A fleet prepares each map once and aligns it in several pairs: a prepared
// pair must align exactly as the grids do, one map may serve both roles, and
// maps prepared with other feature options are refused, not silently mixed.
TEST(PreparedMaps, AlignAsTheGridsDoAndRefuseOtherFeatureOptions)
{
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.08, 30, 0.6});
	CScalingGridMapAligner aligner;
	const auto ref = aligner.prepare(pair.ref), other = aligner.prepare(pair.other);
	ASSERT_TRUE(ref->problem.empty() && other->problem.empty());
	const auto from_grids = aligner.alignScaled(pair.ref, pair.other);
	const auto prepared = aligner.alignScaled(*ref, *other);
	expectAccurate(pair, prepared);
	EXPECT_EQ(prepared.cells.t, from_grids.cells.t);
	EXPECT_EQ(prepared.cells.scale, from_grids.cells.scale);
	EXPECT_EQ(prepared.confidence, from_grids.confidence);
	EXPECT_EQ(prepared.stage_seconds.count("features"), 0u);  // paid once, in prepare
	// The mirror check flips the reference once and keeps it with the
	// prepared map: every later pair (and thread) gets that one.
	CScalingGridMapAligner exhaustive;  // checks the mirror image even where the cells coincide
	exhaustive.options.exhaustive_search = true;
	ASSERT_EQ(exhaustive.alignScaled(*ref, *other).stage_seconds.count("mirror"), 1u) << "the mirror check did not run";
	const auto flipped = ref->mirrored();
	std::shared_ptr<const PreparedMap> from_another_thread;
	std::thread([&] { from_another_thread = ref->mirrored(); }).join();
	EXPECT_EQ(from_another_thread, flipped);
	cv::Mat flipped_back;
	cv::flip(flipped->classes, flipped_back, 1);
	EXPECT_EQ(cv::countNonZero(flipped_back != ref->classes), 0);
	// Reused the other way round: the inverse transform.
	const auto back = aligner.alignScaled(*other, *ref);
	ASSERT_TRUE(back.success) << back.message;
	EXPECT_NEAR(back.cells.scale * prepared.cells.scale, 1.0, 0.002);

	CScalingGridMapAligner coarser;
	coarser.options.feature_max_level_cells = 1e4;
	const auto r = coarser.alignScaled(*ref, *other);
	EXPECT_FALSE(r.success);
	EXPECT_NE(r.message.find("prepared with other feature options"), std::string::npos) << r.message;
	// A problem found while preparing names the map's role when aligned.
	mrpt::maps::COccupancyGridMap2D tiny(0, 0.2, 0, 0.2, 0.05);
	const auto t = aligner.alignScaled(*ref, *aligner.prepare(tiny));
	EXPECT_EQ(t.message.rfind("other map is too small", 0), 0u) << t.message;
}

// A map file is often mostly unknown around what the robot saw (gmapping's
// grid is 4000 cells across whatever it mapped). Prepared as its known part,
// the padding changes nothing: the same prepared images, the same alignment.
TEST(PreparedMaps, CroppedToTheKnownPartPaddingChangesNothing)
{
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.08, 30, 0.6});
	CScalingGridMapAligner aligner;
	aligner.options.crop_to_known = true;
	const GridInFrame ref_w = widened(GridInFrame{pair.ref, Similarity2D(), MapKind::Sensed}, {300, 40, 120, 120}),
					  other_w = widened(GridInFrame{pair.other, Similarity2D(), MapKind::Sensed}, {7, 210, 0, 0});
	const auto &ref_padded = ref_w.grid, &other_padded = other_w.grid;
	ASSERT_EQ(ref_padded.getSizeX(), pair.ref.getSizeX() + 420);
	const auto ref = aligner.prepare(pair.ref), ref_p = aligner.prepare(ref_padded);
	const auto other = aligner.prepare(pair.other), other_p = aligner.prepare(other_padded);
	ASSERT_EQ(ref->classes.size(), ref_p->classes.size());
	EXPECT_EQ(cv::countNonZero(ref->classes != ref_p->classes), 0);
	EXPECT_EQ(ref_p->grid_corner - ref->grid_corner, cv::Point(300, 40));
	EXPECT_EQ(other_p->grid_corner - other->grid_corner, cv::Point(7, 210));
	EXPECT_LE(ref_p->classes.cols, int(ref_padded.getSizeX()) - 420 + 2 * kKnownMargin);

	const auto r = aligner.alignScaled(*ref, *other), r_p = aligner.alignScaled(*ref_p, *other_p);
	expectAccurate(pair, r);  // reported in the grids' cells and metres
	ASSERT_TRUE(r_p.success) << r_p.message;
	EXPECT_EQ(r_p.confidence, r.confidence);
	EXPECT_EQ(r_p.cells.scale, r.cells.scale);
	EXPECT_EQ(r_p.cells.yaw, r.cells.yaw);
	// In metres, between the maps' frames (the padded grids' corners moved).
	const Similarity2D metric_p = betweenMapFrames(ref_w, r_p.metric, other_w);
	EXPECT_LT((metric_p.t - r.metric.t).norm(), 1e-5);  // MRPT keeps grid corners in float
	EXPECT_NEAR(metric_p.yaw, r.metric.yaw, 1e-12);
	// In the padded grids' cells: the same placement, shifted by the padding.
	const Similarity2D shift_ref(1, 0, {300, 40}), shift_other(1, 0, {7, 210});
	EXPECT_LT((r_p.cells.t - shift_ref.compose(r.cells).compose(shift_other.inverse()).t).norm(), 1e-6);
}

// A live fleet tracks a placed pair as its maps grow: refined from the last
// transform, no search. A start that is wrong (a quarter turn off) must not
// be trusted: the search runs and finds the right transform anyway.
TEST(PreparedMaps, AStartIsTrackedWhenConfidentAndSearchedPastWhenWrong)
{
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.08, 30, 0.6});
	CScalingGridMapAligner aligner;
	const auto ref = aligner.prepare(pair.ref), other = aligner.prepare(pair.other);
	const auto searched = aligner.alignScaled(*ref, *other);
	ASSERT_TRUE(searched.success) << searched.message;

	const Similarity2D nudged(searched.metric.scale * 1.01, searched.metric.yaw + 0.02,
							  searched.metric.t + Eigen::Vector2d(0.15, -0.1));
	const auto tracked = aligner.alignScaled(*ref, *other, nudged);
	ASSERT_TRUE(tracked.success) << tracked.message;
	expectAccurate(pair, tracked);
	EXPECT_EQ(tracked.hypotheses_refined, 1u);
	EXPECT_EQ(tracked.stage_seconds.count("ransac"), 0u);  // no search

	const Similarity2D wrong(searched.metric.scale, searched.metric.yaw + M_PI / 2, searched.metric.t);
	const auto recovered = aligner.alignScaled(*ref, *other, wrong);
	ASSERT_TRUE(recovered.success) << recovered.message;
	expectAccurate(pair, recovered);
	EXPECT_GT(recovered.hypotheses_refined, 1u);
	EXPECT_EQ(recovered.stage_seconds.count("ransac"), 1u);
}

TEST(MetadataFree, WrongStatedResolutionIsRecovered)
{
	// The other map is really 8 cm but claims 5 cm: the implied resolution
	// must say 8 cm, and the metric scale must absorb the lie.
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.08, 60, 0.6});
	const auto liar = withStatedResolution(pair.other, 0.05);
	CScalingGridMapAligner aligner;
	const auto r = aligner.alignScaled(pair.ref, liar);
	ASSERT_TRUE(r.success) << r.message;
	EXPECT_NEAR(r.implied_resolution_other, 0.08, 0.08 * 0.002);
	EXPECT_NEAR(r.metric.scale, 0.08 / 0.05, 1.6 * 0.002);
}

TEST(MetadataPrior, UsedWhenTrustedAndRejectsContradictingScales)
{
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.10, 200, 0.6});
	CScalingGridMapAligner aligner;
	aligner.options.use_resolution_metadata = true;
	expectAccurate(pair, aligner.alignScaled(pair.ref, pair.other));
	// A prior that lies by 2x leaves no hypothesis it allows.
	const auto r = aligner.alignScaled(pair.ref, withStatedResolution(pair.other, 0.05));
	EXPECT_FALSE(r.success);
	EXPECT_FALSE(r.message.empty());
}

TEST(Decision, MapsOfDifferentBuildingsAreNotMerged)
{
	const auto malaga = renderGrid(scansOf(test::mrptDataset(kMalaga)), 0, 99, 0.05);
	const auto& loc_scans = scansOf(test::mrptDataset(kLocalization));
	const auto loc = renderGrid(loc_scans, 0, loc_scans.size(), 0.08);
	CScalingGridMapAligner aligner;
	for (const auto& [a, b] : {std::pair{&malaga, &loc}, std::pair{&loc, &malaga}})
	{
		const auto r = aligner.alignScaled(*a, *b);
		EXPECT_FALSE(r.success) << "confidence " << r.confidence << " tolerant consistency " << r.evidence.tolerant_consistency;
		EXPECT_FALSE(r.message.empty());
	}
}

TEST(Decision, BadMapsGiveAReasonNotACrash)
{
	const auto good = renderGrid(scansOf(test::mrptDataset(kMalaga)), 0, 40, 0.05);
	CScalingGridMapAligner aligner;
	const mrpt::maps::COccupancyGridMap2D tiny(0, 0.2f, 0, 0.2f, 0.1f);
	const mrpt::maps::COccupancyGridMap2D unknown(-10, 10, -10, 10, 0.05f);  // all unknown
	auto r = aligner.alignScaled(good, tiny);
	EXPECT_FALSE(r.success);
	EXPECT_NE(r.message.find("too small"), std::string::npos) << r.message;
	r = aligner.alignScaled(unknown, good);
	EXPECT_FALSE(r.success);
	EXPECT_FALSE(r.message.empty());
}

TEST(MrptInterface, AlignPDFGivesTheMetricPoseOfTheOtherFrame)
{
	const auto pair = makePair(scansOf(test::mrptDataset(kMalaga)), Case{kMalaga, 0.05, 0.08, 75, 0.6});
	CScalingGridMapAligner aligner;
	CScalingGridMapAligner::TReturnInfo info;
	const auto pdf = aligner.Align(&pair.ref, &pair.other, mrpt::poses::CPose2D(), info);
	ASSERT_TRUE(pdf);
	const auto mean = pdf->getMeanVal();
	EXPECT_NEAR(mean.x(), 1.5, 0.04);
	EXPECT_NEAR(mean.y(), -2.5, 0.04);
	EXPECT_NEAR(wrapToPi(mean.phi() - 75 * M_PI / 180), 0, 0.2 * M_PI / 180);
	EXPECT_TRUE(info.success);
	EXPECT_GT(info.executionTime, 0);
	// Not a grid: a clear exception rather than a crash.
	mrpt::poses::CPose2D notAMap;
	EXPECT_THROW(aligner.Align(&pair.ref, nullptr, notAMap), std::exception);
}

TEST(Config, IniRoundTripAndOverride)
{
	CScalingGridMapAligner::TConfigParams a;
	a.xi_min = 0.4;
	a.lambda = 1.5;
	a.use_resolution_metadata = true;
	a.pyramid_levels = 3;
	// Through a real ini file, as users keep them (MRPT writes "key = value // comment").
	const std::string path = ::testing::TempDir() + "/aligner_roundtrip.ini";
	{
		mrpt::config::CConfigFile out(path);
		a.saveToConfigFile(out, "aligner");
	}
	CScalingGridMapAligner::TConfigParams b;
	b.loadFromConfigFile(mrpt::config::CConfigFile(path), "aligner");
	EXPECT_DOUBLE_EQ(b.xi_min, 0.4);
	EXPECT_DOUBLE_EQ(b.lambda, 1.5);
	EXPECT_TRUE(b.use_resolution_metadata);
	EXPECT_EQ(b.pyramid_levels, 3);
	EXPECT_DOUBLE_EQ(b.ransac_threshold, a.ransac_threshold);
	// Keys absent from the file keep their defaults.
	mrpt::config::CConfigFileMemory partial;
	partial.write("aligner", "min_confidence", 0.8);
	CScalingGridMapAligner::TConfigParams c;
	c.loadFromConfigFile(partial, "aligner");
	EXPECT_DOUBLE_EQ(c.decision.min_confidence, 0.8);
	EXPECT_DOUBLE_EQ(c.xi_min, 0.35);
}

// Every parameter of the one list: a value other than its default survives an
// ini file, and one outside its range is refused naming its key.
TEST(Config, EveryListedParameterRoundTripsAndIsRangeChecked)
{
	using P = CScalingGridMapAligner::TConfigParams;
	const P defaults;
	P changed;
	for (const auto& f : alignerParamFields())
		std::visit(
			[&](auto member) {
				using T = std::remove_reference_t<decltype(changed.*member)>;
				if constexpr (std::is_same_v<T, bool>) changed.*member = !(defaults.*member);
				else
				{
					changed.*member = static_cast<T>(f.hi > f.lo + 1 ? std::floor(f.lo + 1) : (f.lo + f.hi) / 2);
					if (changed.*member == defaults.*member) changed.*member = static_cast<T>(f.hi);
				}
				EXPECT_NE(changed.*member, defaults.*member) << f.key;
			},
			f.member);
	ASSERT_EQ(changed.invalidReason(), "");
	const std::string path = ::testing::TempDir() + "/aligner_every_key.ini";
	{
		mrpt::config::CConfigFile out(path);
		changed.saveToConfigFile(out, "aligner");
	}
	P loaded;
	loaded.loadFromConfigFile(mrpt::config::CConfigFile(path), "aligner");
	for (const auto& f : alignerParamFields())
		std::visit([&](auto member) { EXPECT_EQ(loaded.*member, changed.*member) << f.key; }, f.member);

	for (const auto& f : alignerParamFields())
	{
		if (std::holds_alternative<bool P::*>(f.member)) continue;
		mrpt::config::CConfigFileMemory bad;
		const std::string too_big = std::to_string(static_cast<long long>(f.hi * 2 + 1));  // an int key reads it too
		bad.write("aligner", f.key, too_big);
		try
		{
			P().loadFromConfigFile(bad, "aligner");
			ADD_FAILURE() << f.key << " = " << too_big << " was taken";
		}
		catch (const std::invalid_argument& e)
		{
			EXPECT_NE(std::string(e.what()).find(f.key), std::string::npos) << e.what();
		}
	}
	// The ROS nodes read exactly these keys, the aligner's then the decision's.
	EXPECT_EQ(alignerParamKeys().size(), alignerParamFields().size() + decisionParamFields().size());
}
}  // namespace

TEST(Carmen, HundredEightyBeamScansSpanHalfACircle)
{
	// MRPT's CARMEN parser reads 180-beam FLASER lines as 90°, which smears
	// the Intel lab beyond recognition; the loader corrects it, so the
	// Intel halves align like any other pair.
	MMM_REQUIRE_SHARED(log, "carmen_corrected/intel-corrected.log.gz");
	const ScanSequence& scans = scansOf(log);
	ASSERT_EQ(scans.front().scan->getScanSize(), 180u);
	EXPECT_NEAR(scans.front().scan->aperture, M_PI * 179 / 180, 1e-6);
	CScalingGridMapAligner aligner;
	const auto pair = makePair(scans, Case{"intel", 0.05, 0.08, 120, 0.6});
	expectAccurate(pair, aligner.alignScaled(pair.ref, pair.other));
}

// A robot that has seen little of one building against the whole of
// another: walls agree about as well at the best placement as anywhere, and
// with no rival the lead over the floor alone could merge it. The score's
// lead over chance (chance_weight (B - C)) and the threshold refuse it with
// room: the first 15 % of orebro against fr079 is among the calibration's
// negatives.
TEST(Decision, WallsNoBetterThanChanceAreNotMerged)
{
	MMM_REQUIRE_SHARED(fr079, "carmen_corrected/freiburg-079-corrected.log.gz");
	MMM_REQUIRE_SHARED(orebro, "carmen_corrected/orebro-corrected.log.gz");
	const ScanSequence &a = scansOf(fr079), &b = scansOf(orebro);
	const auto ref = renderGrid(a, 0, a.size(), 0.08), other = renderGrid(b, 0, b.size() * 15 / 100, 0.05);
	const CScalingGridMapAligner defaults;
	const auto d = defaults.alignScaled(ref, other);
	EXPECT_FALSE(d.success) << d.message;
	// Refused with room: the threshold lies the safety margin (a quarter of
	// the confidence scale) above the highest wrong calibration value;
	// another machine's hypotheses move it by a few hundredths.
	EXPECT_LT(d.confidence, 0.35) << d.message;
	EXPECT_LT(d.evidence.bent_consistency - d.evidence.chance_consistency, 0.05) << d.message;
}

TEST(Decision, RealMapsOfDifferentBuildingsFromTheSharedDataAreNeverMerged)
{
	// The confidence bar, checked on real negatives at mixed resolutions
	// (the benchmark runs every ordered pair of six buildings).
	MMM_REQUIRE_SHARED(fr079, "carmen_corrected/freiburg-079-corrected.log.gz");
	MMM_REQUIRE_SHARED(intel, "carmen_corrected/intel-corrected.log.gz");
	MMM_REQUIRE_SHARED(fr101, "carmen_corrected/freiburg-101-corrected.log.gz");
	std::vector<mrpt::maps::COccupancyGridMap2D> maps;
	for (const auto& [log, res] : {std::pair{fr079, 0.05}, std::pair{intel, 0.08}, std::pair{fr101, 0.04}})
	{
		const ScanSequence& s = scansOf(log);
		maps.push_back(renderGrid(s, 0, s.size(), res));
	}
	CScalingGridMapAligner aligner;
	for (size_t i = 0; i < maps.size(); ++i)
		for (size_t j = 0; j < maps.size(); ++j)
			if (i != j)
			{
				const auto r = aligner.alignScaled(maps[i], maps[j]);
				EXPECT_FALSE(r.success) << i << " vs " << j << ": confidence " << r.confidence;
			}
}
