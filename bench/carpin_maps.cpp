#include "carpin_maps.h"

#include "carpin_data.h"
#include "halmstad.h"

#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

namespace
{
std::vector<CarpinPlace> places()
{
	using carpin::intelCopyToIntel;
	return {
		{"ap_hill", {"robot0_cast", "robot1_cast", "robot2_cast", "robot3_cast"}, std::vector<Similarity2D>(4),
		 carpin::kApHillRoughCells},
		{"intel",
		 {"intel", "intel30", "intel90"},
		 {intelCopyToIntel("intel"), intelCopyToIntel("intel30"), intelCopyToIntel("intel90")},
		 1},
		{"UC Merced", {"LongCorridor1", "LongCorridor2", "LongRun6", "LongRun7"}, {}, 0},
	};
}

double meanDisplacementCells(
	const std::vector<Eigen::Vector2d>& points, const Similarity2D& a, const Similarity2D& b, double cell)
{
	double sum = 0;
	for (const auto& p : points) sum += (a.apply(p) - b.apply(p)).norm();
	return sum / double(std::max<size_t>(1, points.size())) / cell;
}

using Maps = std::map<std::string, GridInFrame>;

CarpinRun runPair(
	const BenchContext& ctx, const Maps& maps, const CarpinPlace& place, size_t ref, size_t other)
{
	CarpinRun run;
	run.place = place.name, run.ref = place.maps[ref], run.other = place.maps[other];
	run.positive = true;
	const GridInFrame &r = maps.at(run.ref), &o = maps.at(run.other);
	mrpt::system::CTicTac clock;
	const auto res = ctx.aligner().alignScaled(r, o);
	run.seconds = clock.Tac();
	run.merged = res.success, run.confidence = res.confidence, run.metric = res.metric;
	run.has_truth = !place.truth_to_first.empty();
	if (run.has_truth && res.success)
	{
		const Similarity2D truth_cells = place.truth_to_first[ref].inverse().compose(place.truth_to_first[other]);
		run.displacement_cells = meanDisplacementCells(
			occupiedPointsInMapFrame(o), res.metric, candidateMetric(r, truth_cells, o), r.grid.getResolution());
		run.right = run.displacement_cells <= place.right_within_cells;
	}
	return run;
}

CarpinRun runNegative(const BenchContext& ctx, const Maps& maps, const std::string& place, const std::string& ref,
					  const std::string& other)
{
	CarpinRun run;
	run.place = place, run.ref = ref, run.other = other;
	mrpt::system::CTicTac clock;
	const auto res = ctx.aligner().alignScaled(maps.at(ref), maps.at(other));
	run.seconds = clock.Tac();
	run.merged = res.success, run.confidence = res.confidence;
	return run;
}

/** Over every ordered triple of a place's merged pairs: how far a ← c and
 * a ← b ∘ b ← c put c's occupied cells apart. */
CarpinCycles closeCycles(const Maps& maps, const CarpinPlace& place, const std::vector<CarpinRun>& runs)
{
	CarpinCycles cycles;
	std::map<std::pair<std::string, std::string>, Similarity2D> merged;
	for (const auto& r : runs)
		if (r.positive && r.place == place.name && r.merged) merged[{r.ref, r.other}] = r.metric;
	for (const auto& a : place.maps)
		for (const auto& b : place.maps)
			for (const auto& c : place.maps)
			{
				const auto ab = merged.find({a, b}), bc = merged.find({b, c}), ac = merged.find({a, c});
				if (a == b || b == c || a == c || ab == merged.end() || bc == merged.end() || ac == merged.end())
					continue;
				const double d = meanDisplacementCells(
					occupiedPointsInMapFrame(maps.at(c)), ac->second, ab->second.compose(bc->second),
					maps.at(a).grid.getResolution());
				cycles.worst_cells = std::max(cycles.worst_cells, d);
				++cycles.closed;
			}
	return cycles;
}

void printRun(const CarpinRun& r)
{
	std::cout << "carpin " << r.ref << " <- " << r.other << ": "
			  << (r.positive ? (!r.merged ? "refused" : !r.has_truth ? "merged (no truth)" : r.right ? "merged right" : "MERGED WRONG")
						   : (r.merged ? "MERGED (other place)" : "refused (other place)"))
			  << ", " << r.displacement_cells << " cells from the truth, confidence " << r.confidence << ", "
			  << r.seconds << " s" << std::endl;
}
}  // namespace

CarpinResult runCarpinMaps(const BenchContext& ctx)
{
	const std::string dir = ctx.tempDir("carpin");
	fs::create_directories(dir);
	const auto all = places();
	Maps maps;
	for (const auto& place : all)
		for (const auto& m : place.maps)
			maps.emplace(m, loadGridMap(carpin::writeAsMapServer(ctx.data + "/carpin_mapmerge/" + m + ".txt.gz", dir, m)));
	fs::remove_all(dir);
	CarpinResult result;
	for (const auto& place : all)
	{
		for (size_t a = 0; a < place.maps.size(); ++a)
			for (size_t b = 0; b < place.maps.size(); ++b)
				if (a != b) printRun(result.runs.emplace_back(runPair(ctx, maps, place, a, b)));
		result.cycles[place.name] = closeCycles(maps, place, result.runs);
	}
	for (const auto& ref_place : all)
		for (const auto& other_place : all)
			if (&ref_place != &other_place)
				for (const auto& ref : ref_place.maps)
					for (const auto& other : other_place.maps)
						printRun(result.runs.emplace_back(runNegative(ctx, maps, ref_place.name, ref, other)));
	return result;
}

size_t carpinWrongMerges(const CarpinResult& result)
{
	size_t wrong = 0;
	for (const auto& r : result.runs) wrong += r.merged && (r.positive ? r.has_truth && !r.right : true);
	return wrong;
}

void writeCarpinSection(std::ostream& md, const CarpinResult& result)
{
	md << "\n## Carpin's map-merging maps (never tuned on)\n\n"
	   << "The test maps of Carpin's `mapmerge` (SOURCES.md 4), used to tune or calibrate nothing, each written as a "
		  "map_server file at 5 cm (their cell size is not stated). *ap_hill*: four partial maps of one run, written "
		  "roughly co-registered (best offsets within 6 cells, turns of a few degrees): **right** = merged with the "
		  "other map's occupied cells within the place's tolerance (mean) of where they lie, which tells the right "
		  "place from a wrong one, not how precisely. *intel*: the Intel lab and Carpin's exact copies of it shifted "
		  "and turned 90°. *UC Merced*: two runs of a corridor and two of a building with a hall, no truth. *Cycles*: "
		  "where a ← b, b ← c and a ← c all merged, how far a ← c and a ← b ∘ b ← c put c's walls apart (mean, in "
		  "cells of a). Every ordered pair of a place, and every map against every map of the other places (must not "
		  "merge).\n\n"
	   << "| place | pairs | merged | of which right (tolerance) | merged wrong | displacement of the right: median / "
		  "max [cells] | cycles closed | their largest disagreement [cells] | other places' maps merged | median "
		  "time [s] |\n|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& place : places())
	{
		size_t pairs = 0, merged = 0, right = 0, wrong = 0, negatives = 0, false_merges = 0;
		std::vector<double> disp, secs;
		for (const auto& r : result.runs)
		{
			if (r.place != place.name) continue;
			secs.push_back(r.seconds);
			if (!r.positive)
			{
				++negatives, false_merges += r.merged;
				continue;
			}
			++pairs, merged += r.merged;
			if (r.merged && r.has_truth) r.right ? (++right, disp.push_back(r.displacement_cells)) : (void)++wrong;
		}
		const bool truth = !place.truth_to_first.empty();
		const CarpinCycles& cycles = result.cycles.at(place.name);
		md << "| " << place.name << " | " << pairs << " | " << merged << " | "
		   << (truth ? std::to_string(right) + " (≤ " + num(place.right_within_cells, 0) + " cells)" : "no truth") << " | "
		   << (truth ? std::to_string(wrong) : "–") << " | "
		   << (disp.empty() ? std::string("–")
						   : num(median(disp), 2) + " / " + num(*std::max_element(disp.begin(), disp.end()), 2))
		   << " | " << cycles.closed << " | " << (cycles.closed ? num(cycles.worst_cells, 2) : "–") << " | "
		   << false_merges << " / " << negatives << " | " << num(median(secs), 2) << " |\n";
	}
}

}  // namespace multires_bench
