#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/Finish.h>
#include <multires_map_merge/GridImage.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

namespace multires_map_merge
{
namespace
{
/** How far `to` moves `points` from where `from` puts them (reference
 * cells), over those that `from` puts on the reference's known space. */
double largestShift(const PointList& points, const Similarity2D& from, const Similarity2D& to, const OccupancyField& ref)
{
	double shift = 0;
	const Eigen::Matrix2d a = from.linear(), b = to.linear();
	for (const auto& p : points)
	{
		const Eigen::Vector2d q = a * p + from.t;
		if (onMask(ref.known, q)) shift = std::max(shift, (b * p + to.t - q).norm());
	}
	return shift;
}

/** The points that `t` puts on `near_known` (a target's knownWithin). The
 * margin keeps whole walls: the space behind a wall is unknown, and a wall
 * band cut where the other map's knowledge ends would pull the fit to one
 * side. */
PointList nearKnown(const PointList& points, const Similarity2D& t, const cv::Mat& near_known)
{
	PointList inside;
	const Eigen::Matrix2d a = t.linear();
	for (const auto& p : points)
		if (onMask(near_known, a * p + t.t)) inside.push_back(p);
	return inside;
}
}  // namespace

// The coarser map's cells are the fixed set: each coarse cell centre lies
// inside the band the finer map draws a wall with and finds its partner
// there, while a fine point finds a coarse centre up to half a coarse cell
// off, to one side or the other. The coarse centres keep the coarse map's
// rounding, which the lattice shift then takes out.
Similarity2D finishOnOccupied(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, const TsICPParams& ip,
	const LatticeShiftParams& lattice)
{
	// Two cells of the coarser map, in each target's cells.
	const double coarse_in_ref = std::max(1.0, cells.scale), coarse_in_other = coarse_in_ref / cells.scale;
	const cv::Mat ref_near_known = knownWithin(ref.field.known, 2 * coarse_in_ref);
	const cv::Mat other_near_known = knownWithin(other.field.known, 2 * coarse_in_other);
	// From the classes here rather than kept prepared: only merged pairs pay.
	const PointList ref_seen = nearKnown(occupiedPoints(ref.classes), cells.inverse(), other_near_known);
	const PointList other_seen = nearKnown(occupiedPoints(other.classes), cells, ref_near_known);
	if (ref_seen.size() < 10 || other_seen.size() < 10) return cells;
	const bool other_coarser = cells.scale > 1;
	const PointList& coarse_seen = other_coarser ? other_seen : ref_seen;
	const PointList& fine_seen = other_coarser ? ref_seen : other_seen;
	const TsICPResult r = runTsICP(coarse_seen, fine_seen, other_coarser ? cells.inverse() : cells, ip);
	Similarity2D fine_to_coarse = r.transform;
	if (lattice.step > 0 && fine_to_coarse.isFinite())
	{
		PointList fine_in_coarse(fine_seen.size());
		const Eigen::Matrix2d a = fine_to_coarse.linear();
		for (size_t i = 0; i < fine_seen.size(); ++i) fine_in_coarse[i] = a * fine_seen[i] + fine_to_coarse.t;
		// Two cells of the coarse map: what latticeShift counts extras on.
		const cv::Mat& coarse_near_known = other_coarser ? other_near_known : ref_near_known;
		const Eigen::Vector2d shift = latticeShift(fine_in_coarse, coarse_seen, coarse_near_known, lattice);
		fine_to_coarse = Similarity2D(1, 0, shift).compose(fine_to_coarse);
	}
	const Similarity2D t = other_coarser ? fine_to_coarse.inverse() : fine_to_coarse;
	return t.isFinite() && t.scale > 0 ? t : cells;
}

namespace
{
/** finishBent's refit, or none where it does not apply or is not taken. */
std::optional<Similarity2D> bentRefit(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, double exact_confidence,
	const FinishParams& p, const DecisionParams& decision)
{
	// Maps that coincide are the exact finish's (finishOnOccupied).
	if (p.bent_lambda <= 0 || cellsCoincide(exact_confidence) || other.edges.empty() || !ref.edge_tree ||
		!other.edge_tree)
		return std::nullopt;
	TsICPParams wide = p.icp;
	wide.lambda = p.bent_lambda;
	const Similarity2D refit = refineFromTheInside(ref, other, cells, wide).transform;
	const Eigen::Vector2d& centroid = other.wall_centroid;
	// The decision judged `cells`: the refit moves it within its bends, never
	// to a rival placement.
	if (refit.isFinite() && refit.scale > 0 &&
		!decision.areRivals({refit, refit.apply(centroid)}, {cells, cells.apply(centroid)}))
		return refit;
	return std::nullopt;
}
}  // namespace

Similarity2D finishBent(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, double exact_confidence,
	const FinishParams& p, const DecisionParams& decision)
{
	return bentRefit(ref, other, cells, exact_confidence, p, decision).value_or(cells);
}

Finished finishDecided(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, double exact_confidence,
	bool confident, const FinishParams& p, const DecisionParams& decision)
{
	Finished out;
	out.cells = cells;
	const bool coincide = cellsCoincide(exact_confidence);
	if (p.on_occupied && confident && coincide)
	{
		out.ran = true;
		const Similarity2D finished = finishOnOccupied(ref, other, cells, p.icp, p.lattice);
		const double shift = largestShift(other.edges, cells, finished, ref.field);
		const double coarse = std::max(1.0, cells.scale);
		if (shift <= p.max_shift * coarse)
			out.cells = finished;
		else
		{
			std::ostringstream why;
			why << "finish on occupied cells not taken: it moves a wall by " << shift / coarse << " coarse cells";
			out.note = why.str();
		}
	}
	else if (p.bent_lambda > 0 && !coincide)
	{
		out.ran = true;
		if (auto refit = bentRefit(ref, other, cells, exact_confidence, p, decision))
			out.cells = *refit;
		else
			out.note = "refit over the whole overlap not taken: it places the other map elsewhere";
	}
	return out;
}

}  // namespace multires_map_merge
