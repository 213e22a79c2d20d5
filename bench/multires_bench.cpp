// multires_bench: the paper's experiments on real SLAM-corrected logs, side
// by side with MRPT's CGridMapAligner, in one run. Writes pairs.csv, PNG
// matrices and plots, and REPORT.md (every number in it comes from this run).
//   multires_bench --quick  --out DIR     a few pairs (CI: the bench cannot rot)
//   multires_bench --out DIR              the full run (bench/README.md)
// A child mode aligns one scaling case in a fresh process, so its peak
// memory is its own (maps + aligner).

#include <mrpt/config/CConfigFile.h>
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/TsICP.h>

#include <mrpt/system/CTicTac.h>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <tclap/CmdLine.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>

#include "coarser_other.h"
#include "floor_plans.h"
#include "halmstad.h"
#include "halmstad_fleets.h"
#include "live_fleet.h"
#include "mrpt_anchor.h"
#include "plots.h"

extern char** environ;

using namespace multires_map_merge;
using namespace multires_bench;
namespace fs = std::filesystem;

namespace
{
// ---------------------------------------------------------------- data
struct Log
{
	std::string name, file;
};
const std::vector<Log> kLogs = {
	{"fr079", "freiburg-079-corrected.log.gz"}, {"intel", "intel-corrected.log.gz"},
	{"fr101", "freiburg-101-corrected.log.gz"}, {"orebro", "orebro-corrected.log.gz"},
	{"fhw", "fhw-corrected.log.gz"},           {"belgioioso", "belgioioso-corrected.log.gz"},
};

std::string g_data;  // ../shared/data

const ScanSequence& scansOf(const std::string& log)
{
	static std::map<std::string, ScanSequence> cache;
	auto it = cache.find(log);
	if (it != cache.end()) return it->second;
	for (const auto& l : kLogs)
		if (l.name == log) return cache.emplace(log, loadScans(g_data + "/carmen_corrected/" + l.file)).first->second;
	throw std::runtime_error("unknown log " + log);
}

/** The paper's split: the reference renders the first 60 % of the run, the
 * other the last 60 %, in a frame rotated by yaw and shifted. Renders are
 * cached: a row of the matrix shares its reference. */
const mrpt::maps::COccupancyGridMap2D& render(const std::string& log, bool ref, double res, double yaw_deg)
{
	static std::map<std::tuple<std::string, bool, long, long>, mrpt::maps::COccupancyGridMap2D> cache;
	const auto key = std::make_tuple(log, ref, std::lround(res * 1e4), std::lround(yaw_deg * 100));
	auto it = cache.find(key);
	if (it != cache.end()) return it->second;
	if (cache.size() > 40) cache.clear();  // bounded memory on the full run
	const ScanSequence& s = scansOf(log);
	const size_t n = s.size();
	const auto g = ref ? renderGrid(s, 0, n * 6 / 10, res)
					   : renderGrid(s, n * 4 / 10, n, res, mrpt::poses::CPose2D(1.5, -2.5, yaw_deg * M_PI / 180));
	return cache.emplace(key, g).first->second;
}

Similarity2D truthFor(double yaw_deg) { return Similarity2D(1, yaw_deg * M_PI / 180, {1.5, -2.5}); }

/** The same map as users feed it: rendered in its frame shifted by a
 * sub-cell offset, so that its origin lies off the cell lattice (as every
 * map_saver output's does), written as a map_server .yaml + .pgm with that
 * exact origin, and read back by the loader. The offset is drawn from the
 * pair's key, so a run is reproducible. */
std::shared_ptr<const GridInFrame> mapServerFile(const std::string& log, bool ref, double res, double yaw_deg)
{
	// Shared pointers: clearing the cache cannot pull a map from under a caller.
	static std::map<std::tuple<std::string, bool, long, long>, std::shared_ptr<const GridInFrame>> cache;
	const auto key = std::make_tuple(log, ref, std::lround(res * 1e4), std::lround(yaw_deg * 100));
	auto it = cache.find(key);
	if (it != cache.end()) return it->second;
	if (cache.size() > 40) cache.clear();
	std::seed_seq seed{int(std::hash<std::string>()(log) & 0xffff), int(ref), int(std::get<2>(key)), int(std::get<3>(key))};
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> sub_cell(0.1 * res, 0.9 * res);
	const double dx = sub_cell(rng), dy = sub_cell(rng);
	const ScanSequence& s = scansOf(log);
	const size_t n = s.size();
	const mrpt::poses::CPose2D frame = ref ? mrpt::poses::CPose2D() : mrpt::poses::CPose2D(1.5, -2.5, yaw_deg * M_PI / 180);
	const GridInFrame map = ref ? renderGridOffLattice(s, 0, n * 6 / 10, res, frame, dx, dy)
								: renderGridOffLattice(s, n * 4 / 10, n, res, frame, dx, dy);
	const fs::path dir = fs::temp_directory_path() / ("multires_bench_maps_" + std::to_string(getpid()));
	fs::create_directories(dir);
	std::ostringstream name;
	name << log << (ref ? "_ref_" : "_other_") << std::get<2>(key) << "_" << std::get<3>(key) << ".yaml";
	const std::string path = (dir / name.str()).string();
	saveGridMap(map, path);
	auto loaded = std::make_shared<const GridInFrame>(loadGridMap(path));
	if (!std::getenv("MMM_BENCH_KEEP_MAPS"))  // kept for one-pair runs: bench/README.md
		fs::remove(path), fs::remove(fs::path(path).replace_extension(".pgm"));
	return cache.emplace(key, loaded).first->second;
}

// ---------------------------------------------------------------- candidates (calibration data)
/** Every refined hypothesis of every pair, with its features and whether it
 * was right: what scripts/calibrate_decision.py fits the decision on. */
std::ofstream g_candidates;
/** The columns of candidates.csv: the pair, the truth, the placement, then
 * every evidence field (Decision.h's one list). */
std::string candidateHeader()
{
	std::string header =
		"site,ref,other,positive,calibration,index,right,error,initial_error,scale,yaw_deg,centre_x,centre_y,overlap,"
		"rmse_coarse,consistency,screened,mirrored,score,confidence";
	for (const auto& f : evidenceFields()) header += std::string(",") + f.name;
	return header + "\n";
}

/** The options every aligner of the benchmark runs with: the defaults, except
 * for --calibration-data, which refines every hypothesis and always searches
 * the structure (no decision cuts the candidate lists short). */
CScalingGridMapAligner::TConfigParams g_aligner_options;
CScalingGridMapAligner benchAligner()
{
	CScalingGridMapAligner a;
	a.options = g_aligner_options;
	return a;
}

bool candidatesWanted() { return g_candidates.is_open(); }

/** The transform a candidate would be reported with, if decided on. */
using ReportedOf = std::function<Similarity2D(const CScalingGridMapAligner::TCandidate&)>;
const Similarity2D& asRefined(const CScalingGridMapAligner::TCandidate& c) { return c.cells; }

/** `error_of(cells)` is the candidate's error (pixels or coarse cells) and
 * whether that is right, judged on `reported_of(candidate)`; for negatives
 * every candidate is wrong. */
template <class ErrorOf>
void writeCandidates(
	const std::string& site, const std::string& ref, const std::string& other, bool positive, bool calibration,
	const CScalingGridMapAligner::TReturnInfo& r, ErrorOf error_of, const ReportedOf& reported_of = asRefined)
{
	if (!candidatesWanted()) return;
	for (size_t i = 0; i < r.candidates.size(); ++i)
	{
		const auto& c = r.candidates[i];
		// A mirrored candidate (mirror_check) is a transform of the flipped map: never right.
		const bool judge = positive && !c.mirrored;
		const auto [err, right] = judge ? error_of(reported_of(c)) : std::pair<double, bool>{NAN, false};
		const auto init = judge ? error_of(c.initial_cells) : std::pair<double, bool>{NAN, false};
		g_candidates << site << "," << ref << "," << other << "," << positive << "," << calibration << "," << i << ","
					 << right << "," << err << "," << init.first << "," << c.cells.scale << ","
					 << c.cells.yaw * 180 / M_PI << "," << c.other_centre.x() << "," << c.other_centre.y() << ","
					 << c.overlap << "," << c.rmse_coarse_cells << "," << c.consistency << "," << c.screened << ","
					 << c.mirrored << "," << c.score << "," << c.confidence;
		for (const auto& f : evidenceFields()) g_candidates << "," << c.evidence.*f.member;
		g_candidates << "\n";
	}
}

/** For negatives: no candidate can be right. */
std::pair<double, bool> noTruth(const Similarity2D&) { return {NAN, false}; }

// ---------------------------------------------------------------- one pair
struct PairResult
{
	std::string set, log;
	double ref_res = 0, other_res = 0, yaw_deg = 0;
	unsigned ref_w = 0, ref_h = 0, other_w = 0, other_h = 0;
	// ours
	bool merged = false;  //!< reported merged
	bool correct = false;  //!< merged and point RMSE ≤ 2 coarse cells
	std::string message;
	double rmse = NAN, yaw_err = NAN, scale_err_pct = NAN, implied_err_pct = NAN;
	double overlap = NAN, true_overlap = NAN, confidence = 0, seconds = 0;
	double floor_rmse = NAN;  //!< TsICP started at the truth: what the rendering allows
	std::map<std::string, double> stages;
	// MRPT
	bool mrpt_ran = false, mrpt_correct = false;
	double mrpt_rmse = NAN, mrpt_yaw_err = NAN, mrpt_seconds = 0;
	std::string mrpt_why;
};

/** Edge points in metres of the map's frame. */
PointList metricEdges(const GridInFrame& m)
{
	PointList pts = edgePoints(toClassImage(m.grid));
	const Similarity2D to_map = m.cellToMapFrame();
	for (auto& p : pts) p = to_map(p);
	return pts;
}

/** The overlap TsICP estimates, from the truth: the share of the reference's
 * edge points with an edge point of the other within one coarse cell. */
double trueOverlap(const PointList& ref_edges, const PointList& other_edges, const Similarity2D& truth, double coarse)
{
	PointList moved = other_edges;
	for (auto& p : moved) p = truth(p);
	if (moved.empty() || ref_edges.empty()) return 0;
	const PointKDTree tree(std::move(moved));
	size_t near = 0;
	for (const auto& q : ref_edges) near += tree.nearest(q).second <= coarse * coarse;
	return double(near) / ref_edges.size();
}

PairResult runPair(const std::string& set, const std::string& log, double rr, double ro, double yaw, bool with_mrpt)
{
	PairResult p;
	p.set = set, p.log = log, p.ref_res = rr, p.other_res = ro, p.yaw_deg = yaw;
	// Fed as users feed it: map_server files with origins off the cell lattice.
	const auto ref_map = mapServerFile(log, true, rr, 0), other_map = mapServerFile(log, false, ro, yaw);
	const GridInFrame &ref = *ref_map, &other = *other_map;
	p.ref_w = ref.grid.getSizeX(), p.ref_h = ref.grid.getSizeY();
	p.other_w = other.grid.getSizeX(), p.other_h = other.grid.getSizeY();
	const Similarity2D truth = truthFor(yaw);
	const double coarse = std::max(rr, ro);
	const PointList other_edges = metricEdges(other);

	CScalingGridMapAligner aligner = benchAligner();
	mrpt::system::CTicTac clock;
	const auto r = aligner.alignScaled(ref, other);  // between the maps' frames
	p.seconds = clock.Tac();
	p.merged = r.success;
	p.message = r.message;
	p.stages = r.stage_seconds;
	p.confidence = r.confidence;
	if (r.success)
	{
		p.rmse = pointRmse(r.metric, truth, other_edges) / coarse;
		p.yaw_err = std::abs(wrapToPi(r.metric.yaw - truth.yaw)) * 180 / M_PI;
		p.scale_err_pct = std::abs(r.metric.scale - 1) * 100;
		p.implied_err_pct = std::abs(r.implied_resolution_other / ro - 1) * 100;
		p.overlap = r.overlap;
		p.correct = p.rmse <= 2;
	}
	p.true_overlap = trueOverlap(metricEdges(ref), other_edges, truth, coarse);
	{
		const Similarity2D truth_cells = ref.cellToMapFrame().inverse().compose(truth).compose(other.cellToMapFrame());
		// The aligner's last refinement, started at the truth.
		const Similarity2D at_truth = aligner.options.icp_finish_on_occupied
			? finishOnOccupied(*aligner.prepare(ref.grid), *aligner.prepare(other.grid), truth_cells,
							   aligner.options.icpParams(), aligner.options.latticeParams())
			: runTsICP(edgePoints(toClassImage(ref.grid)), edgePoints(toClassImage(other.grid)), truth_cells,
					   aligner.options.icpParams()).transform;
		p.floor_rmse = pointRmse(ref.cellToMapFrame().compose(at_truth).compose(other.cellToMapFrame().inverse()),
								 truth, other_edges) / coarse;
	}
	const auto cm_of = [](double res) { return std::to_string(std::lround(res * 100)) + "cm"; };
	writeCandidates(log, set + "_" + cm_of(rr), cm_of(ro) + "_yaw" + std::to_string(std::lround(yaw)), true, false, r,
					[&](const Similarity2D& cells) {
		const double e = pointRmse(candidateMetric(ref, cells, other), truth, other_edges) / coarse;
		return std::pair<double, bool>{e, e <= 2};
	});

	if (with_mrpt)
	{
		const AnchorResult a = alignWithMrpt(ref.grid, other.grid);
		p.mrpt_ran = true;
		p.mrpt_seconds = a.seconds;
		p.mrpt_why = a.why;
		if (a.aligned)
		{
			// MRPT aligns the grids; given the same exact frames as ours.
			const Similarity2D between_maps = betweenMapFrames(ref, a.metric, other);
			p.mrpt_rmse = pointRmse(between_maps, truth, other_edges) / coarse;
			p.mrpt_yaw_err = std::abs(wrapToPi(between_maps.yaw - truth.yaw)) * 180 / M_PI;
			p.mrpt_correct = p.mrpt_rmse <= 2;
			if (!p.mrpt_correct) p.mrpt_why = "wrong pose";
		}
	}
	std::cout << std::fixed << std::setprecision(3) << set << " " << log << " " << rr * 100 << "cm vs "
			  << ro * 100 << "cm yaw " << yaw << ": " << (p.correct ? "OK" : (p.merged ? "WRONG" : "not merged"))
			  << " rmse " << p.rmse << " coarse cells (from the truth " << p.floor_rmse << "), " << p.seconds << " s";
	if (with_mrpt)
		std::cout << " | MRPT " << (p.mrpt_correct ? "OK" : p.mrpt_why) << " " << p.mrpt_seconds << " s";
	std::cout << std::endl;
	return p;
}

// ---------------------------------------------------------------- statistics

template <class F>
std::vector<double> column(const std::vector<PairResult>& rs, F f)
{
	std::vector<double> v;
	for (const auto& r : rs) v.push_back(f(r));
	return v;
}

std::string num(double v, int prec = 3)
{
	if (!std::isfinite(v)) return "–";
	std::ostringstream s;
	s << std::fixed << std::setprecision(prec) << v;
	return s.str();
}

std::string cm(double res) { return num(res * 100, 0); }

// ---------------------------------------------------------------- scaling (child process)
struct ScalingCase
{
	int cells = 0;  //!< longer side of the reference map
	double ref_res = 0, other_res = 0, seconds = 0, peak_mb = 0;
	double process_seconds = 0;  //!< the whole child process: start, loading both files, aligning, exit
	unsigned ref_w = 0, ref_h = 0;
	bool merged = false;
	std::string message;  //!< the aligner's
};

/** This process's peak resident memory: VmHWM is this process image's own
 * peak (getrusage would inherit the spawning parent's across exec). */
double peakRssMb()
{
	std::ifstream status("/proc/self/status");
	for (std::string line; std::getline(status, line);)
		if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024;
	return NAN;
}

/** In the child: align two saved grids and print the time; the parent
 * reads the child's peak memory (maps + aligner, nothing else). */
int scalingChild(const std::string& ref_path, const std::string& other_path)
{
	const auto ref = loadGridMap(ref_path), other = loadGridMap(other_path);
	CScalingGridMapAligner aligner = benchAligner();
	mrpt::system::CTicTac clock;
	const auto r = aligner.alignScaled(ref, other);
	const double seconds = clock.Tac();
	std::cout << "SCALING " << seconds << " " << r.success << " " << peakRssMb() << "\nMESSAGE " << r.message << std::endl;
	return 0;
}

/** Starts this program again with `args` (args[0] = its path), its standard
 * output into `out_path`. Returns the child's pid, or -1. */
pid_t spawnSelf(std::vector<std::string> args, const std::string& out_path)
{
	std::vector<char*> argv;
	for (auto& a : args) argv.push_back(a.data());
	argv.push_back(nullptr);
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
	pid_t pid;
	const bool started = posix_spawn(&pid, args[0].c_str(), &fa, nullptr, argv.data(), environ) == 0;
	posix_spawn_file_actions_destroy(&fa);
	return started ? pid : -1;
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

struct LimitedMrpt
{
	bool finished = false, aligned = false;
	double seconds = 0;
	Similarity2D metric;
};

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
ScalingCase runScalingCase(const std::string& self, int cells)
{
	ScalingCase c;
	c.cells = cells;
	const ScanSequence& s = scansOf("fr079");
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
	const pid_t pid = spawnSelf({self, "--scaling-align", ref_path, "--scaling-other", other_path}, out);
	if (pid < 0) throw std::runtime_error("cannot start " + self);
	int status = 0;
	waitpid(pid, &status, 0);
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

/** One same-resolution fr079 pair as whole processes: ours and MRPT's, each
 * loading the two map_server files, aligning and exiting (median of 3). */
struct WholeProcessRow
{
	double res = 0, ours_s = 0, mrpt_s = 0, ours_peak_mb = 0, mrpt_peak_mb = 0;
	bool ours_merged = false, mrpt_aligned = false;
};

WholeProcessRow runWholeProcess(const std::string& self, double res)
{
	WholeProcessRow row;
	row.res = res;
	const fs::path dir = fs::temp_directory_path() / ("multires_bench_process_" + std::to_string(getpid()));
	fs::create_directories(dir);
	const std::string ref = (dir / "ref.yaml").string(), other = (dir / "other.yaml").string(), out = (dir / "out.txt").string();
	saveGridMap(*mapServerFile("fr079", true, res, 0), ref);
	saveGridMap(*mapServerFile("fr079", false, res, 0), other);
	auto run = [&](const std::vector<std::string>& args, const char* tag, bool& ok, double& peak_mb) {
		std::vector<double> times;
		for (int k = 0; k < 3; ++k)
		{
			const auto t0 = std::chrono::steady_clock::now();
			const pid_t pid = spawnSelf(args, out);
			if (pid < 0) throw std::runtime_error("cannot start " + self);
			int status = 0;
			waitpid(pid, &status, 0);
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
	row.ours_s = run({self, "--scaling-align", ref, "--scaling-other", other}, "SCALING ", row.ours_merged, row.ours_peak_mb);
	row.mrpt_s = run({self, "--mrpt-align", ref, "--scaling-other", other}, "MRPT ", row.mrpt_aligned, unused);
	fs::remove_all(dir);
	std::cout << "whole process " << res * 100 << " cm: ours " << row.ours_s << " s, MRPT " << row.mrpt_s << " s" << std::endl;
	return row;
}

// ---------------------------------------------------------------- fleets (child process)
struct FleetCase
{
	std::string name;
	int maps = 0;
	std::string sizes;  //!< "w×h @ res" of each map
	double seconds = 0, placing_seconds = 0, peak_mb = 0;  //!< placing: placeFleet alone (the rest is fuseFleet)
	size_t aligned = 0, skipped = 0, building = 0, placed_right = 0, placed_wrong = 0, others_placed = 0;
	double max_err = NAN;  //!< worst placement error, cells of the coarser map of its pair with the reference
};

/** In the child: places and fuses the fleet map_0.yaml, map_1.yaml, ... of
 * `dir` (map_0 the reference); prints the time, the pairs and each placement. */
int fleetChild(const std::string& dir)
{
	std::vector<GridInFrame> maps;
	for (int i = 0; fs::exists(dir + "/map_" + std::to_string(i) + ".yaml"); ++i)
		maps.push_back(loadGridMap(dir + "/map_" + std::to_string(i) + ".yaml"));
	mrpt::system::CTicTac clock;
	const FleetParams fp;
	const FleetResult r = placeFleet(maps, 0, benchAligner(), fp);
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
std::string placeFleetInChild(const std::string& self, const std::string& dir)
{
	const std::string out = dir + "/out.txt";
	const pid_t pid = spawnSelf({self, "--fleet-child", dir}, out);
	if (pid < 0) throw std::runtime_error("cannot start " + self);
	int status = 0;
	waitpid(pid, &status, 0);
	return out;
}

/** A fleet of `n` robots of fr079, each a 40 % share of the run spread over
 * it, at resolutions cycling over 5, 3, 8, 4, 6, 10, 2.5, 7 cm, in frames
 * turned by 37° more each, origins off the lattice, as map_server files;
 * `pad_to` > 0 pads each to that many cells a side. `beyond_reference` adds
 * a robot (4 cm) that saw nothing the reference saw (it can only be placed
 * through another robot); `other_building` an intel robot that must stay
 * out. Placed in a fresh process. */
FleetCase runFleetCase(const std::string& self, const std::string& name, int n, int pad_to, bool beyond_reference,
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
		const ScanSequence& s = scansOf(other ? "intel" : "fr079");
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
	const std::string out = placeFleetInChild(self, dir.string());
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

std::vector<FleetCase> runFleets(const std::string& self, bool quick)
{
	std::vector<FleetCase> cases;
	for (int n : quick ? std::vector<int>{3} : std::vector<int>{2, 3, 4, 5, 6, 7, 8})
		cases.push_back(runFleetCase(self, "N = " + std::to_string(n), n, 0, false, false));
	if (!quick)
	{
		cases.push_back(runFleetCase(self, "5 / 3 / 8 cm, one 4 cm beyond the reference, + another building", 3, 0, true, true));
		cases.push_back(runFleetCase(self, "8 maps of 1000×1000 cells", 8, 1000, false, false, 0.05));
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

// ---------------------------------------------------------------- basin of convergence
struct BasinCell
{
	double dyaw_deg, dscale_pct, rmse;
	bool converged;
};

/** TsICP alone, started from the truth perturbed in rotation and scale about
 * the other map's centre (the paper's Fig. 7): does it come back? */
std::vector<BasinCell> basin(const std::string& log, double rr, double ro, const std::vector<double>& dyaws,
							 const std::vector<double>& dscales)
{
	const auto ref = render(log, true, rr, 0);  // copies: the cache may be cleared by the next render
	const auto other = render(log, false, ro, 30);
	const PointList ref_edges = edgePoints(toClassImage(ref)), other_edges = edgePoints(toClassImage(other));
	const Similarity2D truth_cells = cellToMetric(ref).inverse().compose(truthFor(30)).compose(cellToMetric(other));
	const Eigen::Vector2d centre =
		std::accumulate(other_edges.begin(), other_edges.end(), Eigen::Vector2d(0, 0)) / double(other_edges.size());
	const Eigen::Vector2d c_ref = truth_cells(centre);
	const double coarse_in_ref = std::max(1.0, truth_cells.scale);
	std::vector<BasinCell> out;
	for (const double dy : dyaws)
		for (const double ds : dscales)
		{
			// Rotate and scale about where the other map's centre truly lands.
			const Similarity2D about(1 + ds / 100, dy * M_PI / 180, c_ref - (1 + ds / 100) * Eigen::Rotation2Dd(dy * M_PI / 180).toRotationMatrix() * c_ref);
			const TsICPResult r = runTsICP(ref_edges, other_edges, about.compose(truth_cells));
			PointList probe = other_edges;
			double se = 0;
			for (const auto& p : probe) se += (r.transform(p) - truth_cells(p)).squaredNorm();
			const double rmse = std::sqrt(se / probe.size()) / coarse_in_ref;
			out.push_back({dy, ds, rmse, rmse <= 0.5});
		}
	return out;
}

// ---------------------------------------------------------------- report
void writeCsv(const std::string& path, const std::vector<PairResult>& rs)
{
	std::ofstream f(path);
	f << "set,log,ref_res,other_res,yaw_deg,ref_w,ref_h,other_w,other_h,merged,correct,rmse_coarse_cells,yaw_err_deg,"
		 "scale_err_pct,implied_res_err_pct,overlap,true_overlap,confidence,seconds,features_s,ransac_s,edges_s,icp_s,"
		 "verify_s,mrpt_ran,mrpt_correct,mrpt_rmse_coarse_cells,mrpt_yaw_err_deg,mrpt_seconds,message,mrpt_why\n";
	auto q = [](std::string s) {
		std::replace(s.begin(), s.end(), '"', '\'');
		return "\"" + s + "\"";
	};
	for (const auto& r : rs)
	{
		auto st = [&](const char* k) { return r.stages.count(k) ? r.stages.at(k) : NAN; };
		f << r.set << "," << r.log << "," << r.ref_res << "," << r.other_res << "," << r.yaw_deg << "," << r.ref_w
		  << "," << r.ref_h << "," << r.other_w << "," << r.other_h << "," << r.merged << "," << r.correct << ","
		  << r.rmse << "," << r.yaw_err << "," << r.scale_err_pct << "," << r.implied_err_pct << "," << r.overlap
		  << "," << r.true_overlap << "," << r.confidence << "," << r.seconds << "," << st("features") << ","
		  << st("ransac") << "," << st("edges") << "," << st("icp") << "," << st("verify") << "," << r.mrpt_ran
		  << "," << r.mrpt_correct << "," << r.mrpt_rmse << "," << r.mrpt_yaw_err << "," << r.mrpt_seconds << ","
		  << q(r.message) << "," << q(r.mrpt_why) << "\n";
	}
}

std::string machine()
{
	std::ifstream cpu("/proc/cpuinfo");
	std::string line, model = "unknown CPU";
	while (std::getline(cpu, line))
		if (line.rfind("model name", 0) == 0)
		{
			model = line.substr(line.find(':') + 2);
			break;
		}
	return model + ", " + std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) + " cores";
}

// ---------------------------------------------------------------- false merges (CARMEN)
struct Negative
{
	std::string a, b, what;
	bool merged;
	double confidence;
	std::string message;
};

/** Different buildings (every ordered pair of the six logs, 5 vs 8 cm) and
 * the two ends of one run: all must be refused. */
std::vector<Negative> runCarmenNegatives(bool quick)
{
		std::vector<Negative> negatives;
	std::vector<std::pair<std::string, std::string>> pairs_of_logs;
	for (size_t i = 0; i < kLogs.size(); ++i)
		for (size_t j = 0; j < kLogs.size(); ++j)
		if (i != j && (!quick || (i == 0 && j == 1))) pairs_of_logs.push_back({kLogs[i].name, kLogs[j].name});
	for (const auto& [a, b] : pairs_of_logs)
	{
		const ScanSequence& sa = scansOf(a);
		const ScanSequence& sb = scansOf(b);
		const auto ga = renderGrid(sa, 0, sa.size(), 0.05);
		const auto gb = renderGrid(sb, 0, sb.size(), 0.08);
		const auto r = benchAligner().alignScaled(ga, gb);
		writeCandidates("carmen", a, b, false, true, r, noTruth);
		negatives.push_back({a, b, "different buildings", r.success, r.confidence, r.message});
		std::cout << "negative " << a << " vs " << b << ": " << (r.success ? "MERGED (false merge)" : "refused")
			  << std::endl;
	}
	for (const auto& log : quick ? std::vector<std::string>{"fr079"}
					 : std::vector<std::string>{"fr079", "intel", "fr101", "fhw"})
	{
		// Two ends of the building: columns [0, 40 %) and [60 %, 100 %) of the whole run.
		const ScanSequence& s = scansOf(log);
		const auto whole5 = renderGrid(s, 0, s.size(), 0.05), whole8 = renderGrid(s, 0, s.size(), 0.08);
		auto crop = [](const mrpt::maps::COccupancyGridMap2D& g, double f0, double f1) {
		const double x0 = g.getXMin() + f0 * (g.getXMax() - g.getXMin());
		const double x1 = g.getXMin() + f1 * (g.getXMax() - g.getXMin());
		mrpt::maps::COccupancyGridMap2D c(x0, x1, g.getYMin(), g.getYMax(), g.getResolution());
		for (unsigned cy = 0; cy < c.getSizeY(); ++cy)
			for (unsigned cx = 0; cx < c.getSizeX(); ++cx)
			{
			const int gx = g.x2idx(c.idx2x(cx)), gy = g.y2idx(c.idx2y(cy));
			if (gx >= 0 && gy >= 0 && gx < int(g.getSizeX()) && gy < int(g.getSizeY()))
				c.setCell(cx, cy, g.getCell(gx, gy));
			}
		return c;
		};
		const auto r = benchAligner().alignScaled(crop(whole5, 0, 0.4), crop(whole8, 0.6, 1));
		writeCandidates("carmen", log + "_west", log + "_east", false, true, r, noTruth);
		negatives.push_back({log + " west", log + " east", "disjoint parts of one run", r.success, r.confidence, r.message});
		std::cout << "negative " << log << " disjoint halves: " << (r.success ? "MERGED (false merge)" : "refused")
			  << std::endl;
	}

	return negatives;
}

/** The live bench's growing maps, pair by pair at a few states, both orders:
 * fr079 robots against each other (judged against their frames: a wrong best
 * candidate of a barely grown map is what a lower bar would place wrong) and
 * against the intel robot (another building: negatives). The fleet sees these
 * pairs again at every estimation, so the decision must hold on all states. */
void runLiveFleetCalibrationPairs()
{
	const int states = 16;
	for (const int state : {1, 2, 3, 4, 6, 8, 11, 16})
	{
		const auto maps = liveMapsAt(scansOf, state, states);
		for (size_t a = 0; a < maps.size(); ++a)
			for (size_t b = 0; b < maps.size(); ++b)
			{
				if (a == b) continue;
				const LiveMap &ref = maps[a], &other = maps[b];
				const bool positive = !ref.other_building && !other.other_building;
				const auto r = benchAligner().alignScaled(ref.map, other.map);
				const Similarity2D truth = ref.frame_in_world.inverse().compose(other.frame_in_world);
				const auto points = occupiedPointsInMapFrame(other.map);
				const double coarse = std::max(ref.resolution, other.resolution);
				const std::string name = "_state" + std::to_string(state);
				writeCandidates("live", ref.robot + name, other.robot + name, positive, true, r, [&](const Similarity2D& cells) {
					const double e = pointRmse(candidateMetric(ref.map, cells, other.map), truth, points) / coarse;
					return std::pair<double, bool>{e, e <= 2};
				});
				std::cout << "live state " << state << " " << ref.robot << " <- " << other.robot << ": "
						  << (r.success ? "merged" : "refused") << std::endl;
			}
	}
}

/** Negatives for the calibration beyond the list, of the kinds the
 * decision must also reject: each calibration-site map against its own
 * mirror image (a reflection is no similarity), and the CARMEN buildings at
 * the other resolution order (8 cm against 5 cm). */
void runExtraCalibrationNegatives(const HalmstadData& data)
{
	const std::string dir = (fs::temp_directory_path() / ("multires_bench_mirror_" + std::to_string(getpid()))).string();
	fs::create_directories(dir);
	for (const auto& site : {"E5", "HIH"})
		for (const auto& m : data.sensorMaps(site))
		{
			cv::Mat img = cv::imread(data.png(m), cv::IMREAD_GRAYSCALE), mirrored;
			cv::flip(img, mirrored, 1);
			const GridInFrame orig = loadGridMap(data.yaml(m, dir));
			cv::imwrite(dir + "/mirror.png", mirrored);
			std::ofstream(dir + "/mirror.yaml") << "image: mirror.png\nresolution: 0.05\norigin: [0, 0, 0]\n";
			const auto r = benchAligner().alignScaled(orig, loadGridMap(dir + "/mirror.yaml"));
			writeCandidates("mirror", m, m + "_mirrored", false, true, r, noTruth);
			std::cout << "negative " << m << " vs its mirror image: " << (r.success ? "MERGED (false)" : "refused") << std::endl;
		}
	fs::remove_all(dir);
	// Each CARMEN building at 8 cm against each other one at 5 cm: whole,
	// and as a robot that has seen little of it (the first 15 % of its run:
	// few wall points, so the evidence discount decides).
	for (const int percent : {100, 15})
		for (size_t i = 0; i < kLogs.size(); ++i)
			for (size_t j = 0; j < kLogs.size(); ++j)
				if (i != j)
				{
					const ScanSequence& sa = scansOf(kLogs[i].name);
					const ScanSequence& sb = scansOf(kLogs[j].name);
					const auto r = benchAligner().alignScaled(
						renderGrid(sa, 0, sa.size(), 0.08), renderGrid(sb, 0, sb.size() * percent / 100, 0.05));
					const std::string part = percent < 100 ? "_first" + std::to_string(percent) : "";
					writeCandidates("carmen", kLogs[i].name + "_8cm", kLogs[j].name + part + "_5cm", false, true, r, noTruth);
					std::cout << "negative " << kLogs[i].name << " 8 cm vs " << kLogs[j].name << part << " 5 cm: "
							  << (r.success ? "MERGED (false)" : "refused") << std::endl;
				}
}

// ---------------------------------------------------------------- real independent maps (Halmstad)
/** OTHER's cells this many times larger (issue 35: 2× and 3.3×). */
const std::vector<double> kCoarserFactors = {2.0, 3.3};

struct HalmstadRun
{
	std::string site, ref, other;
	bool positive = true;  //!< same site (annotated) or a cross-site negative
	bool calibration = false;  //!< a calibration site's pair (may be tuned on)
	bool merged = false;
	HalmstadOutcome outcome;  //!< of the reported transform (positives)
	double seconds = 0, confidence = 0;
	std::string message;
	LimitedMrpt mrpt;
	bool mrpt_right = false;
};

/** Aligns REF ← OTHER from map_server files; for positives judges the result
 * against the annotation. Every candidate goes to `candidates_csv` with its
 * features and whether it was right: the data the decision is calibrated on. */
HalmstadRun runHalmstadPair(
	const HalmstadData& data, const std::string& ref, const std::string& other, const std::string& dir,
	double mrpt_limit_s = 0)
{
	HalmstadRun run;
	run.site = ref.substr(0, ref.find('_'));
	run.ref = ref, run.other = other;
	run.positive = run.site == other.substr(0, other.find('_'));
	// Calibration data (the issue's): E5 and HIH positives; negatives of an E5 map against another site.
	run.calibration = run.positive ? isCalibrationSite(run.site) : (ref.rfind("E5_", 0) == 0 || other.rfind("E5_", 0) == 0);
	const GridInFrame ref_map = loadGridMap(data.yaml(ref, dir)), other_map = loadGridMap(data.yaml(other, dir));
	const HalmstadPair* truth = run.positive ? data.pair(other, ref) : nullptr;
	mrpt::system::CTicTac clock;
	const auto r = benchAligner().alignScaled(ref_map, other_map);
	run.seconds = clock.Tac();
	run.merged = r.success;
	run.confidence = r.confidence;
	run.message = r.message;
	const int ref_rows = static_cast<int>(ref_map.grid.getSizeY());
	if (truth && r.candidates.size()) run.outcome = judge(r.metric, *truth, other_map, ref_rows);
	if (mrpt_limit_s > 0)
	{
		run.mrpt = mrptWithTimeLimit(
			fs::canonical("/proc/self/exe"), data.yaml(ref, dir), data.yaml(other, dir), mrpt_limit_s);
		if (truth && run.mrpt.aligned) run.mrpt_right = judge(run.mrpt.metric, *truth, other_map, ref_rows).right;
	}
	// Each candidate judged as it would be reported (the aligner's finish for
	// maps that bend, finishBent): what a user gets if the decision picks it.
	CScalingGridMapAligner::PreparedMapPtr ref_prepared, other_prepared;
	if (truth && candidatesWanted())
		ref_prepared = benchAligner().prepare(ref_map.grid), other_prepared = benchAligner().prepare(other_map.grid);
	const auto error_of = [&](const Similarity2D& cells) {
		const HalmstadOutcome o = judge(candidateMetric(ref_map, cells, other_map), *truth, other_map, ref_rows);
		return std::pair<double, bool>{o.mean_displacement_px, o.right};
	};
	writeCandidates(run.site, ref, other, run.positive, run.calibration, r, error_of, [&](const auto& c) {
		const auto& o = g_aligner_options;
		return ref_prepared
			? finishBent(*ref_prepared, *other_prepared, c.cells, c.rmse_coarse_cells, o.finishParams(), o.decision)
			: c.cells;
	});
	std::cout << "halmstad " << ref << " <- " << other << ": "
			  << (run.positive ? (run.merged ? (run.outcome.right ? "merged right" : "MERGED WRONG") : "refused")
						   : (run.merged ? "MERGED (false)" : "refused (negative)"))
			  << " disp " << run.outcome.mean_displacement_px << " px, " << run.seconds << " s" << std::endl;
	return run;
}

/** Calibration pairs of the kind the package exists for: each E5 and HIH
 * pair (REF = the later map) with OTHER recorded as a coarser grid whose
 * stated resolution is wrong (the coarser-OTHER section's maps). Each
 * candidate judged as it would be reported, as runHalmstadPair does. */
void runCoarserCalibrationPairs(const HalmstadData& data)
{
	const std::string dir = (fs::temp_directory_path() / ("multires_bench_coarser_" + std::to_string(getpid()))).string();
	const auto sink = [](const CoarserRun& run, const GridInFrame& ref, const GridInFrame& other,
						  const CScalingGridMapAligner::TReturnInfo& r, const CandidateError& error_of) {
		const auto ref_prepared = benchAligner().prepare(ref.grid), other_prepared = benchAligner().prepare(other.grid);
		const auto& o = g_aligner_options;
		std::ostringstream other_name;
		other_name << run.other << "_x" << run.factor;
		writeCandidates(run.site, run.ref, other_name.str(), true, true, r, error_of, [&](const auto& c) {
			return finishBent(*ref_prepared, *other_prepared, c.cells, c.rmse_coarse_cells, o.finishParams(), o.decision);
		});
	};
	runCoarserOther(data, {"E5", "HIH"}, kCoarserFactors, g_aligner_options, dir, sink);
	fs::remove_all(dir);
}

/** The pair sets: every unordered same-site pair (REF = the later
 * map), and cross-site negatives: each map of one site against maps of the
 * others, `negatives_per_map` each. */
std::vector<HalmstadRun> runHalmstad(
	const HalmstadData& data, const std::vector<std::string>& sites, size_t negatives_per_map)
{
	const std::string dir = (fs::temp_directory_path() / ("multires_bench_halmstad_" + std::to_string(getpid()))).string();
	std::vector<HalmstadRun> runs;
	for (const auto& site : sites)
	{
		size_t k = 0;
		// MRPT beside on a few pairs per site (13 s a pair; killed at 30 s).
		for (const auto& p : data.unorderedPairs(site))
			runs.push_back(runHalmstadPair(data, p.dst, p.src, dir, k++ % 16 == 0 ? 30.0 : 0.0));
	}
	if (negatives_per_map)
	{
		std::vector<std::string> all;
		for (const auto& site : data.sites())
			for (const auto& m : data.sensorMaps(site)) all.push_back(m);
		for (const auto& site : sites)
			for (const auto& ref : data.sensorMaps(site))
			{
				size_t taken = 0;
				// Walk the other sites' maps from a per-map offset, so the
				// negatives spread over every site and map.
				const size_t start = std::hash<std::string>()(ref) % all.size();
				for (size_t k = 0; k < all.size() && taken < negatives_per_map; ++k)
				{
					const std::string& other = all[(start + k * 7) % all.size()];
					if (other.substr(0, other.find('_')) == site) continue;
					runs.push_back(runHalmstadPair(data, ref, other, dir));
					++taken;
				}
			}
	}
	fs::remove_all(dir);
	return runs;
}

/** Calibration negatives in the other order: each map of another site as
 * REF against `per_map` E5 maps as OTHER. The decision is not symmetric in
 * its maps, and the report's cross-site negatives take every site's maps as
 * REF; runHalmstad's calibration negatives take only E5 and HIH maps. */
void runReverseCrossSiteNegatives(const HalmstadData& data, size_t per_map)
{
	const std::string dir = (fs::temp_directory_path() / ("multires_bench_reverse_" + std::to_string(getpid()))).string();
	const std::vector<std::string> e5 = data.sensorMaps("E5");
	for (const auto& site : data.sites())
		if (site != "E5")
			for (const auto& ref : data.sensorMaps(site))
			{
				// Spread over the E5 maps from a per-map offset, as runHalmstad's.
				const size_t start = std::hash<std::string>()(ref) % e5.size();
				for (size_t k = 0; k < per_map; ++k) runHalmstadPair(data, ref, e5[(start + k * 5) % e5.size()], dir);
			}
	fs::remove_all(dir);
}

/** Calibration positives in the other order: each unordered pair of the
 * calibration sites with the earlier map as REF. The issue tunes on both
 * orders; the report measures one (REF = the later map), and the decision is
 * not symmetric in its maps. */
void runReverseCalibrationPositives(const HalmstadData& data)
{
	const std::string dir = (fs::temp_directory_path() / ("multires_bench_swapped_" + std::to_string(getpid()))).string();
	for (const std::string site : {"E5", "HIH"})
		for (const auto& p : data.unorderedPairs(site)) runHalmstadPair(data, p.src, p.dst, dir);
	fs::remove_all(dir);
}

/** The accuracy matrices alone (no MRPT, no report): for work on accuracy. */
int runAccuracySets(const std::string& list)
{
	const std::vector<double> res_all = {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};
	std::stringstream in(list);
	for (std::string set; std::getline(in, set, ',');)
	{
		std::vector<PairResult> rs;
		if (set == "resolution")
			for (const double rr : res_all)
				for (const double ro : res_all) rs.push_back(runPair(set, "fr079", rr, ro, 0, false));
		else if (set == "other-logs")
			for (const std::string log : {"intel", "fr101", "orebro", "fhw", "belgioioso"})
				for (const double rr : {0.02, 0.05, 0.10})
					for (const double ro : {0.02, 0.05, 0.10}) rs.push_back(runPair(set, log, rr, ro, 0, false));
		else if (set == "rotation")
			for (const double yaw : {0, 90, 180, 270, 137})
				for (const double ro : res_all) rs.push_back(runPair(set, "fr079", 0.02, ro, yaw, false));
		else
		{
			std::cerr << "multires_bench: unknown set '" << set << "'\n";
			return 2;
		}
		std::vector<double> ok, floor;
		for (const auto& r : rs)
		{
			if (r.correct) ok.push_back(r.rmse);
			floor.push_back(r.floor_rmse);
		}
		std::cout << set << ": " << ok.size() << "/" << rs.size() << " right, median RMSE " << median(ok)
				  << " coarse cells; TsICP from the truth " << median(floor) << std::endl;
	}
	return 0;
}

}  // namespace

int main(int argc, char** argv)
{
	TCLAP::CmdLine cmd("multires_map_merge benchmark (see bench/README.md)", ' ', "0.1.0");
	TCLAP::SwitchArg quick_arg("", "quick", "a few pairs only (what CI runs)", cmd);
	TCLAP::ValueArg<std::string> out_arg("", "out", "output folder", false, "bench_output", "DIR", cmd);
	TCLAP::ValueArg<std::string> data_arg("", "data", "the shared data folder", false, "", "DIR", cmd);
	TCLAP::SwitchArg calibration_arg(
		"", "calibration-data", "only the calibration data (Halmstad E5/HIH, E5 cross-site and CARMEN negatives) "
		"into candidates.csv, for scripts/calibrate_decision.py", cmd);
	TCLAP::ValueArg<std::string> config_arg(
		"", "config",
		"aligner parameters, section [aligner] of an MRPT ini file (calibration data made with other defaults)",
		false, "", "FILE.ini", cmd);
	TCLAP::SwitchArg extra_arg("", "extra-negatives-only", "with --calibration-data: only the mirror and 8-vs-5 cm negatives", cmd);
	TCLAP::SwitchArg coarser_pairs_arg(
		"", "coarser-pairs-only", "with --calibration-data: only the E5 and HIH pairs with OTHER recorded coarser", cmd);
	TCLAP::SwitchArg live_pairs_arg(
		"", "live-pairs-only", "with --calibration-data: only the live fleet's growing maps, pair by pair", cmd);
	TCLAP::ValueArg<std::string> coarser_arg(
		"", "coarser-only", "only the coarser-OTHER section (×2, ×3.3) on these sites (e.g. F5,KPT4A)", false, "", "SITES",
		cmd);
	TCLAP::ValueArg<std::string> floor_plans_arg(
		"", "floor-plans-only", "only the floor-plan section, sensor maps of these sites (e.g. E5,HIH) on every plan", false,
		"", "SITES", cmd);
	TCLAP::ValueArg<std::string> halmstad_arg(
		"", "halmstad-only", "only the real-independent-maps section, on these sites (e.g. E5,HIH)", false, "", "SITES", cmd);
	TCLAP::ValueArg<int> negatives_arg(
		"", "halmstad-negatives", "cross-site negatives per map (with --halmstad-only)", false, 8, "N", cmd);
	TCLAP::ValueArg<std::string> sets_arg(
		"", "sets", "only these accuracy sets (resolution, other-logs, rotation), printing their medians", false, "",
		"SETS", cmd);
	TCLAP::SwitchArg fleet_arg("", "fleet-only", "only the fleet section (printed as markdown)", cmd);
	TCLAP::ValueArg<std::string> halmstad_fleets_arg(
		"", "halmstad-fleets-only", "only the Halmstad fleets, same and mixed cell sizes, of these sites (e.g. F5,HIH)",
		false, "", "SITES", cmd);
	TCLAP::ValueArg<int> scaling_arg(
		"", "scaling-only", "only the scaling case of this many cells a side (e.g. 4000)", false, 0, "CELLS", cmd);
	TCLAP::SwitchArg live_arg(
		"", "live-only", "only the live node's latency (printed as markdown); exit 1 if a robot was ever placed wrong", cmd);
	TCLAP::SwitchArg negatives_only_arg(
		"", "negatives-only", "only the CARMEN pairs that must not merge (different buildings, disjoint parts)", cmd);
	TCLAP::ValueArg<std::string> fleet_child("", "fleet-child", "internal: place a fleet in a fresh process", false, "", "DIR", cmd);
	TCLAP::ValueArg<std::string> mrpt_child("", "mrpt-align", "internal: MRPT's aligner in a fresh process", false, "", "REF", cmd);
	TCLAP::ValueArg<std::string> child_ref("", "scaling-align", "internal: align in a fresh process", false, "", "REF", cmd);
	TCLAP::ValueArg<std::string> child_other("", "scaling-other", "internal: with --scaling-align", false, "", "OTHER", cmd);
	try
	{
		cmd.parse(argc, argv);
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "multires_bench: " << e.error() << "\n";
		return 2;
	}
	if (child_ref.isSet()) return scalingChild(child_ref.getValue(), child_other.getValue());
	if (mrpt_child.isSet()) return mrptChild(mrpt_child.getValue(), child_other.getValue());
	if (fleet_child.isSet()) return fleetChild(fleet_child.getValue());
	g_data = data_arg.getValue();
	if (g_data.empty()) g_data = (fs::path(argv[0]).parent_path() / "../../../../shared/data").lexically_normal();
	if (!fs::is_directory(g_data + "/carmen_corrected"))
	{
		std::cerr << "multires_bench: no carmen_corrected logs under '" << g_data << "' (pass --data DIR)\n";
		const char* ci = std::getenv("CI");
		return ci && std::string(ci) == "true" ? 2 : 77;  // 77: ctest's "skipped" outside CI
	}
	try
	{

		if (config_arg.isSet())
		{
			if (!fs::is_regular_file(config_arg.getValue()))
				throw std::runtime_error("'" + config_arg.getValue() + "': no such config file");
			g_aligner_options.loadFromConfigFile(mrpt::config::CConfigFile(config_arg.getValue()), "aligner");
		}
		const bool quick = quick_arg.getValue();
		const std::string out = out_arg.getValue();
		fs::create_directories(out);
		g_candidates.open(out + "/candidates.csv");
		g_candidates << candidateHeader();
		if (calibration_arg.getValue())
		{
			// Every hypothesis refined, the structure always searched: the
			// decision is fitted on the candidates it sees when it runs (the
			// screen's included), of every pair, not on those a decision kept.
			g_aligner_options.exhaustive_search = true;
			const HalmstadData data(g_data + "/halmstad");
			const bool everything =
				!extra_arg.getValue() && !live_pairs_arg.getValue() && !coarser_pairs_arg.getValue();
			if (everything)
			{
				runHalmstad(data, {"E5", "HIH"}, negatives_arg.getValue());
				runReverseCalibrationPositives(data);
				runReverseCrossSiteNegatives(data, negatives_arg.getValue());
				runCarmenNegatives(false);
			}
			if (everything || extra_arg.getValue()) runExtraCalibrationNegatives(data);
			if (everything || live_pairs_arg.getValue()) runLiveFleetCalibrationPairs();
			if (everything || coarser_pairs_arg.getValue()) runCoarserCalibrationPairs(data);
			std::cout << "wrote " << out << "/candidates.csv" << std::endl;
			return 0;
		}
		if (coarser_arg.isSet())
		{
			std::vector<std::string> sites;
			std::stringstream list(coarser_arg.getValue());
			for (std::string site; std::getline(list, site, ',');) sites.push_back(site);
			const std::string dir = (fs::temp_directory_path() / ("multires_bench_coarser_" + std::to_string(getpid()))).string();
			const auto runs = runCoarserOther(HalmstadData(g_data + "/halmstad"), sites, kCoarserFactors, g_aligner_options, dir);
			fs::remove_all(dir);
			writeCoarserSection(std::cout, runs);
			size_t wrong = 0;
			for (const auto& r : runs) wrong += r.merged && !r.outcome.right;
			return wrong == 0 ? 0 : 1;
		}
		if (floor_plans_arg.isSet())
		{
			std::vector<std::string> sites;
			std::stringstream list(floor_plans_arg.getValue());
			for (std::string site; std::getline(list, site, ',');) sites.push_back(site);
			const std::string dir = (fs::temp_directory_path() / ("multires_bench_plans_" + std::to_string(getpid()))).string();
			const auto runs = runFloorPlans(HalmstadData(g_data + "/halmstad"), sites, g_aligner_options, dir);
			fs::remove_all(dir);
			writeFloorPlanSection(std::cout, runs);
			const FloorPlanTotals t = floorPlanTotals(runs);
			return t.merged_wrong + t.negatives_merged == 0 ? 0 : 1;
		}
		if (halmstad_arg.isSet())
		{
			std::vector<std::string> sites;
			std::stringstream list(halmstad_arg.getValue());
			for (std::string site; std::getline(list, site, ',');) sites.push_back(site);
			const auto runs = runHalmstad(HalmstadData(g_data + "/halmstad"), sites, negatives_arg.getValue());
			size_t right = 0, wrong = 0, pos = 0, false_merges = 0;
			for (const auto& r : runs)
				if (r.positive)
					++pos, right += r.merged && r.outcome.right, wrong += r.merged && !r.outcome.right;
				else
					false_merges += r.merged;
			std::cout << "halmstad: " << right << "/" << pos << " merged right, " << wrong << " merged wrong, "
					  << false_merges << "/" << runs.size() - pos << " false merges\n";
			return 0;
		}
		if (sets_arg.isSet())
			return runAccuracySets(sets_arg.getValue());
		if (negatives_only_arg.isSet())
		{
			const auto negatives = runCarmenNegatives(quick);
			const auto merged = std::count_if(negatives.begin(), negatives.end(), [](const Negative& n) { return n.merged; });
			std::cout << "false merges: " << merged << " / " << negatives.size() << "\n";
			return merged == 0 ? 0 : 1;
		}
		if (live_arg.isSet())
		{
			const LiveLatency live = runLiveLatency(scansOf, quick ? 4 : 16);
			writeLiveSection(std::cout, live);
			// Exit 1 when a robot was ever placed wrong (the other building at
			// all); its latency depends on this machine's speed and is only shown.
			const bool never_wrong = std::none_of(
				live.robots.begin(), live.robots.end(), [](const LiveRobotRow& r) { return r.wrong_estimations > 0; });
			return never_wrong ? 0 : 1;
		}
		if (scaling_arg.isSet())
		{
			runScalingCase(fs::canonical("/proc/self/exe"), scaling_arg.getValue());
			return 0;
		}
		if (halmstad_fleets_arg.isSet())
		{
			std::vector<std::string> sites;
			std::stringstream list(halmstad_fleets_arg.getValue());
			for (std::string site; std::getline(list, site, ',');) sites.push_back(site);
			const std::string dir = (fs::temp_directory_path() / ("multires_bench_fleets_" + std::to_string(getpid()))).string();
			const std::string self = fs::canonical("/proc/self/exe");
			const auto runs = runHalmstadFleets(
				HalmstadData(g_data + "/halmstad"), sites, true, [&](const std::string& d) { return placeFleetInChild(self, d); },
				dir);
			fs::remove_all(dir);
			writeHalmstadFleetSection(std::cout, runs);
			return 0;
		}
		if (fleet_arg.isSet())
		{
			writeFleetSection(std::cout, runFleets(fs::canonical("/proc/self/exe"), quick));
			writeLiveSection(std::cout, runLiveLatency(scansOf, quick ? 4 : 16));
			return 0;
		}
		const auto started = std::chrono::steady_clock::now();
		std::vector<PairResult> all;

		// 1. Fig. 8: every pair of resolutions, fr079 (and a coarser grid on the other logs).
		const std::vector<double> res_all = {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};
		const std::vector<double> res = quick ? std::vector<double>{0.02, 0.10} : res_all;
		for (const double rr : res)
			for (const double ro : res)
				all.push_back(runPair("resolution", "fr079", rr, ro, 0, std::abs(rr - ro) < 1e-9 || !quick));
		std::vector<std::string> others;
		if (!quick) others = {"intel", "fr101", "orebro", "fhw", "belgioioso"};
		for (const auto& log : others)
			for (const double rr : {0.02, 0.05, 0.10})
				for (const double ro : {0.02, 0.05, 0.10}) all.push_back(runPair("other-logs", log, rr, ro, 0, false));

		// 2. Fig. 9: rotations against the other map's resolution (reference at 2 cm: the hard side).
		const std::vector<double> yaws = {0, 90, 180, 270, 137};
		const std::vector<double> rot_res = quick ? std::vector<double>{0.05} : res_all;
		for (const double yaw : quick ? std::vector<double>{90} : yaws)
			for (const double ro : rot_res) all.push_back(runPair("rotation", "fr079", 0.02, ro, yaw, false));

		// 3. False merges: different buildings, and disjoint parts of one run.
		const std::vector<Negative> negatives = runCarmenNegatives(quick);

		// 3b. Real independent maps: Halmstad (every same-site sensor pair;
		// cross-site negatives) and the Willow pair.
		std::vector<HalmstadRun> halmstad;
		{
			const HalmstadData data(g_data + "/halmstad");
			if (quick)
			{
				const std::string dir = (fs::temp_directory_path() / "multires_bench_halmstad_quick").string();
				halmstad.push_back(runHalmstadPair(data, "E5_02", "E5_01", dir));
				halmstad.push_back(runHalmstadPair(data, "E5_02", "F5_01", dir));
				fs::remove_all(dir);
			}
			else
				halmstad = runHalmstad(data, data.sites(), 6);
		}
		// 3c. Floor plans: every sensor map on every site's plan; 3d. OTHER
		// recorded as a coarser grid.
		std::vector<FloorPlanRun> floor_plans;
		std::vector<CoarserRun> coarser;
		if (!quick)
		{
			const std::string dir = (fs::temp_directory_path() / ("multires_bench_plans_" + std::to_string(getpid()))).string();
			const HalmstadData data(g_data + "/halmstad");
			floor_plans = runFloorPlans(data, data.sites(), g_aligner_options, dir);
			coarser = runCoarserOther(data, data.sites(), kCoarserFactors, g_aligner_options, dir);
			fs::remove_all(dir);
		}
		CScalingGridMapAligner::TReturnInfo willow;
		{
			const std::string w = g_data + "/ros_maps/willow/";
			willow = benchAligner().alignScaled(
				loadGridMap(w + "navstage_willow_5cm.yaml"), loadGridMap(w + "stageros_willow_10cm.yaml"));
		}

		// 4. Scaling with map size (fresh process each: its own peak memory).
		std::vector<ScalingCase> scaling;
		for (const int cells : quick ? std::vector<int>{500} : std::vector<int>{500, 1000, 2000, 4000, 8000})
			scaling.push_back(runScalingCase(fs::canonical("/proc/self/exe"), cells));
		// 4a. Whole processes against MRPT's on the same-resolution pairs.
		std::vector<WholeProcessRow> processes;
		for (const double r : quick ? std::vector<double>{0.10} : res_all)
			processes.push_back(runWholeProcess(fs::canonical("/proc/self/exe"), r));

		// 4b. Fleets: N maps into one (fresh process each).
		const std::vector<FleetCase> fleets = runFleets(fs::canonical("/proc/self/exe"), quick);
		std::vector<HalmstadFleetRun> halmstad_fleets;
		if (!quick)
		{
			const std::string dir = (fs::temp_directory_path() / ("multires_bench_fleets_" + std::to_string(getpid()))).string();
			const std::string self = fs::canonical("/proc/self/exe");
			const HalmstadData data(g_data + "/halmstad");
			halmstad_fleets = runHalmstadFleets(
				data, data.sites(), true, [&](const std::string& d) { return placeFleetInChild(self, d); }, dir);
			fs::remove_all(dir);
		}
		const LiveLatency live = runLiveLatency(scansOf, quick ? 4 : 16);

		// 5. Basin of convergence of TsICP alone.
		const std::vector<double> dyaws = quick ? std::vector<double>{-8, 0, 8}
												: std::vector<double>{-8, -6, -4, -2, 0, 2, 4, 6, 8};
		const std::vector<double> dscales = dyaws;  // percent
		const auto basin_same = basin("fr079", 0.05, 0.05, dyaws, dscales);
		const auto basin_ratio = basin("fr079", 0.02, 0.10, dyaws, dscales);

		// ------------------------------------------------------------ outputs
		writeCsv(out + "/pairs.csv", all);
		auto matrixOf = [&](const std::string& set, const std::vector<double>& rows, const std::vector<double>& cols,
							 bool rows_are_yaw, bool mrpt) {
			std::vector<std::vector<MatrixCell>> m(rows.size(), std::vector<MatrixCell>(cols.size()));
			for (const auto& r : all)
			{
				if (r.set != set || r.log != "fr079") continue;
				const double rv = rows_are_yaw ? r.yaw_deg : r.ref_res;
				const auto ri = std::find_if(rows.begin(), rows.end(), [&](double v) { return std::abs(v - rv) < 1e-9; });
				const auto ci = std::find_if(cols.begin(), cols.end(), [&](double v) { return std::abs(v - r.other_res) < 1e-9; });
				if (ri == rows.end() || ci == cols.end()) continue;
				MatrixCell& c = m[ri - rows.begin()][ci - cols.begin()];
				c.ran = !mrpt || r.mrpt_ran;
				c.ok = mrpt ? r.mrpt_correct : r.correct;
				c.text = mrpt ? (r.mrpt_correct ? num(r.mrpt_rmse, 2) : (r.mrpt_ran ? "fail" : ""))
							  : (r.correct ? num(r.rmse, 2) : (r.merged ? "wrong" : "no"));
			}
			return m;
		};
		std::vector<std::string> res_labels, yaw_labels;
		for (double r : res) res_labels.push_back(cm(r) + " cm");
		for (double y : quick ? std::vector<double>{90} : yaws) yaw_labels.push_back(num(y, 0) + " deg");
		std::vector<std::string> rot_labels;
		for (double r : rot_res) rot_labels.push_back(cm(r) + " cm");
		cv::imwrite(out + "/fig8_resolution_matrix_ours.png",
					successMatrix("fr079: ours (RMSE in coarse cells; green = merged within 2 cells)", res_labels,
								  "reference", res_labels, "other map's resolution",
								  matrixOf("resolution", res, res, false, false)));
		cv::imwrite(out + "/fig8_resolution_matrix_mrpt.png",
					successMatrix("fr079: MRPT CGridMapAligner (featsPerSquareMeter 0.1)", res_labels, "reference",
								  res_labels, "other map's resolution", matrixOf("resolution", res, res, false, true)));
		cv::imwrite(out + "/fig9_rotation_matrix_ours.png",
					successMatrix("fr079, reference 2 cm: ours by rotation and other's resolution", yaw_labels,
								  "rotation", rot_labels, "other map's resolution",
								  matrixOf("rotation", quick ? std::vector<double>{90} : yaws, rot_res, true, false)));
		{
			std::vector<std::vector<MatrixCell>> m1(dyaws.size(), std::vector<MatrixCell>(dscales.size())), m2 = m1;
			for (size_t i = 0; i < basin_same.size(); ++i)
			{
				auto& c1 = m1[i / dscales.size()][i % dscales.size()];
				c1 = {basin_same[i].converged, true, num(basin_same[i].rmse, 2)};
				auto& c2 = m2[i / dscales.size()][i % dscales.size()];
				c2 = {basin_ratio[i].converged, true, num(basin_ratio[i].rmse, 2)};
			}
			std::vector<std::string> yl, sl;
			for (double d : dyaws) yl.push_back(num(d, 0) + " deg");
			for (double d : dscales) sl.push_back(num(d, 0) + " %");
			cv::imwrite(out + "/fig7_basin_5cm_5cm.png",
						successMatrix("TsICP from perturbed truth, fr079 5 vs 5 cm (RMSE, coarse cells)", yl,
									  "rotation error", sl, "scale error", m1));
			cv::imwrite(out + "/fig7_basin_2cm_10cm.png",
						successMatrix("TsICP from perturbed truth, fr079 2 vs 10 cm (RMSE, coarse cells)", yl,
									  "rotation error", sl, "scale error", m2));
		}
		{
			Series t{"runtime [s]", {}, {}, cv::Scalar(200, 80, 40)}, mem{"peak RSS [100 MB]", {}, {}, cv::Scalar(40, 140, 40)};
			for (const auto& c : scaling)
			{
				const double cells = double(c.ref_w) * c.ref_h;
				t.x.push_back(cells), t.y.push_back(c.seconds);
				mem.x.push_back(cells), mem.y.push_back(c.peak_mb / 100);
			}
			cv::imwrite(out + "/scaling_size.png",
						logLogPlot("fr079 pair, other at half the resolution", "reference cells", "", {t, mem}));
			Series byratio{"runtime [s]", {}, {}, cv::Scalar(200, 80, 40)};
			for (const double ro : res)
				for (const auto& r : all)
					if (r.set == "resolution" && r.log == "fr079" && std::abs(r.ref_res - 0.02) < 1e-9 &&
						std::abs(r.other_res - ro) < 1e-9)
						byratio.x.push_back(ro / 0.02), byratio.y.push_back(r.seconds);
			cv::imwrite(out + "/scaling_ratio.png",
						logLogPlot("fr079, reference 2 cm", "resolution ratio (other / reference)", "", {byratio}));
		}

		// REPORT.md
		std::ofstream md(out + "/REPORT.md");
		const double total_s =
			std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
		md << "# multires_map_merge benchmark report\n\n"
		   << "Generated by `multires_bench" << (quick ? " --quick" : "") << " --out " << out << "` ("
		   << (quick ? "quick mode: a few pairs" : "full run") << ") on " << machine() << ", in "
		   << num(total_s / 60, 1) << " min. Every number below comes from that run; per-pair rows are in "
		   << "`pairs.csv`.\n\n"
		   << "Protocol (the paper's): a SLAM-corrected CARMEN log from `../shared/data/carmen_corrected` is split; "
		   << "the reference renders the first 60 % of the scans, the other the last 60 % in a frame rotated by "
		   << "the given angle and shifted by (1.5, -2.5) m; ground truth is exact. Each map is fed as users feed it: "
		   << "written as a map_server `.yaml` + `.pgm` whose origin lies off the cell lattice (a sub-cell offset "
		   << "drawn per map, as every `map_saver` output has) and read back by the loader. A pair **succeeds** when it is "
		   << "reported merged *and* the point RMSE of the other map's edge points is ≤ 2 cells of the coarser map. "
		   << "MRPT's `CGridMapAligner` gets the same pairs as a `CMultiMetricMap` (grid + points map of occupied "
		   << "cells), `featsPerSquareMeter = 0.1`, all else default; it refuses different resolutions, which count "
		   << "as failures (Table III of the paper). MRPT is judged on accuracy alone (it has no refusal).\n\n";

		auto summarise = [&](const std::string& title, std::function<bool(const PairResult&)> in) {
			std::vector<PairResult> s;
			for (const auto& r : all)
				if (in(r)) s.push_back(r);
			if (s.empty()) return;
			size_t ok = 0, merged_wrong = 0, mrpt_ran = 0, mrpt_ok = 0;
			for (const auto& r : s)
			{
				ok += r.correct;
				merged_wrong += r.merged && !r.correct;
				mrpt_ran += r.mrpt_ran;
				mrpt_ok += r.mrpt_correct;
			}
			std::vector<PairResult> good;
			for (const auto& r : s)
				if (r.correct) good.push_back(r);
			md << "| " << title << " | " << ok << " / " << s.size() << " | " << merged_wrong << " | "
			   << num(median(column(good, [](auto& r) { return r.rmse; })), 3) << " | "
			   << num(median(column(s, [](auto& r) { return r.floor_rmse; })), 3) << " | "
			   << num(median(column(good, [](auto& r) { return r.yaw_err; })), 4) << " | "
			   << num(median(column(good, [](auto& r) { return r.scale_err_pct; })), 4) << " | "
			   << num(median(column(good, [](auto& r) { return r.implied_err_pct; })), 4) << " | "
			   << num(median(column(s, [](auto& r) { return r.seconds; })), 2) << " | "
			   << (mrpt_ran ? std::to_string(mrpt_ok) + " / " + std::to_string(s.size()) : "not run") << " |\n";
		};
		md << "## Success and accuracy (Table II / III analogue)\n\n"
		   << "Medians over the pairs that succeeded; runtime median over all pairs of the row. *TsICP from the "
			  "truth*: the RMSE TsICP converges to when started at the exact transform, over all pairs of the row: "
			  "what these renderings allow an edge-point registration.\n\n"
		   << "| pairs | ours: success | ours: merged but wrong | median RMSE [coarse cells] | TsICP from the truth "
			  "[coarse cells] | median yaw error [deg] | median scale error [%] | median implied-resolution error [%] | "
			  "median runtime [s] | MRPT: success |\n|---|---|---|---|---|---|---|---|---|---|\n";
		summarise("fr079, all resolution pairs (Fig. 8)", [](auto& r) { return r.set == "resolution"; });
		summarise("fr079, same resolution", [](auto& r) { return r.set == "resolution" && r.ref_res == r.other_res; });
		summarise("fr079, different resolutions", [](auto& r) { return r.set == "resolution" && r.ref_res != r.other_res; });
		summarise("fr079, ratio ≥ 4 (2↔8..10 cm)", [](auto& r) {
			return r.set == "resolution" && std::max(r.ref_res, r.other_res) / std::min(r.ref_res, r.other_res) >= 4 - 1e-9;
		});
		summarise("fr079, rotations (Fig. 9)", [](auto& r) { return r.set == "rotation"; });
		for (const auto& l : kLogs)
			summarise(l.name + " (2/5/10 cm)", [&](auto& r) { return r.set == "other-logs" && r.log == l.name; });

		// Runtime ratio on the same-resolution pairs, pair by pair.
		md << "\n## Runtime against MRPT, same-resolution pairs (same run, same machine)\n\n"
		   << "| pair | ours [s] | MRPT [s] | ours / MRPT | ours ok | MRPT ok |\n|---|---|---|---|---|---|\n";
		std::vector<double> ratios;
		for (const auto& r : all)
			if (r.set == "resolution" && r.ref_res == r.other_res && r.mrpt_ran)
			{
				const double ratio = r.seconds / std::max(1e-9, r.mrpt_seconds);
				ratios.push_back(ratio);
				md << "| " << cm(r.ref_res) << " cm | " << num(r.seconds, 2) << " | " << num(r.mrpt_seconds, 2) << " | "
				   << num(ratio, 2) << " | " << (r.correct ? "yes" : "no") << " | " << (r.mrpt_correct ? "yes" : "no")
				   << " |\n";
			}
		md << "\nMedian ratio ours/MRPT: **" << num(median(ratios), 2) << "**.\n";

		md << "\n### Whole process, same-resolution pairs\n\nEach side in a fresh process that loads the two "
			  "map_server files, aligns and exits (median of 3 runs, wall time).\n\n"
			  "| pair | ours [s] | MRPT [s] | ours / MRPT | ours: merged | MRPT: aligned | our peak RSS [MB] |\n"
			  "|---|---|---|---|---|---|---|\n";
		double worst_process_ratio = 0;
		for (const auto& p : processes)
		{
			const double ratio = p.ours_s / std::max(1e-9, p.mrpt_s);
			worst_process_ratio = std::max(worst_process_ratio, ratio);
			md << "| " << cm(p.res) << " cm | " << num(p.ours_s, 2) << " | " << num(p.mrpt_s, 2) << " | " << num(ratio, 2)
			   << " | " << (p.ours_merged ? "yes" : "no") << " | " << (p.mrpt_aligned ? "yes" : "no") << " | "
			   << num(p.ours_peak_mb, 0) << " |\n";
		}

		// Alignment time distributions (in-process, `seconds` of each pair).
		auto quantile = [](std::vector<double> v, double q) -> double {
			v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
			if (v.empty()) return NAN;
			std::sort(v.begin(), v.end());
			return v[std::min(v.size() - 1, size_t(std::ceil(q * v.size())) - (q > 0 ? 1 : 0))];
		};
		const auto fig8_secs = column(all, [](auto& r) { return r.set == "resolution" ? r.seconds : NAN; });
		const auto fig9_secs = column(all, [](auto& r) { return r.set == "rotation" ? r.seconds : NAN; });
		// MRPT "runs" every pair but refuses different resolutions at once: only the pairs it aligns count.
		const auto mrpt_fig8_secs = column(all, [](auto& r) {
			return r.set == "resolution" && r.mrpt_ran && r.ref_res == r.other_res ? r.mrpt_seconds : NAN;
		});
		md << "\n### Alignment time distribution (in-process)\n\n| pairs | median [s] | p95 [s] | max [s] |\n|---|---|---|---|\n";
		auto distribution = [&](const std::string& title, const std::vector<double>& v) {
			md << "| " << title << " | " << num(quantile(v, 0.5), 2) << " | " << num(quantile(v, 0.95), 2) << " | "
			   << num(quantile(v, 1.0), 2) << " |\n";
		};
		distribution("fr079 Fig. 8 (81 pairs)", fig8_secs);
		distribution("fr079 Fig. 9 (45 pairs)", fig9_secs);
		distribution("MRPT on the Fig. 8 pairs it aligns (same resolution)", mrpt_fig8_secs);
		std::vector<double> halmstad_secs_all;
		for (const auto& h : halmstad)
			if (h.positive) halmstad_secs_all.push_back(h.seconds);
		distribution("Halmstad, every same-site sensor pair", halmstad_secs_all);
		size_t mrpt_refused = 0, mrpt_diff = 0;
		for (const auto& r : all)
			if (r.set == "resolution" && r.ref_res != r.other_res && r.mrpt_ran)
			{
				++mrpt_diff;
				mrpt_refused += !r.mrpt_correct;
			}
		if (mrpt_diff)
			md << "On the " << mrpt_diff << " different-resolution pairs MRPT failed " << mrpt_refused
			   << " (first reason: `"
			   << std::find_if(all.begin(), all.end(), [](auto& r) { return r.mrpt_ran && r.ref_res != r.other_res; })->mrpt_why
			   << "`).\n";

		md << "\n## Matrices\n\n![ours](fig8_resolution_matrix_ours.png)\n\n![MRPT](fig8_resolution_matrix_mrpt.png)\n\n"
		   << "![rotations](fig9_rotation_matrix_ours.png)\n\nCells: RMSE in cells of the coarser map when merged "
			  "within 2 cells; `wrong` = reported merged but off; `no` = reported not merged.\n";

		md << "\n## Overlap: TsICP's ξ against the true overlap\n\n"
		   << "True overlap: share of the reference's edge points with an edge point of the other (true transform) "
			  "within one coarse cell. Median |ξ - true| over merged pairs: **"
		   << num(median(column(all, [](auto& r) { return r.merged ? std::abs(r.overlap - r.true_overlap) : NAN; })), 3)
		   << "** (median ξ " << num(median(column(all, [](auto& r) { return r.merged ? r.overlap : NAN; })), 3)
		   << ", median true " << num(median(column(all, [](auto& r) { return r.true_overlap; })), 3) << ").\n";

		md << "\n## Runtime per stage (medians over all pairs, seconds)\n\n| features | ransac | edges | icp | verify |\n|---|---|---|---|---|\n|";
		for (const char* k : {"features", "ransac", "edges", "icp", "verify"})
			md << " " << num(median(column(all, [&](auto& r) { return r.stages.count(k) ? r.stages.at(k) : NAN; })), 3) << " |";
		md << "\n";

		size_t false_merges = 0;
		md << "\n## False merges (pairs that must not merge)\n\n| reference | other | kind | result | confidence |\n|---|---|---|---|---|\n";
		for (const auto& n : negatives)
		{
			false_merges += n.merged;
			md << "| " << n.a << " (5 cm) | " << n.b << " (8 cm) | " << n.what << " | "
			   << (n.merged ? "**MERGED (false)**" : "refused") << " | " << num(n.confidence, 2) << " |\n";
		}
		md << "\nFalse-merge rate: **" << false_merges << " / " << negatives.size() << "**.\n";

		// Real independent maps.
		struct SiteRow
		{
			size_t pairs = 0, right = 0, refused = 0, wrong = 0, with_right_candidate = 0;
			std::vector<double> disp, corr, corr_annot, secs;
			size_t mrpt_ran = 0, mrpt_right = 0, mrpt_timeout = 0;
		};
		std::map<std::string, SiteRow> sites;
		size_t cross = 0, cross_merged = 0;
		std::vector<double> cross_secs;
		for (const auto& h : halmstad)
		{
			if (!h.positive)
			{
				++cross, cross_merged += h.merged, cross_secs.push_back(h.seconds);
				continue;
			}
			SiteRow& row = sites[h.site];
			++row.pairs;
			row.secs.push_back(h.seconds);
			if (!h.merged) ++row.refused;
			else if (h.outcome.right) ++row.right, row.disp.push_back(h.outcome.mean_displacement_px), row.corr.push_back(h.outcome.corr_rms_px);
			else ++row.wrong;
			if (h.mrpt.seconds > 0) ++row.mrpt_ran, row.mrpt_right += h.mrpt_right, row.mrpt_timeout += !h.mrpt.finished;
		}
		md << "\n## Real independent maps (Halmstad Robot Maps)\n\n"
		   << "Real sensor maps of four sites, each made in a separate session (`../shared/data/halmstad`), fed as "
			  "map_server files at 0.05 m. REF = the later map of each unordered same-site pair, OTHER = the earlier; "
			  "**right** = reported merged with the mean displacement of OTHER's occupied pixels against the annotated "
			  "similarity ≤ 40 px *and* the annotated inlier correspondences' RMS ≤ max(2 × the annotation's own "
			  "`rms_px`, 40 px). E5 and HIH are the calibration sites (the decision was tuned on them, "
			  "`scripts/calibrate_decision.py`); **F5 and KPT4A are the acceptance set: never tuned on**.\n\n"
		   << "| site | role | pairs | merged right | refused | merged wrong | median displacement [px] | median corr. RMS [px] | median runtime [s] | MRPT (sample, 30 s limit) |\n"
		   << "|---|---|---|---|---|---|---|---|---|---|\n";
		size_t acc_pairs = 0, acc_right = 0, cal_pairs = 0, cal_right = 0, halm_wrong = 0;
		std::vector<double> halm_secs;
		for (const auto& site : {"E5", "HIH", "F5", "KPT4A"})
		{
			if (!sites.count(site)) continue;
			const SiteRow& r = sites[site];
			const bool cal = isCalibrationSite(site);
			(cal ? cal_pairs : acc_pairs) += r.pairs;
			(cal ? cal_right : acc_right) += r.right;
			halm_wrong += r.wrong;
			halm_secs.insert(halm_secs.end(), r.secs.begin(), r.secs.end());
			md << "| " << site << " | " << (cal ? "calibration" : "**acceptance**") << " | " << r.pairs << " | "
			   << r.right << " (" << num(100.0 * r.right / std::max<size_t>(1, r.pairs), 0) << " %) | " << r.refused
			   << " | " << r.wrong << " | " << num(median(r.disp), 1) << " | " << num(median(r.corr), 1) << " | "
			   << num(median(r.secs), 2) << " | " << r.mrpt_right << " right of " << r.mrpt_ran << " ("
			   << r.mrpt_timeout << " timed out) |\n";
		}
		md << "\nCross-site negatives (a sensor map of one site against sensor maps of the others, 6 per map): **"
		   << cross_merged << " merged / " << cross << "**.\n";
		md << "\nWillow Garage, navstage 5 cm (REF) vs stageros 10 cm (two independent SLAM maps, one turned 90°): "
		   << (willow.success ? "merged" : "**not merged**") << ", x " << num(willow.metric.t.x(), 3) << " m, y "
		   << num(willow.metric.t.y(), 3) << " m, yaw " << num(willow.metric.yaw * 180 / M_PI, 2) << "°, scale "
		   << num(willow.metric.scale, 4) << ", confidence " << num(willow.confidence, 2)
		   << " (reference and tolerance: README, test_real_maps).\n";

		if (!floor_plans.empty()) writeFloorPlanSection(md, floor_plans);
		if (!coarser.empty()) writeCoarserSection(md, coarser);

		md << "\n## Scaling\n\nThe fr079 pair at finer and finer resolution, each map padded with unknown cells to a square "
		  "(the other at half the reference's resolution, rotated 30°), aligned in a fresh process.\n\n"
		  "*Whole process*: the child from start to exit (loading both `.gridmap` files, aligning, exiting).\n\n"
		  "| reference cells | other cells | alignment [s] | whole process [s] | peak RSS [MB] | merged |\n|---|---|---|---|---|---|\n";
		for (const auto& c : scaling)
			md << "| " << c.ref_w << "×" << c.ref_h << " (" << num(c.ref_res * 100, 2) << " cm) | "
			   << c.ref_w / 2 << "×" << c.ref_h / 2 << " | " << num(c.seconds, 2) << " | " << num(c.process_seconds, 2)
			   << " | " << num(c.peak_mb, 0) << " | " << (c.merged ? std::string("yes") : "no: " + c.message) << " |\n";
		std::vector<ScalingCase> aligned_cases;
		for (const auto& c : scaling)
			if (c.merged) aligned_cases.push_back(c);
		if (aligned_cases.size() >= 2)
		{
			const auto& a = aligned_cases.front();
			const auto& b = aligned_cases.back();
			const double dc = std::log(double(b.ref_w) * b.ref_h / (double(a.ref_w) * a.ref_h));
			md << "\nFitted growth between the smallest and largest case: runtime ∝ cells^"
			   << num(std::log(b.seconds / a.seconds) / dc, 2) << ", peak memory ∝ cells^"
			   << num(std::log(b.peak_mb / a.peak_mb) / dc, 2) << ".\n";
		}
		md << "\n![size](scaling_size.png)\n\n![ratio](scaling_ratio.png)\n";

		auto basinShare = [](const std::vector<BasinCell>& b) {
			return std::count_if(b.begin(), b.end(), [](auto& c) { return c.converged; });
		};
		writeFleetSection(md, fleets);
		if (!halmstad_fleets.empty()) writeHalmstadFleetSection(md, halmstad_fleets);
		writeLiveSection(md, live);

		md << "\n## Basin of convergence of TsICP alone (Fig. 7 analogue)\n\n"
		   << "TsICP started from the truth rotated by Δθ and scaled by Δs about the other map's centre; converged = "
			  "edge-point RMSE ≤ 0.5 coarse cell afterwards. 5 vs 5 cm: "
		   << basinShare(basin_same) << " / " << basin_same.size() << " starts converge; 2 vs 10 cm: "
		   << basinShare(basin_ratio) << " / " << basin_ratio.size() << ".\n\n"
		   << "![basin](fig7_basin_5cm_5cm.png)\n\n![basin](fig7_basin_2cm_10cm.png)\n";

		// Targets.
		std::vector<PairResult> fig8, good8;
		for (const auto& r : all)
			if (r.set == "resolution" || r.set == "rotation")
			{
				fig8.push_back(r);
				if (r.correct) good8.push_back(r);
			}
		const size_t merged8 = good8.size();
		md << "\n## Targets\n\n| target | this run | met |\n|---|---|---|\n";
		auto target = [&](const std::string& what, const std::string& got, bool met) {
			md << "| " << what << " | " << got << " | " << (met ? "yes" : "**no**") << " |\n";
		};
		target("every fr079 pair of the resolution and rotation matrices merged", std::to_string(merged8) + " / " + std::to_string(fig8.size()), merged8 == fig8.size());
		const double m_rmse = median(column(good8, [](auto& r) { return r.rmse; }));
		const double m_yaw = median(column(good8, [](auto& r) { return r.yaw_err; }));
		const double m_scale = median(column(good8, [](auto& r) { return r.scale_err_pct; }));
		target("median point RMSE ≤ 0.15 coarse cell", num(m_rmse, 3), m_rmse <= 0.15);
		target("median yaw error ≤ 0.04°", num(m_yaw, 4) + "°", m_yaw <= 0.04);
		target("median scale error ≤ 0.05 %", num(m_scale, 4) + " %", m_scale <= 0.05);
		target("median runtime no slower than MRPT on same-resolution pairs (ratio ≤ 1)", num(median(ratios), 2),
			   median(ratios) <= 1);
		for (const std::string set : {"rotation", "other-logs"})
		{
			std::vector<double> e;
			for (const auto& r : all)
				if (r.set == set && r.correct) e.push_back(r.rmse);
			if (!e.empty())
				target("median point RMSE ≤ 0.15 coarse cell, " + set + " (map_server files)", num(median(e), 3),
					   median(e) <= 0.15);
		}
		for (const auto& c : fleets)
		{
			if (c.name.find("another building") != std::string::npos)
				target("fleet " + c.name + ": every robot of the building placed within 2 cells, the other kept out",
					   std::to_string(c.placed_right) + " / " + std::to_string(c.building) + ", other placed: " +
						   std::to_string(c.others_placed),
					   c.placed_right == c.building && c.others_placed == 0);
			if (c.name.find("1000×1000") != std::string::npos)
				target("fleet of 8 maps of 1000×1000 cells in ≤ 3 s on 2 cores", num(c.seconds, 1) + " s", c.seconds <= 3);
		}
		for (const auto& f : halmstad_fleets)
		{
			const std::string name = "Halmstad fleet " + f.site + (f.mixed_cells ? " (mixed cells)" : "");
			if (f.maps >= 14)
				target(name + " of " + std::to_string(f.maps) + " maps in one call: ≤ 10 s, ≤ 2 GiB peak",
					   num(f.seconds, 1) + " s, " + num(f.peak_mb, 0) + " MB", f.seconds <= 10 && f.peak_mb <= 2048);
			const auto& d = f.joint.displacement_px;
			const double med = median(d), worst = d.empty() ? NAN : *std::max_element(d.begin(), d.end());
			target(name + ": every map placed right, displacement median ≤ 7 px, max ≤ 15 px",
				   std::to_string(f.joint.right) + " / " + std::to_string(f.maps - 1) + ", median " + num(med, 1) +
					   " px, max " + num(worst, 1) + " px",
				   f.joint.right + 1 == f.maps && med <= 7 && worst <= 15);
		}
		{
			const double worst = live.maxLatencySeconds();
			target("live node: merged map and TF within two estimation periods of the maps overlapping (simulated "
				   "clock, estimations as slow as measured; never wrong, the other building kept out)",
				   (worst < 0 ? std::string("a robot never published") : "latency max " + num(worst, 1) + " s") + " of " +
					   num(2 * live.period_s, 1) + " s; estimations median " + num(live.medianEstimateSeconds(), 2) +
					   " s, max " + num(live.maxEstimateSeconds(), 2) + " s",
				   live.met());
		}
		{
			// Issue 12: speed and memory.
			target("whole process ≤ 1.0× MRPT on every same-resolution fr079 pair", "worst " + num(worst_process_ratio, 2) + "×",
				   !processes.empty() && worst_process_ratio <= 1.0);
			const double m8 = quantile(fig8_secs, 0.5), mm = quantile(mrpt_fig8_secs, 0.5), max8 = quantile(fig8_secs, 1.0);
			target("Fig. 8 alignment time: median ≤ 1.3× MRPT's median, max ≤ 1.5 s",
				   num(m8, 2) + " s vs MRPT " + num(mm, 2) + " s, max " + num(max8, 2) + " s", m8 <= 1.3 * mm && max8 <= 1.5);
			if (!quick)
				target("Halmstad pairs: median alignment time ≤ 0.4 s", num(quantile(halmstad_secs_all, 0.5), 2) + " s",
					   quantile(halmstad_secs_all, 0.5) <= 0.4);
			for (const auto& c : scaling)
			{
				if (c.cells == 4000)
					target("4000×4000 in ≤ 3 s with peak RSS ≤ 1 GiB", num(c.seconds, 2) + " s, " + num(c.peak_mb, 0) + " MB",
						   c.merged && c.seconds <= 3 && c.peak_mb <= 1024);
				if (c.cells == 8000)
					target("8000×8000 aligns or is refused clearly within 4 GiB",
						   (c.merged ? "aligned" : "refused (" + c.message.substr(0, 40) + "…)") + std::string(", ") +
							   num(c.peak_mb, 0) + " MB",
						   (c.merged || c.message.find("too large") != std::string::npos) && c.peak_mb <= 4096);
			}
		}
		target("zero false merges", std::to_string(false_merges) + " / " + std::to_string(negatives.size()), false_merges == 0);
		if (!quick)
		{
			target("Halmstad F5 + KPT4A (acceptance) ≥ 85 % merged right",
				   std::to_string(acc_right) + " / " + std::to_string(acc_pairs), acc_right >= 0.85 * acc_pairs);
			target("Halmstad E5 + HIH ≥ 80 % merged right", std::to_string(cal_right) + " / " + std::to_string(cal_pairs),
				   cal_right >= 0.8 * cal_pairs);
			target("0 merged wrong over all Halmstad sensor pairs and cross-site negatives",
				   std::to_string(halm_wrong + cross_merged), halm_wrong + cross_merged == 0);
			target("Halmstad runtime per pair no worse than before (median 1.1 s)", num(median(halm_secs), 2) + " s",
				   median(halm_secs) <= 1.1);
			const FloorPlanTotals plans = floorPlanTotals(floor_plans);
			target("floor plans F5 + KPT4A (acceptance) ≥ 17 / 18 merged right",
				   std::to_string(plans.acceptance_right) + " / " + std::to_string(plans.acceptance_pairs),
				   plans.acceptance_right >= 17);
			target("floor plans E5 + HIH ≥ 16 / 18 merged right",
				   std::to_string(plans.calibration_right) + " / " + std::to_string(plans.calibration_pairs),
				   plans.calibration_right >= 16);
			for (const auto& [factor, share] : {std::pair{kCoarserFactors[0], 0.95}, std::pair{kCoarserFactors[1], 0.9}})
			{
				const CoarserTotals acc = coarserTotals(coarser, factor, false), cal = coarserTotals(coarser, factor, true);
				target("OTHER " + num(factor, 1) + "× coarser, F5 + KPT4A ≥ " + num(100 * share, 0) + " % merged right, 0 wrong",
					   std::to_string(acc.right) + " / " + std::to_string(acc.pairs) + ", " +
						   std::to_string(acc.wrong + cal.wrong) + " wrong (E5 + HIH " + std::to_string(cal.right) +
						   " / " + std::to_string(cal.pairs) + ")",
					   acc.right >= share * acc.pairs && acc.wrong + cal.wrong == 0);
			}
			target("0 merged wrong over floor plans: own plan and every other site's",
				   std::to_string(plans.merged_wrong + plans.negatives_merged) + " (of " +
					   std::to_string(plans.negatives) + " negatives)",
				   plans.merged_wrong + plans.negatives_merged == 0);
		}
		md.close();
		std::cout << "wrote " << out << "/REPORT.md (" << num(total_s, 0) << " s)" << std::endl;
		return 0;
	}
	catch (const std::exception& e)
	{
		std::cerr << "multires_bench: " << e.what() << "\n";
		return 1;
	}
}
