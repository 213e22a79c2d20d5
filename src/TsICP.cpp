#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/TsICP.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace multires_map_merge
{
Trimming chooseOverlap(const std::vector<double>& sorted_sq_dist, const TsICPParams& p)
{
	const size_t n_all = sorted_sq_dist.size();
	Trimming best;
	if (n_all == 0) return best;
	const size_t n_min = std::max<size_t>(
		1, static_cast<size_t>(std::ceil(p.xi_min * static_cast<double>(n_all))));
	best.objective = std::numeric_limits<double>::infinity();
	double sum = 0;
	for (size_t n = 1; n <= n_all; ++n)
	{
		sum += sorted_sq_dist[n - 1];
		if (n < n_min) continue;
		const double xi = static_cast<double>(n) / static_cast<double>(n_all);
		const double e = sum / static_cast<double>(n);
		const double psi = e / std::pow(xi, 1.0 + p.lambda);
		// On ties the larger overlap wins: identical maps (e = 0 everywhere)
		// overlap fully, they are not "pinned at ξmin".
		if (psi <= best.objective) best = {n, xi, e, psi};
	}
	return best;
}

namespace
{
struct Pair
{
	double sq_dist;  //!< in ref units
	size_t ref_idx, other_idx;
};

// Backward correspondences: every reference point with its nearest
// transformed other point. Similarities preserve the order of distances, so
// the query runs in the other map's frame on a tree built once, and the
// distance is scaled back to ref units.
// `previous` (the pairs of the transform before, any order, or empty): each
// reference point's partner there bounds its search (PointKDTree::nearest).
std::vector<Pair> backwardPairs(
	const PointList& ref, const PointKDTree& other_tree, const Similarity2D& other_to_ref,
	const std::vector<Pair>& previous = {})
{
	const Similarity2D ref_to_other = other_to_ref.inverse();
	const Eigen::Matrix2d a = ref_to_other.linear();  // once, not a sine and cosine per point
	const double s2 = other_to_ref.scale * other_to_ref.scale;
	// Each reference point's partner before, by its index (`previous` is
	// sorted by distance).
	std::vector<size_t> partner_before;
	if (previous.size() == ref.size())
	{
		partner_before.resize(ref.size());
		for (const Pair& q : previous) partner_before[q.ref_idx] = q.other_idx;
	}
	const bool hinted = !partner_before.empty();
	std::vector<Pair> pairs(ref.size());
#pragma omp parallel for schedule(static)
	for (size_t j = 0; j < ref.size(); ++j)
	{
		const Eigen::Vector2d q = a * ref[j] + ref_to_other.t;
		const auto [i, d2] = hinted ? other_tree.nearest(q, partner_before[j]) : other_tree.nearest(q);
		pairs[j] = {s2 * d2, j, i};
	}
	std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
		return a.sq_dist < b.sq_dist;
	});
	return pairs;
}

Trimming trim(const std::vector<Pair>& pairs, const TsICPParams& p)
{
	std::vector<double> d(pairs.size());
	std::transform(pairs.begin(), pairs.end(), d.begin(), [](const Pair& q) {
		return q.sq_dist;
	});
	return chooseOverlap(d, p);
}

Similarity2D fitSimilarity(
	const PointList& ref, const PointList& other, const std::vector<Pair>& pairs, size_t n)
{
	Eigen::Matrix2Xd src(2, n), dst(2, n);
	for (size_t k = 0; k < n; ++k)
	{
		src.col(k) = other[pairs[k].other_idx];
		dst.col(k) = ref[pairs[k].ref_idx];
	}
	return Similarity2D::fromMatrix(Eigen::Matrix3d(Eigen::umeyama(src, dst, true)));
}
}  // namespace

namespace
{
/** Pairs (backwardPairs of a transform) and their trimming. */
struct Trimmed
{
	std::vector<Pair> pairs;
	Trimming trimming;
};
Trimmed trimmedPairs(
	const PointList& ref, const PointKDTree& other_tree, const Similarity2D& other_to_ref, const TsICPParams& p,
	const std::vector<Pair>& previous = {})
{
	Trimmed out{backwardPairs(ref, other_tree, other_to_ref, previous), {}};
	out.trimming = trim(out.pairs, p);
	return out;
}

/** The iterations of TsICP on a fixed point set, from `start` and its
 * trimmed pairs. */
TsICPResult iterate(
	const PointList& ref, const PointList& other, const PointKDTree& other_tree, const Similarity2D& start,
	Trimmed at_start, const TsICPParams& p, int max_iterations)
{
	TsICPResult r;
	r.transform = start;
	std::vector<Pair> pairs = std::move(at_start.pairs);
	Trimming t = at_start.trimming;
	r.objective_history.push_back(t.objective);

	for (r.iterations = 1; r.iterations <= max_iterations; ++r.iterations)
	{
		const Similarity2D candidate = fitSimilarity(ref, other, pairs, t.count);
		Trimmed next = trimmedPairs(ref, other_tree, candidate, p, pairs);
		// The re-fit and re-association can only lower ψ in exact arithmetic;
		// a rise is rounding noise, and keeping the previous transform keeps
		// the objective monotone.
		if (!(next.trimming.objective <= t.objective)) { r.converged = true; break; }
		const double gain = t.objective - next.trimming.objective;
		r.transform = candidate;
		pairs = std::move(next.pairs);
		t = next.trimming;
		r.objective_history.push_back(t.objective);
		if (gain <= p.relative_tolerance * t.objective) { r.converged = true; break; }
	}
	r.iterations = std::min(r.iterations, max_iterations);
	r.overlap = t.overlap;
	r.objective = t.objective;
	r.trimmed_mse = t.mse;
	return r;
}
}  // namespace

PointList strided(const PointList& points, size_t most)
{
	if (most == 0 || points.size() <= most) return points;
	const size_t stride = points.size() / most;
	PointList out;
	out.reserve(points.size() / stride + 1);
	for (size_t k = 0; k < points.size(); k += stride) out.push_back(points[k]);
	return out;
}

TsICPResult runTsICP(
	const PointList& ref, const PointList& other, const Similarity2D& start,
	const TsICPParams& p)
{
	if (ref.size() < 3 || other.size() < 3)
		throw std::invalid_argument("TsICP needs at least 3 points in each set");
	return runTsICP(ref, PointKDTree(other), start, p);
}

TsICPResult runTsICP(
	const PointList& ref, const PointKDTree& other_tree, const Similarity2D& start,
	const TsICPParams& p)
{
	const PointList& other = other_tree.points();
	if (ref.size() < 3 || other.size() < 3)
		throw std::invalid_argument("TsICP needs at least 3 points in each set");
	if (!start.isFinite() || !(start.scale > 0))
		throw std::invalid_argument("TsICP start transform must be finite with scale > 0");
	if (!(p.xi_min > 0 && p.xi_min <= 1))
		throw std::invalid_argument("TsICP xi_min must be in (0, 1]");

	if (p.coarse_points <= 0 || ref.size() <= 2 * size_t(p.coarse_points))
		return iterate(ref, other, other_tree, start, trimmedPairs(ref, other_tree, start, p), p, p.max_iterations);

	// Coarse: every k-th reference point.
	const PointList sample = strided(ref, size_t(p.coarse_points));
	const TsICPResult coarse =
		iterate(sample, other, other_tree, start, trimmedPairs(sample, other_tree, start, p), p, p.max_iterations);
	// Fine: on all points, from the coarse result unless (rarely) it is worse
	// there than the start; the trimmed pairs of whichever it starts from are
	// the fine phase's first.
	Trimmed fine_start = trimmedPairs(ref, other_tree, start, p);
	const double at_start = fine_start.trimming.objective;
	bool better = false;
	if (coarse.transform.isFinite())
	{
		Trimmed at_coarse = trimmedPairs(ref, other_tree, coarse.transform, p);
		better = at_coarse.trimming.objective <= at_start;
		if (better) fine_start = std::move(at_coarse);
	}
	TsICPResult r = iterate(
		ref, other, other_tree, better ? coarse.transform : start, std::move(fine_start), p,
		std::max(1, p.max_iterations - (better ? coarse.iterations : 0)));
	if (better) r.objective_history.insert(r.objective_history.begin(), at_start);
	r.iterations += coarse.iterations;
	return r;
}

}  // namespace multires_map_merge
