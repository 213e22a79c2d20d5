// A fleet: N maps into one (FleetMerge.h), through map_server files as users
// feed them. Four robots of one building (fr079) at 5 / 3 / 8 / 4 cm in their
// own frames with off-lattice origins, where the fourth robot's part of the
// run overlaps only the third's; plus a robot of another building (intel),
// which must stay out, named.
#include <multires_map_merge/FleetGraph.h>
#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/JointPlacement.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "cli_run.h"
#include "test_data.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;
namespace fs = std::filesystem;

namespace
{
struct Robot
{
	std::string file;
	double resolution;
	Similarity2D truth;  //!< its map frame → the reference's map frame
};

struct Fleet
{
	std::vector<Robot> robots;  // [0] the reference; the last one another building
	std::vector<GridInFrame> maps;  // loaded back from the files
};

std::string tmpDir()
{
	const fs::path d = fs::temp_directory_path() / ("mmm_test_fleet_" + std::to_string(getpid()));
	fs::create_directories(d);
	return d.string();
}

struct RemoveTmpDir : ::testing::Environment
{
	void TearDown() override { fs::remove_all(tmpDir()); }
};
const auto* const kRemoveTmpDir = ::testing::AddGlobalTestEnvironment(new RemoveTmpDir);

/** Renders a robot's share [begin, end) of a run, in `frame`, written as a
 * map_server file with its origin off the lattice by (dx, dy) cells. With
 * `unseen_by`, the cells within a metre of what that robot saw are made
 * unknown: a robot that explored only beyond it. */
Robot writeRobot(
	const ScanSequence& s, double begin, double end, double res, const mrpt::poses::CPose2D& frame, double dx,
	double dy, const std::string& name, const GridInFrame* unseen_by = nullptr)
{
	const size_t n = s.size();
	Robot r{tmpDir() + "/" + name + ".yaml", res, Similarity2D(1, frame.phi(), {frame.x(), frame.y()})};
	GridInFrame map = renderGridOffLattice(s, size_t(begin * n), size_t(end * n), res, frame, dx * res, dy * res);
	if (unseen_by) forgetSeenBy(map, r.truth, *unseen_by, 1.0);  // unseen_by's map frame is the run's
	saveGridMap(map, r.file);
	return r;
}

const Fleet* fleet()
{
	static std::unique_ptr<Fleet> f = []() -> std::unique_ptr<Fleet> {
		const std::string fr079 = std::string(MMM_SHARED_DATA) + "/carmen_corrected/freiburg-079-corrected.log.gz";
		const std::string intel = std::string(MMM_SHARED_DATA) + "/carmen_corrected/intel-corrected.log.gz";
		if (!fileExists(fr079) || !fileExists(intel)) return nullptr;
		const ScanSequence a = loadScans(fr079), b = loadScans(intel);
		auto out = std::make_unique<Fleet>();
		out->robots = {
			writeRobot(a, 0.00, 0.45, 0.05, {}, 0.3, 0.7, "ref_5cm"),
			writeRobot(a, 0.30, 0.75, 0.03, {2.0, -1.0, 40 * M_PI / 180}, 0.6, 0.2, "robot_3cm"),
			writeRobot(a, 0.55, 0.95, 0.08, {-1.5, 3.0, -120 * M_PI / 180}, 0.5, 0.5, "robot_8cm"),
		};
		const GridInFrame ref = loadGridMap(out->robots[0].file);
		out->robots.push_back(writeRobot(a, 0.45, 1.00, 0.04, {4.0, 1.0, 170 * M_PI / 180}, 0.1, 0.9, "robot_4cm", &ref));
		out->robots.push_back(writeRobot(b, 0.00, 0.60, 0.05, {}, 0.4, 0.4, "other_building"));
		for (const auto& r : out->robots) out->maps.push_back(loadGridMap(r.file));
		return out;
	}();
	return f.get();
}

/** RMS displacement of a map's occupied cells between the estimate and the
 * truth, in cells of the coarser of it and the reference. */
double errorCoarseCells(const Fleet& f, size_t m, const Similarity2D& estimate)
{
	return pointRmse(estimate, f.robots[m].truth, occupiedPointsInMapFrame(f.maps[m])) / std::max(f.robots[0].resolution, f.robots[m].resolution);
}
}  // namespace

TEST(Fleet, PlacesEveryRobotOfTheBuildingAndKeepsTheOtherBuildingOut)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const Fleet& f = *fleet();
	const FleetResult r = placeFleet(f.maps, 0, CScalingGridMapAligner());
	ASSERT_EQ(r.maps.size(), f.maps.size());
	EXPECT_TRUE(r.maps[0].placed);
	for (size_t m = 1; m + 1 < f.maps.size(); ++m)
	{
		ASSERT_TRUE(r.maps[m].placed) << f.robots[m].file << ": " << r.maps[m].message;
		EXPECT_LE(errorCoarseCells(f, m, r.maps[m].in_reference), 2.0) << f.robots[m].file << " " << r.maps[m].message;
		EXPECT_NEAR(r.maps[m].in_reference.scale, 1.0, 0.01) << f.robots[m].file;
	}
	const size_t other_building = f.maps.size() - 1;
	EXPECT_FALSE(r.maps[other_building].placed);
	EXPECT_NE(r.maps[other_building].message.find("not placed"), std::string::npos);
	EXPECT_FALSE(r.allPlaced());
	// Pairs are tried most promising first, but a map not placed tries every
	// pair it has: none that could have placed it is skipped.
	const size_t tried_by_other =
		std::count_if(r.edges.begin(), r.edges.end(), [&](const FleetEdge& e) { return e.from == other_building || e.to == other_building; });
	EXPECT_EQ(tried_by_other, f.maps.size() - 1);
	// The last robot of the building saw nothing the reference saw: it is
	// placed through another robot, not directly.
	EXPECT_GT(r.maps[3].parent, 0) << r.maps[3].message;
	EXPECT_EQ(r.pairs_aligned + r.pairs_skipped, f.maps.size() * (f.maps.size() - 1) / 2);
	// Placed through a chain, it lands as close as the robots placed directly.
	double worst_direct = 0;
	for (size_t m : {1, 2}) worst_direct = std::max(worst_direct, errorCoarseCells(f, m, r.maps[m].in_reference));
	EXPECT_LE(errorCoarseCells(f, 3, r.maps[3].in_reference), std::max(0.5, 1.5 * worst_direct)) << r.maps[3].message;
}

/** Whether some confident pair kept, taken out, leaves map m connected to
 * the reference by nothing (its placement hangs on that one pair). */
bool hangsOnOnePair(const FleetResult& r, size_t m)
{
	for (size_t cut = 0; cut < r.edges.size(); ++cut)
	{
		std::vector<bool> reached(r.maps.size(), false);
		reached[0] = true;
		for (bool grew = true; grew;)
		{
			grew = false;
			for (size_t k = 0; k < r.edges.size(); ++k)
			{
				const FleetEdge& e = r.edges[k];
				if (k == cut || !e.merged || e.dropped || reached[e.from] == reached[e.to]) continue;
				reached[e.from] = reached[e.to] = grew = true;
			}
		}
		if (!reached[m]) return true;
	}
	return false;
}

// With second_path_tries (1, the default), a robot placed by one pair looks
// for a second path, so a cycle checks that pair; at 0, the two robots
// placed directly on the reference hang on their one pair each.
// Prepared as their known parts (crop_to_known), maps padded with unknown
// are placed as they are without it: the same placements, and each pair is
// weighed where it measured (FleetEdge::overlap) in the maps' own frames.
TEST(Fleet, CroppedToTheirKnownPartsPaddedMapsArePlacedAsTheyAre)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const Fleet& f = *fleet();
	std::vector<GridInFrame> padded_maps = f.maps;
	for (size_t m = 0; m < padded_maps.size(); ++m)
		padded_maps[m] = widened(f.maps[m], {150 + 40 * int(m), 90, 60, 60});
	CScalingGridMapAligner cropping;
	cropping.options.crop_to_known = true;
	const FleetResult r = placeFleet(f.maps, 0, cropping), r_padded = placeFleet(padded_maps, 0, cropping);
	ASSERT_EQ(r.edges.size(), r_padded.edges.size());
	for (size_t m = 1; m + 1 < f.maps.size(); ++m)
	{
		ASSERT_TRUE(r_padded.maps[m].placed) << f.robots[m].file << ": " << r_padded.maps[m].message;
		EXPECT_LE(errorCoarseCells(f, m, r_padded.maps[m].in_reference), 2.0) << f.robots[m].file;
		EXPECT_LT(wallRms(wallSpread(f.maps[m]), r_padded.maps[m].in_reference, r.maps[m].in_reference), 1e-4)
			<< f.robots[m].file;
	}
	EXPECT_FALSE(r_padded.maps.back().placed);
	size_t overlaps = 0;
	for (size_t k = 0; k < r.edges.size(); ++k)
	{
		const FleetEdge &e = r.edges[k], &e_padded = r_padded.edges[k];
		ASSERT_EQ(e.overlap.has_value(), e_padded.overlap.has_value()) << e.from << " -> " << e.to;
		if (!e.overlap) continue;
		++overlaps;
		for (size_t c = 0; c < 4; ++c)
			EXPECT_LT(((*e.overlap)[c] - (*e_padded.overlap)[c]).norm(), 1e-4) << e.from << " -> " << e.to;
	}
	EXPECT_GE(overlaps, 3u);
}

TEST(Fleet, ARobotHangingOnOnePairLooksForASecondPathWhenAsked)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const Fleet& f = *fleet();
	FleetParams one_path;
	one_path.second_path_tries = 0;
	const FleetResult once = placeFleet(f.maps, 0, CScalingGridMapAligner(), one_path);
	FleetParams two_paths;
	two_paths.second_path_tries = 1;
	const FleetResult checked = placeFleet(f.maps, 0, CScalingGridMapAligner(), two_paths);
	// Robot 3 overlaps robot 2 alone: the data allows it one path.
	for (size_t m : {1, 2})
	{
		ASSERT_TRUE(checked.maps[m].placed) << checked.maps[m].message;
		EXPECT_FALSE(hangsOnOnePair(checked, m)) << f.robots[m].file;
		EXPECT_LE(errorCoarseCells(f, m, checked.maps[m].in_reference), 2.0) << checked.maps[m].message;
	}
	EXPECT_TRUE(checked.maps[3].placed) << checked.maps[3].message;
	EXPECT_TRUE(hangsOnOnePair(once, 1) && hangsOnOnePair(once, 2));
	// What each placement reports says the same.
	for (const FleetResult* r : {&once, &checked})
		for (size_t m = 1; m < r->maps.size(); ++m)
			EXPECT_EQ(r->maps[m].checked_by_cycle, r->maps[m].placed && !hangsOnOnePair(*r, m)) << f.robots[m].file;
	EXPECT_GT(checked.pairs_aligned, once.pairs_aligned);
	// The second path between two placed robots was refined from where the
	// fleet put them (tracked), and found confident there.
	EXPECT_TRUE(std::any_of(checked.edges.begin(), checked.edges.end(), [&](const FleetEdge& e) {
		return e.tracked && e.merged && !e.dropped && e.from != 0 && e.to != 0;
	}));
	EXPECT_FALSE(checked.maps.back().placed);  // the other building still out
}

TEST(Fleet, FusesThePlacedMapsOnTheReferenceLattice)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const Fleet& f = *fleet();
	// Placement by the truth: the fusion alone is under test here.
	FleetResult truth;
	truth.maps.resize(f.maps.size());
	for (size_t m = 0; m + 1 < f.maps.size(); ++m) truth.maps[m].placed = true, truth.maps[m].in_reference = f.robots[m].truth;
	const FusedFleet fused = fuseFleet(f.maps, truth, 0, 0.05);
	EXPECT_FLOAT_EQ(fused.merged.grid.getResolution(), 0.05f);
	EXPECT_EQ(fused.merged.origin.t, f.maps[0].origin.t);  // the reference's frame
	ASSERT_EQ(fused.classes.size(), f.maps.size());
	EXPECT_TRUE(fused.classes.back().empty());  // not placed, not drawn
	// Every placed map's walls are walls of the merged map (cell rule: occupied if any).
	const cv::Mat merged_occ = toClassImage(fused.merged.grid) == kOccupied;
	for (size_t m = 0; m + 1 < f.maps.size(); ++m)
	{
		ASSERT_EQ(fused.classes[m].size(), merged_occ.size());
		const cv::Mat occ = fused.classes[m] == kOccupied;
		EXPECT_GT(cv::countNonZero(occ), 100);
		EXPECT_EQ(cv::countNonZero(occ & ~merged_occ), 0) << "map " << m;
	}
	// The merged map covers the union: larger than the reference alone.
	EXPECT_GT(cv::countNonZero(toClassImage(fused.merged.grid) != kUnknown),
			  cv::countNonZero(toClassImage(f.maps[0].grid) != kUnknown) * 1.3);
}

TEST(Fleet, CliReportsEveryMapInArgumentOrder)
{
	MMM_REQUIRE_SHARED(log, "carmen_corrected/freiburg-079-corrected.log.gz");
	const Fleet& f = *fleet();
	const std::string dir = tmpDir();
	// Reference, the other building, then two robots of the building.
	const std::vector<size_t> order = {0, 4, 2, 1};
	std::string args;
	for (size_t m : order) args += f.robots[m].file + " ";
	const CliRun run = runCli(args + "--json " + dir + "/fleet.json --png " + dir + "/fleet.png --out " + dir + "/fleet.yaml");
	EXPECT_EQ(run.exit_code, 1) << run.output;  // one map not placed
	const auto j = nlohmann::json::parse(slurp(dir + "/fleet.json"));
	ASSERT_TRUE(j.contains("maps")) << j.dump();
	EXPECT_FALSE(j["success"].get<bool>());
	ASSERT_EQ(j["maps"].size(), order.size() - 1);
	for (size_t k = 1; k < order.size(); ++k)
	{
		const auto& e = j["maps"][k - 1];
		EXPECT_EQ(e["file"], f.robots[order[k]].file);
		const bool building = order[k] != 4;
		ASSERT_EQ(e["success"].get<bool>(), building) << e.dump();
		if (!building)
		{
			EXPECT_FALSE(e["error"].get<std::string>().empty());
			continue;
		}
		const auto& t = e["transform"];
		const Similarity2D est(t["scale"].get<double>(), t["yaw"].get<double>(),
							   Eigen::Vector2d(t["x"].get<double>(), t["y"].get<double>()));
		EXPECT_LE(errorCoarseCells(f, order[k], est), 2.0) << e.dump();
	}
	EXPECT_NE(run.output.find("NOT PLACED " + f.robots[4].file), std::string::npos) << run.output;
	// The maps placed are still merged (on the reference's lattice) and drawn.
	const Eigen::Vector2d cells =
		(loadGridMap(dir + "/fleet.yaml").cornerInMapFrame() - f.maps[0].cornerInMapFrame()) / f.robots[0].resolution;
	EXPECT_NEAR(cells.x(), std::round(cells.x()), 1e-4);
	EXPECT_NEAR(cells.y(), std::round(cells.y()), 1e-4);
	EXPECT_FALSE(cv::imread(dir + "/fleet.png").empty());
}

TEST(Fleet, RefusesTooFewMapsAndABadReference)
{
	std::vector<GridInFrame> one(1);
	EXPECT_THROW(placeFleet(one, 0, CScalingGridMapAligner()), std::invalid_argument);
	std::vector<GridInFrame> two(2);
	EXPECT_THROW(placeFleet(two, 2, CScalingGridMapAligner()), std::invalid_argument);
	FleetParams bad;
	bad.settled_confidence = std::nan("");
	try
	{
		placeFleet(two, 0, CScalingGridMapAligner(), bad);
		ADD_FAILURE() << "a NaN settled_confidence was taken";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("settled_confidence"), std::string::npos) << e.what();
	}
}

// Placements the aligner's decision tells apart are never one: the largest
// cycle tolerance follows its distinct_shift unless set.
TEST(Fleet, TheLargestToleranceFollowsTheDecisionsDistinctShift)
{
	DecisionParams decision;
	decision.distinct_shift = 25;
	FleetEdge loose;
	loose.rmse_coarse_cells = 100;
	EXPECT_DOUBLE_EQ(FleetParams().resolvedFor(decision).toleranceOf(loose), 25);
	FleetParams set;
	set.cycle_tolerance_max_cells = 30;
	EXPECT_DOUBLE_EQ(set.resolvedFor(decision).toleranceOf(loose), 30);
}

// Every fleet key is written and reads back; a bad value is refused naming
// its section and key.
TEST(Fleet, ParametersReadBackFromAnIniAndBadOnesAreNamed)
{
	FleetParams set;
	set.threads = 3, set.settled_confidence = 0.7, set.unsettled_tries = 4, set.cycle_tolerance_cells = 2.5;
	set.second_path_tries = 3;
	set.cycle_tolerance_per_rmse = 6, set.cycle_tolerance_max_cells = 25, set.joint_refinement = false;
	const std::string path = tmpDir() + "/fleet.ini";
	{
		mrpt::config::CConfigFile ini(path);
		set.saveToConfigFile(ini, "fleet");
	}  // written when closed
	FleetParams read;
	read.loadFromConfigFile(mrpt::config::CConfigFile(path), "fleet");
	EXPECT_EQ(read.threads, 3u);
	EXPECT_EQ(read.settled_confidence, 0.7);
	EXPECT_EQ(read.unsettled_tries, 4u);
	EXPECT_EQ(read.second_path_tries, 3u);
	EXPECT_EQ(read.cycle_tolerance_cells, 2.5);
	EXPECT_EQ(read.cycle_tolerance_per_rmse, 6);
	EXPECT_EQ(read.cycle_tolerance_max_cells, 25);
	EXPECT_FALSE(read.joint_refinement);
	for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
			 {"unsettled_tries", "-1"}, {"unsettled_tries", "two"}, {"unsettled_tries", "1e30"},
			 {"fleet_threads", "1.5"}, {"settled_confidence", "2"},
			 {"cycle_tolerance_cells", "0"}, {"cycle_tolerance_max_cells", "-3"}})
	{
		mrpt::config::CConfigFileMemory bad;
		bad.write("fleet", key, value);
		try
		{
			FleetParams().loadFromConfigFile(bad, "fleet");
			ADD_FAILURE() << key << " = " << value << " was taken";
		}
		catch (const std::invalid_argument& e)
		{
			EXPECT_NE(std::string(e.what()).find("[fleet] " + key), std::string::npos) << e.what();
		}
	}
	// A refused file leaves the parameters as they were.
	mrpt::config::CConfigFileMemory half;
	half.write("fleet", "joint_refinement", "false");
	half.write("fleet", "settled_confidence", "7");
	FleetParams kept;
	EXPECT_THROW(kept.loadFromConfigFile(half, "fleet"), std::invalid_argument);
	EXPECT_TRUE(kept.joint_refinement);
}

namespace
{
/** Maps for the graph alone: 10 m × 10 m of unknown at 10 cm. */
std::vector<GridInFrame> blankMaps(size_t n)
{
	std::vector<GridInFrame> maps(n);
	for (auto& m : maps) m.grid.setSize(0, 10, 0, 10, 0.1f);
	return maps;
}

FleetEdge edge(size_t from, size_t to, const Similarity2D& from_to_to, double confidence)
{
	FleetEdge e;
	e.from = from, e.to = to, e.merged = true, e.from_to_to = from_to_to, e.confidence = confidence;
	e.message = "merged";
	return e;
}

void expectNear(const Similarity2D& a, const Similarity2D& b)
{
	EXPECT_NEAR(a.scale, b.scale, 1e-9);
	EXPECT_NEAR(wrapToPi(a.yaw - b.yaw), 0, 1e-9);
	EXPECT_NEAR((a.t - b.t).norm(), 0, 1e-9);
}
}  // namespace

TEST(FleetGraph, AMapHangsOnOnePairWhereNoSecondPathOfKeptPairsReachesIt)
{
	// 0-1-2 a cycle (each map has two paths); 3 joined to 2 by one kept
	// pair, its other pairs refused (0 <- 3) or dropped by a cycle (1 <- 3);
	// 4 not placed.
	std::vector<FleetEdge> edges = {edge(1, 0, {}, 1), edge(2, 1, {}, 1), edge(2, 0, {}, 1), edge(3, 2, {}, 1),
									edge(3, 1, {}, 1), edge(3, 0, {}, 0.2)};
	edges[4].dropped = true;
	edges[5].merged = false;
	std::vector<FleetPlacement> placements(5);
	for (size_t m = 0; m < 4; ++m) placements[m].placed = true;
	EXPECT_EQ(multires_map_merge::hangsOnOnePair(placements, edges, 0), std::vector<bool>({false, false, false, true, false}));
	// The pair dropped by the cycle kept after all: a second path for 3.
	edges[4].dropped = false;
	EXPECT_EQ(multires_map_merge::hangsOnOnePair(placements, edges, 0), std::vector<bool>(5, false));
	// Without the closing pair 0 <- 2, 1 and 2 hang on the chain too.
	edges[4].dropped = true;
	edges[2].merged = false;
	EXPECT_EQ(multires_map_merge::hangsOnOnePair(placements, edges, 0), std::vector<bool>({false, true, true, true, false}));
}

TEST(FleetGraph, AContradictedCycleDropsItsWeakestPairNotTheSharedPath)
{
	// Truth: map i's frame in map 0's.
	const std::vector<Similarity2D> truth = {
		{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1.25, -0.5, {-3, 4}), Similarity2D(0.8, 2.0, {5, -2})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	Similarity2D wrong = between(3, 2);
	wrong.t += Eigen::Vector2d(5, 0);  // 50 cells off
	// The path all share (0 <- 1) is the weakest pair: a cycle 1-2-3 closed by
	// a wrong 2 <- 3 must drop that one, not the shared path.
	const std::vector<FleetEdge> edges = {
		edge(1, 0, between(1, 0), 0.55), edge(2, 1, between(2, 1), 0.97), edge(3, 1, between(3, 1), 0.96),
		edge(3, 2, wrong, 0.6)};
	const FleetResult r = placeFromPairs(blankMaps(4), 0, edges);
	for (size_t m = 0; m < 4; ++m)
	{
		ASSERT_TRUE(r.maps[m].placed) << m << ": " << r.maps[m].message;
		expectNear(r.maps[m].in_reference, truth[m]);
	}
	EXPECT_TRUE(r.edges[3].dropped);
	// Said, and the aligner's own words kept: a live fleet remembers them.
	EXPECT_EQ(r.edges[3].describe().rfind("dropped: contradicts", 0), 0u) << r.edges[3].describe();
	EXPECT_EQ(r.edges[3].message, edges[3].message);
	EXPECT_FALSE(r.edges[0].dropped);
	EXPECT_DOUBLE_EQ(r.maps[2].confidence, 0.55);  // as sure as the weakest pair on its path
	EXPECT_EQ(r.maps[3].parent, 1);
}

TEST(FleetGraph, TheMostConfidentPathWinsAndAnUnconnectedMapIsNamed)
{
	const std::vector<Similarity2D> truth = {{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1, -0.5, {-3, 4})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	Similarity2D slightly_off = between(2, 0);
	slightly_off.t += Eigen::Vector2d(0.15, 0);  // 1.5 cells: within the cycle tolerance, kept
	std::vector<FleetEdge> edges = {edge(1, 0, between(1, 0), 1.0), edge(2, 1, between(2, 1), 0.9),
									edge(2, 0, slightly_off, 0.7)};
	FleetEdge refused;
	refused.from = 3, refused.to = 0, refused.message = "alignment not confident enough (confidence 0.2 < 0.5)";
	refused.confidence = 0;
	edges.push_back(refused);
	FleetParams tree_alone;
	tree_alone.joint_refinement = false;
	const FleetResult r = placeFromPairs(blankMaps(4), 0, edges, tree_alone);
	ASSERT_TRUE(r.maps[2].placed);
	EXPECT_EQ(r.maps[2].parent, 1);  // 0.9 through map 1 beats 0.7 directly
	expectNear(r.maps[2].in_reference, truth[2]);
	EXPECT_FALSE(r.edges[2].dropped);
	EXPECT_FALSE(r.maps[3].placed);
	EXPECT_NE(r.maps[3].message.find("not confident enough"), std::string::npos) << r.maps[3].message;
	EXPECT_FALSE(r.allPlaced());
	EXPECT_THROW(placeFromPairs(blankMaps(2), 0, {edge(5, 0, {}, 1)}), std::invalid_argument);
}

TEST(FleetGraph, JointRefinementPlacesAChainedMapByEveryPairThatSeesIt)
{
	// Four maps at 10 cm; each link of the chain 0 <- 1 <- 2 <- 3 is the most
	// confident pair but 1 cell (0.1 m) off, the same way: through the tree,
	// map k lands k cells off. Two less confident pairs (0 <- 2, 1 <- 3) are
	// exact and within the cycle tolerance of the chain, so they are kept.
	const std::vector<Similarity2D> truth = {
		{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1.25, -0.5, {-3, 4}), Similarity2D(0.8, 2.0, {5, -2})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	auto off = [&](size_t from, size_t to) {
		Similarity2D t = between(from, to);
		t.t += truth[to].inverse().linear() * Eigen::Vector2d(0.1, 0);  // 0.1 m along x of map 0
		return t;
	};
	const std::vector<FleetEdge> edges = {
		edge(1, 0, off(1, 0), 0.99), edge(2, 1, off(2, 1), 0.99), edge(3, 2, off(3, 2), 0.99),
		edge(2, 0, between(2, 0), 0.8), edge(3, 1, between(3, 1), 0.8)};
	const std::vector<GridInFrame> maps = blankMaps(4);
	FleetParams tree_alone;
	tree_alone.joint_refinement = false;
	const FleetResult tree = placeFromPairs(maps, 0, edges, tree_alone), joint = placeFromPairs(maps, 0, edges);
	auto cellsOff = [&](const FleetResult& r, size_t m) { return cornerRms(maps[m], r.maps[m].in_reference, truth[m]) / 0.1; };
	for (const auto* r : {&tree, &joint})
		for (size_t m = 0; m < 4; ++m) ASSERT_TRUE(r->maps[m].placed) << m << ": " << r->maps[m].message;
	EXPECT_FALSE(std::any_of(joint.edges.begin(), joint.edges.end(), [](const FleetEdge& e) { return e.dropped; }));
	EXPECT_NEAR(cellsOff(tree, 3), 3.0, 0.01);  // the chain's errors add up
	EXPECT_NEAR(cellsOff(tree, 2), 2.0, 0.01);
	// Jointly, the chain's end is off by at most a third of what the tree
	// gives (least squares over these five pairs: 1 cell), and no map by more.
	for (size_t m = 1; m < 4; ++m) EXPECT_LT(cellsOff(joint, m), 1.2) << m;
	EXPECT_LT(cellsOff(joint, 3), 0.4 * cellsOff(tree, 3));
	EXPECT_NE(joint.maps[3].message.find("refined jointly"), std::string::npos) << joint.maps[3].message;
	// Its parent and confidence are still the tree's: the path that placed it first.
	EXPECT_EQ(joint.maps[3].parent, 2);
	EXPECT_DOUBLE_EQ(joint.maps[3].confidence, 0.99);
	// A list of the wrong length is said, not padded with zeros.
	const std::vector<WallSpread> spread(4, wallSpread(maps[0]));
	const std::vector<double> per_edge(edges.size(), 3.0), per_map(4, 3.0);
	EXPECT_NO_THROW(refineJointly(maps, 0, tree.maps, edges, spread, per_edge, per_map));
	EXPECT_THROW(refineJointly(maps, 0, tree.maps, edges, spread, per_edge, {3.0}), std::invalid_argument);
	EXPECT_THROW(refineJointly(maps, 0, tree.maps, edges, spread, per_map, per_map), std::invalid_argument);
}

TEST(Fleet, APlacementsWallDisplacementIsItsRmsOverEveryWallCell)
{
	// What the cycle check and the joint refinement measure (wallRms at the
	// four points of a WallSpread) is how far two placements move the map's
	// walls, RMS over every wall cell: checked against the cells one by one.
	const Fleet* f = fleet();
	if (!f) GTEST_SKIP() << "needs " << MMM_SHARED_DATA << "/carmen_corrected";
	const GridInFrame& map = f->maps[1];
	const cv::Mat classes = toClassImage(map.grid);
	std::vector<cv::Point> walls;
	cv::findNonZero(classes == kOccupied, walls);
	ASSERT_GT(walls.size(), 100u);
	const Similarity2D cells = map.cellToMapFrame(), a = f->robots[1].truth,
					   b = Similarity2D(1.03, 0.05, {0.4, -0.3}).compose(a);
	double se = 0;
	for (const auto& w : walls) se += (a(cells({double(w.x), double(w.y)})) - b(cells({double(w.x), double(w.y)}))).squaredNorm();
	const double every_cell = std::sqrt(se / double(walls.size()));
	EXPECT_NEAR(wallRms(wallSpread(map), a, b), every_cell, 1e-6 * every_cell);
	// The grid's corners count a turn farther from the walls than they are.
	EXPECT_GT(cornerRms(map, a, b), 1.2 * every_cell);
}

TEST(FleetGraph, TheCycleToleranceFollowsThePairsPrecision)
{
	// Map 2 is placed through map 1 (the surer path); the direct pair 0 <- 2 is
	// 8 cells (0.8 m) off it. Pairs of precise maps (edge RMSE 0.3 cells) that
	// far apart mean one is off: the direct pair is dropped and map 2 stays where
	// its path puts it. Pairs of bent maps fitting at an edge RMSE of 3 cells
	// disagree that much when both are right: the pair is kept and the joint
	// refinement places map 2 between them.
	const std::vector<Similarity2D> truth = {{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1, -0.5, {-3, 4})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	Similarity2D direct = between(2, 0);
	direct.t += Eigen::Vector2d(0.8, 0);
	auto placed = [&](double rmse_cells) {
		std::vector<FleetEdge> edges = {
			edge(1, 0, between(1, 0), 0.99), edge(2, 1, between(2, 1), 0.99), edge(2, 0, direct, 0.7)};
		for (auto& e : edges) e.rmse_coarse_cells = rmse_cells;
		return placeFromPairs(blankMaps(3), 0, edges);
	};
	const std::vector<GridInFrame> maps = blankMaps(3);
	const FleetParams defaults;
	EXPECT_DOUBLE_EQ(defaults.toleranceOf(edge(2, 0, {}, 1)), defaults.cycle_tolerance_cells);  // no RMSE: the floor
	// At most what the decision tells apart as rival placements (unset: its default).
	FleetEdge loose = edge(2, 0, {}, 1);
	loose.rmse_coarse_cells = 100;
	EXPECT_DOUBLE_EQ(defaults.toleranceOf(loose), DecisionParams{}.distinct_shift);
	FleetParams narrower;
	narrower.cycle_tolerance_max_cells = 25;
	EXPECT_DOUBLE_EQ(narrower.toleranceOf(loose), 25);

	const FleetResult precise = placed(0.3);
	EXPECT_TRUE(precise.edges[2].dropped);
	expectNear(precise.maps[2].in_reference, truth[2]);

	const FleetResult bent = placed(3.0);
	EXPECT_FALSE(bent.edges[2].dropped);
	const WallSpread spread = wallSpread(maps[2]);
	const double off_path = wallRms(spread, bent.maps[2].in_reference, truth[2]) / 0.1,
				 off_direct = wallRms(spread, bent.maps[2].in_reference, truth[0].compose(direct)) / 0.1;
	EXPECT_GT(off_path, 1.0);
	EXPECT_GT(off_direct, 1.0);
	EXPECT_NEAR(off_path + off_direct, 8.0, 0.5);
	EXPECT_NE(bent.maps[2].message.find("refined jointly"), std::string::npos) << bent.maps[2].message;
}

TEST(FleetGraph, AChainsErrorsAddUpAroundACycle)
{
	// Map 3 is placed through the chain 0 <- 1 <- 2 <- 3 (the surer path); the
	// direct pair 0 <- 3 is 12 cells (1.2 m) off it. Bent maps fitting at an
	// edge RMSE of 2 cells (a pair's tolerance 8) disagree that much around a
	// cycle of four pairs when all are right (their errors add in quadrature:
	// 16): kept. Precise maps (RMSE 0.3: the 3-cell floor) 4 cells apart around
	// the same cycle mean one pair is off: dropped.
	const std::vector<Similarity2D> truth = {
		{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1.25, -0.5, {-3, 4}), Similarity2D(0.8, 2.0, {5, -2})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	auto placed = [&](double rmse_cells, double direct_off_m) {
		Similarity2D direct = between(3, 0);
		direct.t += Eigen::Vector2d(direct_off_m, 0);
		std::vector<FleetEdge> edges = {edge(1, 0, between(1, 0), 0.99), edge(2, 1, between(2, 1), 0.99),
										edge(3, 2, between(3, 2), 0.99), edge(3, 0, direct, 0.7)};
		for (auto& e : edges) e.rmse_coarse_cells = rmse_cells;
		return std::make_pair(placeFromPairs(blankMaps(4), 0, edges), edges);
	};
	const auto [bent, bent_edges] = placed(2.0, 1.2);
	const FleetParams defaults;
	EXPECT_DOUBLE_EQ(defaults.cycleTolerance({3, 0, 1, 2}, bent_edges), 16.0);
	EXPECT_DOUBLE_EQ(defaults.toleranceOf(bent_edges[3]), 8.0);  // one pair's: 12 cells would contradict it
	EXPECT_FALSE(bent.edges[3].dropped);
	// The joint refinement may move map 3 as far as its cycle let the pairs
	// disagree: it lands between the chain and the direct pair.
	const std::vector<GridInFrame> maps = blankMaps(4);
	Similarity2D direct = between(3, 0);
	direct.t += Eigen::Vector2d(1.2, 0);
	const WallSpread spread = wallSpread(maps[3]);
	const double off_chain = wallRms(spread, bent.maps[3].in_reference, truth[3]) / 0.1,
				 off_direct = wallRms(spread, bent.maps[3].in_reference, direct) / 0.1;
	EXPECT_GT(off_chain, 2.0);
	EXPECT_GT(off_direct, 1.0);
	EXPECT_NEAR(off_chain + off_direct, 12.0, 0.5);
	EXPECT_NE(bent.maps[3].message.find("refined jointly"), std::string::npos) << bent.maps[3].message;

	const auto [precise, precise_edges] = placed(0.3, 0.4);
	EXPECT_DOUBLE_EQ(defaults.cycleTolerance({3, 0, 1, 2}, precise_edges), defaults.cycle_tolerance_cells);
	EXPECT_TRUE(precise.edges[3].dropped);
	expectNear(precise.maps[3].in_reference, truth[3]);

	// Pairs of maps with cells of other sizes: each RMSE counts in its own
	// pair's coarser cells, the cycle's tolerance in the closing pair's (two
	// pairs of 2× cells at RMSE 2 allow 16 of its 1× cells each, not 8).
	const std::vector<double> coarse_cell = {2, 2, 1, 1};
	EXPECT_DOUBLE_EQ(defaults.cycleTolerance({3, 0, 1, 2}, bent_edges, coarse_cell), std::sqrt(2 * 8.0 * 8 + 2 * 16.0 * 16));

	// At most what the decision tells apart as rival placements.
	std::vector<FleetEdge> loose = bent_edges;
	for (auto& e : loose) e.rmse_coarse_cells = 30;
	EXPECT_DOUBLE_EQ(defaults.cycleTolerance({3, 0, 1, 2}, loose), defaults.maxToleranceCells());
}

TEST(FleetGraph, APairCountsWhereItsMapsOverlap)
{
	// Map 2 through map 1 (exact pairs), and a direct pair 0 <- 2 right where
	// the two maps overlap (a corner of map 2, around (1, 1) m of its frame)
	// but turned 1° about it: two bent maps fit at their overlap, and their
	// pair says little about the turn farther off. Measured at its overlap, it
	// agrees with the path and leaves map 2 where the path puts it; measured
	// over the whole map, it would pull map 2 turned.
	const std::vector<Similarity2D> truth = {{}, Similarity2D(1, 0.3, {2, 1}), Similarity2D(1, -0.5, {-3, 4})};
	auto between = [&](size_t from, size_t to) { return truth[to].inverse().compose(truth[from]); };
	const Eigen::Vector2d corner(1, 1);  // map 2's frame
	const Similarity2D about_corner =
		Similarity2D(1, 0, corner).compose(Similarity2D(1, M_PI / 180, {0, 0})).compose(Similarity2D(1, 0, -corner));
	const Similarity2D direct = between(2, 0).compose(about_corner);
	std::vector<FleetEdge> edges = {edge(1, 0, between(1, 0), 0.99), edge(2, 1, between(2, 1), 0.99), edge(2, 0, direct, 0.7)};
	for (auto& e : edges) e.rmse_coarse_cells = 3.0;  // bent maps: the pairs' disagreement is within their tolerance
	const std::vector<GridInFrame> maps = blankMaps(3);
	const WallSpread whole = wallSpread(maps[2]);
	const FleetResult over_the_map = placeFromPairs(maps, 0, edges);
	edges[2].overlap = WallSpread{corner + Eigen::Vector2d(0.5, 0), corner - Eigen::Vector2d(0.5, 0),
								  corner + Eigen::Vector2d(0, 0.5), corner - Eigen::Vector2d(0, 0.5)};
	const FleetResult at_overlap = placeFromPairs(maps, 0, edges);
	ASSERT_FALSE(at_overlap.edges[2].dropped);
	ASSERT_NE(at_overlap.maps[2].message.find("refined jointly"), std::string::npos) << at_overlap.maps[2].message;
	const double turned_cells = wallRms(whole, over_the_map.maps[2].in_reference, truth[2]) / 0.1,
				 at_overlap_cells = wallRms(whole, at_overlap.maps[2].in_reference, truth[2]) / 0.1;
	EXPECT_GT(turned_cells, 0.5);  // the whole-map pull: about half the turn's 1.3 cells at the walls
	EXPECT_LT(at_overlap_cells, 0.4 * turned_cells);
}
