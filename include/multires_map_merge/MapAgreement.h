#pragma once
// How well two maps agree under a transform, judged on their cells rather
// than on the edge points TsICP fitted: a wrong alignment puts walls of one
// map across free space of the other, which point distances alone can hide
// when both maps have many similar walls.

#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/PointList.h>
#include <multires_map_merge/Similarity2D.h>

#include <opencv2/core.hpp>

namespace multires_map_merge
{
struct Agreement
{
	/** Occupied cells (of either map, in reference cells) that fall where the
	 * other map knows the space. */
	size_t occupied_overlap = 0;
	/** Of those, the ones the other map sees as clearly free (not within one
	 * coarse cell of an obstacle or the unknown). */
	size_t conflicts = 0;
	/** 1 − conflicts / occupied_overlap; 0 when nothing overlaps. */
	double consistency = 0;
};

/** `free_margin_coarse_cells`: how far from any obstacle or unknown cell a
 * free cell must be to count as clearly free (1: quantisation only; larger
 * values tolerate walls bent or drawn thicker by that much). */
Agreement mapAgreement(
	const cv::Mat& ref_classes, const cv::Mat& other_classes, const Similarity2D& other_to_ref_cells,
	double free_margin_coarse_cells = 1.0);

// ---- Tolerant support: the verification that holds on independent maps ----
// Two SLAM runs of one building bend their walls by a few cells, draw them
// thicker or thinner, and see different clutter. What still holds under the
// right transform: most walls of one map lie *near* walls of the other,
// wherever the other has seen the space. And what a wrong transform cannot
// fake: that nearness drops sharply when the transform is moved by a few
// tolerances (a peak), unlike a repetitive pattern or a lucky overlap.

/** What a map offers for judging points moved into it. */
struct OccupancyField
{
	cv::Mat dist_to_occupied;  //!< CV_32F, cells to the nearest occupied cell
	cv::Mat dist_to_not_free;  //!< CV_32F, cells to the nearest occupied or unknown cell
	cv::Mat known;  //!< CV_8U, non-zero where the map has seen the space
	/** CV_8U: the wall normal (degrees, 0–179) at each occupied cell,
	 * kNoDirection elsewhere. */
	cv::Mat wall_normal_deg;
	/** A floor plan draws its whole building, so beyond its image is its
	 * outside, empty, judged like the outside it draws; a robot's map has
	 * seen nothing beyond its grid. */
	bool empty_beyond = false;
};
constexpr uint8_t kNoDirection = 255;

/** How far from its walls a floor plan vouches for its space (plan cells):
 * the drawn line, its anti-aliased fringe and the wall's thickness, which
 * the line stands for. Farther inside, a plan's white is drawn, not seen:
 * furniture there is no conflict. One number, chosen on the calibration
 * sites' plans (E5, HIH; docs/decision.md). */
constexpr double kPlanVouchesCells = 3.0;

/** The field of a map's `classes`. A robot's map (Sensed) knows what it
 * saw. A floor plan's field: inside the building only the space within
 * kPlanVouchesCells of its walls is known, so furniture on its white judges
 * nothing; what it leaves outside the building counts as seen empty, so a
 * wall there conflicts, within its image or beyond (empty_beyond). */
OccupancyField occupancyField(const cv::Mat& classes, MapKind kind = MapKind::Sensed);

/** `known` grown by `cells` (rounded up, at least one) each way: the walls at
 * the edge of what a map saw lie just outside its known space. */
cv::Mat knownWithin(const cv::Mat& known, double cells);

struct Support
{
	size_t judged = 0;  //!< points landing on the target's known space
	size_t supported = 0;  //!< of those, within the tolerance of its walls
	/** Of those, on free space farther than the tolerance from any wall or
	 * unknown cell: a wall where the target clearly sees none. */
	size_t conflicts = 0;
	/** Of the supported points, those whose own wall has a direction (not
	 * a corner or a speck) and that lie within the tolerance of a target
	 * wall with a direction, and of these the ones within the tolerance of
	 * a target wall running the same way (normals within about 20°). */
	size_t directed = 0, directed_supported = 0;
	double ratio() const { return judged ? double(supported) / double(judged) : 0.0; }
};

/** `points` (cells of the source map) moved by `source_to_target` (cells)
 * into the target map: how many land on its known space, and how many of
 * those within `tolerance` target cells of an occupied cell; with
 * `judge_directions`, also whether those run like the walls near them
 * (Support::directed; a search of the target's cells within the tolerance,
 * so only where the wall alignment is wanted). */
Support tolerantSupport(
	const PointList& points, const OccupancyField& source, const Similarity2D& source_to_target,
	const OccupancyField& target, double tolerance, bool judge_directions = true);

/** Wall points judged per map at most (evenly thinned): the ratios, not the
 * counts, matter. A screen judges fewer. */
constexpr size_t kJudgedPoints = 6000;

/** hits over cases, pooled over both directions; 0 with no cases. */
inline double pooledShare(size_t hits_a, size_t hits_b, size_t cases_a, size_t cases_b)
{
	return cases_a + cases_b ? double(hits_a + hits_b) / double(cases_a + cases_b) : 0.0;
}

/** 1 − conflicts / judged, pooled over both directions; 0 with nothing judged. */
inline double pooledConsistency(const Support& a, const Support& b)
{
	return a.judged + b.judged ? 1.0 - pooledShare(a.conflicts, b.conflicts, a.judged, b.judged) : 0.0;
}

/** The verification tolerance in a target map's cells, for points moved in
 * by a similarity of this scale: `tolerance` cells of the finer map (how far
 * independent maps bend and thicken walls: a distance in the world, which
 * the finer map measures best) plus the coarser map's quantisation (a wall
 * lies anywhere within the coarse cells that drew it: one coarse cell less
 * one fine). Equal cells: `tolerance`. Not `tolerance` coarse cells: a map
 * recorded 2x coarser would then be judged at twice the distance, where
 * walls of look-alike rooms turned onto each other agree (Halmstad E5). */
double toleranceInTarget(double tolerance, double source_to_target_scale);

/** Both ways, for a transform between two maps' cells; `tolerance` as
 * toleranceInTarget. */
struct TwoWaySupport
{
	Support other_in_ref, ref_in_other;
	/** The weaker direction's ratio: a small map inside a large one is
	 * judged where they overlap, from both sides. */
	double score() const { return std::min(other_in_ref.ratio(), ref_in_other.ratio()); }
	size_t judged() const { return std::min(other_in_ref.judged, ref_in_other.judged); }
	/** 1 − conflicts / judged over both directions. */
	double consistency() const { return pooledConsistency(other_in_ref, ref_in_other); }
	/** Wall alignment: of the supported points with a direction, over both
	 * directions, the share near a wall of the other map running the same
	 * way. A wrong transform lays walls across walls; T counts that as
	 * agreement, this does not. */
	double wallAlignment() const
	{
		return pooledShare(
			other_in_ref.directed_supported, ref_in_other.directed_supported, other_in_ref.directed, ref_in_other.directed);
	}
};

TwoWaySupport twoWaySupport(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance,
	size_t most_points = kJudgedPoints, bool judge_directions = true);

/** Whether the walls agree region by region the same way. SLAM bends a map
 * by a few cells, smoothly: under the right transform each tile of one map's
 * moved walls fits the other's walls best after a small shift of its own,
 * and neighbouring tiles want about the same shift. Under a wrong transform
 * that happens to lay walls near walls, each tile's best shift goes its own
 * way. */
struct ShiftField
{
	/** Adjacent (8-neighbour) pairs of tiles with wall points enough to fit
	 * a shift. */
	size_t neighbour_pairs = 0;
	size_t coherent_pairs = 0;  //!< of which shifted alike (within the tolerance)
	/** Every tile's points judged (tolerantSupport, without directions)
	 * after the shift its neighbours fit best: the walls as if a smooth bend
	 * were taken out. */
	Support bent;
	/** Each fitted tile: the centroid of its points (source cells) and where
	 * its best shift puts it (target cells). */
	std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> fitted;
};

/** `points` (cells of the `source` map) moved by `source_to_target` into
 * the target, binned in square tiles of `tile` target cells; each tile's
 * best shift (within ±`reach`, by `step`) is the one that puts the most
 * points within `tolerance` of a target wall less those on the target's
 * clearly free space (tolerantSupport's counts); ties go to the smaller
 * shift. */
ShiftField shiftField(
	const PointList& points, const OccupancyField& source, const Similarity2D& source_to_target,
	const OccupancyField& target, double tolerance, double tile, double reach, double step);

/** Tiles of this many coarse cells, shifts within this reach: the bending of
 * independent maps (a few cells over a room) without letting a tile slide
 * onto the next corridor. */
constexpr double kShiftTileCoarseCells = 30.0;
constexpr double kShiftReachCoarseCells = 8.0;

/** Both ways, for a transform between two maps' cells; `most_points` per
 * map, thinned evenly, as twoWaySupport. */
struct TwoWayShiftField
{
	ShiftField other_in_ref, ref_in_other;
	/** Of adjacent tiles (both directions), the share whose best shifts
	 * agree within the tolerance; 0 with no adjacent tiles. */
	double coherence() const
	{
		return pooledShare(
			other_in_ref.coherent_pairs, ref_in_other.coherent_pairs, other_in_ref.neighbour_pairs,
			ref_in_other.neighbour_pairs);
	}
	/** The tolerant consistency (TwoWaySupport::consistency) with each tile
	 * shifted as its neighbours fit best, over both directions. */
	double bentConsistency() const { return pooledConsistency(other_in_ref.bent, ref_in_other.bent); }
};
TwoWayShiftField twoWayShiftField(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance,
	size_t most_points = kJudgedPoints);

/** The similarity that best takes every fitted tile of `f` (both
 * directions, one vote per tile) to where its best shift puts it: the
 * transform balanced over a bent map's regions, where TsICP's trimmed fit
 * follows the part that agrees best. `other_to_ref` itself with fewer than
 * three fitted tiles. */
Similarity2D bendBalanced(const TwoWayShiftField& f, const Similarity2D& other_to_ref);

/** The best two-way score under "far" perturbations of the transform: the
 * other map shifted by ±`shift_coarse_cells` along each axis and turned by
 * ±`turn_deg` about the centre of its points — what chance alone gives in
 * this pair of maps. */
struct Chance
{
	double support = 0, consistency = 0;  //!< the best of each over the perturbations
};
Chance chanceSupport(
	const PointList& ref_points, const OccupancyField& ref_field, const PointList& other_points,
	const OccupancyField& other_field, const Similarity2D& other_to_ref, double tolerance,
	double shift_coarse_cells, double turn_deg, size_t most_points = kJudgedPoints);

}  // namespace multires_map_merge
