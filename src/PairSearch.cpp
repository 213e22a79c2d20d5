#include "PairSearch.h"

#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MapAgreement.h>
#include <multires_map_merge/StructureHypotheses.h>

#include <mrpt/system/CTicTac.h>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace multires_map_merge::pair_search
{
namespace
{
using mrpt::system::LVL_DEBUG;

// Confidence that two maps coincide cell for cell (two parts of one SLAM
// run: walls within a cell), from the strict cell agreement, discounted when
// the overlap TsICP settled on is pinned at ξmin (the sign of a wrong start)
// or when the fitted edges sit far apart. A pinned ξ whose pairs fit to a
// fraction of a cell is no such sign: maps whose edges coincide exactly on
// part of the overlap make ψ = 0 there, and any larger ξ loses to it.
// At kExactMaxRmse (Finish.h) or more, 0 whatever the cells say; at this
// cell consistency or less, too.
constexpr double kExactMinConsistency = 0.7;
// The screen's tolerant consistency (walls 3 coarse cells apart do not
// conflict) is the same count with a wider margin: on the calibration pairs
// it never fell more than 0.03 below the cell consistency; 0.05 less leaves
// room for its sample.
constexpr double kExactMinScreenConsistency = kExactMinConsistency - 0.05;
// A sample refinement this close to a candidate that coincides cell for cell
// (centre in coarse cells, turn, log scale) is the same placement: within
// the spread of TsICP's optima from different starts on one pair of maps.
constexpr double kSamePlacementCells = 1.5;
constexpr double kSamePlacementTurnDeg = 0.5;
constexpr double kSamePlacementScale = 0.01;
// Merged with this exact confidence, no other hypothesis can do meaningfully
// better: the search stops.
constexpr double kExactEnough = 0.95;

double exactConfidence(double consistency, double overlap, double xi_min, double rmse_coarse)
{
	const double exact = std::clamp((0.5 - rmse_coarse) / 0.2, 0.0, 1.0);
	const double pinned = std::max(exact, std::clamp((overlap - xi_min) / 0.02, 0.0, 1.0));
	const double tight = std::clamp(kExactMaxRmse - rmse_coarse, 0.0, 1.0);
	const double agree = std::clamp((consistency - kExactMinConsistency) / 0.25, 0.0, 1.0);
	return agree * std::min(pinned, tight);
}

template <class Write>
void debug(const PairContext& c, Write write)
{
	if (!c.log.isLoggingLevelVisible(LVL_DEBUG)) return;
	std::ostringstream line;
	write(line);
	c.log.logStr(LVL_DEBUG, line.str());
}

/** One hypothesis refined and judged: no shared state, so a few run at once. */
struct Refined
{
	bool valid = false;
	TsICPResult r;
	Candidate cand;
	double icp_s = 0, verify_s = 0;
};

/** The cheap verification of a hypothesis (screen_points): TsICP on a
 * sample of the fixed set, judged on samples. It needs nothing of the other
 * hypotheses, so screens run ahead of the refinements they gate. */
struct Screen
{
	bool ran = false;  //!< screen_points > 0
	bool valid = false;  //!< a usable transform
	TsICPResult quick;
	Judgement judged;
	double rmse_coarse = 0;
	/** Near neither way to be sure: the maps are not the same cells there. */
	bool may_be_exact = false;
	double icp_s = 0, verify_s = 0;
};

Candidate candidateOf(
	const PairContext& c, const Hypothesis& h, const TsICPResult& r, double rmse_coarse, double cell_consistency,
	const Judgement& j)
{
	Candidate cand;
	cand.initial_cells = h.other_to_ref;
	cand.cells = r.transform;
	cand.overlap = r.overlap;
	cand.objective = r.objective;
	cand.rmse_coarse_cells = rmse_coarse;
	cand.consistency = cell_consistency;
	cand.evidence = j.evidence;
	cand.score = j.score;
	cand.other_centre = r.transform.apply(c.other.wall_centroid);
	return cand;
}

/** On a sample, near enough to coinciding cells that a full refinement starts
 * from the hypothesis, not from the sample's result (refineInFull). */
bool mayBeExactOnScreen(double rmse_coarse, const Evidence& e)
{
	return rmse_coarse < kExactMaxRmse && e.tolerant_consistency > kExactMinScreenConsistency;
}

Screen screenOne(const PairContext& c, const Hypothesis& h)
{
	Screen s;
	const auto& o = c.options;
	if (o.screen_points <= 0) return s;
	s.ran = true;
	mrpt::system::CTicTac clock;
	s.quick = refineFromTheInside(c.ref, c.other, h.other_to_ref, c.icp, size_t(o.screen_points));
	s.icp_s = clock.Tac();
	if (!c.usable(s.quick.transform)) return s;
	clock.Tic();
	s.judged = judge(c, s.quick.transform, size_t(o.screen_points), false);
	s.verify_s = clock.Tac();
	s.rmse_coarse = std::sqrt(s.quick.trimmed_mse) / std::max(1.0, s.quick.transform.scale);
	debug(c, [&](std::ostream& out) {
		out << "screen " << h.other_to_ref << " -> " << s.quick.transform << " rmse " << s.rmse_coarse
			<< " tolerant consistency " << s.judged.evidence.tolerant_consistency << " bent "
			<< s.judged.evidence.bent_consistency << " chance " << s.judged.evidence.chance_consistency << " score "
			<< s.judged.score;
	});
	s.may_be_exact = mayBeExactOnScreen(s.rmse_coarse, s.judged.evidence);
	s.valid = true;
	return s;
}

/** The screen a screened candidate went through, from what it kept (its
 * sample result and evidence): refining it in full later needs no second
 * screen. Its times were counted when it ran. */
Screen storedScreen(const Candidate& cand, const TsICPResult& quick)
{
	Screen s;
	s.ran = s.valid = true;
	s.quick = quick;
	s.rmse_coarse = cand.rmse_coarse_cells;
	s.may_be_exact = mayBeExactOnScreen(s.rmse_coarse, cand.evidence);
	return s;
}

bool onExactFound(const PairContext& c, const SearchState& state, const Similarity2D& t)
{
	const Placement at{t, t.apply(c.other.wall_centroid)};
	return std::any_of(state.exact_found.begin(), state.exact_found.end(), [&](const Candidate& e) {
		return samePlacement(at, e.placement(), kSamePlacementCells, kSamePlacementTurnDeg, kSamePlacementScale);
	});
}

bool convergedOnExact(const PairContext& c, const SearchState& state, const Screen& s)
{
	return s.valid && !c.options.exhaustive_search && onExactFound(c, state, s.quick.transform);
}

/** A screened hypothesis goes no further when it cannot come near a merge
 * (below the screen's bar) or it landed on a candidate found to coincide
 * cell for cell. */
bool stopsAtScreen(const PairContext& c, const SearchState& state, const Screen& s, double bar)
{
	return s.ran && (!s.valid || (!s.may_be_exact && s.judged.score < bar) || convergedOnExact(c, state, s));
}

/** What a hypothesis that stops at its screen leaves: its screen's
 * candidate (none without a valid screen). */
Refined screenedOnly(const PairContext& c, const SearchState& state, const Hypothesis& h, const Screen& s)
{
	Refined out;
	out.icp_s = s.icp_s, out.verify_s = s.verify_s;
	if (!s.valid) return out;
	out.cand = candidateOf(c, h, s.quick, s.rmse_coarse, std::numeric_limits<double>::quiet_NaN(), s.judged);
	out.cand.screened = true;
	out.cand.converged_on_exact = convergedOnExact(c, state, s);
	out.r = s.quick;
	out.valid = true;
	return out;
}

/** The transform refit to where its walls' regions fit best
 * (bend_refit_iterations); the first refit from its judgement's shift field
 * where that was on the walls alone (not computed again). */
Similarity2D bendRefit(const PairContext& c, const Judgement& judged_at, Similarity2D t)
{
	for (int i = 0; i < c.options.bend_refit_iterations && t.isFinite() && t.scale > 0; ++i)
		t = bendBalanced(
			i == 0 && c.judgesWallsAlone()
				? judged_at.bends
				: twoWayShiftField(
					  c.ref.edges, c.ref.field, c.other.edges, c.other.field, t, c.options.verify_tolerance),
			t);
	return t;
}

Refined refineInFull(const PairContext& c, const Hypothesis& h, const Screen& s)
{
	Refined out;
	out.icp_s = s.icp_s, out.verify_s = s.verify_s;
	// Independent maps: refined on every point from the sample's result
	// (fewer iterations; the same optimum to within a cell). Where the maps
	// may coincide cell for cell, from the hypothesis, as without the screen:
	// converged from a sample, TsICP stops a few hundredths of a cell short.
	const Similarity2D full_start = s.ran && !s.may_be_exact ? s.quick.transform : h.other_to_ref;
	mrpt::system::CTicTac clock;
	TsICPResult r = refineFromTheInside(c.ref, c.other, full_start, c.icp);
	out.icp_s += clock.Tac();
	if (!c.usable(r.transform)) return out;

	// Judged on the cells, against chance (MapAgreement.h).
	clock.Tic();
	const double coarse = std::max(1.0, r.transform.scale);  // coarser cell, in ref cells
	const double rmse_coarse = std::sqrt(r.trimmed_mse) / coarse;
	// The strict cell check warps whole maps: spared where it cannot count
	// (most hypotheses between independent maps).
	const bool may_be_exact = rmse_coarse < kExactMaxRmse;
	const double cell_consistency = may_be_exact ? mapAgreement(c.ref.classes, c.other.classes, r.transform).consistency
												 : std::numeric_limits<double>::quiet_NaN();
	Judgement judgement = judge(c, r.transform, kJudgedPoints, true);
	// Refit to where its regions fit best; kept where it scores higher.
	if (c.options.bend_refit_iterations > 0 && !may_be_exact)
	{
		const Similarity2D balanced = bendRefit(c, judgement, r.transform);
		if (c.usable(balanced))
			if (Judgement j = judge(c, balanced, kJudgedPoints, true); j.score > judgement.score)
				judgement = std::move(j), r.transform = balanced;
	}
	// The first way to be sure (the maps coincide cell for cell) is this
	// candidate's alone; the second is the pair's (the decision). Both need
	// walls enough to judge: a map squeezed into a few cells (TsICP let the
	// scale collapse to 0.02 on two disjoint parts) agrees with anything.
	judgement.evidence.exact_confidence =
		may_be_exact && judgement.evidence.judged_points >= DecisionParams::min_judged_points
		? exactConfidence(cell_consistency, r.overlap, c.icp.xi_min, rmse_coarse)
		: 0.0;
	out.verify_s += clock.Tac();
	out.cand = candidateOf(c, h, r, rmse_coarse, cell_consistency, judgement);
	out.cand.confidence = c.options.decision.exactConfidence(out.cand.evidence);
	out.r = r;
	out.valid = true;
	return out;
}

/** The screen's bar: below it a hypothesis can neither merge nor lower a
 * sure best candidate's confidence below 1, beyond the sample's noise.
 * Raised as better candidates are found (relevantScore only rises). Never
 * below the lowest mergeable score (less the margin): a rival between the
 * floor and that bar, which would lower a marginal best's value, is
 * screened away here (seeking them in every pair would cost about 40 %
 * more full judgements); a pair about to merge refines them after all
 * (refineScreenedRivals). */
double screenBar(const PairContext& c, const SearchState& state)
{
	const auto& o = c.options;
	if (o.exhaustive_search) return state.least_relevant - o.screen_margin;
	return std::max(state.least_relevant, o.decision.relevantScore(bestScore(state.candidates))) - o.screen_margin;
}

/** One hypothesis's result added to the state; whether it is merged
 * whatever comes (searching on is then only time). */
bool record(const PairContext& c, SearchState& state, const Hypothesis& h, const Refined& one)
{
	++state.hypotheses_refined;
	state.stage_seconds["icp"] += one.icp_s;
	state.stage_seconds["verify"] += one.verify_s;
	if (!one.valid) return false;
	const Candidate& cand = one.cand;
	state.candidates.push_back(cand);
	state.refinements.push_back({h, one.r});
	debug(c, [&](std::ostream& out) {
		const Evidence& e = cand.evidence;
		out << "hypothesis " << h.other_to_ref << " inliers " << h.inliers << " -> " << one.r.transform << " xi "
			<< one.r.overlap << " rmse " << cand.rmse_coarse_cells << " tolerant consistency "
			<< e.tolerant_consistency << " bent " << e.bent_consistency << " chance " << e.chance_consistency
			<< " score " << cand.score
			<< (cand.converged_on_exact ? " (on an exact candidate)" : cand.screened ? " (screened)" : "")
			<< " exact conf " << e.exact_confidence;
	});
	const DecisionParams& d = c.options.decision;
	if (!cand.screened && d.exactConfidence(cand.evidence) >= d.min_confidence) state.exact_found.push_back(cand);
	return d.mergedWhateverComes(decisionInput(cand), kExactEnough) && !c.options.exhaustive_search;
}

/** Free cells of `classes` on a lattice whose stride leaves about `most`. */
PointList freeSample(const cv::Mat& classes, size_t most)
{
	const double free = cv::countNonZero(classes == kFree);
	PointList out;
	if (most == 0 || free == 0) return out;
	const int stride = std::max(1, int(std::ceil(std::sqrt(free / double(most)))));
	for (int y = 0; y < classes.rows; y += stride)
		for (int x = 0; x < classes.cols; x += stride)
			if (classes.at<uint8_t>(y, x) == kFree) out.emplace_back(x, y);
	return out;
}

/** A robot map judged against a floor plan: its walls, and free cells as
 * many as half its walls (a plan's outside conflicts with them). Empty for
 * any other pair: the map is judged on its walls alone. */
PointList wallsAndFreeAgainstPlan(const PreparedMap& map, const PreparedMap& against)
{
	if (against.kind != MapKind::FloorPlan || map.kind == MapKind::FloorPlan) return {};
	PointList points = map.edges;
	const PointList free = freeSample(map.classes, map.edges.size() / 2);
	points.insert(points.end(), free.begin(), free.end());
	return points;
}
}  // namespace

bool PairContext::usable(const Similarity2D& t) const
{
	return t.isFinite() && t.scale > 0 &&
		(!expected_scale ||
		 std::abs(std::log(t.scale / *expected_scale)) <= std::log1p(options.metadata_scale_tolerance));
}

PairContext makeContext(
	const PreparedMap& ref, const PreparedMap& other, const AlignerParams& options,
	const mrpt::system::COutputLogger& log, std::map<std::string, double>& stage_seconds)
{
	mrpt::system::CTicTac clock;
	std::vector<LevelMatches> matches = featureMatches(ref.features, other.features, options.featureParams());
	stage_seconds["matches"] = clock.Tac();
	std::optional<double> expected_scale;
	if (options.use_resolution_metadata) expected_scale = other.resolution / ref.resolution;
	return {ref,
			other,
			options,
			log,
			std::move(matches),
			expected_scale,
			options.icpParams(),
			wallsAndFreeAgainstPlan(ref, other),
			wallsAndFreeAgainstPlan(other, ref)};
}

Judgement judge(const PairContext& c, const Similarity2D& t, size_t most, bool in_full)
{
	const auto& o = c.options;
	Judgement j;
	const TwoWaySupport sup = twoWaySupport(
		c.refJudged(), c.ref.field, c.otherJudged(), c.other.field, t, o.verify_tolerance, most, in_full);
	const Chance chance = chanceSupport(
		c.refJudged(), c.ref.field, c.otherJudged(), c.other.field, t, o.verify_tolerance, o.verify_shift,
		o.verify_turn_deg, most);
	// B on the points T and C judge (a robot map against a plan: its walls
	// and free sample), so the score's B − C compares like with like.
	j.bends = twoWayShiftField(
		c.refJudged(), c.ref.field, c.otherJudged(), c.other.field, t, o.verify_tolerance, most);
	// The count a full judgement would take, from a sample's.
	auto full = [&](size_t judged, size_t n) {
		return double(judged) * double(std::min(n, kJudgedPoints)) / double(std::max<size_t>(1, std::min(n, most)));
	};
	Evidence& e = j.evidence;
	e.tolerant_consistency = sup.consistency();
	e.chance_consistency = chance.consistency;
	e.bent_consistency = j.bends.bentConsistency();
	e.support = sup.score();
	e.chance_support = chance.support;
	e.wall_alignment = sup.wallAlignment();
	e.shift_coherence = j.bends.coherence();
	e.feature_agreement = double(agreeingMatches(c.matches, t));
	e.judged_points = std::min(
		full(sup.other_in_ref.judged, c.otherJudged().size()), full(sup.ref_in_other.judged, c.refJudged().size()));
	j.score = o.decision.score(e);
	return j;
}

// Refined a few at a time (one per thread), recorded in order: the result is
// the sequential one, at most a round's tail computed in vain when a
// candidate is merged whatever comes. A round takes the hypotheses in order
// until one per thread needs refining on every point; their screens run
// ahead, one per thread at a time: the threads refine together instead of
// one waiting while the other screens.
void refineAll(const PairContext& c, SearchState& state, const std::vector<Hypothesis>& list)
{
	const size_t n = std::min<size_t>(list.size(), size_t(std::max(0, c.options.max_hypotheses)));
	const size_t threads = size_t(std::clamp(cv::getNumThreads(), 1, 4));
	std::vector<Screen> screens(n);
	size_t screened_up_to = 0;
	bool stop = false;
	for (size_t first = 0; first < n && !stop;)
	{
		const double bar = screenBar(c, state);
		std::vector<Refined> done;
		std::vector<size_t> in_full;  // hypotheses of this round refined on every point
		size_t end = first;
		while (end < n && in_full.size() < threads)
		{
			if (end == screened_up_to)
			{
				const size_t upto = std::min(n, screened_up_to + threads);
				cv::parallel_for_(cv::Range(int(screened_up_to), int(upto)), [&](const cv::Range& range) {
					for (int j = range.start; j < range.end; ++j) screens[j] = screenOne(c, list[j]);
				});
				screened_up_to = upto;
			}
			if (stopsAtScreen(c, state, screens[end], bar))
				done.push_back(screenedOnly(c, state, list[end], screens[end]));
			else
				done.emplace_back(), in_full.push_back(end);
			++end;
		}
		cv::parallel_for_(cv::Range(0, int(in_full.size())), [&](const cv::Range& range) {
			for (int k = range.start; k < range.end; ++k)
				done[in_full[k] - first] = refineInFull(c, list[in_full[k]], screens[in_full[k]]);
		});
		for (size_t j = first; j < end; ++j)
			if (record(c, state, list[j], done[j - first])) stop = true;
		first = end;
	}
}

void refineStart(const PairContext& c, SearchState& state, const Similarity2D& start_metric)
{
	Hypothesis h;
	h.other_to_ref = c.ref.cell_to_metric.inverse().compose(start_metric).compose(c.other.cell_to_metric);
	state.hypotheses += 1;
	refineAll(c, state, {h});
}

void refineFeatureHypotheses(const PairContext& c, SearchState& state)
{
	mrpt::system::CTicTac clock;
	const auto hyps = featureHypotheses(
		c.matches, c.options.featureParams(), c.expected_scale, c.options.metadata_scale_tolerance);
	state.stage_seconds["ransac"] = clock.Tac();
	state.hypotheses += hyps.size();
	refineAll(c, state, hyps);
}

void refineStructureHypotheses(const PairContext& c, SearchState& state)
{
	mrpt::system::CTicTac clock;
	const auto hyps = structureHypotheses(c.ref.walls(), c.other.walls(), {}, c.expected_scale);
	state.stage_seconds["structure"] = clock.Tac();
	state.hypotheses += hyps.size();
	refineAll(c, state, hyps);
}

size_t refineScreenedRivals(const PairContext& c, SearchState& state, const std::optional<Placement>& of)
{
	const DecisionParams& d = c.options.decision;
	std::vector<size_t> rivals;
	for (size_t i = 0; i < state.candidates.size(); ++i)
	{
		const Candidate& cand = state.candidates[i];
		if (cand.screened && cand.score >= d.runner_up_floor - c.options.screen_margin &&
			(!of || d.areRivals(*of, cand.placement())))
			rivals.push_back(i);
	}
	std::vector<Refined> done(rivals.size());
	cv::parallel_for_(cv::Range(0, int(rivals.size())), [&](const cv::Range& range) {
		for (int k = range.start; k < range.end; ++k)
		{
			const Refinement& screened = state.refinements[rivals[k]];
			done[k] = refineInFull(c, screened.h, storedScreen(state.candidates[rivals[k]], screened.r));
		}
	});
	for (size_t k = 0; k < rivals.size(); ++k)
	{
		state.stage_seconds["icp"] += done[k].icp_s;
		state.stage_seconds["verify"] += done[k].verify_s;
		if (!done[k].valid) continue;
		state.candidates[rivals[k]] = done[k].cand;
		state.refinements[rivals[k]].r = done[k].r;
		debug(c, [&](std::ostream& out) {
			out << "screened rival refined in full: " << done[k].r.transform << " score " << done[k].cand.score;
		});
	}
	return rivals.size();
}

double bestScore(const std::vector<Candidate>& candidates)
{
	double best = -std::numeric_limits<double>::infinity();
	for (const auto& c : candidates)
		if (!c.screened && !c.mirrored && c.evidence.judged_points >= DecisionParams::min_judged_points)
			best = std::max(best, c.score);
	return best;
}

DecisionCandidate decisionInput(const Candidate& c)
{
	return {c.evidence, c.placement(), c.screened, c.mirrored, c.objective};
}

std::vector<DecisionCandidate> decisionInput(const std::vector<Candidate>& candidates)
{
	std::vector<DecisionCandidate> in;
	in.reserve(candidates.size());
	for (const auto& c : candidates) in.push_back(decisionInput(c));
	return in;
}

}  // namespace multires_map_merge::pair_search
