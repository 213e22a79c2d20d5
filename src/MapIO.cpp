#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

bool hasSuffix(const std::string& s, const std::string& suffix)
{
	return s.size() >= suffix.size() &&
		s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

namespace
{
[[noreturn]] void fail(const std::string& path, const std::string& why)
{
	throw MapIOError("'" + path + "': " + why);
}

void checkLoaded(const COccupancyGridMap2D& g, const std::string& path)
{
	if (!std::isfinite(g.getResolution()) || !(g.getResolution() > 0))
		fail(path, "invalid resolution " + std::to_string(g.getResolution()));
	if (!std::isfinite(g.getXMin()) || !std::isfinite(g.getYMin()) || !std::isfinite(g.getXMax()) ||
		!std::isfinite(g.getYMax()))
		fail(path, "non-finite origin or extent");
	if (g.getSizeX() == 0 || g.getSizeY() == 0) fail(path, "the map has no cells");
}

COccupancyGridMap2D loadSerialized(const std::string& path)
{
	mrpt::io::CFileGZInputStream in;
	if (!in.open(path)) fail(path, "cannot open");
	COccupancyGridMap2D g;
	try
	{
		auto arch = mrpt::serialization::archiveFrom(in);
		arch >> g;
	}
	catch (const std::exception& e)
	{
		fail(path, std::string("not a serialized COccupancyGridMap2D (") + e.what() + ")");
	}
	return g;
}
}  // namespace

COccupancyGridMap2D loadGridMap(const std::string& path, double simplemap_resolution)
{
	if (!std::filesystem::is_regular_file(path)) fail(path, "no such file");
	COccupancyGridMap2D g;
	if (hasSuffix(path, ".gridmap") || hasSuffix(path, ".gridmap.gz"))
		g = loadSerialized(path);
	else if (hasSuffix(path, ".yaml") || hasSuffix(path, ".yml"))
	{
		bool ok = false;
		try
		{
			ok = g.loadFromROSMapServerYAML(path);
		}
		catch (const std::exception& e)
		{
			fail(path, std::string("unreadable map_server YAML or image (") + e.what() + ")");
		}
		if (!ok) fail(path, "unreadable map_server YAML or image");
	}
	else if (hasSuffix(path, ".simplemap") || hasSuffix(path, ".simplemap.gz"))
	{
		if (!std::isfinite(simplemap_resolution) || !(simplemap_resolution > 0))
			fail(path, "simplemap resolution must be > 0");
		try
		{
			const ScanSequence scans = loadSimplemapScans(path);
			g = renderGrid(scans, 0, scans.size(), simplemap_resolution);
		}
		catch (const std::exception& e)
		{
			fail(path, e.what());
		}
	}
	else
		fail(path, "unknown map format (expected .gridmap[.gz], .yaml or .simplemap[.gz])");
	checkLoaded(g, path);
	return g;
}

void saveGridMap(const COccupancyGridMap2D& grid, const std::string& path, const Similarity2D& frame)
{
	const bool identity = frame.scale == 1 && frame.yaw == 0 && frame.t.isZero();
	if (hasSuffix(path, ".gridmap") || hasSuffix(path, ".gridmap.gz"))
	{
		// MRPT snaps a grid's corner to whole cells: an arbitrary frame would shift it.
		if (!identity) fail(path, "a .gridmap cannot hold the map's origin pose exactly; save as .yaml");
		mrpt::io::CFileGZOutputStream out;
		if (!out.open(path, hasSuffix(path, ".gz") ? 6 : 0)) fail(path, "cannot write");
		auto arch = mrpt::serialization::archiveFrom(out);
		arch << grid;
		return;
	}
	if (hasSuffix(path, ".yaml") || hasSuffix(path, ".yml"))
	{
		const std::filesystem::path yaml(path);
		const std::filesystem::path pgm = std::filesystem::path(yaml).replace_extension(".pgm");
		cv::Mat img = toClassImage(grid);
		img.setTo(254, img == kFree);
		img.setTo(205, img == kUnknown);
		// map_server images have +y up: the first row is the top of the map.
		if (!cv::imwrite(pgm.string(), forDisplay(img))) fail(pgm.string(), "cannot write");
		const Eigen::Vector2d corner = frame.apply({grid.getXMin(), grid.getYMin()});
		std::ofstream y(path);
		y.precision(12);
		y << "image: " << pgm.filename().string() << "\n"
		  << "resolution: " << grid.getResolution() << "\n"
		  << "origin: [" << corner.x() << ", " << corner.y() << ", " << frame.yaw << "]\n"
		  << "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
		if (!y) fail(path, "cannot write");
		return;
	}
	fail(path, "unknown output format (expected .gridmap[.gz] or .yaml)");
}

}  // namespace multires_map_merge
