#pragma once
// OTHER recorded as a coarser grid (issue 35): each Halmstad sensor pair
// (REF = the later map) with OTHER resampled as a coarser robot would have
// recorded it (a coarse cell is occupied if any fine cell in it is, else free
// if any is, else unknown), cells `factor` times larger, its stated
// resolution left at 0.05 m: wrong metadata, the scale from the content.

#include "halmstad.h"

#include <multires_map_merge/CScalingGridMapAligner.h>

#include <functional>
#include <ostream>
#include <utility>
#include <string>
#include <vector>

namespace multires_bench
{
/** OTHER's cells this many times larger (issue 35: 2× and 3.3×). */
inline const std::vector<double> kCoarserFactors = {2.0, 3.3};

struct CoarserRun
{
	std::string site, ref, other;
	double factor = 1;
	bool merged = false;
	HalmstadOutcome outcome;  //!< of the reported transform, against the annotation of the fine maps
	double seconds = 0;
};

/** Called after each pair with its maps, its result and how to judge any of
 * its candidates (cells of REF ← cells of the coarse OTHER): the calibration
 * data's writer. */
using CoarserCandidatesSink = std::function<void(const CoarserRun&, const GridInFrame& ref,
	const GridInFrame& coarse_other, const multires_map_merge::CScalingGridMapAligner::TReturnInfo&,
	const CandidateError&)>;

/** Every unordered same-site pair of `sites` at each of `factors`. */
std::vector<CoarserRun> runCoarserOther(
	const HalmstadData& data, const std::vector<std::string>& sites, const std::vector<double>& factors,
	const multires_map_merge::CScalingGridMapAligner::TConfigParams& options, const std::string& dir,
	const CoarserCandidatesSink& sink = {});

/** Merged right and merged wrong over the runs of `factor` on sites of one role. */
struct CoarserTotals
{
	size_t pairs = 0, right = 0, wrong = 0;
};
CoarserTotals coarserTotals(const std::vector<CoarserRun>& runs, double factor, bool calibration_sites);

/** The report's section: a row per site and factor. */
void writeCoarserSection(std::ostream& md, const std::vector<CoarserRun>& runs);

}  // namespace multires_bench
