// multires_bench: the paper's experiments on real SLAM-corrected logs, side
// by side with MRPT's CGridMapAligner, the real independent maps, floor plans,
// fleets and the live node, in one run. Writes pairs.csv, PNG matrices and
// plots, and REPORT.md (every number in it comes from this run).
//   multires_bench --quick  --out DIR     a few pairs (CI: the bench cannot rot)
//   multires_bench --out DIR              the full run (bench/README.md)
// One file per experiment (carmen, halmstad_pairs, floor_plans,
// coarser_other, partial_maps, scaling, fleets, halmstad_fleets, live_fleet, calibration),
// the report apart (report.cpp); this file picks what to run.

#include "calibration.h"
#include "carmen.h"
#include "coarser_other.h"
#include "context.h"
#include "fleets.h"
#include "floor_plans.h"
#include "halmstad_fleets.h"
#include "halmstad_pairs.h"
#include "live_fleet.h"
#include "partial_maps.h"
#include "report.h"
#include "scaling.h"

#include <multires_map_merge/MapIO.h>

#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

using namespace multires_map_merge;
using namespace multires_bench;
namespace fs = std::filesystem;

namespace
{
std::vector<std::string> siteList(const std::string& comma_separated)
{
	std::vector<std::string> sites;
	std::stringstream list(comma_separated);
	for (std::string site; std::getline(list, site, ',');) sites.push_back(site);
	return sites;
}

// ---------------------------------------------------------------- one section alone
int partialOnly(const BenchContext& ctx, const std::string& sites)
{
	const std::string dir = ctx.tempDir("partial");
	const auto runs = runPartialMaps(HalmstadData(ctx.data + "/halmstad"), siteList(sites), ctx.options, dir);
	fs::remove_all(dir);
	writePartialSection(std::cout, runs);
	const PartialTotals t = partialTotals(runs);
	return t.wrong + t.negatives_merged == 0 ? 0 : 1;
}

int coarserOnly(const BenchContext& ctx, const std::string& sites)
{
	const std::string dir = ctx.tempDir("coarser");
	const auto runs = runCoarserOther(HalmstadData(ctx.data + "/halmstad"), siteList(sites), kCoarserFactors, ctx.options, dir);
	fs::remove_all(dir);
	writeCoarserSection(std::cout, runs);
	size_t wrong = 0;
	for (const auto& r : runs) wrong += r.merged && !r.outcome.right;
	return wrong == 0 ? 0 : 1;
}

int floorPlansOnly(const BenchContext& ctx, const std::string& sites)
{
	const std::string dir = ctx.tempDir("plans");
	const auto runs = runFloorPlans(HalmstadData(ctx.data + "/halmstad"), siteList(sites), ctx.options, dir);
	fs::remove_all(dir);
	writeFloorPlanSection(std::cout, runs);
	const FloorPlanTotals t = floorPlanTotals(runs);
	return t.merged_wrong + t.negatives_merged == 0 ? 0 : 1;
}

int halmstadOnly(const BenchContext& ctx, const std::string& sites, size_t negatives_per_map)
{
	const auto runs = runHalmstad(ctx, HalmstadData(ctx.data + "/halmstad"), siteList(sites), negatives_per_map);
	std::map<std::string, HalmstadTally> per_site;
	size_t negatives = 0, false_merges = 0, wrong = 0;
	for (const auto& r : runs)
		if (r.positive) per_site[r.site].add(r), wrong += r.merged && !r.outcome.right;
		else ++negatives, false_merges += r.merged;
	for (const auto& [site, t] : per_site)
		std::cout << "halmstad " << site << ": " << t.right << "/" << t.pairs << " merged right, " << t.wrong
				  << " merged wrong; of the others, from the annotation: " << t.search_missed
				  << " merged right (the search missed them), " << t.evidence_weak << " refused (weak evidence or a rival)\n";
	std::cout << "halmstad negatives: " << false_merges << "/" << negatives << " merged\n";
	return wrong + false_merges == 0 ? 0 : 1;
}

int rosMapsOnly(const BenchContext& ctx)
{
	const auto runs = runRosMaps(ctx, kRosFactors);
	writeRosMapsSection(std::cout, runs);
	const bool wrong = std::any_of(runs.begin(), runs.end(), [](const RosMapsRun& r) { return r.merged && !r.right; });
	return wrong ? 1 : 0;
}

int carpinOnly(const BenchContext& ctx)
{
	const CarpinResult result = runCarpinMaps(ctx);
	writeCarpinSection(std::cout, result);
	return carpinWrongMerges(result) == 0 ? 0 : 1;
}

int negativesOnly(const BenchContext& ctx)
{
	const auto negatives = runCarmenNegatives(ctx);
	const auto merged = std::count_if(negatives.begin(), negatives.end(), [](const Negative& n) { return n.merged; });
	std::cout << "false merges: " << merged << " / " << negatives.size() << "\n";
	return merged == 0 ? 0 : 1;
}

int liveOnly(const BenchContext& ctx)
{
	const LiveLatency live = runLiveLatency(carmenScans(ctx), ctx.quick ? 4 : 16, ctx.options, ctx.fleet);
	writeLiveSection(std::cout, live);
	// Exit 1 when a robot was ever placed wrong (the other building at
	// all); its latency depends on this machine's speed and is only shown.
	const bool never_wrong = std::none_of(
		live.robots.begin(), live.robots.end(), [](const LiveRobotRow& r) { return r.wrong_estimations > 0; });
	return never_wrong ? 0 : 1;
}

std::vector<HalmstadFleetRun> halmstadFleets(const BenchContext& ctx, const std::vector<std::string>& sites)
{
	const std::string dir = ctx.tempDir("fleets");
	const auto runs = runHalmstadFleets(
		HalmstadData(ctx.data + "/halmstad"), sites, true,
		[&](const std::string& d) { return placeFleetInChild(ctx, d); }, dir);
	fs::remove_all(dir);
	return runs;
}

// ---------------------------------------------------------------- the full run
const std::vector<double> kAllResolutions = {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};

/** The accuracy matrices with MRPT beside: Fig. 8 (every pair of
 * resolutions, fr079; a coarser grid on the other logs) and Fig. 9. */
void runMatrices(const BenchContext& ctx, FullRun& run)
{
	const bool quick = ctx.quick;
	run.res = quick ? std::vector<double>{0.02, 0.10} : kAllResolutions;
	for (const double rr : run.res)
		for (const double ro : run.res)
			run.pairs.push_back(runPair(ctx, "resolution", "fr079", rr, ro, 0, std::abs(rr - ro) < 1e-9 || !quick));
	std::vector<std::string> others;
	if (!quick) others = {"intel", "fr101", "orebro", "fhw", "belgioioso"};
	for (const auto& log : others)
		for (const double rr : {0.02, 0.05, 0.10})
			for (const double ro : {0.02, 0.05, 0.10}) run.pairs.push_back(runPair(ctx, "other-logs", log, rr, ro, 0, false));
	// Rotations against the other map's resolution (reference at 2 cm: the hard side).
	run.yaws = quick ? std::vector<double>{90} : std::vector<double>{0, 90, 180, 270, 137};
	run.rot_res = quick ? std::vector<double>{0.05} : kAllResolutions;
	for (const double yaw : run.yaws)
		for (const double ro : run.rot_res) run.pairs.push_back(runPair(ctx, "rotation", "fr079", 0.02, ro, yaw, false));
}

/** Halmstad sensor pairs and cross-site negatives, floor plans, OTHER
 * recorded coarser, partial maps, the independent ROS maps, Carpin's maps and the Willow
 * pair. */
void runRealMaps(const BenchContext& ctx, FullRun& run)
{
	const HalmstadData data(ctx.data + "/halmstad");
	if (ctx.quick)
	{
		const std::string dir = (fs::temp_directory_path() / "multires_bench_halmstad_quick").string();
		run.halmstad.push_back(runHalmstadPair(ctx, data, "E5_02", "E5_01", dir));
		run.halmstad.push_back(runHalmstadPair(ctx, data, "E5_02", "F5_01", dir));
		fs::remove_all(dir);
	}
	else
	{
		run.halmstad = runHalmstad(ctx, data, data.sites(), 6);
		const std::string dir = ctx.tempDir("plans");
		run.floor_plans = runFloorPlans(data, data.sites(), ctx.options, dir);
		run.coarser = runCoarserOther(data, data.sites(), kCoarserFactors, ctx.options, dir);
		run.partial = runPartialMaps(data, data.sites(), ctx.options, dir);
		fs::remove_all(dir);
		run.ros_maps = runRosMaps(ctx, kRosFactors);
		run.carpin = runCarpinMaps(ctx);
	}
	const std::string w = ctx.data + "/ros_maps/willow/";
	run.willow = ctx.aligner().alignScaled(
		loadGridMap(w + "navstage_willow_5cm.yaml"), loadGridMap(w + "stageros_willow_10cm.yaml"));
}

/** Cost with map size and against MRPT's whole process, fleets, the live
 * node, and TsICP's basin of convergence. */
void runCostFleetsAndBasin(const BenchContext& ctx, FullRun& run)
{
	const bool quick = ctx.quick;
	for (const int cells : quick ? std::vector<int>{500} : std::vector<int>{500, 1000, 2000, 4000, 8000})
		run.scaling.push_back(runScalingCase(ctx, cells));
	for (const double r : quick ? std::vector<double>{0.10} : kAllResolutions)
		run.processes.push_back(runWholeProcess(ctx, r));
	run.fleets = runFleets(ctx);
	if (!quick) run.halmstad_fleets = halmstadFleets(ctx, HalmstadData(ctx.data + "/halmstad").sites());
	run.live = runLiveLatency(carmenScans(ctx), quick ? 4 : 16, ctx.options, ctx.fleet);
	run.basin_dyaws = quick ? std::vector<double>{-8, 0, 8} : std::vector<double>{-8, -6, -4, -2, 0, 2, 4, 6, 8};
	run.basin_dscales = run.basin_dyaws;  // percent
	run.basin_same = basin(ctx, "fr079", 0.05, 0.05, run.basin_dyaws, run.basin_dscales);
	run.basin_ratio = basin(ctx, "fr079", 0.02, 0.10, run.basin_dyaws, run.basin_dscales);
}

int fullRun(const BenchContext& ctx, const std::string& out)
{
	const auto started = std::chrono::steady_clock::now();
	FullRun run;
	runMatrices(ctx, run);
	run.negatives = runCarmenNegatives(ctx);
	runRealMaps(ctx, run);
	runCostFleetsAndBasin(ctx, run);
	run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
	writeReport(ctx, out, run);
	std::cout << "wrote " << out << "/REPORT.md (" << num(run.seconds, 0) << " s)" << std::endl;
	return 0;
}
}  // namespace

// Long for its option declarations, one per section that can run alone.
int main(int argc, char** argv)
{
	TCLAP::CmdLine cmd("multires_map_merge benchmark (see bench/README.md)", ' ', "0.1.0");
	TCLAP::SwitchArg quick_arg("", "quick", "a few pairs only (what CI runs)", cmd);
	TCLAP::ValueArg<std::string> out_arg("", "out", "output folder", false, "bench_output", "DIR", cmd);
	TCLAP::ValueArg<std::string> data_arg("", "data", "the shared data folder", false, "", "DIR", cmd);
	TCLAP::SwitchArg calibration_arg(
		"", "calibration-data", "only the calibration data (Halmstad E5/HIH, E5 cross-site and CARMEN negatives) "
		"into candidates.csv, for decision-fit", cmd);
	TCLAP::ValueArg<std::string> config_arg(
		"", "config",
		"parameters: sections [aligner] and [fleet] of an MRPT ini file (e.g. calibration data made with other defaults)",
		false, "", "FILE.ini", cmd);
	TCLAP::SwitchArg extra_arg("", "extra-negatives-only", "with --calibration-data: only the mirror and 8-vs-5 cm negatives", cmd);
	TCLAP::SwitchArg coarser_pairs_arg(
		"", "coarser-pairs-only", "with --calibration-data: only the E5 and HIH pairs with OTHER recorded coarser", cmd);
	TCLAP::SwitchArg floor_plan_pairs_arg(
		"", "floor-plan-pairs-only", "with --calibration-data: only the E5 and HIH sensor maps on every site's floor plan", cmd);
	TCLAP::SwitchArg partial_pairs_arg(
		"", "partial-pairs-only", "with --calibration-data: only the halves of the E5 and HIH maps (partial maps)", cmd);
	TCLAP::SwitchArg live_pairs_arg(
		"", "live-pairs-only", "with --calibration-data: only the live fleet's growing maps, pair by pair", cmd);
	TCLAP::ValueArg<std::string> coarser_arg(
		"", "coarser-only", "only the coarser-OTHER section (×2, ×3.3) on these sites (e.g. F5,KPT4A)", false, "", "SITES",
		cmd);
	TCLAP::ValueArg<std::string> partial_arg(
		"", "partial-only", "only the partial-maps section (halves of these sites' sensor maps, e.g. E5,HIH)", false, "",
		"SITES", cmd);
	TCLAP::ValueArg<std::string> floor_plans_arg(
		"", "floor-plans-only", "only the floor-plan section, sensor maps of these sites (e.g. E5,HIH) on every plan", false,
		"", "SITES", cmd);
	TCLAP::ValueArg<std::string> halmstad_arg(
		"", "halmstad-only", "only the real-independent-maps section, on these sites (e.g. E5,HIH)", false, "", "SITES", cmd);
	TCLAP::ValueArg<int> pad_arg(
		"", "pad-to",
		"with --halmstad-only: each map framed in this many cells a side of unknown (gmapping's default grid is 4000)",
		false, 0, "CELLS", cmd);
	TCLAP::ValueArg<int> negatives_arg(
		"", "halmstad-negatives", "cross-site negatives per map (with --halmstad-only)", false, 8, "N", cmd);
	TCLAP::ValueArg<std::string> sets_arg(
		"", "sets", "only these accuracy sets (resolution, other-logs, rotation), printing their medians", false, "",
		"SETS", cmd);
	TCLAP::SwitchArg fleet_arg("", "fleet-only", "only the fleet section (printed as markdown)", cmd);
	TCLAP::ValueArg<std::string> halmstad_fleets_arg(
		"", "halmstad-fleets-only", "only the Halmstad fleets, same and mixed cell sizes, of these sites (e.g. F5,HIH)",
		false, "", "SITES", cmd);
	TCLAP::ValueArg<int> scaling_arg(
		"", "scaling-only", "only the scaling case of this many cells a side (e.g. 4000)", false, 0, "CELLS", cmd);
	TCLAP::SwitchArg live_arg(
		"", "live-only", "only the live node's latency (printed as markdown); exit 1 if a robot was ever placed wrong", cmd);
	TCLAP::SwitchArg ros_maps_arg(
		"", "ros-maps-only", "only the independent ROS maps (ros_maps, SOURCES.md 2b); with --calibration-data: their candidates",
		cmd);
	TCLAP::SwitchArg carpin_arg(
		"", "carpin-only", "only Carpin's map-merging maps (SOURCES.md 4; never tuned on); exit 1 on a wrong merge", cmd);
	TCLAP::SwitchArg negatives_only_arg(
		"", "negatives-only", "only the CARMEN pairs that must not merge (different buildings, disjoint parts)", cmd);
	TCLAP::ValueArg<std::string> fleet_child("", "fleet-child", "internal: place a fleet in a fresh process", false, "", "DIR", cmd);
	TCLAP::ValueArg<std::string> mrpt_child("", "mrpt-align", "internal: MRPT's aligner in a fresh process", false, "", "REF", cmd);
	TCLAP::ValueArg<std::string> child_ref("", "scaling-align", "internal: align in a fresh process", false, "", "REF", cmd);
	TCLAP::ValueArg<std::string> child_other("", "scaling-other", "internal: with --scaling-align", false, "", "OTHER", cmd);
	try
	{
		cmd.parse(argc, argv);
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "multires_bench: " << e.error() << "\n";
		return 2;
	}
	BenchContext ctx;
	ctx.self = fs::canonical("/proc/self/exe");
	ctx.quick = quick_arg.getValue();
	ctx.data = data_arg.getValue();
	if (ctx.data.empty()) ctx.data = (fs::path(argv[0]).parent_path() / "../../../../shared/data").lexically_normal();
	try
	{
		if (config_arg.isSet()) ctx.loadConfig(config_arg.getValue());
	}
	catch (const std::exception& e)
	{
		std::cerr << "multires_bench: " << e.what() << "\n";
		return 2;
	}
	if (child_ref.isSet()) return scalingChild(ctx, child_ref.getValue(), child_other.getValue());
	if (mrpt_child.isSet()) return mrptChild(mrpt_child.getValue(), child_other.getValue());
	if (fleet_child.isSet()) return fleetChild(ctx, fleet_child.getValue());
	if (!fs::is_directory(ctx.data + "/carmen_corrected"))
	{
		std::cerr << "multires_bench: no carmen_corrected logs under '" << ctx.data << "' (pass --data DIR)\n";
		const char* ci = std::getenv("CI");
		return ci && std::string(ci) == "true" ? 2 : 77;  // 77: ctest's "skipped" outside CI
	}
	try
	{
		const std::string out = out_arg.getValue();
		fs::create_directories(out);
		std::ofstream candidates(out + "/candidates.csv");
		candidates << candidateHeader();
		ctx.candidates = &candidates;
		if (calibration_arg.getValue())
		{
			// Every hypothesis refined, the structure always searched: the
			// decision is fitted on the candidates it sees when it runs (the
			// screen's included), of every pair, not on those a decision kept.
			ctx.options.exhaustive_search = true;
			ctx.calibration_only = true;
			CalibrationParts parts;
			parts.extra_negatives = extra_arg.getValue(), parts.live_pairs = live_pairs_arg.getValue();
			parts.coarser_pairs = coarser_pairs_arg.getValue(), parts.floor_plan_pairs = floor_plan_pairs_arg.getValue();
			parts.ros_pairs = ros_maps_arg.getValue(), parts.partial_pairs = partial_pairs_arg.getValue();
			parts.negatives_per_map = size_t(negatives_arg.getValue());
			writeCalibrationData(ctx, parts);
			std::cout << "wrote " << out << "/candidates.csv" << std::endl;
			return 0;
		}
		if (coarser_arg.isSet()) return coarserOnly(ctx, coarser_arg.getValue());
		if (partial_arg.isSet()) return partialOnly(ctx, partial_arg.getValue());
		if (floor_plans_arg.isSet()) return floorPlansOnly(ctx, floor_plans_arg.getValue());
		ctx.pad_to_cells = pad_arg.getValue();
		if (halmstad_arg.isSet()) return halmstadOnly(ctx, halmstad_arg.getValue(), negatives_arg.getValue());
		if (sets_arg.isSet()) return runAccuracySets(ctx, sets_arg.getValue());
		if (negatives_only_arg.isSet()) return negativesOnly(ctx);
		if (ros_maps_arg.isSet()) return rosMapsOnly(ctx);
		if (carpin_arg.isSet()) return carpinOnly(ctx);
		if (live_arg.isSet()) return liveOnly(ctx);
		if (scaling_arg.isSet())
		{
			runScalingCase(ctx, scaling_arg.getValue());
			return 0;
		}
		if (halmstad_fleets_arg.isSet())
		{
			writeHalmstadFleetSection(std::cout, halmstadFleets(ctx, siteList(halmstad_fleets_arg.getValue())),
									  ctx.fleet.resolvedFor(ctx.options.decision));
			return 0;
		}
		if (fleet_arg.isSet())
		{
			writeFleetSection(std::cout, runFleets(ctx));
			writeLiveSection(std::cout, runLiveLatency(carmenScans(ctx), ctx.quick ? 4 : 16, ctx.options, ctx.fleet));
			return 0;
		}
		return fullRun(ctx, out);
	}
	catch (const std::exception& e)
	{
		std::cerr << "multires_bench: " << e.what() << "\n";
		return 1;
	}
}
