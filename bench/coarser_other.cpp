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

namespace
{
/** The sensor map's PNG (0 occupied, 127 unknown, 255 free) recorded with
 * cells `factor` times larger, as a map_server file stated at 0.05 m. */
std::string coarserMap(const HalmstadData& data, const std::string& map, double factor, const std::string& dir)
{
	std::ostringstream name;
	name << map << "_x" << factor;
	const std::string yaml = dir + "/" + name.str() + ".yaml";
	if (fs::exists(yaml)) return yaml;
	const cv::Mat fine = cv::imread(data.png(map), cv::IMREAD_GRAYSCALE);
	if (fine.empty()) throw std::runtime_error("'" + data.png(map) + "': cannot read");
	const int rows = int(std::ceil(fine.rows / factor)), cols = int(std::ceil(fine.cols / factor));
	cv::Mat occupied(rows, cols, CV_8U, cv::Scalar(0)), free(rows, cols, CV_8U, cv::Scalar(0));
	for (int v = 0; v < fine.rows; ++v)
		for (int u = 0; u < fine.cols; ++u)
		{
			// Coarse cell j spans fine cells [j·factor, (j+1)·factor).
			const int cv = std::min(rows - 1, int(v / factor)), cu = std::min(cols - 1, int(u / factor));
			const uint8_t p = fine.at<uint8_t>(v, u);
			if (p < 64) occupied.at<uint8_t>(cv, cu) = 1;
			else if (p > 191) free.at<uint8_t>(cv, cu) = 1;
		}
	cv::Mat coarse(rows, cols, CV_8U, cv::Scalar(127));
	coarse.setTo(255, free);
	coarse.setTo(0, occupied);
	fs::create_directories(dir);
	const std::string pgm = dir + "/" + name.str() + ".pgm";
	if (!cv::imwrite(pgm, coarse)) throw std::runtime_error("'" + pgm + "': cannot write");
	std::ofstream(yaml) << "image: " << fs::path(pgm).filename().string() << "\nresolution: " << kHalmstadResolution
						<< "\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
	return yaml;
}

/** The fine map's frame into the coarse map's (both read at 0.05 m, origin
 * 0, +y up from the bottom row): x / factor, and y measured from the top
 * edge, which both share. */
Similarity2D fineToCoarse(double factor, int fine_rows, int coarse_rows)
{
	const double r = kHalmstadResolution;
	return Similarity2D(1 / factor, 0, {0, (coarse_rows - fine_rows / factor) * r});
}
}  // namespace

std::vector<CoarserRun> runCoarserOther(
	const HalmstadData& data, const std::vector<std::string>& sites, const std::vector<double>& factors,
	const CScalingGridMapAligner::TConfigParams& options, const std::string& dir)
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
				const GridInFrame coarse = multires_map_merge::loadGridMap(coarserMap(data, p.src, factor, dir));
				mrpt::system::CTicTac clock;
				const auto r = aligner.alignScaled(ref, coarse);
				run.seconds = clock.Tac();
				run.merged = r.success;
				if (r.candidates.size())
				{
					const Similarity2D fine_in_ref = r.metric.compose(fineToCoarse(
						factor, int(fine.grid.getSizeY()), int(coarse.grid.getSizeY())));
					run.outcome = judge(fine_in_ref, p, fine, int(ref.grid.getSizeY()));
				}
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
