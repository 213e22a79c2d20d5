#include "PairSearch.h"

#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GridImage.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/core/format.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/system/CTicTac.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

CScalingGridMapAligner::CScalingGridMapAligner()
{
	setLoggerName("CScalingGridMapAligner");
}

namespace
{
std::string checkGrid(const COccupancyGridMap2D& g)
{
	std::ostringstream why;
	const double res = g.getResolution();
	if (!std::isfinite(res) || !(res > 0))
		why << "has an invalid resolution (" << res << ")";
	else if (!std::isfinite(g.getXMin()) || !std::isfinite(g.getYMin()))
		why << "has a non-finite origin";
	else if (g.getSizeX() < 8 || g.getSizeY() < 8)
		why << "is too small (" << g.getSizeX() << "x" << g.getSizeY()
			<< " cells; at least 8x8 needed)";
	return why.str();
}

}  // namespace


CScalingGridMapAligner::PreparedMapPtr CScalingGridMapAligner::prepare(
	const COccupancyGridMap2D& grid, MapKind kind) const
{
	auto p = std::make_shared<TPreparedMap>();
	p->resolution = grid.getResolution();
	p->kind = kind;
	p->feature_params = options.featureParams();
	if (!options.invalidReason().empty()) return p;  // alignScaled says why; nothing here is safe to run
	if (std::string why = checkGrid(grid); !why.empty())
	{
		p->problem = std::move(why);
		return p;
	}
	if (double(grid.getSizeX()) * grid.getSizeY() > options.max_map_cells)
	{
		std::ostringstream why;
		why << "is too large (" << grid.getSizeX() << "x" << grid.getSizeY() << " cells > max_map_cells = "
			<< options.max_map_cells << "); resample it coarser or raise max_map_cells (memory grows with it)";
		p->problem = why.str();
		return p;
	}
	// 1. The map as an image (with crop_to_known, its known part); features
	// over a resolution pyramid (describe).
	mrpt::system::CTicTac stage;
	p->classes = toClassImage(grid);
	if (options.crop_to_known) p->classes = knownPart(p->classes, kKnownMargin, p->grid_corner);
	p->cell_to_metric = cellToMetric(grid).compose(p->toGridCells());
	p->stage_seconds["features"] = stage.Tac();
	// Said plainly here rather than as "no feature matches" later.
	const int occupied = cv::countNonZero(p->classes == kOccupied), free = cv::countNonZero(p->classes == kFree);
	if (occupied + free == 0) p->problem = "is all unknown: nothing to align";
	else if (occupied == 0) p->problem = "has no occupied cells: nothing to align";
	else if (free == 0) p->problem = "has no free cells: no walls to align";
	if (!p->problem.empty()) return p;
	describeMap(*p);
	return p;
}


CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const COccupancyGridMap2D& ref, const COccupancyGridMap2D& other) const
{
	return alignGrids(ref, MapKind::Sensed, other, MapKind::Sensed);
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignGrids(
	const COccupancyGridMap2D& ref, MapKind ref_kind, const COccupancyGridMap2D& other, MapKind other_kind) const
{
	mrpt::system::CTicTac total;
	// The two maps are independent: prepared at once (prepare logs nothing;
	// OpenCV runs a parallel_for_ that finds its pool busy on the caller's
	// thread). Most of that time is serial: distance field, edges, k-d tree.
	auto other_prepared = std::async(std::launch::async, [&]() { return prepare(other, other_kind); });
	const PreparedMapPtr ref_map = prepare(ref, ref_kind), other_map = other_prepared.get();
	TReturnInfo info = alignScaled(*ref_map, *other_map);
	for (const auto* p : {ref_map.get(), other_map.get()})
		for (const auto& [name, seconds] : p->stage_seconds) info.stage_seconds[name] += seconds;
	info.executionTime = total.Tac();
	return info;
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const TPreparedMap& ref, const TPreparedMap& other, const Similarity2D& start_metric) const
{
	return align(ref, other, start_metric);
}


namespace
{
using pair_search::PairContext;
using pair_search::SearchState;

/** Why the pair cannot be searched ("" when it can). */
std::string inputProblem(
	const CScalingGridMapAligner::TConfigParams& options, const PreparedMap& ref, const PreparedMap& other)
{
	if (const std::string why = options.invalidReason(); !why.empty()) return "invalid parameters: " + why;
	for (const auto& [p, which] : {std::pair{&ref, "reference"}, std::pair{&other, "other"}})
		if (!p->problem.empty()) return std::string(which) + " map " + p->problem;
	const FeatureParams fp = options.featureParams();
	if (!sameExtraction(fp, ref.feature_params) || !sameExtraction(fp, other.feature_params))
		return "the maps were prepared with other feature options than this aligner's";
	if (ref.edges.size() < 10 || other.edges.size() < 10)
		return "too few occupied cells bordering free space to register the maps";
	return "";
}

/** The decision written onto the candidates, and the chosen one's numbers
 * onto `info`. */
void report(
	const Decision& d, const std::vector<pair_search::Refinement>& refinements,
	CScalingGridMapAligner::TReturnInfo& info)
{
	auto& cands = info.candidates;
	for (size_t i = 0; i < cands.size(); ++i)
	{
		cands[i].confidence = d.confidence[i];
		cands[i].runner_up_score = i == d.best ? d.runner_up_score : std::numeric_limits<double>::quiet_NaN();
		cands[i].decision_value = i == d.best ? d.value : std::numeric_limits<double>::quiet_NaN();
	}
	if (!d.chosen) return;
	const auto& cand = cands[*d.chosen];
	const Hypothesis& h = refinements[*d.chosen].h;
	const TsICPResult& r = refinements[*d.chosen].r;
	info.cells = cand.cells;
	info.initial_cells = h.other_to_ref;
	info.overlap = r.overlap;
	info.objective = r.objective;
	info.trimmed_rmse_coarse_cells = cand.rmse_coarse_cells;
	info.evidence = cand.evidence;
	info.score = cand.score;
	info.runner_up_score = cand.runner_up_score;
	info.decision_value = cand.decision_value;
	info.confidence = cand.confidence;
	info.ransac_inliers = h.inliers;
	info.ransac_matches = h.matches;
	info.icp_iterations = r.iterations;
	info.objective_history = r.objective_history;
}
}  // namespace

namespace
{
/** A result of `other` ← `ref` (the maps' roles swapped) as `ref` ← `other`. */
CScalingGridMapAligner::TReturnInfo swappedBack(
	CScalingGridMapAligner::TReturnInfo r, const PreparedMap& ref, const PreparedMap& other)
{
	r.roles_swapped = true;
	r.cells = r.cells.inverse();
	r.initial_cells = r.initial_cells.inverse();
	r.metric = r.metric.inverse();
	r.implied_resolution_other = r.cells.scale * ref.resolution;
	std::swap(r.ref_edge_points, r.other_edge_points);
	for (auto& c : r.candidates)
	{
		c.cells = c.cells.inverse(), c.initial_cells = c.initial_cells.inverse();
		// A mirrored candidate now starts from the mirrored other map (the
		// swapped alignment's mirrored reference, made by its mirror pass).
		c.other_centre = c.cells.apply(
			other.toGridCells().apply(c.mirrored ? other.mirrored()->wall_centroid : other.wall_centroid));
	}
	return r;
}
}  // namespace

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const TPreparedMap& ref, const TPreparedMap& other) const
{
	TReturnInfo info = align(ref, other, std::nullopt);
	if (info.success || !options.both_orders || options.exhaustive_search ||
		!inputProblem(options, ref, other).empty())
		return info;
	TReturnInfo swapped = align(other, ref, std::nullopt);
	for (const auto& [name, seconds] : info.stage_seconds) swapped.stage_seconds[name] += seconds;
	swapped.executionTime += info.executionTime;
	if (swapped.success)
	{
		MRPT_LOG_INFO("merged with the maps' roles swapped (the reference aligned onto the other map)");
		return swappedBack(std::move(swapped), ref, other);
	}
	std::ostringstream why;
	why << info.message << "; the other way round not either (confidence " << swapped.confidence << ")";
	info.message = why.str();
	info.stage_seconds = swapped.stage_seconds;
	info.executionTime = swapped.executionTime;
	return info;
}

namespace
{
/** A result between prepared maps' cells (crop_to_known: their known parts)
 * as one between their grids' cells, as the aligner reports it. */
void toGridCells(CScalingGridMapAligner::TReturnInfo& info, const PreparedMap& ref, const PreparedMap& other)
{
	info.cells = gridCells(ref, info.cells, other);
	info.initial_cells = gridCells(ref, info.initial_cells, other);
	for (auto& c : info.candidates)
	{
		c.cells = gridCells(ref, c.cells, other);
		c.initial_cells = gridCells(ref, c.initial_cells, other);
		c.other_centre = ref.toGridCells().apply(c.other_centre);
	}
}
}  // namespace

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::align(
	const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric) const
{
	TReturnInfo info = alignInPreparedCells(ref, other, start_metric);
	toGridCells(info, ref, other);
	return info;
}

CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignInPreparedCells(
	const TPreparedMap& ref, const TPreparedMap& other, const std::optional<Similarity2D>& start_metric) const
{
	mrpt::system::CTicTac total, stage;
	TReturnInfo info;
	auto refuse = [&](const std::string& why) {
		info.success = false;
		info.message = why;
		info.executionTime = total.Tac();
		MRPT_LOG_INFO_STREAM("not merged: " << why);
		return info;
	};
	info.ref_edge_points = ref.edges.size();
	info.other_edge_points = other.edges.size();
	if (const std::string why = inputProblem(options, ref, other); !why.empty()) return refuse(why);
	const DecisionParams& decision = options.decision;

	// 1-4. Hypotheses refined and judged (PairSearch.h): a given start first
	// (tracking: confident, it needs no search), then the features'.
	const PairContext ctx = pair_search::makeContext(ref, other, options, *this, info.stage_seconds);
	SearchState search;
	search.least_relevant = decision.lowestMergeableScore();
	if (start_metric)
	{
		pair_search::refineStart(ctx, search, *start_metric);
		info.tracked = !options.exhaustive_search && decide(pair_search::decisionInput(search.candidates), decision).merged;
	}
	if (!info.tracked) pair_search::refineFeatureHypotheses(ctx, search);
	// The building's structure gives more hypotheses: right ones for
	// independent maps whose corners differ, and rivals the decision must see
	// (it was calibrated with them). Spared only where a candidate is merged
	// whatever comes, or a given start was confident.
	const bool sure = std::any_of(search.candidates.begin(), search.candidates.end(), [&](const TCandidate& c) {
		return decision.mergedWhateverComes(pair_search::decisionInput(c), decision.min_confidence);
	});
	if (options.structure_search && !info.tracked && (!sure || options.exhaustive_search))
		pair_search::refineStructureHypotheses(ctx, search);
	Decision d = decide(pair_search::decisionInput(search.candidates), decision);
	// A merge is decided against every rival: those the screen stopped on
	// their samples are refined in full first (PairSearch.h). (In
	// calibration data, for every pair's best: a refit may merge it.)
	if (d.best && (d.merged || options.exhaustive_search) && !info.tracked &&
		pair_search::refineScreenedRivals(ctx, search, search.candidates[*d.best].placement()) > 0)
		d = decide(pair_search::decisionInput(search.candidates), decision);

	// 5. The mirror check (mirror_check): a merge that does not rest on
	// coinciding cells rests on walls agreeing, which a mirror image can reach
	// on a building's symmetries: the mirrored map's candidates are rivals.
	// (In calibration data, every pair is checked.)
	const bool rests_on_walls = d.merged &&
		std::none_of(search.candidates.begin(), search.candidates.end(), [&](const TCandidate& c) {
			return decision.exactConfidence(c.evidence) >= decision.min_confidence;
		});
	if (options.mirror_check && !info.tracked && (rests_on_walls || (d.chosen && options.exhaustive_search)))
	{
		stage.Tic();
		info.mirror_score = mirrorPass(ref, other, search);
		d = decide(pair_search::decisionInput(search.candidates), decision);
		info.stage_seconds["mirror"] = stage.Tac();
	}
	info.hypotheses = search.hypotheses;
	info.hypotheses_refined = search.hypotheses_refined;
	for (const auto& [name, seconds] : search.stage_seconds) info.stage_seconds[name] = seconds;
	info.candidates = std::move(search.candidates);
	report(d, search.refinements, info);
	if (!d.chosen)
		return refuse(info.hypotheses ? "no hypothesis survived refinement"
									  : "no consistent feature matches or structure between the maps (do they overlap?)");

	// 6. The decided transform finished (Finish.h).
	stage.Tic();
	const Finished finished = finishDecided(
		ref, other, info.cells, decision.exactConfidence(info.evidence), d.merged, options.finishParams(), decision);
	if (finished.ran)
	{
		info.cells = finished.cells;
		info.stage_seconds["finish"] = stage.Tac();
		if (!finished.note.empty()) MRPT_LOG_DEBUG_STREAM(finished.note);
	}
	info.metric = ref.cell_to_metric.compose(info.cells).compose(other.cell_to_metric.inverse());
	info.implied_resolution_other = info.cells.scale * ref.resolution;
	info.executionTime = total.Tac();
	if (!d.merged)
	{
		std::ostringstream why;
		why << "alignment not confident enough (" << refusalReasons(info.evidence, d, decision) << ", overlap "
			<< info.overlap << ", edge RMSE " << info.trimmed_rmse_coarse_cells << " cells)";
		if (info.mirror_score > info.score)
			why << "; the other map fits better mirrored (score " << info.mirror_score
				<< "): is one of the maps flipped (y axis up vs down)?";
		return refuse(why.str());
	}
	info.success = true;
	info.message = "merged";
	return info;
}

double CScalingGridMapAligner::mirrorPass(const TPreparedMap& ref, const TPreparedMap& other, SearchState& search) const
{
	// The reference mirrored, not the other map: the same check (a
	// reflection of both is no change), and kept with the prepared
	// reference, which a fleet aligns every map of its first round to.
	const PreparedMapPtr flipped = ref.mirrored();
	std::map<std::string, double> not_reported;  // its stages are timed as "mirror"
	const PairContext ctx = pair_search::makeContext(*flipped, other, options, *this, not_reported);
	SearchState mirror;
	// Below the best score so far, a mirrored candidate cannot lower the confidence.
	const double lowest = options.decision.lowestMergeableScore();
	mirror.least_relevant = options.exhaustive_search
		? lowest
		: std::max(lowest, options.decision.relevantScore(pair_search::bestScore(search.candidates)));
	pair_search::refineFeatureHypotheses(ctx, mirror);
	// Every mirrored candidate is a rival: those its screen stopped between
	// the floor and the bar are refined too (refineScreenedRivals).
	pair_search::refineScreenedRivals(ctx, mirror, std::nullopt);
	double best = std::numeric_limits<double>::quiet_NaN();
	for (size_t i = 0; i < mirror.candidates.size(); ++i)
	{
		TCandidate c = mirror.candidates[i];
		c.mirrored = true;
		if (!c.screened && c.evidence.judged_points >= DecisionParams::min_judged_points)
			best = std::isnan(best) ? c.score : std::max(best, c.score);
		search.candidates.push_back(c);
		search.refinements.push_back(mirror.refinements[i]);
	}
	search.hypotheses += mirror.hypotheses;
	search.hypotheses_refined += mirror.hypotheses_refined;
	return best;
}


CScalingGridMapAligner::TReturnInfo CScalingGridMapAligner::alignScaled(
	const GridInFrame& ref, const GridInFrame& other) const
{
	TReturnInfo info = alignGrids(ref.grid, ref.kind, other.grid, other.kind);
	info.metric = betweenMapFrames(ref, info.metric, other);
	return info;
}

mrpt::poses::CPosePDF::Ptr CScalingGridMapAligner::AlignPDF(
	const mrpt::maps::CMetricMap* m1, const mrpt::maps::CMetricMap* m2,
	const mrpt::poses::CPosePDFGaussian&,
	mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult> outInfo)
{
	const auto* ref = dynamic_cast<const COccupancyGridMap2D*>(m1);
	const auto* other = dynamic_cast<const COccupancyGridMap2D*>(m2);
	ASSERTMSG_(ref && other, "CScalingGridMapAligner aligns two COccupancyGridMap2D");
	const TReturnInfo info = alignScaled(*ref, *other);
	if (outInfo)
	{
		if (auto* full = dynamic_cast<TReturnInfo*>(&outInfo->get()))
			*full = info;
		else
			outInfo->get().executionTime = info.executionTime;
	}
	if (!info.success) return nullptr;
	const double sigma_xy = info.trimmed_rmse_coarse_cells *
		std::max(ref->getResolution(), other->getResolution());
	mrpt::math::CMatrixDouble33 cov;
	cov.setZero();
	cov(0, 0) = cov(1, 1) = sigma_xy * sigma_xy;
	cov(2, 2) = mrpt::square(0.1 * M_PI / 180.0);
	return std::make_shared<mrpt::poses::CPosePDFGaussian>(
		mrpt::poses::CPose2D(info.metric.t.x(), info.metric.t.y(), info.metric.yaw), cov);
}

mrpt::poses::CPose3DPDF::Ptr CScalingGridMapAligner::Align3DPDF(
	const mrpt::maps::CMetricMap*, const mrpt::maps::CMetricMap*,
	const mrpt::poses::CPose3DPDFGaussian&, mrpt::optional_ref<mrpt::slam::TMetricMapAlignmentResult>)
{
	THROW_EXCEPTION("CScalingGridMapAligner aligns 2-D grid maps only; use AlignPDF()");
}

}  // namespace multires_map_merge