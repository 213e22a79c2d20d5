#include "floor_plans.h"

#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <algorithm>
#include <iostream>
#include <map>

namespace multires_bench
{
using multires_map_merge::CScalingGridMapAligner;

namespace
{
FloorPlanRun alignOnPlan(
	const HalmstadData& data, const std::string& plan_site, const std::string& sensor,
	const CScalingGridMapAligner& aligner, const std::string& dir)
{
	FloorPlanRun run;
	run.site = siteOf(sensor);
	run.plan = HalmstadData::floorPlan(plan_site);
	run.sensor = sensor;
	run.positive = plan_site == run.site;
	const GridInFrame plan = multires_map_merge::loadGridMap(data.yaml(run.plan, dir));
	const GridInFrame map = multires_map_merge::loadGridMap(data.yaml(sensor, dir));
	mrpt::system::CTicTac clock;
	const auto r = aligner.alignScaled(plan, map);
	run.seconds = clock.Tac();
	run.merged = r.success;
	run.confidence = r.confidence;
	if (const HalmstadPair* truth = run.positive ? data.pair(sensor, run.plan) : nullptr; truth && r.candidates.size())
		run.outcome = judge(r.metric, *truth, map, static_cast<int>(plan.grid.getSizeY()));
	std::cout << "floor plan " << run.plan << " <- " << sensor << ": "
			  << (run.positive ? (run.merged ? (run.outcome.right ? "merged right" : "MERGED WRONG") : "refused")
						   : (run.merged ? "MERGED (false)" : "refused (negative)"))
			  << " disp " << run.outcome.mean_displacement_px << " px, conf " << r.confidence << ", " << run.seconds
			  << " s" << std::endl;
	return run;
}
}  // namespace

std::vector<FloorPlanRun> runFloorPlans(
	const HalmstadData& data, const std::vector<std::string>& sites,
	const CScalingGridMapAligner::TConfigParams& options, const std::string& dir)
{
	CScalingGridMapAligner aligner;
	aligner.options = options;
	std::vector<FloorPlanRun> runs;
	for (const auto& site : sites)
		for (const auto& sensor : data.sensorMaps(site))
			for (const auto& plan_site : data.sites())
				runs.push_back(alignOnPlan(data, plan_site, sensor, aligner, dir));
	return runs;
}

FloorPlanTotals floorPlanTotals(const std::vector<FloorPlanRun>& runs)
{
	FloorPlanTotals t;
	for (const auto& r : runs)
	{
		if (!r.positive)
		{
			++t.negatives, t.negatives_merged += r.merged;
			continue;
		}
		const bool right = r.merged && r.outcome.right;
		t.merged_wrong += r.merged && !r.outcome.right;
		if (isCalibrationSite(r.site))
			++t.calibration_pairs, t.calibration_right += right;
		else
			++t.acceptance_pairs, t.acceptance_right += right;
	}
	return t;
}

void writeFloorPlanSection(std::ostream& md, const std::vector<FloorPlanRun>& runs)
{
	std::map<std::string, PairTally> rows;
	for (const auto& r : runs)
		if (r.positive) rows[r.site].add(r.merged, r.outcome.right);
	md << "\n## Floor plans (Halmstad layouts)\n\n"
	   << "Each sensor map (OTHER) placed on its building's floor plan (REF: the `layout` PNG saved for map_server as "
		  "drawn, transparent outside = unknown), both stated at 0.05 m: the scale between them, 0.63–1.59, comes from "
		  "the content. Judged against the annotated similarity as the sensor pairs are. E5 and HIH are calibration "
		  "sites, **F5 and KPT4A acceptance**.\n\n"
	   << "| site | role | pairs | merged right | refused | merged wrong |\n|---|---|---|---|---|---|\n";
	for (const auto& site : {"E5", "HIH", "F5", "KPT4A"})
		if (rows.count(site))
		{
			const PairTally& r = rows[site];
			md << "| " << site << " | " << (isCalibrationSite(site) ? "calibration" : "**acceptance**") << " | "
			   << r.pairs << " | " << r.right << " | " << r.refused << " | " << r.wrong << " |\n";
		}
	const FloorPlanTotals t = floorPlanTotals(runs);
	md << "\nEvery sensor map against the other sites' plans: **" << t.negatives_merged << " merged / " << t.negatives
	   << "**.\n";
}

}  // namespace multires_bench
