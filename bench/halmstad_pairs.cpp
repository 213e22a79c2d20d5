#include "halmstad_pairs.h"

#include <multires_map_merge/Finish.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

void HalmstadTally::add(const HalmstadRun& h)
{
	++pairs;
	secs.push_back(h.seconds);
	if (!h.merged) ++refused;
	else if (h.outcome.right) ++right, disp.push_back(h.outcome.mean_displacement_px), corr.push_back(h.outcome.corr_rms_px);
	else ++wrong;
	if (h.retried_from_truth) ++(h.right_from_truth ? search_missed : evidence_weak);
	if (h.mrpt.seconds > 0) ++mrpt_ran, mrpt_right += h.mrpt_right, mrpt_timeout += !h.mrpt.finished;
}

namespace
{
/** The map in the middle of a grid of `side` cells a side (at least its
 * own), unknown around it; the same map frame. */
GridInFrame paddedTo(const GridInFrame& map, int side)
{
	const int w = int(map.grid.getSizeX()), h = int(map.grid.getSizeY());
	const int left = std::max(0, side - w) / 2, below = std::max(0, side - h) / 2;
	return widened(map, {left, below, std::max(0, side - w) - left, std::max(0, side - h) - below});
}
}  // namespace

HalmstadRun runHalmstadPair(
	const BenchContext& ctx, const HalmstadData& data, const std::string& ref, const std::string& other,
	const std::string& dir, double mrpt_limit_s)
{
	HalmstadRun run;
	run.site = siteOf(ref);
	run.ref = ref, run.other = other;
	run.positive = run.site == siteOf(other);
	// Calibration data (the issue's): E5 and HIH positives, and every
	// negative with an E5 or HIH map or plan (docs/decision.md, Calibration).
	run.calibration = isCalibrationSite(run.site) || isCalibrationSite(siteOf(other));
	const GridInFrame ref_map = loadGridMap(data.yaml(ref, dir)), other_map = loadGridMap(data.yaml(other, dir));
	const HalmstadPair* truth = run.positive ? data.pair(other, ref) : nullptr;
	// Judged on the files as they are; aligned as given (--pad-to: framed).
	std::optional<GridInFrame> ref_padded, other_padded;
	if (ctx.pad_to_cells > 0)
		ref_padded = paddedTo(ref_map, ctx.pad_to_cells), other_padded = paddedTo(other_map, ctx.pad_to_cells);
	mrpt::system::CTicTac clock;
	const auto r = ctx.aligner().alignScaled(ref_padded ? *ref_padded : ref_map, other_padded ? *other_padded : other_map);
	run.seconds = clock.Tac();
	run.merged = r.success;
	run.confidence = r.confidence;
	run.message = r.message;
	const int ref_rows = static_cast<int>(ref_map.grid.getSizeY());
	if (truth && r.candidates.size()) run.outcome = judge(r.metric, *truth, other_map, ref_rows);
	if (mrpt_limit_s > 0)
	{
		run.mrpt = mrptWithTimeLimit(ctx.self, data.yaml(ref, dir), data.yaml(other, dir), mrpt_limit_s);
		if (truth && run.mrpt.aligned) run.mrpt_right = judge(run.mrpt.metric, *truth, other_map, ref_rows).right;
	}
	// Both maps prepared once for what follows: the retry from the
	// annotation (a report's, not the calibration data's) and the
	// candidates' finish.
	const bool retry = truth && !ctx.calibration_only && !(run.merged && run.outcome.right);
	CScalingGridMapAligner::PreparedMapPtr ref_prepared, other_prepared;
	if (truth && (retry || ctx.candidates))
		ref_prepared = ctx.aligner().prepare(ref_map.grid), other_prepared = ctx.aligner().prepare(other_map.grid);
	if (retry)
	{
		// Why not: the search, or the evidence? The annotation as a start
		// (these files' origins are 0: map frames are the grids' frames),
		// then the whole search: a start confident on its own would stop it
		// (tracking), and the decision would not see the rivals that refused
		// the pair.
		const Similarity2D start = truthBetweenMapFrames(*truth, int(other_map.grid.getSizeY()), ref_rows);
		CScalingGridMapAligner searching = ctx.aligner();
		searching.options.exhaustive_search = true;
		const auto again = searching.alignScaled(*ref_prepared, *other_prepared, start);
		run.retried_from_truth = true;
		run.right_from_truth = again.success && judge(again.metric, *truth, other_map, ref_rows).right;
	}
	// Each candidate judged as it would be reported (the aligner's finish for
	// maps that bend, finishBent): what a user gets if the decision picks it.
	const auto error_of = [&](const Similarity2D& cells) {
		const HalmstadOutcome o = judge(candidateMetric(ref_map, cells, other_map), *truth, other_map, ref_rows);
		return std::pair<double, bool>{o.mean_displacement_px, o.right};
	};
	writeCandidates(ctx, run.site, ref, other, run.positive, run.calibration, r, error_of, [&](const auto& c) {
		return ref_prepared ? bentFinished(ctx, *ref_prepared, *other_prepared, c) : c.cells;
	});
	std::cout << "halmstad " << ref << " <- " << other << ": "
			  << (run.positive ? (run.merged ? (run.outcome.right ? "merged right" : "MERGED WRONG") : "refused")
						   : (run.merged ? "MERGED (false)" : "refused (negative)"))
			  << " disp " << run.outcome.mean_displacement_px << " px, " << run.seconds << " s"
			  << (run.retried_from_truth ? run.right_from_truth ? " (from the annotation: merged right, the search missed it)"
																: " (from the annotation: refused too)"
										 : "")
			  << std::endl;
	return run;
}

std::vector<HalmstadRun> runHalmstad(
	const BenchContext& ctx, const HalmstadData& data, const std::vector<std::string>& sites, size_t negatives_per_map)
{
	const std::string dir = ctx.tempDir("halmstad");
	std::vector<HalmstadRun> runs;
	for (const auto& site : sites)
	{
		size_t k = 0;
		// MRPT beside on a few pairs per site (13 s a pair; killed at 30 s).
		for (const auto& p : data.unorderedPairs(site))
			runs.push_back(runHalmstadPair(ctx, data, p.dst, p.src, dir, k++ % 16 == 0 ? 30.0 : 0.0));
	}
	for (const auto& [ref, other] : crossSiteNegatives(data, sites, negatives_per_map))
		runs.push_back(runHalmstadPair(ctx, data, ref, other, dir));
	fs::remove_all(dir);
	return runs;
}

std::vector<std::pair<std::string, std::string>> crossSiteNegatives(
	const HalmstadData& data, const std::vector<std::string>& sites, size_t per_map)
{
	std::vector<std::string> all;
	for (const auto& site : data.sites())
		for (const auto& m : data.sensorMaps(site)) all.push_back(m);
	std::vector<std::pair<std::string, std::string>> out;
	for (const auto& site : sites)
		for (const auto& ref : data.sensorMaps(site))
		{
			size_t taken = 0;
			// Walk the other sites' maps from a per-map offset, so the
			// negatives spread over every site and map.
			const size_t start = std::hash<std::string>()(ref) % all.size();
			for (size_t k = 0; k < all.size() && taken < per_map; ++k)
			{
				const std::string& other = all[(start + k * 7) % all.size()];
				if (siteOf(other) == site) continue;
				out.emplace_back(ref, other);
				++taken;
			}
		}
	return out;
}

}  // namespace multires_bench
