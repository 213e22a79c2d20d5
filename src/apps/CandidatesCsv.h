#pragma once
// The benchmark's candidates.csv (multires_bench --calibration-data) read
// back: each pair's candidates as the decision reads them (Decision.h), with
// the truth about each. What decision-replay and decision-fit read.

#include <multires_map_merge/Decision.h>

#include <string>
#include <vector>

namespace multires_map_merge
{
/** One pair of candidates.csv. */
struct CandidatePair
{
	std::string site, ref, other;
	bool positive = false;  //!< same place: a right candidate exists in truth
	bool calibration = false;  //!< a calibration pair (the others are reported only)
	std::vector<DecisionCandidate> candidates;
	std::vector<bool> right;  //!< per candidate: right against the truth
	std::vector<double> error;  //!< per candidate: its error (pixels or coarse cells; NaN unknown)
};

/** The pairs of a candidates file, in file order (a pair's rows are
 * adjacent). A pair the file holds again is the same alignment again
 * (samples made before the benchmark stopped making some HIH-REF × E5
 * negatives twice hold them twice): read once. Throws naming the file, line
 * and column on bad input. */
std::vector<CandidatePair> loadCandidatePairs(const std::string& path);

}  // namespace multires_map_merge
