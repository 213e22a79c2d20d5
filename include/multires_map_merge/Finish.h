#pragma once
// The decided transform finished (the method's last step before fusion):
// maps whose cells coincide (two parts of one SLAM run) are refined on every
// occupied cell and shifted onto the coarser map's lattice; maps that bend
// (independent runs) are refit over the whole overlap. The decision is made
// before, on the edges. Transforms here are between the prepared maps' cells
// (PreparedMap::grid_corner; preparedCells takes a reported one there).

#include <multires_map_merge/Decision.h>
#include <multires_map_merge/LatticeShift.h>
#include <multires_map_merge/PreparedMap.h>
#include <multires_map_merge/TsICP.h>

#include <string>

namespace multires_map_merge
{
/** At this edge RMSE (coarse cells) or more the maps are not the same cells:
 * they bend (independent SLAM runs), and a finish on occupied cells gains
 * nothing (on Halmstad E5/HIH it moved OTHER by 0.04 px on average). */
constexpr double kExactMaxRmse = 1.5;

/** Whether a candidate's maps coincide cell for cell: its exact_confidence
 * (strict cell agreement with edges within kExactMaxRmse, PairSearch) is
 * above 0. The RMSE alone does not tell: a bent run recorded with cells 3×
 * larger fits within 1.5 of those cells yet bends by 5–30 fine cells, and
 * the occupied-cell finish then keeps the trimmed fit's one region (on
 * Halmstad E5 with OTHER ×3.3, a placement 48 px off the annotation that the
 * refit over the whole overlap brings to 25 px). */
inline bool cellsCoincide(double exact_confidence) { return exact_confidence > 0; }

struct FinishParams
{
	TsICPParams icp;  //!< the search's TsICP
	bool on_occupied = true;  //!< icp_finish_on_occupied
	double max_shift = 1.5;  //!< a finish moving a wall further is not taken [coarse cells]
	LatticeShiftParams lattice;
	double bent_lambda = 4.0;  //!< finish_bent_lambda (0: off)
};

/** TsICP on the occupied cells both maps see (their overlap under `cells`),
 * from `cells`, then the sub-cell lattice shift (LatticeShift.h). Returns
 * `cells` when the overlap is too thin to refine on. */
Similarity2D finishOnOccupied(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, const TsICPParams& ip,
	const LatticeShiftParams& lattice);

/** The refit over the whole overlap (TsICP with λ = bent_lambda) of a
 * candidate transform with this exact_confidence. `cells` itself when off,
 * where the maps coincide (cellsCoincide), or when the refit would place the
 * other map elsewhere (a rival by `decision`'s measure). */
Similarity2D finishBent(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, double exact_confidence,
	const FinishParams& p, const DecisionParams& decision);

struct Finished
{
	bool ran = false;  //!< a finish applied (timed as the "finish" stage)
	Similarity2D cells;
	std::string note;  //!< why a finish that ran was not taken ("" if taken)
};

/** The finish the aligner applies to a decided transform (its candidate's
 * exact_confidence): on occupied cells where the maps coincide
 * (cellsCoincide) and the pair is `confident` (only merged pairs pay),
 * unless it moves a wall by more than max_shift; the bent refit otherwise (a
 * refused pair too: its report shows the pose it would be merged with). */
Finished finishDecided(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& cells, double exact_confidence,
	bool confident, const FinishParams& p, const DecisionParams& decision);

}  // namespace multires_map_merge
