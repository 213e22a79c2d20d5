// Fusion and map I/O: the cell rule, extents and origins on hand-made grids,
// round trips of every output format.
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>

#include "test_data.h"

using namespace multires_map_merge;
using mrpt::maps::COccupancyGridMap2D;

namespace
{
// Sets the cell containing (x, y) to an occupancy probability.
void setOcc(COccupancyGridMap2D& g, double x, double y, float p_occ)
{
	g.setCell(g.x2idx(x), g.y2idx(y), 1.0f - p_occ);
}
float occAt(const COccupancyGridMap2D& g, double x, double y)
{
	return occupancyProbability(g, g.x2idx(x), g.y2idx(y));
}
std::string tmp(const std::string& name) { return ::testing::TempDir() + "/" + name; }
}  // namespace

TEST(FuseCell, RuleTable)
{
	const float occ = 0.9f, occ_weak = 0.6f, fr = 0.1f, fr_weak = 0.4f, unk = 0.5f;
	EXPECT_EQ(classify(fuseCell(occ, fr)), kOccupied);
	EXPECT_EQ(classify(fuseCell(fr, occ_weak)), kOccupied);
	EXPECT_EQ(classify(fuseCell(occ, unk)), kOccupied);
	EXPECT_EQ(classify(fuseCell(fr, unk)), kFree);
	EXPECT_EQ(classify(fuseCell(unk, fr_weak)), kFree);
	EXPECT_EQ(classify(fuseCell(unk, unk)), kUnknown);
	// The stronger evidence of the winning class is kept.
	EXPECT_FLOAT_EQ(fuseCell(occ_weak, occ), occ);
	EXPECT_FLOAT_EQ(fuseCell(fr_weak, fr), fr);
	EXPECT_FLOAT_EQ(fuseCell(unk, unk), 0.5f);
}

TEST(Fusion, UnionOfExtentsInTheReferenceFrame)
{
	COccupancyGridMap2D ref(0, 1, 0, 1, 0.1f), other(0, 1, 0, 1, 0.05f);
	setOcc(ref, 0.55, 0.55, 0.1f);  // free in ref
	setOcc(other, 0.52, 0.52, 0.9f);  // occupied in other's own frame
	// other's frame sits 2 m along x in ref's frame.
	const FusedMap f = fuseGridMaps(ref, other, Similarity2D(1, 0, {2, 0}), 0.1);
	EXPECT_NEAR(f.merged.grid.getXMin(), 0.0, 1e-6);
	EXPECT_NEAR(f.merged.grid.getXMax(), 3.0, 1e-6);
	EXPECT_NEAR(f.merged.grid.getYMax(), 1.0, 1e-6);
	EXPECT_EQ(f.merged.grid.getSizeX(), 30u);
	EXPECT_EQ(f.merged.grid.getSizeY(), 10u);
	EXPECT_EQ(classify(occAt(f.merged.grid, 0.55, 0.55)), kFree);
	EXPECT_EQ(classify(occAt(f.merged.grid, 2.52, 0.52)), kOccupied);
	EXPECT_EQ(classify(occAt(f.merged.grid, 1.5, 0.5)), kUnknown);  // between the maps
	EXPECT_EQ(f.ref_classes.size(), cv::Size(30, 10));
}

TEST(Fusion, RotationScaleAndOriginsHonoured)
{
	// other's grid starts at (-3, 4); its frame is rotated 90° and its stated
	// metres are half the reference's (scale 2).
	COccupancyGridMap2D ref(-1, 1, -1, 1, 0.1f), other(-3, -2, 4, 5, 0.05f);
	for (int i = -1; i <= 1; ++i)
		for (int j = -1; j <= 1; ++j) setOcc(other, -2.475 + 0.05 * i, 4.475 + 0.05 * j, 0.95f);
	const Similarity2D t(2.0, M_PI / 2, {1, 1});
	const Eigen::Vector2d where = t(Eigen::Vector2d(-2.475, 4.475));
	const FusedMap f = fuseGridMaps(ref, other, t, 0.1);
	EXPECT_EQ(classify(occAt(f.merged.grid, where.x(), where.y())), kOccupied);
	EXPECT_LE(f.merged.grid.getXMin(), where.x());
	EXPECT_GE(f.merged.grid.getYMax(), where.y());
}

TEST(Fusion, AOneCellWallSurvivesACoarserOutput)
{
	COccupancyGridMap2D ref(0, 2, 0, 2, 0.1f), other(0, 2, 0, 2, 0.02f);
	for (double x = 0.01; x < 2; x += 0.02)
		for (double y = 0.01; y < 2; y += 0.02) setOcc(other, x, y, std::abs(y - 1.01) < 0.005 ? 0.9f : 0.1f);
	const FusedMap f = fuseGridMaps(ref, other, Similarity2D(), 0.1);
	for (double x = 0.05; x < 2; x += 0.1) EXPECT_EQ(classify(occAt(f.merged.grid, x, 1.01)), kOccupied) << x;
	EXPECT_EQ(classify(occAt(f.merged.grid, 1.0, 0.5)), kFree);
}

TEST(Fusion, ManyMapsInOnePassAnyReferenceOneLeftOut)
{
	// Three maps side by side in their own frames (origins rotated and off the
	// lattice), the second the reference; the third is left out.
	std::vector<GridInFrame> maps(3);
	maps[0].grid = COccupancyGridMap2D(0, 1, 0, 1, 0.1f);
	maps[1].grid = COccupancyGridMap2D(0, 1, 0, 1, 0.05f);
	maps[2].grid = COccupancyGridMap2D(0, 1, 0, 1, 0.1f);
	maps[1].origin = Similarity2D(1, 0.3, {0.013, -0.027});
	setOcc(maps[0].grid, 0.55, 0.55, 0.9f);  // a wall in map 0 ...
	setOcc(maps[1].grid, 0.52, 0.52, 0.1f);  // ... where map 1 (placed on it) sees free space
	setOcc(maps[1].grid, 0.22, 0.22, 0.1f);
	setOcc(maps[2].grid, 0.55, 0.55, 0.9f);
	// Map 0 is placed so that its cell (0.55, 0.55) lands on map 1's (0.52, 0.52).
	const Eigen::Vector2d target = maps[1].origin(Eigen::Vector2d(0.52, 0.52));
	const Similarity2D zero_in_one(1, 0.8, target - Similarity2D(1, 0.8, {0, 0})(Eigen::Vector2d(0.55, 0.55)));
	const FusedMaps f = fuseGridMaps(maps, 1, {zero_in_one, Similarity2D(), std::nullopt}, 0.05);
	EXPECT_EQ(f.merged.origin.yaw, maps[1].origin.yaw);
	ASSERT_EQ(f.classes.size(), 3u);
	EXPECT_TRUE(f.classes[2].empty());
	EXPECT_EQ(f.classes[0].size(), cv::Size(int(f.merged.grid.getSizeX()), int(f.merged.grid.getSizeY())));
	// Occupied wins over free; the free cell of map 1 alone stays free.
	const Similarity2D to_grid = f.merged.origin.inverse();
	const Eigen::Vector2d wall = to_grid(target), free_cell = to_grid(maps[1].origin(Eigen::Vector2d(0.22, 0.22)));
	EXPECT_EQ(classify(occAt(f.merged.grid, wall.x(), wall.y())), kOccupied);
	EXPECT_EQ(classify(occAt(f.merged.grid, free_cell.x(), free_cell.y())), kFree);
	// Map 2 contributed nothing: no second wall where its own would land.
	size_t occupied = 0;
	for (unsigned y = 0; y < f.merged.grid.getSizeY(); ++y)
		for (unsigned x = 0; x < f.merged.grid.getSizeX(); ++x) occupied += classify(occupancyProbability(f.merged.grid, x, y)) == kOccupied;
	EXPECT_GE(occupied, 1u);
	EXPECT_LE(occupied, 4u);  // one 10 cm cell over at most 2x2 output cells
	EXPECT_THROW(fuseGridMaps(maps, 1, {zero_in_one, std::nullopt, std::nullopt}, 0.05), std::invalid_argument);
	EXPECT_THROW(fuseGridMaps(maps, 3, {zero_in_one, Similarity2D(), std::nullopt}, 0.05), std::invalid_argument);
}

// Fusion reads an input only over the box of its known cells: beyond it, a
// robot's unexplored margin leaves the output as the other maps make it. A
// real map inside a wide unknown margin, fused with itself shifted by whole
// cells: each cell lands on one output cell, so each input's class image in
// the fusion is the map's own, cell for cell, every known cell arrived.
TEST(Fusion, ARealMapInAWideMarginArrivesCellForCell)
{
	MMM_REQUIRE_SHARED(yaml, "ros_maps/willow/navstage_willow_10cm.yaml");
	const COccupancyGridMap2D seen = loadGridMap(yaml).grid;
	const double res = seen.getResolution();
	constexpr int kMargin = 60;
	COccupancyGridMap2D padded;
	padded.setSize(
		float(seen.getXMin() - kMargin * res), float(seen.getXMax() + kMargin * res),
		float(seen.getYMin() - kMargin * res), float(seen.getYMax() + kMargin * res), float(res), 0.5f);
	ASSERT_EQ(padded.getSizeX(), seen.getSizeX() + 2 * kMargin);
	ASSERT_EQ(padded.getSizeY(), seen.getSizeY() + 2 * kMargin);
	for (unsigned y = 0; y < seen.getSizeY(); ++y)
		for (unsigned x = 0; x < seen.getSizeX(); ++x) padded.setCell(x + kMargin, y + kMargin, seen.getCell(x, y));
	const cv::Mat own = toClassImage(padded);
	const cv::Rect known = cv::boundingRect(own != kUnknown);
	ASSERT_GE(known.x, kMargin);  // a wide margin for the fusion to skip
	ASSERT_GE(known.y, kMargin);

	constexpr int kDx = 7, kDy = -3;
	const FusedMap f = fuseGridMaps(padded, padded, Similarity2D(1, 0, {kDx * res, kDy * res}), res);
	// Where each input's cell (0, 0) lands among the output's cells.
	const COccupancyGridMap2D& out = f.merged.grid;
	auto cellsFromCorner = [&](double x, double y) {
		return cv::Point(int(std::lround((x - out.getXMin()) / res)), int(std::lround((y - out.getYMin()) / res)));
	};
	const cv::Rect ref_at(cellsFromCorner(padded.getXMin(), padded.getYMin()), own.size());
	const cv::Rect other_at(cellsFromCorner(padded.getXMin() + kDx * res, padded.getYMin() + kDy * res), own.size());
	ASSERT_EQ(other_at.tl() - ref_at.tl(), cv::Point(kDx, kDy));
	const cv::Rect whole(0, 0, int(out.getSizeX()), int(out.getSizeY()));
	ASSERT_EQ(ref_at & whole, ref_at);
	ASSERT_EQ(other_at & whole, other_at);
	EXPECT_EQ(cv::countNonZero(f.ref_classes(ref_at) != own), 0);
	EXPECT_EQ(cv::countNonZero(f.other_classes(other_at) != own), 0);
	EXPECT_EQ(cv::countNonZero(f.other_classes != kUnknown), cv::countNonZero(own != kUnknown));
}

TEST(Fusion, RefusesAbsurdSizesAndBadArguments)
{
	COccupancyGridMap2D a(0, 1, 0, 1, 0.1f);
	EXPECT_THROW(fuseGridMaps(a, a, Similarity2D(), 0.0), std::invalid_argument);
	EXPECT_THROW(fuseGridMaps(a, a, Similarity2D(), NAN), std::invalid_argument);
	EXPECT_THROW(fuseGridMaps(a, a, Similarity2D(0, 0, {0, 0}), 0.1), std::invalid_argument);
	EXPECT_THROW(fuseGridMaps(a, a, Similarity2D(1, 0, {1e6, 0}), 0.01), std::invalid_argument);
}

TEST(MapIO, EveryOutputFormatRoundTripsOnARealMap)
{
	const ScanSequence s = loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
	const COccupancyGridMap2D g = renderGrid(s, 0, 50, 0.08);
	const cv::Mat classes = toClassImage(g);
	for (const std::string name : {"rt.gridmap.gz", "rt.gridmap", "rt.yaml"})
	{
		SCOPED_TRACE(name);
		saveGridMap(g, tmp(name));
		const GridInFrame loaded = loadGridMap(tmp(name));
		const COccupancyGridMap2D& back = loaded.grid;
		ASSERT_EQ(back.getSizeX(), g.getSizeX());
		ASSERT_EQ(back.getSizeY(), g.getSizeY());
		EXPECT_NEAR(back.getResolution(), g.getResolution(), 1e-6);
		// The map's corner where it was (a .yaml holds it in the origin).
		EXPECT_NEAR(loaded.cornerInMapFrame().x(), g.getXMin(), 1e-6);
		EXPECT_NEAR(loaded.cornerInMapFrame().y(), g.getYMin(), 1e-6);
		EXPECT_EQ(cv::countNonZero(toClassImage(back) != classes), 0);  // not mirrored
	}
}

TEST(MapIO, BadFilesGiveErrorsNamingTheFile)
{
	auto expectError = [](const std::string& path, const std::string& words) {
		try
		{
			loadGridMap(path);
			ADD_FAILURE() << "no error for " << path;
		}
		catch (const MapIOError& e)
		{
			EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
			EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
		}
	};
	expectError(tmp("missing.gridmap.gz"), "no such file");
	std::ofstream(tmp("garbage.gridmap.gz")) << "not a map at all";
	expectError(tmp("garbage.gridmap.gz"), "not a serialized");
	std::ofstream(tmp("empty.gridmap")).close();
	expectError(tmp("empty.gridmap"), "not a serialized");
	std::ofstream(tmp("m.txt")) << "x";
	expectError(tmp("m.txt"), "unknown map format");
	std::ofstream(tmp("noimage.yaml")) << "image: nowhere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
									   << "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
	expectError(tmp("noimage.yaml"), "unreadable");
}

// Programs ask before any work whether each output can be written.
TEST(MapIO, WhyNotWritableNamesWhatIsInTheWay)
{
	EXPECT_EQ(whyNotWritable(tmp("new_output.yaml")), "");
	std::ofstream(tmp("existing_output.json")) << "{}";
	EXPECT_EQ(whyNotWritable(tmp("existing_output.json")), "");
	EXPECT_NE(whyNotWritable(tmp("no_such_folder/out.yaml")).find("no folder"), std::string::npos);
	std::filesystem::create_directories(tmp("a_folder"));
	EXPECT_NE(whyNotWritable(tmp("a_folder")).find("exists and is not a file"), std::string::npos);
}

TEST(MapIO, ReadsTheRealWillowMapServerFiles)
{
	MMM_REQUIRE_SHARED(yaml, "ros_maps/willow/navstage_willow_10cm.yaml");
	const COccupancyGridMap2D g = loadGridMap(yaml).grid;
	EXPECT_EQ(g.getSizeX(), 584u);
	EXPECT_EQ(g.getSizeY(), 526u);
	EXPECT_NEAR(g.getResolution(), 0.1, 1e-6);
	const cv::Mat c = toClassImage(g);
	EXPECT_GT(cv::countNonZero(c == kOccupied), 5000);
	EXPECT_GT(cv::countNonZero(c == kFree), 50000);
}
