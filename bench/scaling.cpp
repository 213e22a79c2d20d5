#include "scaling.h"

#include "carmen.h"
#include "halmstad.h"
#include "mrpt_anchor.h"

#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

/** In the child: align two saved grids and print the time; the parent
 * reads the child's peak memory (maps + aligner, nothing else). */
int scalingChild(const BenchContext& ctx, const std::string& ref_path, const std::string& other_path)
{
	const auto ref = loadGridMap(ref_path), other = loadGridMap(other_path);
	CScalingGridMapAligner aligner = ctx.aligner();
	mrpt::system::CTicTac clock;
	const auto r = aligner.alignScaled(ref, other);
	const double seconds = clock.Tac();
	std::cout << "SCALING " << seconds << " " << r.success << " " << peakRssMb() << "\nMESSAGE " << r.message << std::endl;
	return 0;
}

/** In the child: MRPT's aligner on two map files (the parent enforces a time
 * limit by killing it). Prints the pose between the maps' frames. */
int mrptChild(const std::string& ref_path, const std::string& other_path)
{
	const GridInFrame ref = loadGridMap(ref_path), other = loadGridMap(other_path);
	const AnchorResult a = alignWithMrpt(ref.grid, other.grid);
	const Similarity2D m = betweenMapFrames(ref, a.metric, other);
	std::cout << "MRPT " << a.aligned << " " << a.seconds << " " << m.t.x() << " " << m.t.y() << " " << m.yaw << std::endl;
	return 0;
}


/** MRPT's aligner on two map files in a child process, killed after `limit_s`. */
LimitedMrpt mrptWithTimeLimit(const std::string& self, const std::string& ref, const std::string& other, double limit_s)
{
	LimitedMrpt res;
	const std::string out = (fs::temp_directory_path() / ("multires_bench_mrpt_" + std::to_string(getpid()) + ".out")).string();
	const pid_t pid = spawnSelf({self, "--mrpt-align", ref, "--scaling-other", other}, out);
	if (pid < 0) return res;
	const auto t0 = std::chrono::steady_clock::now();
	int status = 0;
	while (waitpid(pid, &status, WNOHANG) == 0)
	{
		if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > limit_s)
		{
			kill(pid, SIGKILL);
			waitpid(pid, &status, 0);
			res.seconds = limit_s;
			fs::remove(out);
			return res;
		}
		usleep(20000);
	}
	std::ifstream f(out);
	for (std::string line; std::getline(f, line);)
		if (line.rfind("MRPT ", 0) == 0)
		{
			std::istringstream in(line.substr(5));
			double x = 0, y = 0, yaw = 0;
			in >> res.aligned >> res.seconds >> x >> y >> yaw;
			res.metric = Similarity2D(1, yaw, {x, y});
			res.finished = true;
		}
	fs::remove(out);
	return res;
}

/** Renders the fr079 pair so the reference's longer side has about `cells`
 * cells (the other at half the resolution, rotated 30°), saves both, and
 * aligns them in a fresh process. */
ScalingCase runScalingCase(const BenchContext& ctx, int cells)
{
	ScalingCase c;
	c.cells = cells;
	const ScanSequence& s = scansOf(ctx, "fr079");
	const auto probe = renderGrid(s, 0, s.size() * 6 / 10, 0.1);
	c.ref_res = std::max(probe.getXMax() - probe.getXMin(), probe.getYMax() - probe.getYMin()) / cells;
	c.other_res = 2 * c.ref_res;
	const fs::path dir = fs::temp_directory_path() / "multires_bench_scaling";
	fs::create_directories(dir);
	const std::string cells_s = std::to_string(cells);
	const std::string ref_path = dir / (cells_s + "_ref.gridmap"), other_path = dir / (cells_s + "_other.gridmap");
	const std::string out = dir / (cells_s + ".out");
	{
		// Padded with unknown cells to exactly cells x cells (the other to
		// half that): the cost is the grid's, whatever the building fills.
		auto square = [](mrpt::maps::COccupancyGridMap2D g, int n) {
			const float r = g.getResolution();
			const int side = std::max<int>(n, std::max(g.getSizeX(), g.getSizeY()));
			g.resizeGrid(g.getXMin(), g.getXMin() + side * r, g.getYMin(), g.getYMin() + side * r, 0.5f, false);
			return g;
		};
		const auto ref = square(renderGrid(s, 0, s.size() * 6 / 10, c.ref_res), cells);
		c.ref_w = ref.getSizeX(), c.ref_h = ref.getSizeY();
		saveGridMap(ref, ref_path);
		saveGridMap(
			square(renderGrid(s, s.size() * 4 / 10, s.size(), c.other_res, mrpt::poses::CPose2D(1.5, -2.5, 30 * M_PI / 180)),
				   cells / 2),
			other_path);
	}
	const auto started = std::chrono::steady_clock::now();
	runSelf(ctx.selfWith({"--scaling-align", ref_path, "--scaling-other", other_path}), out);
	c.process_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
	std::ifstream f(out);
	std::string line;
	while (std::getline(f, line))
		if (line.rfind("SCALING ", 0) == 0)
		{
			std::istringstream in(line.substr(8));
			in >> c.seconds >> c.merged >> c.peak_mb;
		}
		else if (line.rfind("MESSAGE ", 0) == 0)
			c.message = line.substr(8);
	if (!(c.seconds > 0)) throw std::runtime_error("scaling case " + cells_s + " failed (see " + out + ")");
	if (std::getenv("MMM_BENCH_KEEP_SCALING"))  // for profiling the child: bench/README.md
		std::cout << "kept " << ref_path << " " << other_path << std::endl;
	else
		fs::remove(ref_path), fs::remove(other_path);
	std::cout << "scaling " << c.ref_w << "x" << c.ref_h << " cells: " << c.seconds << " s, peak " << c.peak_mb
			  << " MB" << std::endl;
	return c;
}


WholeProcessRow runWholeProcess(const BenchContext& ctx, double res)
{
	WholeProcessRow row;
	row.res = res;
	const fs::path dir = fs::temp_directory_path() / ("multires_bench_process_" + std::to_string(getpid()));
	fs::create_directories(dir);
	const std::string ref = (dir / "ref.yaml").string(), other = (dir / "other.yaml").string(), out = (dir / "out.txt").string();
	saveGridMap(*mapServerFile(ctx, "fr079", true, res, 0), ref);
	saveGridMap(*mapServerFile(ctx, "fr079", false, res, 0), other);
	auto run = [&](const std::vector<std::string>& args, const char* tag, bool& ok, double& peak_mb) {
		std::vector<double> times;
		for (int k = 0; k < 3; ++k)
		{
			const auto t0 = std::chrono::steady_clock::now();
			runSelf(args, out);
			times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
			std::ifstream f(out);
			for (std::string line; std::getline(f, line);)
				if (line.rfind(tag, 0) == 0)
				{
					std::istringstream in(line.substr(std::string(tag).size()));
					double seconds = 0;
					if (std::string(tag) == "SCALING ")
						in >> seconds >> ok >> peak_mb;  // SCALING seconds merged peak
					else
						in >> ok;  // MRPT aligned seconds ...
				}
		}
		return median(times);
	};
	double unused = 0;
	row.ours_s = run(ctx.selfWith({"--scaling-align", ref, "--scaling-other", other}), "SCALING ", row.ours_merged, row.ours_peak_mb);
	row.mrpt_s = run({ctx.self, "--mrpt-align", ref, "--scaling-other", other}, "MRPT ", row.mrpt_aligned, unused);
	fs::remove_all(dir);
	std::cout << "whole process " << res * 100 << " cm: ours " << row.ours_s << " s, MRPT " << row.mrpt_s << " s" << std::endl;
	return row;
}

}  // namespace multires_bench
