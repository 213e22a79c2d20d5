#pragma once
// Carpin's map-merging test maps (../shared/data/carpin_mapmerge, SOURCES.md
// 4): gzipped text, one grid row per line, top row first, 0 occupied, 127
// unknown, 255 free. Those are map_server's own PGM values, so each map is
// written as a map_server file and read back as a user would feed it. The
// cell size is not stated (about 5 cm for the Intel lab): 5 cm. The
// benchmark's section (carpin_maps.h) and test_real_maps read them so.

#include "map_file.h"

#include <multires_map_merge/Similarity2D.h>

#include <mrpt/io/zip.h>

#include <opencv2/imgcodecs.hpp>

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace multires_map_merge::carpin
{
/** The grid as an 8-bit image, top row first; throws naming the file. */
inline cv::Mat readGrid(const std::string& txt_gz)
{
	std::vector<uint8_t> bytes;
	if (!mrpt::io::zip::decompress_gz_file(txt_gz, bytes)) throw std::runtime_error("'" + txt_gz + "': unreadable");
	std::istringstream text(std::string(bytes.begin(), bytes.end()));
	std::vector<std::vector<uint8_t>> rows;
	for (std::string line; std::getline(text, line);)
	{
		std::istringstream values(line);
		std::vector<uint8_t> row;
		for (int v; values >> v;)
		{
			if (v < 0 || v > 255) throw std::runtime_error("'" + txt_gz + "': value outside 0..255");
			row.push_back(uint8_t(v));
		}
		if (row.empty()) continue;
		if (!rows.empty() && row.size() != rows.front().size())
			throw std::runtime_error("'" + txt_gz + "': rows of different lengths");
		rows.push_back(std::move(row));
	}
	if (rows.empty()) throw std::runtime_error("'" + txt_gz + "': no grid");
	cv::Mat image(int(rows.size()), int(rows.front().size()), CV_8UC1);
	for (int r = 0; r < image.rows; ++r) std::copy(rows[r].begin(), rows[r].end(), image.ptr<uint8_t>(r));
	return image;
}

/** ap_hill's four partial maps are written roughly co-registered (best
 * offsets within 6 cells, turns of a few degrees, which move their far walls
 * up to ~15 cells): a placement within this of where a map lies (mean over
 * its occupied cells) is the right place, not a precise one. Another room is
 * 50 cells and more away. */
constexpr double kApHillRoughCells = 25;

/** Carpin's copies of the Intel map (800×800 cells), their grid cells (rows
 * bottom-up) → the Intel map's. intel30 is it shifted by (rows −30, cols
 * +30): (x − 30, y − 30); intel90 numpy's rot90 of it (pixel (column j, row
 * i) is the Intel map's (799 − i, j)): (y, 799 − x). */
inline Similarity2D intelCopyToIntel(const std::string& copy)
{
	if (copy == "intel30") return Similarity2D(1, 0, {-30, -30});
	if (copy == "intel90") return Similarity2D(1, -M_PI / 2, {0, 799});
	if (copy == "intel") return Similarity2D();
	throw std::invalid_argument("not one of Carpin's Intel maps: " + copy);
}

/** `<dir>/<name>.pgm` and `.yaml` (origin 0, `resolution`); returns the yaml. */
inline std::string writeAsMapServer(
	const std::string& txt_gz, const std::string& dir, const std::string& name, double resolution = 0.05)
{
	const std::string pgm = dir + "/" + name + ".pgm", yaml = dir + "/" + name + ".yaml";
	if (!cv::imwrite(pgm, readGrid(txt_gz))) throw std::runtime_error("cannot write '" + pgm + "'");
	multires_bench::writeMapServerYaml(yaml, name + ".pgm", resolution);
	return yaml;
}

}  // namespace multires_map_merge::carpin
