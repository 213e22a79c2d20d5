#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/FleetGraph.h>
#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/JointPlacement.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace multires_map_merge
{
bool FleetResult::allPlaced() const
{
	return std::all_of(maps.begin(), maps.end(), [](const FleetPlacement& p) { return p.placed; });
}

namespace
{
/** The WallSpread of `from`'s walls that `cells` (from's grid cells → to's)
 * puts on space `to` saw (FleetEdge::overlap); none with fewer than three. */
std::optional<WallSpread> overlapSpread(
	const GridInFrame& from, const PreparedMap& from_prepared, const PreparedMap& to_prepared,
	const Similarity2D& cells)
{
	const Similarity2D between_prepared = preparedCells(to_prepared, cells, from_prepared);
	const Eigen::Vector2d from_corner = from_prepared.toGridCells().t;
	PointList shared;
	for (const auto& p : occupiedPoints(from_prepared.classes))
		if (onMask(to_prepared.field.known, between_prepared(p))) shared.push_back(p + from_corner);
	if (shared.size() < 3) return std::nullopt;
	return spreadOf(shared, from.cellToMapFrame());
}

using PairList = std::vector<std::pair<size_t, size_t>>;  // (to, from): `from` aligned onto `to`

/** Runs work(k, aligner) for k in [0, count) on a small pool of threads,
 * each with its own aligner (same options): the aligner keeps logger state. */
template <class Work>
void onThreads(size_t count, const CScalingGridMapAligner& aligner, unsigned threads, Work work)
{
	std::atomic<size_t> next{0};
	auto run = [&]() {
		CScalingGridMapAligner local;
		local.options = aligner.options;
		local.setMinLoggingLevel(aligner.getMinLoggingLevel());
		for (size_t k; (k = next++) < count;) work(k, local);
	};
	if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
	const size_t n = std::min<size_t>(threads, count);
	std::vector<std::thread> pool;
	for (size_t t = 1; t < n; ++t) pool.emplace_back(run);
	run();
	for (auto& t : pool) t.join();
}

using PreparedMaps = std::vector<CScalingGridMapAligner::PreparedMapPtr>;

/** Each map prepared once (most of a pair's time), in parallel; those the
 * caller prepared before are taken as they are. */
PreparedMaps prepareAll(
	const std::vector<GridInFrame>& maps, const PreparedMaps& given, const CScalingGridMapAligner& aligner,
	unsigned threads)
{
	PreparedMaps out(maps.size());
	std::vector<size_t> todo;
	for (size_t k = 0; k < maps.size(); ++k)
		if (k < given.size() && given[k]) out[k] = given[k];
		else todo.push_back(k);
	onThreads(todo.size(), aligner, threads, [&](size_t i, const CScalingGridMapAligner& local) {
		const size_t k = todo[i];
		try
		{
			out[k] = local.prepare(maps[k].grid, maps[k].kind);
		}
		catch (const std::exception& ex)  // out of memory, say: that map's pairs fail, the others go on
		{
			auto failed = std::make_shared<CScalingGridMapAligner::TPreparedMap>();
			failed->problem = std::string("could not be prepared: ") + ex.what();
			out[k] = failed;
		}
	});
	return out;
}

/** The edge as `from` placed in `to` (an edge holds one direction). */
FleetEdge orientedAs(FleetEdge e, size_t to, size_t from)
{
	if (e.to != from || e.from != to) return e;
	// The overlap seen from the other map: a similarity moves the spread's
	// points as it moves every wall cell.
	if (e.overlap)
		for (auto& p : *e.overlap) p = e.from_to_to(p);
	std::swap(e.to, e.from), e.from_to_to = e.from_to_to.inverse();
	return e;
}

struct PairToAlign
{
	size_t to = 0, from = 0;
	std::optional<Similarity2D> start;  //!< from → to between map frames, refined first
	std::optional<FleetEdge> stand_in;  //!< the earlier result, if the deadline leaves it unaligned
	size_t age = size_t(-1);  //!< of the earlier result (none: the oldest)
	/** Order past a deadline: never aligned, then overdue, then tracking a
	 * placed pair (cheap, and what keeps placements fresh), then the rest;
	 * the stalest first within each. */
	int rank(size_t overdue_age) const
	{
		if (!stand_in) return 0;
		if (age >= overdue_age) return 1;
		return start ? 2 : 3;
	}
};

/** Aligns each pair of prepared maps in parallel; a pair not started by the
 * deadline is left empty. */
std::vector<std::optional<FleetEdge>> alignPairs(
	const std::vector<GridInFrame>& maps, const PreparedMaps& prepared, const std::vector<PairToAlign>& pairs,
	const CScalingGridMapAligner& aligner, unsigned threads,
	const std::optional<std::chrono::steady_clock::time_point>& deadline, bool first_must_start)
{
	std::vector<std::optional<FleetEdge>> out(pairs.size());
	std::atomic<size_t> started{0};
	onThreads(pairs.size(), aligner, threads, [&](size_t k, const CScalingGridMapAligner& local) {
		if (deadline && std::chrono::steady_clock::now() > *deadline && (started > 0 || !first_must_start)) return;
		++started;
		FleetEdge& e = out[k].emplace();
		e.to = pairs[k].to, e.from = pairs[k].from;
		try
		{
			const auto& ref = *prepared[e.to];
			const auto& other = *prepared[e.from];
			const auto r = pairs[k].start
				? local.alignScaled(ref, other, betweenGrids(maps[e.to], *pairs[k].start, maps[e.from]))
				: local.alignScaled(ref, other);
			e.merged = r.success;
			e.tracked = r.tracked;
			e.from_to_to = betweenMapFrames(maps[e.to], r.metric, maps[e.from]);
			e.confidence = r.success ? r.confidence : 0.0;
			e.rmse_coarse_cells = r.trimmed_rmse_coarse_cells;
			e.message = r.message;
			if (r.success) e.overlap = overlapSpread(maps[e.from], other, ref, r.cells);
		}
		catch (const std::exception& ex)
		{
			e.message = ex.what();
		}
	});
	return out;
}

using PairKey = std::pair<size_t, size_t>;  // (lower, higher) map index
PairKey keyOf(size_t a, size_t b) { return {std::min(a, b), std::max(a, b)}; }

/** How promising a pair looks before it is aligned: the most RANSAC inliers
 * among its feature hypotheses (the features are prepared: a few ms). An
 * order only: a map not placed still tries every pair. */
double promiseOf(const PreparedMap& a, const PreparedMap& b, const FeatureParams& p)
{
	if (!a.problem.empty() || !b.problem.empty()) return -1;
	const auto hypotheses = featureHypotheses(a.features, b.features, p);
	return hypotheses.empty() ? 0 : hypotheses.front().inliers;
}

/** What the next round needs to know of the fleet so far. */
struct FleetProgress
{
	const FleetResult& placed;
	const std::set<PairKey>& tried;
	/** Pairs aligned for each map since it was placed, looking for another path. */
	const std::vector<size_t>& tries_since_placed;
};

/** Whether map m still wants pairs: not placed; or placed less surely than
 * settled, or hanging on one pair, and not yet given that many more pairs
 * (`unsettled_tries`, `second_path_tries`) to find a surer or a second path. */
bool wantsPairs(size_t m, size_t reference, const FleetProgress& f, const FleetParams& params)
{
	if (m == reference) return false;
	const FleetPlacement& p = f.placed.maps[m];
	if (!p.placed) return true;
	const size_t tries = f.tries_since_placed[m];
	if (p.confidence < params.settled_confidence && tries < params.unsettled_tries) return true;
	return !p.checked_by_cycle && tries < params.second_path_tries;
}

/** The next round: each map that wants pairs takes its most promising one
 * not yet tried, towards a placed map first (one that can carry it); then,
 * while the round has fewer pairs than threads, each takes its next one. */
PairList nextPairs(
	size_t reference, const FleetProgress& f, const std::function<double(size_t, size_t)>& promise,
	const FleetParams& params, unsigned threads)
{
	const size_t n = f.placed.maps.size();
	std::vector<std::vector<size_t>> partners(n);  // per map wanting pairs, best first
	for (size_t m = 0; m < n; ++m)
	{
		if (!wantsPairs(m, reference, f, params)) continue;
		for (size_t o = 0; o < n; ++o)
			if (o != m && !f.tried.count(keyOf(m, o))) partners[m].push_back(o);
		const auto& maps = f.placed.maps;
		std::stable_sort(partners[m].begin(), partners[m].end(), [&](size_t a, size_t b) {
			if (maps[a].placed != maps[b].placed) return maps[a].placed;
			return promise(m, a) > promise(m, b);
		});
	}
	PairList out;
	std::set<PairKey> chosen;
	if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
	for (size_t depth = 0;; ++depth)
	{
		bool any = false;
		for (size_t m = 0; m < n; ++m)
		{
			if (depth >= partners[m].size()) continue;
			any = true;
			const size_t o = partners[m][depth];
			if (!chosen.insert(keyOf(m, o)).second) continue;
			const bool o_first = f.placed.maps[o].placed && !f.placed.maps[m].placed;
			out.emplace_back(o_first ? o : m, o_first ? m : o);  // (to, from): a placed map is the reference
		}
		if (!any || out.size() >= threads) return out;
	}
}

/** Each map's wall spread, from its prepared class image where it has one. */
std::vector<WallSpread> wallSpreadOf(const std::vector<GridInFrame>& maps, const PreparedMaps& prepared = {})
{
	std::vector<WallSpread> out;
	for (size_t m = 0; m < maps.size(); ++m)
	{
		const bool have = m < prepared.size() && prepared[m] && !prepared[m]->classes.empty();
		out.push_back(have ? wallSpread(maps[m], prepared[m]->classes, prepared[m]->grid_corner) : wallSpread(maps[m]));
	}
	return out;
}

FleetResult placeFromPairs(
	const std::vector<GridInFrame>& maps, const std::vector<WallSpread>& spread, size_t reference,
	std::vector<FleetEdge> edges, const FleetParams& params)
{
	FleetResult out;
	const PlacementTree tree = consistentTree(maps, spread, reference, edges, params);
	out.edges = std::move(edges);
	out.maps = tree.maps;
	if (params.joint_refinement)
	{
		std::vector<double> tolerance;
		for (const auto& e : out.edges) tolerance.push_back(params.toleranceOf(e));
		const auto joint =
			refineJointly(maps, reference, out.maps, out.edges, spread, tolerance, tree.cycle_tolerance);
		for (size_t m = 0; m < maps.size(); ++m)
			if (joint[m])
				out.maps[m].in_reference = *joint[m], out.maps[m].message += ", refined jointly with every confident pair";
	}
	const std::vector<bool> on_one_pair = hangsOnOnePair(out.maps, out.edges, reference);
	for (size_t m = 0; m < maps.size(); ++m)
		if (m != reference && out.maps[m].placed && !on_one_pair[m])
			out.maps[m].checked_by_cycle = true, out.maps[m].message += ", checked by a cycle";
	for (size_t m = 0; m < maps.size(); ++m)
	{
		if (out.maps[m].placed) continue;
		// Say why: the most confident pair this map had, and its reason.
		const FleetEdge* best = nullptr;
		for (const auto& e : out.edges)
			if ((e.from == m || e.to == m) && (!best || e.confidence > best->confidence)) best = &e;
		std::ostringstream why;
		why << "not placed: no confident alignment connects it to the reference";
		if (best)
			why << " (closest: map " << (best->from == m ? best->to : best->from) << ", " << best->describe() << ")";
		out.maps[m].message = why.str();
	}
	return out;
}
}  // namespace

FleetResult placeFromPairs(
	const std::vector<GridInFrame>& maps, size_t reference, std::vector<FleetEdge> edges, const FleetParams& params)
{
	if (reference >= maps.size()) throw std::invalid_argument("reference index out of range");
	for (const auto& e : edges)
		if (e.from >= maps.size() || e.to >= maps.size() || e.from == e.to)
			throw std::invalid_argument("a pair names a map that is not there");
	return placeFromPairs(maps, wallSpreadOf(maps), reference, std::move(edges), params);
}

FleetResult placeFleet(
	const std::vector<GridInFrame>& maps, size_t reference, const CScalingGridMapAligner& aligner,
	const FleetParams& given_params, const FleetHints& hints)
{
	if (const std::string why = given_params.invalidReason(); !why.empty())
		throw std::invalid_argument("invalid fleet parameters: " + why);
	// Two placements the aligner's decision tells apart are never one.
	const FleetParams params = given_params.resolvedFor(aligner.options.decision);
	if (maps.size() < 2) throw std::invalid_argument("a fleet merge needs at least two maps");
	if (reference >= maps.size()) throw std::invalid_argument("reference index out of range");
	const size_t n = maps.size();
	std::vector<FleetEdge> edges;
	std::set<PairKey> done;  // unordered pairs aligned, reused or deferred

	// Round 1: everything against the reference (the two-map case exactly),
	// and every earlier result that still holds (it costs nothing).
	PairList todo;
	for (size_t k = 0; k < n; ++k)
		if (k != reference) todo.emplace_back(reference, k);
	if (hints.known)
		for (size_t a = 0; a < n; ++a)
			for (size_t b = a + 1; b < n; ++b)
				if (a != reference && b != reference)
					if (const auto known = hints.known(a, b); known && known->holds) todo.emplace_back(a, b);
	FleetResult out;
	size_t pairs_aligned = 0, pairs_reused = 0, pairs_deferred = 0;
	const PreparedMaps prepared = prepareAll(maps, hints.prepared, aligner, params.threads);
	const std::vector<WallSpread> spread = wallSpreadOf(maps, prepared);
	// A pair's promise, computed when first asked: an earlier merged result
	// first (tracking it is cheap), then the most feature inliers.
	std::map<PairKey, double> promises;
	const FeatureParams feature_params = aligner.options.featureParams();
	auto promise = [&](size_t a, size_t b) {
		const auto [it, fresh] = promises.try_emplace(keyOf(a, b), 0.0);
		if (fresh)
		{
			const auto known = hints.known ? hints.known(a, b) : std::nullopt;
			it->second = known && known->edge.merged ? std::numeric_limits<double>::infinity()
													 : promiseOf(*prepared[a], *prepared[b], feature_params);
		}
		return it->second;
	};
	std::vector<size_t> tries_since_placed(n, 0);
	bool first_round = true;
	while (!todo.empty())
	{
		std::vector<bool> placed_before(n);
		for (size_t m = 0; m < n; ++m) placed_before[m] = !out.maps.empty() && out.maps[m].placed;
		// What still holds from before is taken; the rest is aligned, from its
		// earlier transform first where it had one.
		std::vector<PairToAlign> to_align;
		for (const auto& [to, from] : todo)
		{
			done.insert(keyOf(to, from));
			std::optional<FleetHints::Known> known;
			if (hints.known) known = hints.known(to, from);
			if (known && known->holds)
			{
				FleetEdge e = orientedAs(known->edge, to, from);
				e.reused = true;
				edges.push_back(std::move(e));
				++pairs_reused;
				continue;
			}
			PairToAlign p{to, from, std::nullopt, std::nullopt, size_t(-1)};
			if (known)
			{
				p.stand_in = orientedAs(known->edge, to, from);
				p.stand_in->reused = true;
				if (p.stand_in->merged && known->track) p.start = p.stand_in->from_to_to;
				p.age = known->age;
			}
			// Both maps placed (a second or surer path): the pair is refined
			// from where the fleet puts them first, one refinement when that
			// is confident on the pair's own walls; the global search only
			// when it is not, or when the caller wants it searched afresh
			// (an independent check: FleetHints::Known::track).
			if (!p.start && (!known || known->track) && placed_before[to] && placed_before[from])
				p.start = out.maps[to].in_reference.inverse().compose(out.maps[from].in_reference);
			to_align.push_back(p);
		}
		const size_t overdue = hints.overdue_age;
		std::stable_sort(to_align.begin(), to_align.end(), [overdue](const PairToAlign& a, const PairToAlign& b) {
			return a.rank(overdue) != b.rank(overdue) ? a.rank(overdue) < b.rank(overdue) : a.age > b.age;
		});
		// Past the deadline one pair still starts in the first round (every
		// call progresses) and in a later one if it was never aligned or is
		// overdue (none starves); the rest wait.
		const bool first_must_start = first_round || (!to_align.empty() && to_align.front().rank(overdue) <= 1);
		first_round = false;
		const auto aligned = alignPairs(maps, prepared, to_align, aligner, params.threads, hints.deadline, first_must_start);
		for (size_t k = 0; k < aligned.size(); ++k)
		{
			for (size_t m : {to_align[k].to, to_align[k].from}) tries_since_placed[m] += placed_before[m];
			if (aligned[k]) edges.push_back(*aligned[k]), ++pairs_aligned;
			else if (to_align[k].stand_in) edges.push_back(*to_align[k].stand_in), ++pairs_deferred;
			else ++pairs_deferred;
		}
		out = placeFromPairs(maps, spread, reference, edges, params);
		edges = out.edges;  // with the dropped marks
		todo = nextPairs(reference, {out, done, tries_since_placed}, promise, params, params.threads);
	}
	out.pairs_aligned = pairs_aligned;
	out.pairs_reused = pairs_reused;
	out.pairs_deferred = pairs_deferred;
	out.pairs_skipped = n * (n - 1) / 2 - done.size();
	out.prepared = prepared;
	return out;
}

FusedFleet fuseFleet(
	const std::vector<GridInFrame>& maps, const FleetResult& placement, size_t reference, double output_resolution,
	size_t max_cells)
{
	if (placement.maps.size() != maps.size() || reference >= maps.size())
		throw std::invalid_argument("fuseFleet: placement does not match the maps");
	std::vector<std::optional<Similarity2D>> to_reference(maps.size());
	for (size_t m = 0; m < maps.size(); ++m)
		if (m == reference || placement.maps[m].placed)
			to_reference[m] = m == reference ? Similarity2D() : placement.maps[m].in_reference;
	FusedMaps fused = fuseGridMaps(maps, reference, to_reference, output_resolution, max_cells);
	FusedFleet out;
	out.classes = std::move(fused.classes);
	out.merged = std::move(fused.merged);
	return out;
}

}  // namespace multires_map_merge
