#pragma once
// A fleet's placements refined at once (FleetMerge's last step). The spanning
// tree places each map through one path of pairs, so a map reached through a
// chain carries every link's error. Every confident pair kept is a
// measurement of the similarity between two maps; the placements that agree
// best with all of them at once are found by linear least squares, because a
// 2-D similarity is a complex affine map z ↦ a·z + b (a = s·e^{iθ}), and
// "pair (f → t) says T_f = T_t ∘ M" is linear in (a, b) of both maps.
#include <multires_map_merge/FleetEdge.h>
#include <multires_map_merge/WallSpread.h>

#include <optional>
#include <vector>

namespace multires_map_merge
{
struct JointPlacementParams
{
	/** Iteratively reweighted least squares: a pair that disagrees with the
	 * joint placement by more than this share of its tolerance (RMS over the
	 * walls it is weighed at, wallRms) counts less (Huber), so one bad
	 * pair cannot pull the others. */
	double robust_share = 1.0 / 3;
	int reweighting_rounds = 5;
};

/** Every placed map's pose in the reference's frame (`in_reference` of each
 * placed map; the reference fixed) refined from every confident pair that is
 * not dropped and joins two placed maps, each weighed where it measured
 * (FleetEdge::overlap; without one, at its `from` map's walls: `spread`,
 * one WallSpread per map) in cells of its coarser map, every pair alike:
 * an edge RMSE between independent runs says how much the two maps differ
 * (clutter, doors, wall thickness), not how precisely the pair places them
 * (weighed by it, a pair of two look-alike maps outvoted a direct pair to
 * the reference). Its tolerance (`tolerance_cells`, one per edge, cells of
 * its coarser map: FleetParams::toleranceOf) sets how far it may disagree
 * with the others before it counts less (JointPlacementParams). A map
 * whose refined pose moves its walls from its tree placement by more than
 * its `max_move_cells` (one per map; the cycle check admits pairs that far
 * apart around the cycles it lies on), or than the largest tolerance of its
 * pairs, keeps the tree's: a larger move means the pairs do not support one
 * placement. Returns, per map, the refined pose, or nothing where the tree's
 * stays. Throws std::invalid_argument when a per-map or per-edge list is
 * not one entry per map or edge. */
std::vector<std::optional<Similarity2D>> refineJointly(
	const std::vector<GridInFrame>& maps, size_t reference, const std::vector<FleetPlacement>& placements,
	const std::vector<FleetEdge>& edges, const std::vector<WallSpread>& spread,
	const std::vector<double>& tolerance_cells, const std::vector<double>& max_move_cells,
	const JointPlacementParams& params = {});

}  // namespace multires_map_merge
