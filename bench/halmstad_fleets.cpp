#include "halmstad_fleets.h"

#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/MapIO.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
namespace fs = std::filesystem;
using multires_map_merge::loadGridMap;

namespace
{
constexpr double kMixedFactors[] = {1.0, 2.0, 1.4};  // map i recorded ×kMixedFactors[i % 3]

/** A placement line of the child: "MAP i placed scale yaw x y parent". */
struct Placed
{
	bool placed = false;
	Similarity2D in_reference;
	int parent = -1;  //!< the map it was placed through
};

/** Scores map i's placement in the reference's frame against the annotation
 * (its fine map, as the coarser runs are judged). */
double score(FleetPlacing& tally, const Placed& p, const HalmstadData& data, const std::string& name,
		   const std::string& ref_name, const Similarity2D& joint_truth_px, double factor, const GridInFrame& fine,
		   int coarse_rows, int ref_rows)
{
	if (!p.placed)
	{
		++tally.not_placed;
		return NAN;
	}
	const HalmstadPair* truth = data.pair(name, ref_name);
	if (!truth) throw std::runtime_error("no annotation for " + name + " -> " + ref_name);
	const int fine_rows = int(fine.grid.getSizeY());
	const Similarity2D fine_in_ref =
		factor == 1.0 ? p.in_reference : p.in_reference.compose(fineToCoarse(factor, fine_rows, coarse_rows));
	const HalmstadOutcome o = judge(fine_in_ref, *truth, fine, ref_rows);
	(o.right ? tally.right : tally.wrong)++;
	tally.displacement_px.push_back(o.mean_displacement_px);
	tally.displacement_joint_truth_px.push_back(meanDisplacementPx(fine_in_ref, joint_truth_px, fine, ref_rows));
	return o.mean_displacement_px;
}

HalmstadFleetRun runFleet(
	const HalmstadData& data, const std::string& site, bool mixed, const FleetInChild& place, const std::string& dir)
{
	HalmstadFleetRun run;
	run.site = site, run.mixed_cells = mixed;
	const std::vector<std::string> names = data.sensorMaps(site);
	run.maps = names.size();
	const std::string fleet_dir = dir + "/" + site + (mixed ? "_mixed" : "_same");
	fs::remove_all(fleet_dir);
	fs::create_directories(fleet_dir);
	std::vector<double> factor(names.size(), 1.0);
	std::vector<GridInFrame> fine;
	std::vector<int> rows;
	for (size_t i = 0; i < names.size(); ++i)
	{
		if (mixed) factor[i] = kMixedFactors[i % 3];
		const std::string yaml =
			factor[i] == 1.0 ? data.yaml(names[i], dir) : coarserYaml(data, names[i], factor[i], dir);
		fine.push_back(loadGridMap(data.yaml(names[i], dir)));
		rows.push_back(int(factor[i] == 1.0 ? fine.back().grid.getSizeY() : loadGridMap(yaml).grid.getSizeY()));
		// The yaml's image is absolute or beside it in `dir`: copied there too.
		std::ifstream in(yaml);
		std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
		const std::string image = fs::path(yaml).replace_extension(".pgm").filename().string();
		if (factor[i] != 1.0) fs::copy_file(dir + "/" + image, fleet_dir + "/" + image, fs::copy_options::overwrite_existing);
		std::ofstream(fleet_dir + "/map_" + std::to_string(i) + ".yaml") << text;
	}
	const std::string out = place(fleet_dir);
	std::ifstream f(out);
	std::map<std::string, std::map<size_t, Placed>> placed;  // "MAP" (joint) or "TREE" → map → placement
	for (std::string line; std::getline(f, line);)
	{
		std::istringstream in(line);
		std::string tag;
		in >> tag;
		if (tag == "FLEET")
		{
			double placing = 0;
			in >> run.seconds >> run.pairs_aligned >> run.pairs_skipped >> run.peak_mb >> placing;
		}
		else if (tag == "EDGES")
			in >> run.pairs_confident >> run.pairs_dropped;
		else if (tag == "MAP" || tag == "TREE")
		{
			size_t i = 0;
			Placed p;
			in >> i >> p.placed >> p.in_reference.scale >> p.in_reference.yaw >> p.in_reference.t.x() >> p.in_reference.t.y() >>
				p.parent;
			placed[tag][i] = p;
		}
	}
	if (!(run.seconds > 0)) throw std::runtime_error("Halmstad fleet " + site + " failed (see " + out + ")");
	const std::vector<Similarity2D> truth = data.jointlyToFirst(names);
	run.annotation_disagreement_px = annotationDisagreementPx(data, names, fine);
	for (size_t i = 1; i < names.size(); ++i)
	{
		const double joint = score(
			run.joint, placed["MAP"][i], data, names[i], names[0], truth[i], factor[i], fine[i], rows[i], rows[0]);
		const double tree = score(
			run.tree, placed["TREE"][i], data, names[i], names[0], truth[i], factor[i], fine[i], rows[i], rows[0]);
		std::cout << "  " << names[i] << ": " << joint << " px (tree alone " << tree << "; against every annotated pair "
				  << run.joint.displacement_joint_truth_px.back() << ", tree alone "
				  << run.tree.displacement_joint_truth_px.back() << ") through map " << placed["MAP"][i].parent
				  << std::endl;
	}
	fs::remove_all(fleet_dir);
	return run;
}

double largest(const std::vector<double>& v) { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); }

std::string oneDecimal(double v)
{
	if (!std::isfinite(v)) return "–";
	std::ostringstream s;
	s.setf(std::ios::fixed);
	s.precision(1);
	s << v;
	return s.str();
}

std::string placingCells(const FleetPlacing& p, size_t others)
{
	return std::to_string(p.right) + " / " + std::to_string(others) + " | " + std::to_string(p.wrong) + " | " +
		std::to_string(p.not_placed) + " | " + oneDecimal(median(p.displacement_px)) + " | " +
		oneDecimal(largest(p.displacement_px));
}
}  // namespace

std::vector<HalmstadFleetRun> runHalmstadFleets(
	const HalmstadData& data, const std::vector<std::string>& sites, bool mixed, const FleetInChild& place,
	const std::string& dir)
{
	std::vector<HalmstadFleetRun> runs;
	for (const bool m : mixed ? std::vector<bool>{false, true} : std::vector<bool>{false})
		for (const auto& site : sites)
		{
			runs.push_back(runFleet(data, site, m, place, dir));
			const auto& r = runs.back();
			std::cout << "halmstad fleet " << site << (m ? " mixed cells" : "") << ": " << r.joint.right << "/"
					  << r.maps - 1 << " right, " << r.joint.wrong << " wrong, displacement median "
					  << median(r.joint.displacement_px) << " max " << largest(r.joint.displacement_px)
					  << " px (tree alone: max " << largest(r.tree.displacement_px) << "); " << r.pairs_aligned
					  << " pairs aligned, " << r.seconds << " s, " << r.peak_mb << " MB" << std::endl;
		}
	return runs;
}

void writeHalmstadFleetSection(
	std::ostream& md, const std::vector<HalmstadFleetRun>& runs, const multires_map_merge::FleetParams& placed_with)
{
	const multires_map_merge::FleetParams& fleet = placed_with;
	md << "\n## Fleets of real maps (Halmstad)\n\n"
	   << "Every sensor map of a site in one placement (`placeFleet` + `fuseFleet` in a fresh process, as "
		  "`gridmap-merge MAP_01 … MAP_n` runs it), the first map the reference; each other map's placement is "
		  "judged against the annotated similarity to the reference as the pairs are (mean displacement of its "
		  "occupied pixels, px of 5 cm). *Mixed cells*: the maps recorded ×1, ×2, ×1.4 in turn, all stated "
		  "0.05 m. *Tree alone*: the same pairs, each map placed through its one most confident path (joint "
		  "refinement off). *Dropped by a cycle*: confident pairs that disagree with the tree at the map's walls (RMS) "
		  "by more than the cycle's tolerance (each pair's `cycle_tolerance_per_rmse` ("
	   << fleet.cycle_tolerance_per_rmse << ") × its edge RMSE, added in quadrature around the cycle, within "
	   << fleet.cycle_tolerance_cells << "–" << fleet.maxToleranceCells() << " cells); "
		  "the joint refinement uses only the pairs kept. *Against every annotated pair*: the same displacement "
		  "against the maps placed from all the site's annotated correspondences at once (least squares, the "
		  "reference fixed), an annotation consistent around every cycle. *Annotations' own disagreement*: how far one "
		  "pair's annotated fit (a map to the reference) and its composition through a third map put the map's "
		  "occupied pixels (median over every map and third map; bent maps, 14–27 correspondences a pair): a "
		  "displacement of that size is within what the annotations themselves disagree on. Each map's "
		  "displacements and the map it was placed through are printed as the section runs.\n\n"
	   << "| site | cells | right | wrong | not placed | displacement median [px] | max [px] | against every "
		  "annotated pair: median [px] | max [px] | annotations' own disagreement [px] | tree alone: right | "
		  "wrong | not placed | median [px] | max [px] | pairs aligned | confident | of which dropped by a cycle | pairs skipped | "
		  "time [s] | peak RSS [MB] |\n"
	   << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& r : runs)
		md << "| " << r.site << " | " << (r.mixed_cells ? "mixed" : "same") << " | " << placingCells(r.joint, r.maps - 1)
		   << " | " << oneDecimal(median(r.joint.displacement_joint_truth_px)) << " | "
		   << oneDecimal(largest(r.joint.displacement_joint_truth_px)) << " | "
		   << oneDecimal(r.annotation_disagreement_px) << " | " << placingCells(r.tree, r.maps - 1) << " | " << r.pairs_aligned << " | " << r.pairs_confident << " | "
		   << r.pairs_dropped << " | " << r.pairs_skipped
		   << " | " << oneDecimal(r.seconds) << " | " << oneDecimal(r.peak_mb) << " |\n";
}

}  // namespace multires_bench
