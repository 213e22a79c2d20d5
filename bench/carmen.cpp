#include "carmen.h"

#include "halmstad.h"
#include "mrpt_anchor.h"

#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/Finish.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/TsICP.h>

#include <mrpt/system/CTicTac.h>
#include <Eigen/Geometry>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <random>
#include <sstream>
#include <tuple>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

const std::vector<Log> kLogs = {
	{"fr079", "freiburg-079-corrected.log.gz"}, {"intel", "intel-corrected.log.gz"},
	{"fr101", "freiburg-101-corrected.log.gz"}, {"orebro", "orebro-corrected.log.gz"},
	{"fhw", "fhw-corrected.log.gz"},           {"belgioioso", "belgioioso-corrected.log.gz"},
};

const ScanSequence& scansOf(const BenchContext& ctx, const std::string& log)
{
	static std::map<std::string, ScanSequence> cache;  // by file
	for (const auto& l : kLogs)
		if (l.name == log)
		{
			const std::string path = ctx.data + "/carmen_corrected/" + l.file;
			auto it = cache.find(path);
			return it != cache.end() ? it->second : cache.emplace(path, loadScans(path)).first->second;
		}
	throw std::runtime_error("unknown log " + log);
}

ScansOf carmenScans(const BenchContext& ctx)
{
	return [&ctx](const std::string& log) -> const ScanSequence& { return scansOf(ctx, log); };
}

/** The paper's split: the reference renders the first 60 % of the run, the
 * other the last 60 %, in a frame rotated by yaw and shifted. Renders are
 * cached: a row of the matrix shares its reference. */
const mrpt::maps::COccupancyGridMap2D& render(
	const BenchContext& ctx, const std::string& log, bool ref, double res, double yaw_deg)
{
	static std::map<std::tuple<std::string, bool, long, long>, mrpt::maps::COccupancyGridMap2D> cache;
	const auto key = std::make_tuple(log, ref, std::lround(res * 1e4), std::lround(yaw_deg * 100));
	auto it = cache.find(key);
	if (it != cache.end()) return it->second;
	if (cache.size() > 40) cache.clear();  // bounded memory on the full run
	const ScanSequence& s = scansOf(ctx, log);
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
std::shared_ptr<const GridInFrame> mapServerFile(
	const BenchContext& ctx, const std::string& log, bool ref, double res, double yaw_deg)
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
	const ScanSequence& s = scansOf(ctx, log);
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

/** Edge points in metres of the map's frame. */
PointList metricEdges(const GridInFrame& m)
{
	PointList pts = edgePoints(toClassImage(m.grid));
	const Similarity2D to_map = m.cellToMapFrame();
	for (auto& p : pts) p = to_map(p);
	return pts;
}

namespace
{
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
}  // namespace

PairResult runPair(
	const BenchContext& ctx, const std::string& set, const std::string& log, double rr, double ro, double yaw,
	bool with_mrpt)
{
	PairResult p;
	p.set = set, p.log = log, p.ref_res = rr, p.other_res = ro, p.yaw_deg = yaw;
	// Fed as users feed it: map_server files with origins off the cell lattice.
	const auto ref_map = mapServerFile(ctx, log, true, rr, 0), other_map = mapServerFile(ctx, log, false, ro, yaw);
	const GridInFrame &ref = *ref_map, &other = *other_map;
	p.ref_w = ref.grid.getSizeX(), p.ref_h = ref.grid.getSizeY();
	p.other_w = other.grid.getSizeX(), p.other_h = other.grid.getSizeY();
	const Similarity2D truth = truthFor(yaw);
	const double coarse = std::max(rr, ro);
	const PointList other_edges = metricEdges(other);

	CScalingGridMapAligner aligner = ctx.aligner();
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
		const auto prepared = [&](const GridInFrame& m) { return aligner.prepare(m.grid); };
		const auto ref_p = prepared(ref), other_p = prepared(other);
		const Similarity2D at_truth = aligner.options.icp_finish_on_occupied
			? gridCells(*ref_p, finishOnOccupied(*ref_p, *other_p, preparedCells(*ref_p, truth_cells, *other_p),
									 aligner.options.icpParams(), aligner.options.latticeParams()),
						*other_p)
			: runTsICP(edgePoints(toClassImage(ref.grid)), edgePoints(toClassImage(other.grid)), truth_cells,
					   aligner.options.icpParams()).transform;
		p.floor_rmse = pointRmse(ref.cellToMapFrame().compose(at_truth).compose(other.cellToMapFrame().inverse()),
								 truth, other_edges) / coarse;
	}
	const auto cm_of = [](double res) { return std::to_string(std::lround(res * 100)) + "cm"; };
	writeCandidates(ctx, log, set + "_" + cm_of(rr), cm_of(ro) + "_yaw" + std::to_string(std::lround(yaw)), true, false, r,
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

/** Different buildings (every ordered pair of the six logs, 5 vs 8 cm) and
 * the two ends of one run: all must be refused. */
std::vector<Negative> runCarmenNegatives(const BenchContext& ctx)
{
	const bool quick = ctx.quick;
	std::vector<Negative> negatives;
	std::vector<std::pair<std::string, std::string>> pairs_of_logs;
	for (size_t i = 0; i < kLogs.size(); ++i)
		for (size_t j = 0; j < kLogs.size(); ++j)
		if (i != j && (!quick || (i == 0 && j == 1))) pairs_of_logs.push_back({kLogs[i].name, kLogs[j].name});
	for (const auto& [a, b] : pairs_of_logs)
	{
		const ScanSequence& sa = scansOf(ctx, a);
		const ScanSequence& sb = scansOf(ctx, b);
		const auto ga = renderGrid(sa, 0, sa.size(), 0.05);
		const auto gb = renderGrid(sb, 0, sb.size(), 0.08);
		const auto r = ctx.aligner().alignScaled(ga, gb);
		writeCandidates(ctx, "carmen", a, b, false, true, r, noTruth);
		negatives.push_back({a, b, "different buildings", r.success, r.confidence, r.message});
		std::cout << "negative " << a << " vs " << b << ": " << (r.success ? "MERGED (false merge)" : "refused")
			  << std::endl;
	}
	for (const auto& log : quick ? std::vector<std::string>{"fr079"}
					 : std::vector<std::string>{"fr079", "intel", "fr101", "fhw"})
	{
		// Two ends of the building: columns [0, 40 %) and [60 %, 100 %) of the whole run.
		const ScanSequence& s = scansOf(ctx, log);
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
		const auto r = ctx.aligner().alignScaled(crop(whole5, 0, 0.4), crop(whole8, 0.6, 1));
		writeCandidates(ctx, "carmen", log + "_west", log + "_east", false, true, r, noTruth);
		negatives.push_back({log + " west", log + " east", "disjoint parts of one run", r.success, r.confidence, r.message});
		std::cout << "negative " << log << " disjoint halves: " << (r.success ? "MERGED (false merge)" : "refused")
			  << std::endl;
	}

	return negatives;
}

/** TsICP alone, started from the truth perturbed in rotation and scale about
 * the other map's centre (the paper's Fig. 7): does it come back? */
std::vector<BasinCell> basin(
	const BenchContext& ctx, const std::string& log, double rr, double ro, const std::vector<double>& dyaws,
	const std::vector<double>& dscales)
{
	const auto ref = render(ctx, log, true, rr, 0);  // copies: the cache may be cleared by the next render
	const auto other = render(ctx, log, false, ro, 30);
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

/** The accuracy matrices alone (no MRPT, no report): for work on accuracy. */
int runAccuracySets(const BenchContext& ctx, const std::string& list)
{
	const std::vector<double> res_all = {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};
	std::stringstream in(list);
	for (std::string set; std::getline(in, set, ',');)
	{
		std::vector<PairResult> rs;
		if (set == "resolution")
			for (const double rr : res_all)
				for (const double ro : res_all) rs.push_back(runPair(ctx, set, "fr079", rr, ro, 0, false));
		else if (set == "other-logs")
			for (const std::string log : {"intel", "fr101", "orebro", "fhw", "belgioioso"})
				for (const double rr : {0.02, 0.05, 0.10})
					for (const double ro : {0.02, 0.05, 0.10}) rs.push_back(runPair(ctx, set, log, rr, ro, 0, false));
		else if (set == "rotation")
			for (const double yaw : {0, 90, 180, 270, 137})
				for (const double ro : res_all) rs.push_back(runPair(ctx, set, "fr079", 0.02, ro, yaw, false));
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

}  // namespace multires_bench
