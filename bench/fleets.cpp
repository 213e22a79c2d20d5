#include "fleets.h"

#include "carmen.h"
#include "halmstad.h"

#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

/** In the child: places and fuses the fleet map_0.yaml, map_1.yaml, ... of
 * `dir` (map_0 the reference); prints the time, the pairs and each placement. */
int fleetChild(const BenchContext& ctx, const std::string& dir)
{
	std::vector<GridInFrame> maps;
	for (int i = 0; fs::exists(dir + "/map_" + std::to_string(i) + ".yaml"); ++i)
		maps.push_back(loadGridMap(dir + "/map_" + std::to_string(i) + ".yaml"));
	mrpt::system::CTicTac clock;
	const FleetParams& fp = ctx.fleet;
	const FleetResult r = placeFleet(maps, 0, ctx.aligner(), fp);
	const double placing = clock.Tac();
	const FusedFleet fused = fuseFleet(maps, r, 0, maps[0].grid.getResolution());
	const double seconds = clock.Tac();
	std::cout << std::setprecision(12) << "FLEET " << seconds << " " << r.pairs_aligned << " " << r.pairs_skipped << " "
			  << peakRssMb() << " " << placing << std::endl;
	size_t confident = 0, dropped = 0;
	for (const auto& e : r.edges) confident += e.merged, dropped += e.merged && e.dropped;
	std::cout << "EDGES " << confident << " " << dropped << std::endl;
	// The same pairs placed by the spanning tree alone, for the report's "tree alone".
	FleetParams tree_only = fp;
	tree_only.joint_refinement = false;
	const FleetResult tree = placeFromPairs(maps, 0, r.edges, tree_only);
	for (const auto& [tag, result] : {std::pair("MAP", &r), std::pair("TREE", &tree)})
		for (size_t i = 0; i < result->maps.size(); ++i)
		{
			const auto& p = result->maps[i].in_reference;
			std::cout << tag << " " << i << " " << result->maps[i].placed << " " << p.scale << " " << p.yaw << " "
					  << p.t.x() << " " << p.t.y() << " " << result->maps[i].parent << std::endl;
		}
	return 0;
}

/** Places the fleet map_0.yaml, map_1.yaml, … of `dir` in a fresh process
 * (fleetChild); returns the file holding what it printed. */
std::string placeFleetInChild(const BenchContext& ctx, const std::string& dir)
{
	const std::string out = dir + "/out.txt";
	runSelf(ctx.selfWith({"--fleet-child", dir}), out);
	return out;
}

namespace
{
/** A fleet of `n` robots of fr079, each a 40 % share of the run spread over
 * it, at resolutions cycling over 5, 3, 8, 4, 6, 10, 2.5, 7 cm, in frames
 * turned by 37° more each, origins off the lattice, as map_server files;
 * `pad_to` > 0 pads each to that many cells a side. `beyond_reference` adds
 * a robot (4 cm) that saw nothing the reference saw (it can only be placed
 * through another robot); `other_building` an intel robot that must stay
 * out. Placed in a fresh process. */
FleetCase runFleetCase(const BenchContext& ctx, const std::string& name, int n, int pad_to, bool beyond_reference,
					   bool other_building, double fixed_res = 0)
{
	FleetCase c;
	c.name = name;
	c.maps = n + beyond_reference + other_building;
	c.building = n - 1 + beyond_reference;
	const int other_index = other_building ? c.maps - 1 : -1;
	const fs::path dir = fs::temp_directory_path() / ("multires_bench_fleet_" + std::to_string(getpid()));
	fs::remove_all(dir);
	fs::create_directories(dir);
	const std::vector<double> res_cycle = {0.05, 0.03, 0.08, 0.04, 0.06, 0.10, 0.025, 0.07};
	std::vector<Similarity2D> truth;
	std::vector<double> res;
	std::vector<GridInFrame> written;
	for (int i = 0; i < c.maps; ++i)
	{
		const bool other = i == other_index, beyond = beyond_reference && i == n;
		const ScanSequence& s = scansOf(ctx, other ? "intel" : "fr079");
		const double r = beyond ? 0.04 : fixed_res > 0 ? fixed_res : res_cycle[i % res_cycle.size()];
		const double begin = other || n == 1 ? 0.0 : beyond ? 0.45 : 0.6 * i / (n - 1);
		const double end = beyond ? 1.0 : std::min(1.0, begin + 0.4);
		const mrpt::poses::CPose2D frame = i == 0 || other ? mrpt::poses::CPose2D()
														   : mrpt::poses::CPose2D(0.5 * i, -0.3 * i, (37.0 * i) * M_PI / 180);
		truth.push_back(Similarity2D(1, frame.phi(), {frame.x(), frame.y()}));
		GridInFrame g = renderGridOffLattice(s, size_t(begin * s.size()), size_t(end * s.size()), r, frame, 0.37 * r, 0.61 * r);
		if (beyond) forgetSeenBy(g, truth.back(), written[0], 1.0);
		if (pad_to > 0)
		{
			const float cell = g.grid.getResolution();
			const int w = std::max<int>(pad_to, g.grid.getSizeX()), h = std::max<int>(pad_to, g.grid.getSizeY());
			g.grid.resizeGrid(g.grid.getXMin(), g.grid.getXMin() + w * cell, g.grid.getYMin(), g.grid.getYMin() + h * cell, 0.5f, false);
		}
		saveGridMap(g, (dir / ("map_" + std::to_string(i) + ".yaml")).string());
		res.push_back(r);
		c.sizes += (i ? ", " : "") + std::to_string(g.grid.getSizeX()) + "×" + std::to_string(g.grid.getSizeY()) + " @ " +
			num(r * 100, 1) + " cm" + (beyond ? " (beyond the reference)" : other ? " (another building)" : "");
		written.push_back(loadGridMap((dir / ("map_" + std::to_string(i) + ".yaml")).string()));
	}
	const std::string out = placeFleetInChild(ctx, dir.string());
	std::ifstream f(out);
	double worst = 0;
	for (std::string line; std::getline(f, line);)
	{
		std::istringstream in(line.substr(line.find(' ') + 1));
		if (line.rfind("FLEET ", 0) == 0)
		{
			in >> c.seconds >> c.aligned >> c.skipped >> c.peak_mb >> c.placing_seconds;
		}
		else if (line.rfind("MAP ", 0) == 0)
		{
			int i = 0;
			bool placed = false;
			double sc = 1, yaw = 0, x = 0, y = 0;
			in >> i >> placed >> sc >> yaw >> x >> y;
			if (i == 0 || !placed) continue;
			if (i == other_index)
			{
				++c.others_placed;
				continue;
			}
			const double e = pointRmse(Similarity2D(sc, yaw, {x, y}), truth[i], metricEdges(written[i])) / std::max(res[0], res[i]);
			worst = std::max(worst, e);
			(e <= 2 ? c.placed_right : c.placed_wrong)++;
		}
	}
	if (!(c.seconds > 0)) throw std::runtime_error("fleet case " + name + " failed (see " + out + ")");
	c.max_err = c.placed_right + c.placed_wrong ? worst : NAN;
	if (std::getenv("MMM_BENCH_KEEP_FLEET"))  // for profiling the child: bench/README.md
		std::cout << "kept " << dir << std::endl;
	else
		fs::remove_all(dir);
	std::cout << "fleet " << name << ": " << c.placed_right << "/" << c.building << " placed right, " << c.placed_wrong
			  << " wrong, " << c.others_placed << " of another building placed; " << c.aligned << " pairs aligned, "
			  << c.skipped << " skipped; " << c.seconds << " s, peak " << c.peak_mb << " MB" << std::endl;
	return c;
}
}  // namespace

std::vector<FleetCase> runFleets(const BenchContext& ctx)
{
	const bool quick = ctx.quick;
	std::vector<FleetCase> cases;
	for (int n : quick ? std::vector<int>{3} : std::vector<int>{2, 3, 4, 5, 6, 7, 8})
		cases.push_back(runFleetCase(ctx, "N = " + std::to_string(n), n, 0, false, false));
	if (!quick)
	{
		cases.push_back(runFleetCase(ctx, "5 / 3 / 8 cm, one 4 cm beyond the reference, + another building", 3, 0, true, true));
		cases.push_back(runFleetCase(ctx, "8 maps of 1000×1000 cells", 8, 1000, false, false, 0.05));
	}
	return cases;
}

void writeFleetSection(std::ostream& md, const std::vector<FleetCase>& cases)
{
	md << "\n## Fleets: N maps into one\n\n"
	   << "Robots of fr079, each mapping a 40 % share of the run (the shares spread over it, so robot i overlaps "
		  "its neighbours, not necessarily the reference), at its own resolution and in its own frame (turned by "
		  "37° more each, origins off the lattice), written as map_server files; `placeFleet` + `fuseFleet` in a "
		  "fresh process (time and peak RSS of the whole placement and fusion). **Right** = placed within 2 cells "
		  "of the coarser map of the robot and the reference, against the exact truth.\n\n"
	   << "| fleet | maps (cells @ resolution) | placed right | placed wrong | other building placed | pairs aligned | "
		  "pairs skipped | worst error [cells] | time [s] | of which placing [s] | peak RSS [MB] |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& c : cases)
		md << "| " << c.name << " | " << c.sizes << " | " << c.placed_right << " / " << c.building << " | "
		   << c.placed_wrong << " | " << (c.maps > int(c.building) + 1 ? std::to_string(c.others_placed) : "–") << " | "
		   << c.aligned << " | " << c.skipped << " | " << num(c.max_err, 2) << " | " << num(c.seconds, 1) << " | " << num(c.placing_seconds, 1) << " | "
		   << num(c.peak_mb, 0) << " |\n";
}

}  // namespace multires_bench
