#include "partial_maps.h"

#include "map_file.h"

#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>

namespace multires_bench
{
using multires_map_merge::CScalingGridMapAligner;
namespace fs = std::filesystem;

namespace
{
constexpr uint8_t kUnknownGrey = 127, kOccupiedBelow = 64;  // the sensor PNGs: 0 occupied, 127 unknown, 255 free

cv::Mat readGrey(const std::string& png)
{
	const cv::Mat img = cv::imread(png, cv::IMREAD_GRAYSCALE);
	if (img.empty()) throw std::runtime_error("'" + png + "': cannot read");
	return img;
}

/** Half `k` (0, 1) of the box around what the map knows, cut across its longer side (image pixels). */
cv::Rect halfOfKnown(const cv::Mat& img, size_t k)
{
	std::vector<cv::Point> known;
	cv::findNonZero(img != kUnknownGrey, known);
	const cv::Rect box = cv::boundingRect(known);
	cv::Rect half = box;
	if (box.width >= box.height)
		half.width = box.width / 2, half.x += k ? half.width : 0, half.width = k ? box.width - half.width : half.width;
	else
		half.height = box.height / 2, half.y += k ? half.height : 0, half.height = k ? box.height - half.height : half.height;
	return half;
}

/** The half's occupied pixels, in the whole image's pixels. */
std::vector<Eigen::Vector2d> occupiedIn(const cv::Mat& img, const cv::Rect& half)
{
	std::vector<Eigen::Vector2d> out;
	for (int v = half.y; v < half.y + half.height; ++v)
		for (int u = half.x; u < half.x + half.width; ++u)
			if (img.at<uint8_t>(v, u) < kOccupiedBelow) out.emplace_back(u, v);
	return out;
}

double shareOnKnown(const std::vector<Eigen::Vector2d>& px, const Similarity2D& to_ref_px, const cv::Mat& ref)
{
	size_t on = 0;
	for (const auto& p : px)
	{
		const Eigen::Vector2d q = to_ref_px(p);
		const int u = int(std::lround(q.x())), v = int(std::lround(q.y()));
		on += u >= 0 && v >= 0 && u < ref.cols && v < ref.rows && ref.at<uint8_t>(v, u) != kUnknownGrey;
	}
	return px.empty() ? 0.0 : double(on) / px.size();
}

}  // namespace

std::string halfName(const std::string& map, size_t k) { return map + "_half" + std::to_string(k + 1); }

MapHalf writeHalf(const HalmstadData& data, const std::string& map, size_t k, const std::string& dir)
{
	const cv::Mat img = readGrey(data.png(map));
	const cv::Rect half = halfOfKnown(img, k);
	MapHalf out;
	out.occupied = occupiedIn(img, half);
	out.whole_rows = img.rows;
	fs::create_directories(dir);
	const std::string name = halfName(map, k);
	out.yaml = writeImagePart(img, half, kHalmstadResolution, dir + "/" + name);
	return out;
}

std::vector<PartialRun> runPartialMaps(
	const HalmstadData& data, const std::vector<std::string>& sites,
	const CScalingGridMapAligner::TConfigParams& options, const std::string& dir, const PartialCandidatesSink& sink)
{
	CScalingGridMapAligner aligner;
	aligner.options = options;
	std::map<std::string, std::vector<MapHalf>> halves;
	std::map<std::string, cv::Mat> images;
	auto image = [&](const std::string& map) -> const cv::Mat& {
		auto it = images.find(map);
		return it != images.end() ? it->second : images.emplace(map, readGrey(data.png(map))).first->second;
	};
	auto halvesOf = [&](const std::string& map) -> const std::vector<MapHalf>& {
		auto& out = halves[map];
		for (size_t k = out.size(); k < kPartialHalves.size(); ++k) out.push_back(writeHalf(data, map, k, dir));
		return out;
	};
	std::vector<PartialRun> runs;
	// Aligned, and the candidates handed to the sink judged by `truth_px`
	// (the half's whole map's pixels → REF's; none for a negative).
	auto align = [&](PartialRun run, const std::string& ref_yaml, const MapHalf& half,
					 const std::optional<Similarity2D>& truth_px, int ref_rows) {
		const GridInFrame ref = multires_map_merge::loadGridMap(ref_yaml);
		const GridInFrame other = multires_map_merge::loadGridMap(half.yaml);
		mrpt::system::CTicTac clock;
		const auto r = aligner.alignScaled(ref, other);
		run.seconds = clock.Tac();
		run.merged = r.success;
		const auto displacement = [&](const Similarity2D& metric) {
			return meanDisplacementPx(metric, *truth_px, half.occupied, half.whole_rows, ref_rows);
		};
		if (truth_px && r.candidates.size()) run.displacement_px = displacement(r.metric);
		run.right = run.merged && run.displacement_px <= kRightPx;
		if (sink)
			sink(run, ref, other, r, [&](const Similarity2D& cells) {
				if (!truth_px) return std::pair<double, bool>{NAN, false};
				const double d = displacement(candidateMetric(ref, cells, other));
				return std::pair<double, bool>{d, d <= kRightPx};
			});
		return run;
	};
	for (const auto& site : sites)
	{
		for (const auto& p : data.unorderedPairs(site))
			for (size_t k = 0; k < kPartialHalves.size(); ++k)
			{
				const MapHalf& half = halvesOf(p.src)[k];
				PartialRun run;
				run.site = site, run.ref = p.dst, run.other = p.src, run.half = kPartialHalves[k], run.half_index = k;
				run.positive = true;
				run.inside_ref = shareOnKnown(half.occupied, p.src_to_dst_px, image(p.dst));
				const PartialRun done = align(run, data.yaml(p.dst, dir), half, p.src_to_dst_px, image(p.dst).rows);
				std::cout << "partial " << done.ref << " <- " << done.other << " " << done.half << " (inside REF "
						  << done.inside_ref << "): "
						  << (done.merged ? (done.right ? "merged right" : "MERGED WRONG") : "refused") << " disp "
						  << done.displacement_px << " px, " << done.seconds << " s" << std::endl;
				runs.push_back(done);
			}
		for (const auto& map : data.sensorMaps(site))
			for (const auto& other_site : data.sites())
			{
				if (other_site == site) continue;
				const std::string ref = data.sensorMaps(other_site).front();
				for (size_t k = 0; k < kPartialHalves.size(); ++k)
				{
					PartialRun run;
					run.site = site, run.ref = ref, run.other = map, run.half = kPartialHalves[k], run.half_index = k;
					const PartialRun done = align(run, data.yaml(ref, dir), halvesOf(map)[k], std::nullopt, 0);
					if (done.merged)
						std::cout << "partial " << ref << " <- " << map << " " << done.half << ": MERGED (false)" << std::endl;
					runs.push_back(done);
				}
			}
	}
	return runs;
}

PartialTotals partialTotals(const std::vector<PartialRun>& runs, const std::string& site)
{
	PartialTotals t;
	for (const auto& r : runs)
	{
		if (!site.empty() && r.site != site) continue;
		if (!r.positive)
		{
			++t.negatives, t.negatives_merged += r.merged;
			continue;
		}
		++t.positives, t.right += r.right, t.wrong += r.merged && !r.right;
		if (r.inside_ref >= kMostlyInside) ++t.mostly_inside, t.mostly_inside_right += r.right;
	}
	return t;
}

void writePartialSection(std::ostream& md, const std::vector<PartialRun>& runs)
{
	md << "\n## Partial maps (Halmstad sensor maps cut in half)\n\n"
	   << "A robot that explored part of a building against another robot's whole map of it. Each sensor map's known "
		  "extent is cut across its longer side into two halves, each a map_server file of its own size whose origin "
		  "puts it where it lies in the whole map's frame. OTHER = each half of the earlier map of every same-site "
		  "pair, REF = the later map; **right** = merged with the half's occupied pixels within 40 px (mean) of where "
		  "the annotation puts them. *REF saw most of it*: the pairs where the annotation puts at least "
		  << int(100 * kMostlyInside)
		  << " % of the half's occupied pixels on REF's known space (in the others REF saw less than half of what the "
			 "half shows). Every half also against the first sensor map of each other site (must not merge). The E5 and "
			 "HIH halves are in the decision's calibration data; F5 and KPT4A's never.\n\n"
	   << "| site | role | pairs | merged right | refused | merged wrong | REF saw most of it: merged right | other "
		  "sites' maps merged | median time [s] |\n|---|---|---|---|---|---|---|---|---|\n";
	std::map<std::string, std::vector<double>> seconds;
	for (const auto& r : runs) seconds[r.site].push_back(r.seconds);
	for (const auto& [site, secs] : seconds)
	{
		const PartialTotals t = partialTotals(runs, site);
		md << "| " << site << " | " << (isCalibrationSite(site) ? "calibration" : "**acceptance**") << " | "
		   << t.positives << " | " << t.right << " | " << t.positives - t.right - t.wrong << " | " << t.wrong << " | "
		   << t.mostly_inside_right << " / " << t.mostly_inside << " | " << t.negatives_merged << " / " << t.negatives
		   << " | " << std::fixed << std::setprecision(2) << median(secs) << std::defaultfloat << " |\n";
	}
}

}  // namespace multires_bench
