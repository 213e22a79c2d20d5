#include "coarser_other.h"

#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
using multires_map_merge::CScalingGridMapAligner;
namespace fs = std::filesystem;


std::vector<CoarserRun> runCoarserOther(
	const HalmstadData& data, const std::vector<std::string>& sites, const std::vector<double>& factors,
	const CScalingGridMapAligner::TConfigParams& options, const std::string& dir, const CoarserCandidatesSink& sink)
{
	CScalingGridMapAligner aligner;
	aligner.options = options;
	std::vector<CoarserRun> runs;
	for (const double factor : factors)
		for (const auto& site : sites)
			for (const auto& p : data.unorderedPairs(site))
			{
				CoarserRun run;
				run.site = site, run.ref = p.dst, run.other = p.src, run.factor = factor;
				const GridInFrame ref = multires_map_merge::loadGridMap(data.yaml(p.dst, dir));
				const GridInFrame fine = multires_map_merge::loadGridMap(data.yaml(p.src, dir));
				const GridInFrame coarse = multires_map_merge::loadGridMap(coarserYaml(data, p.src, factor, dir));
				mrpt::system::CTicTac clock;
				const auto r = aligner.alignScaled(ref, coarse);
				run.seconds = clock.Tac();
				run.merged = r.success;
				const Similarity2D fine_in_coarse =
					fineToCoarse(factor, int(fine.grid.getSizeY()), int(coarse.grid.getSizeY()));
				const int ref_rows = int(ref.grid.getSizeY());
				if (r.candidates.size()) run.outcome = judge(r.metric.compose(fine_in_coarse), p, fine, ref_rows);
				if (sink)
					sink(run, ref, coarse, r, [&](const Similarity2D& cells) {
						const HalmstadOutcome o =
							judge(candidateMetric(ref, cells, coarse).compose(fine_in_coarse), p, fine, ref_rows);
						return std::pair<double, bool>{o.mean_displacement_px, o.right};
					});
				std::cout << "coarser x" << factor << " " << run.ref << " <- " << run.other << ": "
						  << (run.merged ? (run.outcome.right ? "merged right" : "MERGED WRONG") : "refused") << " disp "
						  << run.outcome.mean_displacement_px << " px, scale " << r.cells.scale << ", " << run.seconds
						  << " s" << std::endl;
				runs.push_back(run);
			}
	return runs;
}

CoarserTotals coarserTotals(const std::vector<CoarserRun>& runs, double factor, bool calibration_sites)
{
	CoarserTotals t;
	for (const auto& r : runs)
		if (r.factor == factor && isCalibrationSite(r.site) == calibration_sites)
			++t.pairs, t.right += r.merged && r.outcome.right, t.wrong += r.merged && !r.outcome.right;
	return t;
}

void writeCoarserSection(std::ostream& md, const std::vector<CoarserRun>& runs)
{
	std::map<std::pair<double, std::string>, PairTally> rows;
	for (const auto& r : runs) rows[{r.factor, r.site}].add(r.merged, r.outcome.right);
	md << "\n## OTHER recorded as a coarser grid (Halmstad)\n\n"
	   << "The sensor pairs above with OTHER resampled as a coarser robot would record it (a coarse cell is occupied "
		  "if any fine cell in it is, else free if any is), cells ×factor larger, its stated resolution left at "
		  "0.05 m (wrong). Judged against the annotation of the fine maps.\n\n"
	   << "| cells of OTHER | site | role | pairs | merged right | refused | merged wrong |\n|---|---|---|---|---|---|---|\n";
	for (const auto& [key, r] : rows)
		md << "| ×" << key.first << " | " << key.second << " | "
		   << (isCalibrationSite(key.second) ? "calibration" : "**acceptance**") << " | " << r.pairs << " | " << r.right
		   << " | " << r.refused << " | " << r.wrong << " |\n";
}

}  // namespace multires_bench
