#pragma once
// The paper's experiments on SLAM-corrected CARMEN logs
// (../shared/data/carmen_corrected): a log split into two overlapping parts
// with exact truth, rendered at any resolutions and rotation and fed as
// map_server files; the accuracy matrices (Fig. 8, 9), the pairs that must
// not merge, and TsICP's basin of convergence (Fig. 7).

#include "context.h"
#include "live_fleet.h"

#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/GroundTruthPair.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace multires_bench
{
using multires_map_merge::GridInFrame;
using multires_map_merge::PointList;
using multires_map_merge::ScanSequence;

struct Log
{
	std::string name, file;
};
extern const std::vector<Log> kLogs;

/** A log's scans, read once per run. */
const ScanSequence& scansOf(const BenchContext& ctx, const std::string& log);
ScansOf carmenScans(const BenchContext& ctx);

/** The paper's split: the reference renders the first 60 % of the run, the
 * other the last 60 %, in a frame rotated by yaw and shifted (cached). */
const mrpt::maps::COccupancyGridMap2D& render(
	const BenchContext& ctx, const std::string& log, bool ref, double res, double yaw_deg);
/** The same map as users feed it: written as a map_server .yaml + .pgm with
 * its origin off the cell lattice (a sub-cell offset drawn from the pair's
 * key: reproducible) and read back by the loader (cached). */
std::shared_ptr<const GridInFrame> mapServerFile(
	const BenchContext& ctx, const std::string& log, bool ref, double res, double yaw_deg);
/** The other part's frame in the reference's. */
Similarity2D truthFor(double yaw_deg);
/** Edge points in metres of the map's frame. */
PointList metricEdges(const GridInFrame& m);

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

/** One pair of `log` (reference at `rr`, other at `ro` turned by `yaw`), as
 * map_server files with origins off the lattice; MRPT's aligner beside. */
PairResult runPair(
	const BenchContext& ctx, const std::string& set, const std::string& log, double rr, double ro, double yaw,
	bool with_mrpt);

/** f of each result. */
template <class F>
std::vector<double> column(const std::vector<PairResult>& rs, F f)
{
	std::vector<double> v;
	for (const auto& r : rs) v.push_back(f(r));
	return v;
}

/** The accuracy matrices alone (no MRPT, no report): for work on accuracy.
 * `list`: resolution, other-logs, rotation. */
int runAccuracySets(const BenchContext& ctx, const std::string& list);

struct Negative
{
	std::string a, b, what;
	bool merged;
	double confidence;
	std::string message;
};
/** Different buildings (every ordered pair of the six logs, 5 vs 8 cm) and
 * the two ends of one run: all must be refused. */
std::vector<Negative> runCarmenNegatives(const BenchContext& ctx);

struct BasinCell
{
	double dyaw_deg, dscale_pct, rmse;
	bool converged;
};
/** TsICP alone, started from the truth perturbed in rotation and scale about
 * the other map's centre (the paper's Fig. 7): does it come back? */
std::vector<BasinCell> basin(
	const BenchContext& ctx, const std::string& log, double rr, double ro, const std::vector<double>& dyaws,
	const std::vector<double>& dscales);

}  // namespace multires_bench
