#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/ScanLog.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <unistd.h>  // access(): may this process write there

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

std::string whyNotWritable(const std::string& path)
{
	namespace fs = std::filesystem;
	const fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
	std::error_code ec;
	if (!fs::is_directory(folder, ec)) return "no folder '" + folder.string() + "' to write into";
	const bool exists = fs::exists(path, ec);
	if (exists && !fs::is_regular_file(path, ec)) return "exists and is not a file";
	const bool writable = exists ? ::access(path.c_str(), W_OK) == 0 : ::access(folder.c_str(), W_OK | X_OK) == 0;
	return writable ? "" : "cannot write there (permission denied)";
}

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

/** How map_server turns pixels into occupancy (ROS 1 Noetic map_server). */
enum class MapServerMode
{
	trinary,
	scale,
	raw
};

struct MapServerYaml
{
	std::filesystem::path image;
	double resolution = 0;
	double origin[3] = {0, 0, 0};
	bool negate = false;
	double occupied_thresh = 0.65, free_thresh = 0.196;
	MapServerMode mode = MapServerMode::trinary;
	bool floor_plan = false;  // ours, beside map_server's keys (which it ignores)
};

// A map_server YAML is a few hundred bytes; the limit keeps the parser away
// from anything that is not one.
constexpr std::uintmax_t kMaxYamlBytes = 64 * 1024;

MapServerYaml readMapServerYaml(const std::string& path)
{
	if (std::filesystem::file_size(path) > kMaxYamlBytes)
		fail(path, "not a map_server YAML (larger than " + std::to_string(kMaxYamlBytes / 1024) + " KiB)");
	YAML::Node doc;
	try
	{
		doc = YAML::LoadFile(path);
	}
	catch (const YAML::Exception& e)
	{
		fail(path, "not a map_server YAML (" + e.msg + " at line " + std::to_string(e.mark.line + 1) + ")");
	}
	if (!doc.IsMap()) fail(path, "not a map_server YAML (expected keys image, resolution, origin, ...)");
	auto scalar = [&](const char* key) -> const YAML::Node {
		const YAML::Node n = doc[key];
		if (!n.IsScalar()) fail(path, std::string("'") + key + "' must be a single value");
		return n;
	};
	auto number = [&](const char* key, const YAML::Node& n) {
		double v = NAN;
		try
		{
			v = n.as<double>();
		}
		catch (const YAML::Exception&)
		{
		}
		if (!std::isfinite(v))
			fail(path, std::string("'") + key + "' must be a finite number, not '" + (n.IsScalar() ? n.Scalar() : "a list") + "'");
		return v;
	};
	for (const char* key : {"image", "resolution", "origin"})
		if (!doc[key]) fail(path, std::string("unreadable map_server YAML: no '") + key + "'");

	MapServerYaml y;
	y.image = scalar("image").Scalar();
	if (y.image.empty()) fail(path, "'image' is empty");
	if (y.image.is_relative()) y.image = std::filesystem::path(path).parent_path() / y.image;
	y.resolution = number("resolution", scalar("resolution"));
	if (!(y.resolution > 0)) fail(path, "'resolution' must be > 0, not " + doc["resolution"].Scalar());
	const YAML::Node origin = doc["origin"];
	if (!origin.IsSequence() || origin.size() < 2 || origin.size() > 3)
		fail(path, "'origin' must be [x, y, yaw]");
	for (size_t i = 0; i < origin.size(); ++i) y.origin[i] = number("origin", origin[i]);
	// Absent keys take map_server's documented defaults (ROS 1 map_server
	// itself refuses such a file; nothing is gained by refusing it here).
	if (doc["negate"])
	{
		const YAML::Node n = scalar("negate");
		bool b = false;
		if (YAML::convert<bool>::decode(n, b))
			y.negate = b;
		else
			y.negate = number("negate", n) != 0;
	}
	if (doc["floor_plan"])
	{
		bool b = false;
		if (!YAML::convert<bool>::decode(scalar("floor_plan"), b))
			fail(path, "'floor_plan' must be true or false, not '" + scalar("floor_plan").Scalar() + "'");
		y.floor_plan = b;
	}
	if (doc["occupied_thresh"]) y.occupied_thresh = number("occupied_thresh", scalar("occupied_thresh"));
	if (doc["free_thresh"]) y.free_thresh = number("free_thresh", scalar("free_thresh"));
	for (const auto& [key, v] : {std::pair{"occupied_thresh", y.occupied_thresh}, std::pair{"free_thresh", y.free_thresh}})
		if (v < 0 || v > 1) fail(path, std::string("'") + key + "' must be in [0, 1], not " + std::to_string(v));
	if (doc["mode"])
	{
		const std::string mode = scalar("mode").Scalar();
		if (mode == "trinary") y.mode = MapServerMode::trinary;
		else if (mode == "scale") y.mode = MapServerMode::scale;
		else if (mode == "raw") y.mode = MapServerMode::raw;
		else fail(path, "'mode' must be trinary, scale or raw, not '" + mode + "'");
	}
	if (y.mode == MapServerMode::scale && !(y.occupied_thresh > y.free_thresh))
		fail(path, "'mode: scale' needs occupied_thresh > free_thresh");
	return y;
}

/** A pixel's occupancy in [0, 1] as map_server reads it (trinary and scale
 * modes): dark is occupied, unless `negate`. */
double pixelOccupancy(double colour, const MapServerYaml& y)
{
	return (y.negate ? colour : 255 - colour) / 255.0;
}

/** Occupancy in 0..100, or -1 for unknown, of one pixel: map_server's rules.
 * `colour` is the channel mean (alpha included in trinary mode, as
 * map_server does), `opaque` false for a fully transparent pixel. */
int mapServerValue(double colour, bool opaque, const MapServerYaml& y)
{
	if (y.mode == MapServerMode::raw)
	{
		// map_server copies the byte into an int8: 0..100 are occupancies,
		// 255 reads as -1 (unknown); anything else is no occupancy at all.
		const int v = static_cast<int>(y.negate ? 255 - colour : colour);
		return v <= 100 ? v : -1;
	}
	const double occ = pixelOccupancy(colour, y);
	if (occ > y.occupied_thresh) return 100;
	if (occ < y.free_thresh) return 0;
	if (y.mode == MapServerMode::trinary || !opaque) return -1;
	return static_cast<int>(99 * (occ - y.free_thresh) / (y.occupied_thresh - y.free_thresh));
}

/** Grey walls (trinary mode): an image whose walls are drawn in grey
 * probabilities (a probabilistic SLAM's map saved as is, a drawn plan) has
 * many wall pixels between free_thresh and occupied_thresh, which map_server
 * reads as unknown, losing the walls. Unexplored space is drawn in one grey:
 * where one in-between value holds most in-between pixels, an in-between
 * pixel darker than it by more than this (occupancy, 0.1 ≈ 25 grey levels)
 * is read as a faint wall. Elsewhere map_server's reading stands. */
constexpr double kFaintWallMargin = 0.1;

GridInFrame loadMapServerYaml(const std::string& path)
{
	const MapServerYaml y = readMapServerYaml(path);
	if (!std::filesystem::is_regular_file(y.image))
		fail(path, "unreadable map_server YAML or image (no image '" + y.image.string() + "')");
	cv::Mat img;
	try
	{
		img = cv::imread(y.image.string(), cv::IMREAD_UNCHANGED);
	}
	catch (const cv::Exception& e)
	{
		fail(path, "unreadable map_server YAML or image (" + std::string(e.what()) + ")");
	}
	if (img.empty()) fail(path, "unreadable map_server YAML or image ('" + y.image.string() + "' is not an image)");
	if (img.depth() == CV_16U) img.convertTo(img, CV_8U, 1.0 / 257);  // as SDL_image reads 16-bit PNGs
	if (img.depth() != CV_8U || img.channels() > 4)
		fail(path, "image '" + y.image.string() + "' is not an 8- or 16-bit grey or colour image");
	const int channels = img.channels();
	const bool has_alpha = channels == 2 || channels == 4;
	// map_server averages alpha in with the colour in trinary mode only.
	const int averaged = (has_alpha && y.mode != MapServerMode::trinary) ? channels - 1 : channels;

	// A pixel's reading depends only on its channel sum and whether it is
	// opaque: read through tables over those, each value worked out once.
	auto channelSum = [&](const uint8_t* px) {
		int sum = 0;
		for (int k = 0; k < averaged; ++k) sum += px[k];
		return sum;
	};
	auto opaqueAt = [&](const uint8_t* px) { return !has_alpha || px[channels - 1] > 0; };
	const int sums = 255 * averaged + 1;
	// The unknown grey: the commonest in-between colour (trinary mode).
	std::optional<double> faint_wall_above;  // occupancy
	if (y.mode == MapServerMode::trinary)
	{
		std::vector<int> in_between_bin(sums, -1);  // by channel sum, for an opaque pixel
		for (int sum = 0; sum < sums; ++sum)
			if (const double colour = double(sum) / averaged; mapServerValue(colour, true, y) < 0)
				in_between_bin[sum] = static_cast<int>(std::lround(colour));
		std::array<size_t, 256> in_between{};
		for (int row = 0; row < img.rows; ++row)
		{
			const uint8_t* px = img.ptr<uint8_t>(row);
			for (int cx = 0; cx < img.cols; ++cx, px += channels)
				if (const int bin = in_between_bin[channelSum(px)]; bin >= 0 && opaqueAt(px)) ++in_between[bin];
		}
		const auto commonest = std::max_element(in_between.begin(), in_between.end());
		const size_t all_in_between = std::accumulate(in_between.begin(), in_between.end(), size_t(0));
		if (2 * *commonest > all_in_between)
		{
			const double grey = double(commonest - in_between.begin());
			faint_wall_above = pixelOccupancy(grey, y) + kFaintWallMargin;
		}
	}
	auto occupancyOf = [&](double colour, bool opaque) {
		const int v = mapServerValue(colour, opaque, y);
		float occupancy = v < 0 ? 0.5f : v / 100.0f;
		if (v < 0 && faint_wall_above && opaque)
		{
			// Between the unknown grey's occupancy and occupied_thresh
			// onto (0.5, 1]: a wall (kOccupiedAbove), as sure as it is dark.
			const double occ = pixelOccupancy(colour, y);
			const double unknown = *faint_wall_above - kFaintWallMargin;
			if (occ > *faint_wall_above && y.occupied_thresh > unknown)
				occupancy = float(std::min(1.0, 0.5 + 0.5 * (occ - unknown) / (y.occupied_thresh - unknown)));
		}
		return occupancy;
	};
	using Cell = COccupancyGridMap2D::cellType;
	std::array<std::vector<Cell>, 2> cell_of;  // [opaque][channel sum]; MRPT stores P(free)
	for (int opaque : {0, 1})
		for (int sum = 0; sum < sums; ++sum)
			cell_of[opaque].push_back(COccupancyGridMap2D::p2l(1.0f - occupancyOf(double(sum) / averaged, opaque)));

	GridInFrame map;
	map.origin = Similarity2D(1, y.origin[2], {y.origin[0], y.origin[1]});
	map.kind = y.floor_plan ? MapKind::FloorPlan : MapKind::Sensed;
	COccupancyGridMap2D& g = map.grid;
	g.setSize(0, float(img.cols * y.resolution), 0, float(img.rows * y.resolution), float(y.resolution), 0.5f);
	if (int(g.getSizeX()) != img.cols || int(g.getSizeY()) != img.rows)
		fail(path, "resolution " + std::to_string(y.resolution) + " is too extreme for a " +
					   std::to_string(img.cols) + "x" + std::to_string(img.rows) + " image");
	for (int row = 0; row < img.rows; ++row)
	{
		const uint8_t* px = img.ptr<uint8_t>(row);
		Cell* cells = g.getRow(img.rows - 1 - row);  // image rows run top-down, grid rows bottom-up
		for (int cx = 0; cx < img.cols; ++cx, px += channels) cells[cx] = cell_of[opaqueAt(px)][channelSum(px)];
	}
	return map;
}
}  // namespace

GridInFrame loadGridMap(const std::string& path, double simplemap_resolution)
{
	if (!std::filesystem::is_regular_file(path)) fail(path, "no such file");
	GridInFrame map;
	if (hasSuffix(path, ".gridmap") || hasSuffix(path, ".gridmap.gz"))
		map.grid = loadSerialized(path);
	else if (hasSuffix(path, ".yaml") || hasSuffix(path, ".yml"))
		map = loadMapServerYaml(path);
	else if (hasSuffix(path, ".simplemap") || hasSuffix(path, ".simplemap.gz"))
	{
		if (!std::isfinite(simplemap_resolution) || !(simplemap_resolution > 0))
			fail(path, "simplemap resolution must be > 0");
		try
		{
			const ScanSequence scans = loadSimplemapScans(path);
			map.grid = renderGrid(scans, 0, scans.size(), simplemap_resolution);
		}
		catch (const std::exception& e)
		{
			fail(path, e.what());
		}
	}
	else
		fail(path, "unknown map format (expected .gridmap[.gz], .yaml or .simplemap[.gz])");
	checkLoaded(map.grid, path);
	return map;
}

std::vector<GridInFrame> loadGridMaps(const std::vector<std::string>& paths, double simplemap_resolution)
{
	std::vector<GridInFrame> maps(paths.size());
	std::vector<std::exception_ptr> errors(paths.size());
#pragma omp parallel for schedule(dynamic, 1)
	for (size_t i = 0; i < paths.size(); ++i)
	{
		try
		{
			maps[i] = loadGridMap(paths[i], simplemap_resolution);
		}
		catch (...)
		{
			errors[i] = std::current_exception();  // an exception may not leave the parallel loop
		}
	}
	// Every file that cannot be read is named at once: a user fixing a
	// fleet's list should not find the bad files one run at a time.
	// A failure that is not the file's (out of memory and the like) is said
	// as it is, before any file's.
	std::vector<std::string> problems;
	std::exception_ptr first, unexpected;
	for (const auto& e : errors)
	{
		if (!e) continue;
		if (!first) first = e;
		try
		{
			std::rethrow_exception(e);
		}
		catch (const MapIOError& bad_file)
		{
			problems.push_back(bad_file.what());
		}
		catch (...)
		{
			if (!unexpected) unexpected = e;
		}
	}
	if (unexpected) std::rethrow_exception(unexpected);
	if (problems.size() > 1)
	{
		throw MapIOError(everyMapsProblem(problems, "cannot be read"));
	}
	if (first) std::rethrow_exception(first);
	return maps;
}

std::string everyMapsProblem(const std::vector<std::string>& problems, const std::string& what)
{
	std::string all = std::to_string(problems.size()) + " maps " + what + ": ";
	for (size_t i = 0; i < problems.size(); ++i) all += (i ? "; " : "") + problems[i];
	return all;
}

std::string saveGridMap(const GridInFrame& map, const std::string& path)
{
	const COccupancyGridMap2D& grid = map.grid;
	if (hasSuffix(path, ".gridmap") || hasSuffix(path, ".gridmap.gz"))
	{
		std::string note;
		const COccupancyGridMap2D* out = &grid;
		COccupancyGridMap2D moved;
		if (!map.originIsIdentity())
		{
			if (map.origin.yaw != 0)
				fail(path, "a .gridmap cannot hold a rotated map origin; save as .yaml");
			// MRPT snaps the corner to a multiple of the cell size.
			const Eigen::Vector2d corner = map.cornerInMapFrame();
			const double r = grid.getResolution();
			moved.setSize(
				float(corner.x()), float(corner.x() + grid.getSizeX() * r), float(corner.y()),
				float(corner.y() + grid.getSizeY() * r), float(r), 0.5f);
			const unsigned w = std::min(moved.getSizeX(), grid.getSizeX()), h = std::min(moved.getSizeY(), grid.getSizeY());
			for (unsigned cy = 0; cy < h; ++cy)
				for (unsigned cx = 0; cx < w; ++cx) moved.setCell(cx, cy, grid.getCell(cx, cy));
			const Eigen::Vector2d shift = Eigen::Vector2d(moved.getXMin(), moved.getYMin()) - corner;
			if (shift.norm() > 1e-9)
			{
				std::ostringstream s;
				s << "a .gridmap keeps its corner on a multiple of the cell size: the map in '" << path
				  << "' is shifted by (" << shift.x() << ", " << shift.y() << ") m; a .yaml holds it exactly";
				note = s.str();
			}
			out = &moved;
		}
		mrpt::io::CFileGZOutputStream stream;
		if (!stream.open(path, hasSuffix(path, ".gz") ? 6 : 0)) fail(path, "cannot write");
		auto arch = mrpt::serialization::archiveFrom(stream);
		arch << *out;
		return note;
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
		std::ofstream y(path);
		y << mapServerYaml(
			pgm.filename().string(), grid.getResolution(), map.cornerInMapFrame(), map.origin.yaw, map.kind);
		if (!y) fail(path, "cannot write");
		return "";
	}
	fail(path, "unknown output format (expected .gridmap[.gz] or .yaml)");
}

namespace
{
/** The shortest decimal that reads back as `v` exactly. */
template <typename Number>
std::string exactDecimal(Number v)
{
	std::array<char, 32> text{};
	const auto end = std::to_chars(text.data(), text.data() + text.size(), v).ptr;
	return std::string(text.data(), end);
}

/** `s` as a YAML double-quoted scalar: a file name may hold '#' or ": ",
 * which a plain scalar would end at. */
std::string quotedYaml(const std::string& s)
{
	YAML::Emitter e;
	e << YAML::DoubleQuoted << s;
	return e.c_str();
}
}  // namespace

std::string mapServerYaml(
	const std::string& image, double resolution, const Eigen::Vector2d& corner, double yaw, MapKind kind)
{
	// A grid's resolution is a float: written as that float's shortest
	// decimal (0.05, not 0.05000000074505806), which a grid reads back as it.
	const bool a_float = double(float(resolution)) == resolution;
	return "image: " + quotedYaml(image) +
		"\nresolution: " + (a_float ? exactDecimal(float(resolution)) : exactDecimal(resolution)) +
		"\norigin: [" + exactDecimal(corner.x()) + ", " + exactDecimal(corner.y()) + ", " + exactDecimal(yaw) +
		"]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n" +
		(kind == MapKind::FloorPlan ? "floor_plan: true\n" : "");
}

std::string saveGridMap(const COccupancyGridMap2D& grid, const std::string& path)
{
	return saveGridMap(GridInFrame{grid, Similarity2D()}, path);
}

}  // namespace multires_map_merge
