#include "calibration.h"

#include "carmen.h"
#include "coarser_other.h"
#include "halmstad_pairs.h"
#include "live_fleet.h"
#include "partial_maps.h"
#include "ros_maps.h"

#include <multires_map_merge/Finish.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

namespace
{
/** The live bench's growing maps, pair by pair at a few states, both orders:
 * fr079 robots against each other (judged against their frames: a wrong best
 * candidate of a barely grown map is what a lower bar would place wrong) and
 * against the intel robot (another building: negatives). The fleet sees these
 * pairs again at every estimation, so the decision must hold on all states. */
void runLiveFleetCalibrationPairs(const BenchContext& ctx)
{
	const int states = 16;
	for (const int state : {1, 2, 3, 4, 6, 8, 11, 16})
	{
		const auto maps = liveMapsAt(carmenScans(ctx), state, states);
		for (size_t a = 0; a < maps.size(); ++a)
			for (size_t b = 0; b < maps.size(); ++b)
			{
				if (a == b) continue;
				const LiveMap &ref = maps[a], &other = maps[b];
				const bool positive = !ref.other_building && !other.other_building;
				const auto r = ctx.aligner().alignScaled(ref.map, other.map);
				const Similarity2D truth = ref.frame_in_world.inverse().compose(other.frame_in_world);
				const auto points = occupiedPointsInMapFrame(other.map);
				const double coarse = std::max(ref.resolution, other.resolution);
				const std::string name = "_state" + std::to_string(state);
				writeCandidates(ctx, "live", ref.robot + name, other.robot + name, positive, true, r, [&](const Similarity2D& cells) {
					const double e = pointRmse(candidateMetric(ref.map, cells, other.map), truth, points) / coarse;
					return std::pair<double, bool>{e, e <= 2};
				});
				std::cout << "live state " << state << " " << ref.robot << " <- " << other.robot << ": "
						  << (r.success ? "merged" : "refused") << std::endl;
			}
	}
}

/** Negatives for the calibration beyond the list, of the kinds the
 * decision must also reject: each calibration-site map against its own
 * mirror image (a reflection is no similarity), and the CARMEN buildings at
 * the other resolution order (8 cm against 5 cm). */
void runExtraCalibrationNegatives(const BenchContext& ctx, const HalmstadData& data)
{
	const std::string dir = ctx.tempDir("mirror");
	fs::create_directories(dir);
	for (const auto& site : {"E5", "HIH"})
		for (const auto& m : data.sensorMaps(site))
		{
			cv::Mat img = cv::imread(data.png(m), cv::IMREAD_GRAYSCALE), mirrored;
			cv::flip(img, mirrored, 1);
			const GridInFrame orig = loadGridMap(data.yaml(m, dir));
			cv::imwrite(dir + "/mirror.png", mirrored);
			std::ofstream(dir + "/mirror.yaml") << "image: mirror.png\nresolution: 0.05\norigin: [0, 0, 0]\n";
			const auto r = ctx.aligner().alignScaled(orig, loadGridMap(dir + "/mirror.yaml"));
			writeCandidates(ctx, "mirror", m, m + "_mirrored", false, true, r, noTruth);
			std::cout << "negative " << m << " vs its mirror image: " << (r.success ? "MERGED (false)" : "refused") << std::endl;
		}
	fs::remove_all(dir);
	// Each CARMEN building at 8 cm against each other one at 5 cm: whole,
	// and as a robot that has seen little of it (the first 15 % of its run:
	// few wall points, so the evidence discount decides).
	for (const int percent : {100, 15})
		for (size_t i = 0; i < kLogs.size(); ++i)
			for (size_t j = 0; j < kLogs.size(); ++j)
				if (i != j)
				{
					const ScanSequence& sa = scansOf(ctx, kLogs[i].name);
					const ScanSequence& sb = scansOf(ctx, kLogs[j].name);
					const auto r = ctx.aligner().alignScaled(
						renderGrid(sa, 0, sa.size(), 0.08), renderGrid(sb, 0, sb.size() * percent / 100, 0.05));
					const std::string part = percent < 100 ? "_first" + std::to_string(percent) : "";
					writeCandidates(ctx, "carmen", kLogs[i].name + "_8cm", kLogs[j].name + part + "_5cm", false, true, r, noTruth);
					std::cout << "negative " << kLogs[i].name << " 8 cm vs " << kLogs[j].name << part << " 5 cm: "
							  << (r.success ? "MERGED (false)" : "refused") << std::endl;
				}
}

/** A calibration pair's names in candidates.csv. */
struct PairNames
{
	std::string site, ref, other;
	bool positive;
};

/** The pair's candidates, each judged where the aligner would report it if
 * decided on (the bent finish, Finish.h). */
void writeFinishedCandidates(const BenchContext& ctx, const PairNames& names, const GridInFrame& ref,
	const GridInFrame& other, const CScalingGridMapAligner::TReturnInfo& r, const CandidateError& error_of)
{
	const auto ref_prepared = ctx.aligner().prepare(ref.grid), other_prepared = ctx.aligner().prepare(other.grid);
	writeCandidates(ctx, names.site, names.ref, names.other, names.positive, true, r, error_of, [&](const auto& c) {
		return bentFinished(ctx, *ref_prepared, *other_prepared, c);
	});
}

/** Calibration pairs of the kind the package exists for: each E5 and HIH
 * pair (REF = the later map) with OTHER recorded as a coarser grid whose
 * stated resolution is wrong (the coarser-OTHER section's maps). Each
 * candidate judged as it would be reported, as runHalmstadPair does. */
void runCoarserCalibrationPairs(const BenchContext& ctx, const HalmstadData& data)
{
	const std::string dir = ctx.tempDir("coarser");
	const auto sink = [&ctx](const CoarserRun& run, const GridInFrame& ref, const GridInFrame& other,
						  const CScalingGridMapAligner::TReturnInfo& r, const CandidateError& error_of) {
		std::ostringstream other_name;
		other_name << run.other << "_x" << run.factor;
		writeFinishedCandidates(ctx, {run.site, run.ref, other_name.str(), true}, ref, other, r, error_of);
	};
	runCoarserOther(data, {"E5", "HIH"}, kCoarserFactors, ctx.options, dir, sink);
	fs::remove_all(dir);
}

/** Floor plans: each E5 and HIH sensor map (OTHER) on its own site's plan
 * (positives, judged against the annotation) and on every other site's plan
 * (negatives), as the floor-plan section aligns them. */
void runFloorPlanCalibrationPairs(const BenchContext& ctx, const HalmstadData& data)
{
	const std::string dir = ctx.tempDir("plans");
	for (const std::string site : {"E5", "HIH"})
		for (const auto& sensor : data.sensorMaps(site))
			for (const auto& plan_site : data.sites())
				runHalmstadPair(ctx, data, HalmstadData::floorPlan(plan_site), sensor, dir);
	fs::remove_all(dir);
}

/** Partial maps: each half of the earlier map of every E5 and HIH pair on
 * the later map (positives, judged against the annotation on the half's own
 * walls), and every such half on the first map of each other site
 * (negatives), as the partial-maps section aligns them. A half REF saw
 * little of is a positive whose best candidate is often wrong: the decision
 * must refuse it. */
void runPartialCalibrationPairs(const BenchContext& ctx, const HalmstadData& data)
{
	const std::string dir = ctx.tempDir("partial");
	const auto sink = [&ctx](const PartialRun& run, const GridInFrame& ref, const GridInFrame& half,
						  const CScalingGridMapAligner::TReturnInfo& r, const CandidateError& error_of) {
		writeFinishedCandidates(ctx, {run.site, run.ref, halfName(run.other, run.half_index), run.positive}, ref, half, r, error_of);
	};
	runPartialMaps(data, {"E5", "HIH"}, ctx.options, dir, sink);
	fs::remove_all(dir);
}

/** Calibration negatives in the other order: each map of another site as
 * REF against `per_map` E5 maps as OTHER. The decision is not symmetric in
 * its maps, and the report's cross-site negatives take every site's maps as
 * REF; runHalmstad's calibration negatives take only E5 and HIH maps. A
 * pair those made already (an HIH map as REF, an E5 map) is not made again. */
void runReverseCrossSiteNegatives(const BenchContext& ctx, const HalmstadData& data, size_t per_map)
{
	const std::string dir = ctx.tempDir("reverse");
	const std::vector<std::string> e5 = data.sensorMaps("E5");
	const auto made = crossSiteNegatives(data, {"E5", "HIH"}, per_map);
	for (const auto& site : data.sites())
		if (site != "E5")
			for (const auto& ref : data.sensorMaps(site))
			{
				// Spread over the E5 maps from a per-map offset, as runHalmstad's.
				const size_t start = std::hash<std::string>()(ref) % e5.size();
				for (size_t k = 0; k < per_map; ++k)
				{
					const std::pair<std::string, std::string> pair{ref, e5[(start + k * 5) % e5.size()]};
					if (std::find(made.begin(), made.end(), pair) == made.end())
						runHalmstadPair(ctx, data, pair.first, pair.second, dir);
				}
			}
	fs::remove_all(dir);
}

/** Calibration positives in the other order: each unordered pair of the
 * calibration sites with the earlier map as REF. The issue tunes on both
 * orders; the report measures one (REF = the later map), and the decision is
 * not symmetric in its maps. */
void runReverseCalibrationPositives(const BenchContext& ctx, const HalmstadData& data)
{
	const std::string dir = ctx.tempDir("swapped");
	for (const std::string site : {"E5", "HIH"})
		for (const auto& p : data.unorderedPairs(site)) runHalmstadPair(ctx, data, p.src, p.dst, dir);
	fs::remove_all(dir);
}
}  // namespace

void writeCalibrationData(const BenchContext& ctx, const CalibrationParts& parts)
{
	const HalmstadData data(ctx.data + "/halmstad");
	const bool everything = !parts.extra_negatives && !parts.live_pairs && !parts.coarser_pairs &&
		!parts.floor_plan_pairs && !parts.ros_pairs && !parts.partial_pairs;
	if (everything)
	{
		runHalmstad(ctx, data, {"E5", "HIH"}, parts.negatives_per_map);
		runReverseCalibrationPositives(ctx, data);
		runReverseCrossSiteNegatives(ctx, data, parts.negatives_per_map);
		runCarmenNegatives(ctx);
	}
	if (everything || parts.extra_negatives) runExtraCalibrationNegatives(ctx, data);
	if (everything || parts.live_pairs) runLiveFleetCalibrationPairs(ctx);
	if (everything || parts.coarser_pairs) runCoarserCalibrationPairs(ctx, data);
	if (everything || parts.floor_plan_pairs) runFloorPlanCalibrationPairs(ctx, data);
	if (everything || parts.ros_pairs) runRosMaps(ctx);
	if (everything || parts.partial_pairs) runPartialCalibrationPairs(ctx, data);
}

}  // namespace multires_bench
