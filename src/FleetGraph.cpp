#include <multires_map_merge/FleetGraph.h>

#include <algorithm>
#include <sstream>

namespace multires_map_merge
{
namespace
{
/** How far `predicted` (from → to) puts what `from` saw from where the pair
 * `e` puts it, in cells of the coarser map of the pair. */
double disagreementCells(
	const std::vector<GridInFrame>& maps, const WallSpread& from_spread, const FleetEdge& e,
	const Similarity2D& predicted)
{
	return wallRms(from_spread, predicted, e.from_to_to) / coarseCellInTo(maps, e);
}

/** Maximum spanning tree from the reference over the confident, kept edges
 * (Prim): each map joins through the most confident edge to the placed
 * part, so its path is the most confident one (as sure as its weakest edge).
 * Confidences of `sure` and above count as one: among sure paths the one of
 * fewest pairs wins, since each pair adds its own error (bent maps: a few
 * cells each) and a surer-by-a-hair chain only adds more. */
PlacementTree spanningTree(size_t n, size_t reference, const std::vector<FleetEdge>& edges, double sure)
{
	PlacementTree t;
	t.maps.assign(n, {});
	t.via_edge.assign(n, -1);
	t.maps[reference].placed = true;
	t.maps[reference].confidence = 1;
	t.maps[reference].message = "reference";
	std::vector<size_t> hops(n, 0);
	auto anchorOf = [&](const FleetEdge& e) { return t.maps[e.from].placed ? e.from : e.to; };
	auto better = [&](const FleetEdge& a, const FleetEdge& b) {
		const double ca = std::min(a.confidence, sure), cb = std::min(b.confidence, sure);
		if (ca != cb) return ca > cb;
		if (hops[anchorOf(a)] != hops[anchorOf(b)]) return hops[anchorOf(a)] < hops[anchorOf(b)];
		return a.confidence > b.confidence;
	};
	for (;;)
	{
		int best = -1;
		for (size_t k = 0; k < edges.size(); ++k)
		{
			const FleetEdge& e = edges[k];
			if (!e.merged || e.dropped || t.maps[e.from].placed == t.maps[e.to].placed) continue;
			if (best < 0 || better(e, edges[best])) best = static_cast<int>(k);
		}
		if (best < 0) break;
		const FleetEdge& e = edges[best];
		const bool from_new = !t.maps[e.from].placed;
		const size_t added = from_new ? e.from : e.to, anchor = from_new ? e.to : e.from;
		hops[added] = hops[anchor] + 1;
		FleetPlacement& p = t.maps[added];
		p.placed = true;
		p.in_reference = from_new ? t.maps[anchor].in_reference.compose(e.from_to_to)
								  : t.maps[anchor].in_reference.compose(e.from_to_to.inverse());
		p.confidence = std::min(t.maps[anchor].confidence, e.confidence);
		p.parent = static_cast<int>(anchor);
		std::ostringstream how;
		how << "placed through map " << anchor << " (pair confidence " << e.confidence << ")";
		p.message = how.str();
		t.via_edge[added] = best;
	}
	return t;
}

/** Tree edges on the path from `a` to the reference. */
std::vector<int> pathEdges(const PlacementTree& t, size_t a)
{
	std::vector<int> out;
	for (int m = static_cast<int>(a); t.via_edge[m] >= 0; m = t.maps[m].parent) out.push_back(t.via_edge[m]);
	return out;
}

/** The cycle that non-tree edge k closes with the tree: k and both tree
 * paths up to where they meet (the part they share towards the reference is
 * not on the cycle). */
std::vector<int> cycleOf(const PlacementTree& t, const std::vector<FleetEdge>& edges, int k)
{
	const std::vector<int> up_from = pathEdges(t, edges[k].from), up_to = pathEdges(t, edges[k].to);
	std::vector<int> cycle = {k};
	for (const auto* path : {&up_from, &up_to})
		for (int e : *path)
			if (std::count(up_from.begin(), up_from.end(), e) + std::count(up_to.begin(), up_to.end(), e) == 1)
				cycle.push_back(e);
	return cycle;
}

/** Edge k is kept, joins two placed maps and is not on the tree: it closes a cycle. */
bool closesACycle(const PlacementTree& t, const std::vector<FleetEdge>& edges, size_t k)
{
	const FleetEdge& e = edges[k];
	return e.merged && !e.dropped && t.maps[e.from].placed && t.maps[e.to].placed && t.via_edge[e.from] != int(k) &&
		t.via_edge[e.to] != int(k);
}

/** Each edge's coarser cells in the reference's metres (0 where `to` is not placed). */
std::vector<double> coarseCells(const std::vector<GridInFrame>& maps, const PlacementTree& t, const std::vector<FleetEdge>& edges)
{
	std::vector<double> out;
	for (const auto& e : edges) out.push_back(t.maps[e.to].placed ? coarseCellInReference(maps, t.maps, e) : 0.0);
	return out;
}

}  // namespace

PlacementTree consistentTree(
	const std::vector<GridInFrame>& maps, const std::vector<WallSpread>& spread, size_t reference,
	std::vector<FleetEdge>& edges, const FleetParams& params)
{
	for (;;)
	{
		PlacementTree t = spanningTree(maps.size(), reference, edges, params.settled_confidence);
		std::vector<int> contradicted;
		t.cycle_tolerance.assign(maps.size(), 0.0);
		const std::vector<double> cells = coarseCells(maps, t, edges);
		for (size_t k = 0; k < edges.size() && contradicted.empty(); ++k)
		{
			if (!closesACycle(t, edges, k)) continue;
			const FleetEdge& e = edges[k];
			const std::vector<int> cycle = cycleOf(t, edges, int(k));
			const double tol = params.cycleTolerance(cycle, edges, cells);
			const Similarity2D predicted = t.maps[e.to].in_reference.inverse().compose(t.maps[e.from].in_reference);
			if (disagreementCells(maps, spread[e.from], e, predicted) > tol)
				contradicted = cycle;
			for (int c : cycle)
				for (size_t m : {edges[size_t(c)].from, edges[size_t(c)].to})
					t.cycle_tolerance[m] = std::max(t.cycle_tolerance[m], tol);
		}
		if (contradicted.empty()) return t;
		const int weakest = *std::min_element(contradicted.begin(), contradicted.end(), [&](int a, int b) {
			return edges[a].confidence < edges[b].confidence;
		});
		edges[weakest].dropped = true;
	}
}

std::vector<bool> hangsOnOnePair(
	const std::vector<FleetPlacement>& placements, const std::vector<FleetEdge>& edges, size_t reference)
{
	const size_t n = placements.size();
	std::vector<size_t> kept;
	for (size_t k = 0; k < edges.size(); ++k)
		if (edges[k].merged && !edges[k].dropped) kept.push_back(k);
	std::vector<bool> out(n, false);
	for (size_t cut : kept)
	{
		std::vector<bool> reached(n, false);
		reached[reference] = true;
		for (bool grew = true; grew;)
		{
			grew = false;
			for (size_t k : kept)
			{
				const FleetEdge& e = edges[k];
				if (k == cut || reached[e.from] == reached[e.to]) continue;
				reached[e.from] = reached[e.to] = true;
				grew = true;
			}
		}
		for (size_t m = 0; m < n; ++m) out[m] = out[m] || (placements[m].placed && !reached[m]);
	}
	return out;
}

}  // namespace multires_map_merge
