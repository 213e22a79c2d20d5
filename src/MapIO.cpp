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
#include <map>
#include <sstream>

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

/** The map_server YAML keys, read line by line: the format is flat, and a
 * general YAML parser (MRPT's libfyaml) hangs on some corrupt files (found
 * by fuzzing). */
COccupancyGridMap2D loadMapServerYaml(const std::string& path)
{
	std::ifstream in(path);
	if (!in) fail(path, "cannot open");
	const auto trim = [](const std::string& t) {
		const size_t a = t.find_first_not_of(" \t\r\"'"), b = t.find_last_not_of(" \t\r\"'");
		return a == std::string::npos ? std::string() : t.substr(a, b - a + 1);
	};
	std::map<std::string, std::string> kv;
	std::string line;
	for (int n = 0; std::getline(in, line); ++n)
	{
		if (n > 1000 || line.size() > 4096) fail(path, "not a map_server YAML (too long)");
		line = line.substr(0, line.find('#'));
		const size_t colon = line.find(':');
		if (colon != std::string::npos) kv[trim(line.substr(0, colon))] = trim(line.substr(colon + 1));
	}
	auto number = [&](const std::string& key, const std::string& text) {
		try
		{
			size_t used = 0;
			const double v = std::stod(text, &used);
			if (used == text.size() && std::isfinite(v)) return v;
		}
		catch (const std::exception&)
		{
		}
		fail(path, key + " must be a finite number, not '" + text + "'");
	};
	for (const char* key : {"image", "resolution", "origin"})
		if (!kv.count(key)) fail(path, std::string("unreadable map_server YAML: no '") + key + "'");
	const double res = number("resolution", kv["resolution"]);
	if (!(res > 0)) fail(path, "invalid resolution " + kv["resolution"]);
	std::string origin = kv["origin"];
	if (origin.size() < 2 || origin.front() != '[' || origin.back() != ']')
		fail(path, "origin must be [x, y, yaw], not '" + origin + "'");
	std::vector<double> o;
	std::stringstream items(origin.substr(1, origin.size() - 2));
	for (std::string item; std::getline(items, item, ',');) o.push_back(number("origin", trim(item)));
	if (o.size() < 2 || o.size() > 3) fail(path, "origin must be [x, y, yaw], not '" + origin + "'");
	if (o.size() == 3 && o[2] != 0) fail(path, "a rotated origin (yaw " + std::to_string(o[2]) + ") is not supported");
	const bool negate = kv.count("negate") && number("negate", kv["negate"]) != 0;
	const double occ_th = kv.count("occupied_thresh") ? number("occupied_thresh", kv["occupied_thresh"]) : 0.65;
	const double free_th = kv.count("free_thresh") ? number("free_thresh", kv["free_thresh"]) : 0.196;

	std::filesystem::path image(kv["image"]);
	if (image.is_relative()) image = std::filesystem::path(path).parent_path() / image;
	if (!std::filesystem::is_regular_file(image)) fail(path, "unreadable map_server YAML or image (no image '" + image.string() + "')");
	cv::Mat img;
	try
	{
		img = cv::imread(image.string(), cv::IMREAD_GRAYSCALE);
	}
	catch (const cv::Exception& e)
	{
		fail(path, "unreadable map_server YAML or image (" + std::string(e.what()) + ")");
	}
	if (img.empty()) fail(path, "unreadable map_server YAML or image ('" + image.string() + "' is not an image)");
	// map_server's trinary rule; images have +y up, grids row = cy.
	const cv::Mat rows = forDisplay(img);
	COccupancyGridMap2D g(
		float(o[0]), float(o[0] + rows.cols * res), float(o[1]), float(o[1] + rows.rows * res), float(res));
	for (int cy = 0; cy < rows.rows && cy < int(g.getSizeY()); ++cy)
		for (int cx = 0; cx < rows.cols && cx < int(g.getSizeX()); ++cx)
		{
			const double v = rows.at<uint8_t>(cy, cx) / 255.0;
			const double p_occ = negate ? v : 1 - v;
			g.setCell(cx, cy, p_occ > occ_th ? 0.0f : (p_occ < free_th ? 1.0f : 0.5f));
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
		g = loadMapServerYaml(path);
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
