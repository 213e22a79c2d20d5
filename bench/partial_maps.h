#pragma once
// Partial maps (the Halmstad sensor maps cut in half): a robot that explored
// part of a building, against another robot's whole map of it. Each sensor
// map's known extent is cut across its longer side into two halves, each
// written as a map_server file of its own size with its origin where the
// half lies in the whole map's frame. OTHER = a half of the earlier map of
// every same-site pair, REF = the later map, judged against the annotation
// on the half's own occupied pixels; and every half against the first map of
// each other site (must not merge). Calibration data holds the calibration
// sites' halves (E5, HIH: calibration.h); F5 and KPT4A's are acceptance.

#include "halmstad.h"

#include <multires_map_merge/CScalingGridMapAligner.h>

#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
/** The two halves of a map. */
inline const std::vector<std::string> kPartialHalves = {"first half", "second half"};

/** A half of a sensor map, written as a map_server file. */
struct MapHalf
{
	std::string yaml;
	/** Its occupied pixels, in the whole map's image pixels (what its
	 * placement is judged on: meanDisplacementPx with the whole map's rows). */
	std::vector<Eigen::Vector2d> occupied;
	int whole_rows = 0;  //!< of the whole map's image
};

/** The name of half `k` (0, 1) of `map`: MAP_half1, MAP_half2. */
std::string halfName(const std::string& map, size_t k);

/** Half `k` (0, 1) of `map`'s known extent, cut across its longer side, as a
 * map_server file `halfName(map, k).yaml` in `dir` of its own size, its
 * origin where the half lies in the whole map's frame (origin 0). */
MapHalf writeHalf(const HalmstadData& data, const std::string& map, size_t k, const std::string& dir);

struct PartialRun
{
	std::string site, ref, other, half;
	size_t half_index = 0;  //!< which of kPartialHalves `half` is (halfName)
	bool positive = false;  //!< same site: the annotation says where the half lies
	bool merged = false;
	bool right = false;  //!< merged with the half's occupied pixels ≤ kRightPx from the annotation (mean)
	double displacement_px = NAN;
	/** Share of the half's occupied pixels that the annotation puts on REF's
	 * known space: how much of the half REF saw at all. */
	double inside_ref = NAN;
	double seconds = 0;
};

/** Called after each pair with its maps, its result and how to judge any of
 * its candidates: the calibration data's writer. */
using PartialCandidatesSink = std::function<void(const PartialRun&, const GridInFrame& ref, const GridInFrame& half,
	const multires_map_merge::CScalingGridMapAligner::TReturnInfo&, const CandidateError&)>;

/** Every same-site pair of `sites` with OTHER cut in halves, and every half
 * against the first sensor map of each other site of the data set. */
std::vector<PartialRun> runPartialMaps(
	const HalmstadData& data, const std::vector<std::string>& sites,
	const multires_map_merge::CScalingGridMapAligner::TConfigParams& options, const std::string& dir,
	const PartialCandidatesSink& sink = {});

/** How far into REF a half must lie to count among the pairs REF mostly saw. */
constexpr double kMostlyInside = 0.5;

struct PartialTotals
{
	size_t positives = 0, right = 0, wrong = 0;
	size_t mostly_inside = 0, mostly_inside_right = 0;  //!< positives with inside_ref ≥ kMostlyInside
	size_t negatives = 0, negatives_merged = 0;
};
PartialTotals partialTotals(const std::vector<PartialRun>& runs, const std::string& site = "");

/** The report's section: a row per site. */
void writePartialSection(std::ostream& md, const std::vector<PartialRun>& runs);

}  // namespace multires_bench
