// Hostile inputs, one test each (docs/limits.md, "Hostile inputs", lists them): every
// one ends in a clear error or a refusal to merge, never a crash, a hang or a
// silent wrong merge. The OccupancyGrid message cases are in
// test_merge_service.cpp and, on the node, test_merge_maps_node.cpp.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>

#include "test_data.h"

using namespace multires_map_merge;
using mrpt::maps::COccupancyGridMap2D;
namespace fs = std::filesystem;

namespace
{
std::string tmp(const std::string& name)
{
	const std::string d = ::testing::TempDir() + "/hostile";
	fs::create_directories(d);
	return d + "/" + name;
}

const COccupancyGridMap2D& realMap()
{
	static const COccupancyGridMap2D g = [] {
		const auto s = loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz"));
		return renderGrid(s, 0, s.size() * 6 / 10, 0.05);
	}();
	return g;
}

/** loadGridMap must throw MapIOError naming the file and the problem. */
void expectLoadError(const std::string& path, const std::string& words)
{
	try
	{
		const auto g = loadGridMap(path).grid;
		ADD_FAILURE() << path << " loaded as " << g.getSizeX() << "x" << g.getSizeY();
	}
	catch (const MapIOError& e)
	{
		EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
		EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
	}
}

void writeYaml(const std::string& path, const std::string& image, const std::string& res, const std::string& origin)
{
	std::ofstream(path) << "image: " << image << "\nresolution: " << res << "\norigin: " << origin
						<< "\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
}

/** The aligner must refuse, saying `words`. */
void expectRefused(const COccupancyGridMap2D& a, const COccupancyGridMap2D& b, const std::string& words)
{
	const auto r = CScalingGridMapAligner().alignScaled(a, b);
	EXPECT_FALSE(r.success) << "merged with confidence " << r.confidence;
	EXPECT_NE(r.message.find(words), std::string::npos) << r.message;
}

COccupancyGridMap2D filled(float p_free, unsigned w = 200, unsigned h = 150)
{
	COccupancyGridMap2D g(0, w * 0.05f, 0, h * 0.05f, 0.05f);
	g.fill(p_free);
	return g;
}
}  // namespace

TEST(HostileFiles, TruncatedGridmapGz)
{
	const std::string whole = tmp("whole.gridmap.gz"), cut = tmp("truncated.gridmap.gz");
	saveGridMap(realMap(), whole);
	const auto size = fs::file_size(whole);
	fs::copy_file(whole, cut, fs::copy_options::overwrite_existing);
	fs::resize_file(cut, size / 2);
	expectLoadError(cut, "not a serialized");
}

TEST(HostileFiles, GridmapOfAnotherMrptClass)
{
	// A real serialized MRPT object that is not a grid.
	const std::string path = tmp("pose.gridmap");
	{
		mrpt::io::CFileGZOutputStream out(path);
		auto arch = mrpt::serialization::archiveFrom(out);
		arch << mrpt::poses::CPose2D(1, 2, 3);
	}
	expectLoadError(path, "not a serialized");
}

TEST(HostileFiles, YamlWithGarbageImage)
{
	std::ofstream(tmp("garbage.pgm")) << "this is no image";
	writeYaml(tmp("garbage.yaml"), "garbage.pgm", "0.05", "[0, 0, 0]");
	expectLoadError(tmp("garbage.yaml"), "unreadable");
}

TEST(HostileFiles, ImageWithZeroWidth)
{
	std::ofstream(tmp("zero.pgm"), std::ios::binary) << "P5\n0 10\n255\n";
	writeYaml(tmp("zero.yaml"), "zero.pgm", "0.05", "[0, 0, 0]");
	expectLoadError(tmp("zero.yaml"), "zero.yaml");
}

TEST(HostileFiles, OnePixelImageLoadsAndIsRefusedAsTooSmall)
{
	cv::imwrite(tmp("one.pgm"), cv::Mat(1, 1, CV_8U, cv::Scalar(0)));
	writeYaml(tmp("one.yaml"), "one.pgm", "0.05", "[0, 0, 0]");
	const auto g = loadGridMap(tmp("one.yaml")).grid;
	EXPECT_EQ(g.getSizeX() * g.getSizeY(), 1u);
	expectRefused(realMap(), g, "too small");
}

TEST(HostileFiles, YamlWithBadResolutionOrOrigin)
{
	saveGridMap(realMap(), tmp("real.yaml"));  // writes real.pgm
	for (const std::string res : {"0", "-0.05", ".nan", ".inf", "nan", "abc"})
	{
		SCOPED_TRACE(res);
		writeYaml(tmp("badres.yaml"), "real.pgm", res, "[0, 0, 0]");
		expectLoadError(tmp("badres.yaml"), "badres.yaml");
	}
	for (const std::string origin : {"[.nan, 0, 0]", "[0, .inf, 0]", "nonsense"})
	{
		SCOPED_TRACE(origin);
		writeYaml(tmp("badorigin.yaml"), "real.pgm", "0.05", origin);
		expectLoadError(tmp("badorigin.yaml"), "badorigin.yaml");
	}
}

TEST(HostileMaps, AllUnknownAllOccupiedAllFree)
{
	expectRefused(realMap(), filled(0.5f), "all unknown");
	expectRefused(filled(0.0f), realMap(), "no free cells");  // all occupied
	expectRefused(realMap(), filled(1.0f), "no occupied cells");  // all free
}

TEST(HostileMaps, IdenticalMapsMergeAsIdentity)
{
	const auto r = CScalingGridMapAligner().alignScaled(realMap(), realMap());
	ASSERT_TRUE(r.success) << r.message;
	EXPECT_NEAR(r.metric.scale, 1, 1e-6);
	EXPECT_NEAR(r.metric.yaw, 0, 1e-6);
	EXPECT_NEAR(r.metric.t.norm(), 0, 1e-6);
}

TEST(HostileMaps, MirroredMapIsNotMerged)
{
	// A reflection is no similarity: no transform the aligner can return is right.
	const COccupancyGridMap2D& g = realMap();
	COccupancyGridMap2D mirrored(g.getXMin(), g.getXMax(), g.getYMin(), g.getYMax(), g.getResolution());
	for (unsigned cy = 0; cy < g.getSizeY(); ++cy)
		for (unsigned cx = 0; cx < g.getSizeX(); ++cx) mirrored.setCell(g.getSizeX() - 1 - cx, cy, g.getCell(cx, cy));
	const auto r = CScalingGridMapAligner().alignScaled(g, mirrored);
	EXPECT_FALSE(r.success) << "a mirrored map merged with confidence " << r.confidence;
}

TEST(HostileMaps, HugeMapIsRefusedBeforeAnyWork)
{
	// 10000 x 10000 cells (100 MB as an MRPT grid): above max_map_cells, so
	// refused at once with the reason, instead of a bad_alloc later.
	const COccupancyGridMap2D huge(0, 1000, 0, 1000, 0.1f);
	ASSERT_EQ(huge.getSizeX(), 10000u);
	const auto r = CScalingGridMapAligner().alignScaled(realMap(), huge);
	EXPECT_FALSE(r.success);
	EXPECT_NE(r.message.find("too large"), std::string::npos) << r.message;
}

TEST(HostileFiles, YamlThatHungMrptsParserIsAnError)
{
	// Found by fuzz_map_loader: libfyaml (behind MRPT's YAML reader) loops
	// forever on this directive; the map_server reader no longer uses it.
	std::ofstream(tmp("directive.yaml"), std::ios::binary) << "%[\x8a" "9\x8a" "9";
	expectLoadError(tmp("directive.yaml"), "not a map_server YAML");
}
