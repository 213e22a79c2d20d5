#include <multires_map_merge/JointPlacement.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace multires_map_merge
{
namespace
{
/** The 2×2 block of z ↦ a·z as a function of a = (re, im): a·z is linear in a. */
Eigen::Matrix2d timesPoint(const Eigen::Vector2d& z)
{
	Eigen::Matrix2d m;
	m << z.x(), -z.y(), z.y(), z.x();
	return m;
}
}  // namespace

std::vector<std::optional<Similarity2D>> refineJointly(
	const std::vector<GridInFrame>& maps, size_t reference, const std::vector<FleetPlacement>& placements,
	const std::vector<FleetEdge>& edges, const std::vector<WallSpread>& spread,
	const std::vector<double>& tolerance_cells, const std::vector<double>& max_move_cells,
	const JointPlacementParams& params)
{
	const size_t n = maps.size();
	// One per map and one per edge: a list of another length is a caller's mix-up, said, not padded.
	if (placements.size() != n || spread.size() != n || max_move_cells.size() != n)
		throw std::invalid_argument("refineJointly: placements, spread and max_move_cells need one entry per map");
	if (tolerance_cells.size() != edges.size())
		throw std::invalid_argument("refineJointly: tolerance_cells needs one entry per edge");
	std::vector<std::optional<Similarity2D>> out(n);
	// The unknowns: (Re a, Im a, Re b, Im b) of each placed map but the reference.
	std::vector<int> column(n, -1);
	int unknowns = 0;
	for (size_t m = 0; m < n; ++m)
		if (m != reference && placements[m].placed) column[m] = 4 * unknowns++;
	std::vector<size_t> used;
	std::vector<double> max_move(max_move_cells);
	for (size_t k = 0; k < edges.size(); ++k)
	{
		const FleetEdge& e = edges[k];
		if (!e.merged || e.dropped || !placements[e.from].placed || !placements[e.to].placed) continue;
		used.push_back(k);
		for (size_t m : {e.from, e.to}) max_move[m] = std::max(max_move[m], tolerance_cells[k]);
	}
	if (unknowns == 0 || used.size() <= size_t(unknowns)) return out;  // a tree: nothing to balance

	const int rows = int(used.size()) * 8, cols = 4 * unknowns;
	std::vector<double> weight(used.size(), 1.0);
	Eigen::VectorXd x;
	for (int round = 0; round <= params.reweighting_rounds; ++round)
	{
		Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, cols);
		Eigen::VectorXd y = Eigen::VectorXd::Zero(rows);
		for (size_t i = 0; i < used.size(); ++i)
		{
			const FleetEdge& e = edges[used[i]];
			const double w = std::sqrt(weight[i]) / coarseCellInReference(maps, placements, e);
			for (int c = 0; c < 4; ++c)
			{
				// T_from(p) − T_to(M(p)) = 0 at the points p of the pair's
				// overlap (where it measured), else of the from map's walls.
				const Eigen::Vector2d p = (e.overlap ? *e.overlap : spread[e.from])[c], q = e.from_to_to(p);
				const int r = int(i) * 8 + 2 * c;
				if (column[e.from] >= 0)
				{
					a.block<2, 2>(r, column[e.from]) += w * timesPoint(p);
					a.block<2, 2>(r, column[e.from] + 2) += w * Eigen::Matrix2d::Identity();
				}
				else
					y.segment<2>(r) -= w * p;
				if (column[e.to] >= 0)
				{
					a.block<2, 2>(r, column[e.to]) -= w * timesPoint(q);
					a.block<2, 2>(r, column[e.to] + 2) -= w * Eigen::Matrix2d::Identity();
				}
				else
					y.segment<2>(r) += w * q;
			}
		}
		x = a.colPivHouseholderQr().solve(y);
		if (!x.allFinite()) return out;
		// Huber: a pair's weight falls as its disagreement passes robust_share
		// of its tolerance.
		for (size_t i = 0; i < used.size(); ++i)
		{
			// The rows hold sqrt(weight) / cell × each point's two coordinates: r is the RMS in tolerances.
			const double r = (a.middleRows(int(i) * 8, 8) * x - y.segment<8>(int(i) * 8)).norm() /
				(2 * std::sqrt(weight[i]) * tolerance_cells[used[i]]);
			weight[i] = r <= params.robust_share ? 1.0 : params.robust_share / r;
		}
	}
	for (size_t m = 0; m < n; ++m)
	{
		if (column[m] < 0) continue;
		const Eigen::Vector2d lin = x.segment<2>(column[m]), shift = x.segment<2>(column[m] + 2);
		const Similarity2D joint(lin.norm(), std::atan2(lin.y(), lin.x()), shift);
		if (!joint.isFinite() || !(joint.scale > 0)) continue;
		const Similarity2D& tree = placements[m].in_reference;
		const double cell = std::max<double>(
			maps[reference].grid.getResolution(), maps[m].grid.getResolution() * tree.scale);
		if (wallRms(spread[m], joint, tree) / cell <= max_move[m]) out[m] = joint;
	}
	return out;
}

}  // namespace multires_map_merge
