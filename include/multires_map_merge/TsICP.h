#pragma once
// Trimmed scaling ICP (TsICP): registers `other` onto `ref` with a similarity,
// using backward correspondences (for every reference point, the nearest
// transformed other point) and an overlap ξ chosen each iteration to minimise
// ψ(ξ) = e(ξ) / ξ^(1+λ).

#include <multires_map_merge/PointList.h>
#include <multires_map_merge/Similarity2D.h>

#include <vector>

namespace multires_map_merge
{
class PointKDTree;

struct TsICPParams
{
	double xi_min = 0.35;  //!< smallest overlap the trimming may choose
	double lambda = 2.0;  //!< overlap preference in ψ(ξ) = e(ξ)/ξ^(1+λ)
	int max_iterations = 100;
	/** Stops when ψ improves by less than this fraction of itself. */
	double relative_tolerance = 1e-7;
	/** Coarse to fine: with more reference points than twice this, TsICP
	 * first converges on every k-th of them (about this many), then finishes
	 * on all. Most iterations run from afar, where a sample moves the
	 * transform as well as all points do. 0: all points throughout. */
	int coarse_points = 0;
};

struct TsICPResult
{
	Similarity2D transform;  //!< other → ref
	double overlap = 0;  //!< the ξ of the last iteration
	double objective = 0;  //!< ψ(ξ) of the final transform
	double trimmed_mse = 0;  //!< e(ξ), squared ref units
	int iterations = 0;  //!< both phases (coarse_points)
	bool converged = false;  //!< false if it stopped at max_iterations
	/** ψ on all points before each full-resolution re-fit; history[0] is the
	 * start's, history[1] the coarse phase's result when that phase ran (and
	 * was no worse). Non-increasing. */
	std::vector<double> objective_history;
};

/** Result of the trimming step on one correspondence set, exposed so that it
 * can be tested on its own. */
struct Trimming
{
	size_t count = 0;  //!< how many of the sorted pairs are kept
	double overlap = 0;  //!< count / N
	double mse = 0;  //!< e(ξ)
	double objective = 0;  //!< ψ(ξ)
};

/** Picks ξ ∈ [xi_min, 1] minimising ψ over squared distances sorted ascending. */
Trimming chooseOverlap(const std::vector<double>& sorted_sq_dist, const TsICPParams& p);

/** Every k-th point, about `most` of them (all when fewer or `most` is 0).
 * Edge points come row by row, so a stride samples the whole map. */
PointList strided(const PointList& points, size_t most);

/** Runs TsICP from `start`. Throws std::invalid_argument on fewer than 3
 * points in either set or a non-finite/non-positive start. */
TsICPResult runTsICP(
	const PointList& ref, const PointList& other, const Similarity2D& start,
	const TsICPParams& p = {});

/** The same, with the moving set given by a tree built on it beforehand:
 * refining many hypotheses between the same maps builds it once. */
TsICPResult runTsICP(
	const PointList& ref, const PointKDTree& other, const Similarity2D& start,
	const TsICPParams& p = {});

}  // namespace multires_map_merge
